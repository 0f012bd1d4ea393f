// `puzzlecal calibrate-rig` on a real stereo head: the Bumblebee2 pairs of
// ../shared/real/bb2 (README there; BoofCV's baseline 120.04 mm, the
// maker's 120 mm). Its 6 x 4 plain checkerboard is symmetric under half a
// turn, and in some frames the two cameras label it in opposite
// orientations: the rig's poses settle which, and every frame in which
// both cameras find the whole board is used.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "apps/subcommand.h"
#include "tests/support/shared_data.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// $PUZZLECAL_DATA/real, else ../shared/real; "" when neither is a folder.
std::string RealFolder() { return testing_data::SharedFolder("real"); }

fs::path ProgramPath() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return self.parent_path().parent_path() / "apps" / "puzzlecal";
}

fs::path ScratchRoot() {
  return fs::temp_directory_path() /
         ("puzzlecal_real_rig_test_" + std::to_string(getpid()));
}

struct RunResult {
  int exit_code = -1;
  std::string output;
};

RunResult RunProgram(const std::string& arguments) {
  fs::create_directories(ScratchRoot());
  const fs::path log = ScratchRoot() / "run.log";
  const std::string command =
      ProgramPath().string() + " " + arguments + " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  RunResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(log);
  result.output.assign(std::istreambuf_iterator<char>(in),
                       std::istreambuf_iterator<char>());
  return result;
}

TEST(RealRigTest, Bumblebee2UsesEveryWholeBoardFrameAndItsBaseline) {
  const std::string real = RealFolder();
  if (real.empty()) {
    PUZZLECAL_SKIP_WITHOUT_DATA(
        "no real photo set found (../shared/real, or $PUZZLECAL_DATA/real)");
  }
  const fs::path out = ScratchRoot() / "bb2.yaml";
  const RunResult run =
      RunProgram("calibrate-rig --images " + real + "/bb2/rig --board " + real +
                 "/bb2/board.yaml --model pinhole-radtan --out " +
                 out.string() + " --threads 2");
  ASSERT_EQ(run.exit_code, kExitOk) << run.output;
  std::cout << run.output;
  // 11 pairs; in 04.jpg the second camera finds only part of the board
  // (a part of a plain checkerboard has no labels of its own).
  EXPECT_NE(run.output.find("shared frames: 0-1: 10"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("labels turned by half a turn"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("A PuzzleBoard has no such ambiguity"),
            std::string::npos)
      << run.output;
  const YAML::Node rig = YAML::LoadFile(out.string());
  const double baseline = rig["cameras"][1]["baseline_mm"].as<double>();
  const double sigma = rig["cameras"][1]["baseline_stddev_mm"].as<double>();
  EXPECT_NEAR(baseline, 120.04, 0.5);
  EXPECT_GT(sigma, 0);
  EXPECT_LT(sigma, 0.5);
}

}  // namespace
}  // namespace puzzlecal
