#include "util/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace puzzlecal {
namespace {

std::string MakeScratchFolder() {
  const std::string base =
      std::string(::testing::TempDir()) + "/atomic_file_test_XXXXXX";
  std::vector<char> name(base.begin(), base.end());
  name.push_back('\0');
  if (mkdtemp(name.data()) == nullptr) return "";
  return name.data();
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
}

TEST(AtomicFileTest, ReplacesTheFileAndLeavesNoTemporaryBehind) {
  const std::string dir = MakeScratchFolder();
  ASSERT_FALSE(dir.empty());
  const std::string path = dir + "/atomic.txt";
  std::string error;
  ASSERT_TRUE(WriteFileAtomically(path, "first", &error)) << error;
  ASSERT_TRUE(WriteFileAtomically(path, "second", &error)) << error;
  EXPECT_EQ(ReadAll(path), "second");
  std::remove(path.c_str());
  // Only the target was ever in the folder: it is empty again.
  EXPECT_EQ(rmdir(dir.c_str()), 0);
}

TEST(AtomicFileTest, FailuresNameThePathAndTheReason) {
  const std::string dir = MakeScratchFolder();
  ASSERT_FALSE(dir.empty());
  std::string error;
  const std::string missing = dir + "/no_such_folder/file.txt";
  EXPECT_FALSE(WriteFileAtomically(missing, "x", &error));
  EXPECT_NE(error.find(missing), std::string::npos) << error;
  EXPECT_NE(error.find("No such file"), std::string::npos) << error;
  EXPECT_FALSE(WriteFileAtomically(dir, "x", &error));
  EXPECT_NE(error.find("folder"), std::string::npos) << error;
  EXPECT_FALSE(WriteFileAtomically(dir + "/", "x", &error));
  EXPECT_NE(error.find("folder"), std::string::npos) << error;
  EXPECT_FALSE(WriteFileAtomically("", "x", &error));
  EXPECT_NE(error.find("empty path"), std::string::npos) << error;
  rmdir(dir.c_str());
}

}  // namespace
}  // namespace puzzlecal
