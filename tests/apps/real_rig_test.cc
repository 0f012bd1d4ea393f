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
#include "tests/support/program_run.h"
#include "tests/support/shared_data.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using testing_program::ProgramRun;

fs::path RealRigScratch() {
  return fs::temp_directory_path() /
         ("puzzlecal_real_rig_test_" + std::to_string(getpid()));
}

// This process's folder goes when its tests are done.
[[maybe_unused]] const ::testing::Environment* const kRealRigScratchCleanup =
    ::testing::AddGlobalTestEnvironment(
        new testing_program::RemoveAtEnd(RealRigScratch()));

TEST(RealRigTest, Bumblebee2UsesEveryWholeBoardFrameAndItsBaseline) {
  const std::string real = testing_data::SharedFolder("real");
  if (real.empty()) {
    PUZZLECAL_SKIP_WITHOUT_DATA(
        "no real photo set found (../shared/real, or $PUZZLECAL_DATA/real)");
  }
  const fs::path out = RealRigScratch() / "bb2.yaml";
  const ProgramRun run = testing_program::RunProgram(
      "calibrate-rig --images " + real + "/bb2/rig --board " + real +
          "/bb2/board.yaml --model pinhole-radtan --out " + out.string() +
          " --threads 2",
      RealRigScratch());
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  std::cout << run.all();
  // 11 pairs; in 04.jpg the second camera finds only part of the board
  // (a part of a plain checkerboard has no labels of its own).
  EXPECT_NE(run.all().find("shared frames: 0-1: 10"), std::string::npos)
      << run.all();
  EXPECT_NE(run.all().find("labels turned by half a turn"), std::string::npos)
      << run.all();
  EXPECT_NE(run.all().find("A PuzzleBoard has no such ambiguity"),
            std::string::npos)
      << run.all();
  const YAML::Node rig = YAML::LoadFile(out.string());
  const double baseline = rig["cameras"][1]["baseline_mm"].as<double>();
  const double sigma = rig["cameras"][1]["baseline_stddev_mm"].as<double>();
  EXPECT_NEAR(baseline, 120.04, 0.5);
  EXPECT_GT(sigma, 0);
  EXPECT_LT(sigma, 0.5);
}

}  // namespace
}  // namespace puzzlecal
