#ifndef PUZZLECAL_TESTS_SUPPORT_PROGRAM_RUN_H_
#define PUZZLECAL_TESTS_SUPPORT_PROGRAM_RUN_H_

// The end-to-end tests run the built program the way a user does: one shell
// command, its output and exit status read back.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>

#include "tests/support/files.h"

namespace puzzlecal {
namespace testing_program {

// <build>/apps/puzzlecal, found from this test program's own path (the tests
// live in <build>/tests/); empty when that path cannot be read.
inline std::filesystem::path ProgramPath() {
  std::error_code ec;
  const std::filesystem::path self =
      std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  return self.parent_path().parent_path() / "apps" / "puzzlecal";
}

// `s` as one word of a POSIX shell command, whatever characters it holds.
inline std::string Quote(const std::string& s) {
  std::string quoted = "'";
  for (char c : s) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

// What one run of the program printed and how it ended.
struct ProgramRun {
  int exit_code = -1;  // the exit status; 128 + the signal if one killed it
  std::string out;     // stdout
  std::string err;     // stderr
  // Both streams, stdout first (for messages to search and to print).
  std::string all() const { return out + err; }
};

// Runs `puzzlecal ARGUMENTS` (already quoted where needed) from the working
// directory with no input; its streams pass through files in `scratch_dir`
// (created if missing), which are removed afterwards.
inline ProgramRun RunProgram(const std::string& arguments,
                             const std::filesystem::path& scratch_dir) {
  std::filesystem::create_directories(scratch_dir);
  const std::filesystem::path out = scratch_dir / "stdout.txt";
  const std::filesystem::path err = scratch_dir / "stderr.txt";
  const std::string command = Quote(ProgramPath().string()) + " " + arguments +
                              " >" + Quote(out.string()) + " 2>" +
                              Quote(err.string()) + " </dev/null";
  const int status = std::system(command.c_str());
  ProgramRun run;
  run.exit_code =
      WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  run.out = testing_files::ReadFile(out);
  run.err = testing_files::ReadFile(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return run;
}

// Removes a scratch folder, with all in it, when the test program ends, so
// that the runs' folders do not pile up in the temporary directory:
//   const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(
//       new testing_program::RemoveAtEnd(ScratchRoot()));
class RemoveAtEnd : public ::testing::Environment {
 public:
  explicit RemoveAtEnd(std::filesystem::path folder)
      : folder_(std::move(folder)) {}
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(folder_, ec);
  }

 private:
  std::filesystem::path folder_;
};

}  // namespace testing_program
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_SUPPORT_PROGRAM_RUN_H_
