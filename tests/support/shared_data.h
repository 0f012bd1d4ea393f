#ifndef PUZZLECAL_TESTS_SUPPORT_SHARED_DATA_H_
#define PUZZLECAL_TESTS_SUPPORT_SHARED_DATA_H_

// Tests that read data the repository does not hold (the published
// PuzzleBoard codes, real photo sets) skip on a machine without it and fail
// where it must be present: under CI (the environment variable CI set, as
// .ci/run does), where a skip would hide a test that checked nothing.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace puzzlecal {
namespace testing_data {

// True when a missing data set is an error rather than a reason to skip.
inline bool SharedDataRequired() {
  const char* ci = std::getenv("CI");
  if (ci == nullptr) return false;
  const std::string value = ci;
  return !value.empty() && value != "0" && value != "false";
}

// $PUZZLECAL_DATA/<relative>, else ../shared/<relative> (from the working
// directory, the repository root); "" when neither is a folder.
inline std::string SharedFolder(const std::string& relative) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (const char* data = std::getenv("PUZZLECAL_DATA")) {
    const fs::path path = fs::path(data) / relative;
    if (fs::is_directory(path, ec)) return path.string();
  }
  const fs::path shared = fs::path("..") / "shared" / relative;
  return fs::is_directory(shared, ec) ? shared.string() : "";
}

}  // namespace testing_data
}  // namespace puzzlecal

// In a test body or SetUp: fails under CI, skips elsewhere; either way the
// test returns here. `message` says what is missing and how to get it.
#define PUZZLECAL_SKIP_WITHOUT_DATA(message)                      \
  do {                                                            \
    if (::puzzlecal::testing_data::SharedDataRequired()) {        \
      FAIL() << "required data missing (CI is set): " << message; \
    } else {                                                      \
      GTEST_SKIP() << message;                                    \
    }                                                             \
  } while (0)

#endif  // PUZZLECAL_TESTS_SUPPORT_SHARED_DATA_H_
