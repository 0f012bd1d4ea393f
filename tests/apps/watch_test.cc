// `puzzlecal calibrate --watch` end to end: the sample set's rendered
// photos copied into the watched folder one by one (and one of them again
// under another name), a line read back after each, until the verdict is
// good and the camera file is written. The program is the one built beside
// this test (<build>/apps/puzzlecal), run from the source folder.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "tests/support/files.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace watch_test {
namespace {

namespace fs = std::filesystem;
using testing_program::Quote;

fs::path Scratch() {
  return fs::temp_directory_path() /
         ("puzzlecal_watch_test_" + std::to_string(getpid()));
}

[[maybe_unused]] const ::testing::Environment* const kCleanup =
    ::testing::AddGlobalTestEnvironment(
        new testing_program::RemoveAtEnd(Scratch()));

// The next line the program printed ("" at its end).
std::string ReadLine(FILE* pipe) {
  std::string line;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) {
    line += buffer;
    if (!line.empty() && line.back() == '\n') break;
  }
  std::cout << line;
  return line;
}

TEST(CalibrateWatch, SaysWhereItStandsAfterEveryPhotoUntilGood) {
  const fs::path source = fs::absolute("testdata/sample");
  std::vector<fs::path> photos;
  for (const fs::directory_entry& entry : fs::directory_iterator(source)) {
    if (entry.path().extension() == ".png") photos.push_back(entry.path());
  }
  std::sort(photos.begin(), photos.end());
  ASSERT_GE(photos.size(), 12u);
  const fs::path in = Scratch() / "in";
  const fs::path out = Scratch() / "out";
  fs::create_directories(in);
  fs::create_directories(out);
  const std::string command =
      Quote(testing_program::ProgramPath().string()) + " calibrate --watch " +
      Quote(in.string()) + " --board " +
      Quote(
          fs::absolute("configs/boards/puzzleboard_23x16_30mm.yaml").string()) +
      " --out " + Quote((out / "camera.yaml").string()) +
      " --watch-idle 60 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  EXPECT_NE(ReadLine(pipe).find("watching"), std::string::npos);
  // The photos in order, the second one again (as a copy) after the third.
  std::vector<std::pair<fs::path, std::string>> arrivals;
  for (size_t k = 0; k < photos.size(); ++k) {
    arrivals.emplace_back(photos[k], photos[k].filename().string());
    if (k == 2) arrivals.emplace_back(photos[1], "again.png");
  }
  bool good = false, saw_duplicate = false, saw_not_used = false;
  bool saw_next = false;
  int line_number = 0;
  for (const auto& [photo, name] : arrivals) {
    fs::copy_file(photo, in / name);
    const std::string line = ReadLine(pipe);
    ASSERT_FALSE(line.empty()) << "the program ended early";
    ++line_number;
    EXPECT_EQ(
        line.rfind("[" + std::to_string(line_number) + "] " + name + ": ", 0),
        0u)
        << line;
    if (name == "again.png") {
      saw_duplicate =
          line.find("nearly the same pose as " +
                    photos[1].filename().string()) != std::string::npos;
    }
    saw_not_used |=
        line.find(": not used — code not recognised") != std::string::npos;
    if (line.find(" — next: board about") != std::string::npos) {
      saw_next = true;
      EXPECT_TRUE(fs::exists(out / "next_1.png"));
    }
    if (line.find("verdict good") != std::string::npos) {
      good = true;
      break;
    }
  }
  std::string rest;
  for (std::string line = ReadLine(pipe); !line.empty();
       line = ReadLine(pipe)) {
    rest += line;
  }
  const int status = pclose(pipe);
  EXPECT_TRUE(good) << "the verdict never became good";
  EXPECT_TRUE(saw_duplicate);
  EXPECT_TRUE(saw_not_used);  // sample_view_004 is meant to fail
  EXPECT_TRUE(saw_next);
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_NE(rest.find("the verdict is good: done"), std::string::npos);
  EXPECT_NE(rest.find("verdict: good"), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "camera.yaml"));
}

// A watch that ends before the verdict is good (five photos, then
// --watch-idle) names the next advised photo's picture by the path it was
// written to: with --out naming no folder, next_1.png in the working folder
// (it was printed as "/next_1.png").
TEST(CalibrateWatch, NamesTheNextPictureWhereItIsWritten) {
  const fs::path source = fs::absolute("testdata/sample");
  const fs::path work = Scratch() / "work";
  const fs::path in = work / "in";
  fs::create_directories(in);
  for (const char* name :
       {"sample_view_000.png", "sample_view_001.png", "sample_view_002.png",
        "sample_view_003.png", "sample_view_005.png"}) {
    fs::copy_file(source / name, in / name);
  }
  const fs::path log = Scratch() / "work.log";
  const std::string command =
      "cd " + Quote(work.string()) + " && " +
      Quote(testing_program::ProgramPath().string()) +
      " calibrate --watch in --board " +
      Quote(
          fs::absolute("configs/boards/puzzleboard_23x16_30mm.yaml").string()) +
      " --out camera.yaml --watch-idle 1 >" + Quote(log.string()) +
      " 2>&1 </dev/null";
  const int status = std::system(command.c_str());
  const std::string out = testing_files::ReadFile(log);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << out;
  EXPECT_NE(out.find("verdict: insufficient-data"), std::string::npos) << out;
  const std::string prefix = "next photo (";
  const size_t at = out.find(prefix);
  ASSERT_NE(at, std::string::npos) << out;
  const size_t end = out.find("): ", at);
  ASSERT_NE(end, std::string::npos) << out;
  const std::string picture =
      out.substr(at + prefix.size(), end - at - prefix.size());
  EXPECT_EQ(picture, "next_1.png") << out;
  EXPECT_TRUE(fs::exists(work / picture)) << out;
  EXPECT_TRUE(fs::exists(work / "camera.yaml")) << out;
}

}  // namespace
}  // namespace watch_test
}  // namespace puzzlecal
