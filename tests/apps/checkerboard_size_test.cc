// A plain checkerboard file that does not match the photos: rendered
// photos of a 6 x 4 (inner corners) checkerboard calibrated with a file
// saying 10 x 10 or 7 x 5 are refused (bad input, exit 3) with a message
// naming both sizes and no camera file; the right file calibrates.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "apps/subcommand.h"
#include "camera/camera_models.h"
#include "sim/render.h"
#include "target/board.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using testing_program::ProgramPath;
using testing_program::ProgramRun;
using testing_program::RunProgram;

TEST(CheckerboardSize, WrongSizeFileIsRefusedNamingBothSizes) {
  const fs::path program = ProgramPath();
  if (program.empty() || !fs::exists(program)) GTEST_SKIP() << "no program";
  const fs::path dir =
      fs::temp_directory_path() /
      ("puzzlecal_checkerboard_size_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "images");
  const Board board =
      MakeBoard(BoardType::kCheckerboard, 6, 4, Eigen::Vector2i(0, 0), 0.03);
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.params = {560.0, 556.0, 321.0, 239.0, -0.08, 0.03, 0.0, 0.0, 0.0};
  camera.width = 640;
  camera.height = 480;
  const Eigen::Vector3d centre(0.5 * 5 * 0.03, 0.5 * 3 * 0.03, 0);
  int written = 0;
  for (int k = 0; k < 10; ++k) {
    const double ax = 0.45 * std::cos(0.7 * k), ay = 0.45 * std::sin(1.3 * k);
    const Eigen::Matrix3d rotation =
        (Eigen::AngleAxisd(ax, Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(ay, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rotation;
    pose.translation() = Eigen::Vector3d(0.03 * std::sin(k), 0.02 * std::cos(k),
                                         0.35 + 0.02 * k) -
                         rotation * centre;
    RenderOptions options;
    options.supersampling = 2;
    options.blur_sigma_px = 0.8;
    options.noise_sigma = 0.01;
    RenderSummary summary;
    const cv::Mat image =
        RenderBoard(board, camera, pose, options, nullptr, &summary);
    ASSERT_TRUE(summary.ok) << summary.reason;
    ASSERT_TRUE(cv::imwrite(
        (dir / "images" / ("view" + std::to_string(k) + ".png")).string(),
        image));
    ++written;
  }
  struct Case {
    const char* file;
    const char* yaml;
    const char* size;
  };
  for (const Case& c : std::vector<Case>{
           {"ten.yaml",
            "type: checkerboard\ncols: 10\nrows: 10\ntile_size_m: 0.0254\n",
            "10 x 10"},
           {"seven.yaml",
            "type: checkerboard\ncols: 7\nrows: 5\ntile_size_m: 0.03\n",
            "7 x 5"}}) {
    SCOPED_TRACE(c.file);
    std::ofstream(dir / c.file) << c.yaml;
    const fs::path camera_file = dir / "camera.yaml";
    const ProgramRun run = RunProgram(
        "calibrate --images " + (dir / "images").string() + " --board " +
            (dir / c.file).string() + " --out " + camera_file.string(),
        dir);
    EXPECT_EQ(run.exit_code, kExitBadInput) << run.out << run.err;
    EXPECT_NE(
        run.err.find((dir / c.file).string() + " gives a checkerboard of " +
                     c.size + " inner corners"),
        std::string::npos)
        << run.err;
    EXPECT_NE(run.err.find("complete lattice of 6 x 4 inner corners"),
              std::string::npos)
        << run.err;
    EXPECT_FALSE(fs::exists(camera_file));
  }
  // The right file calibrates.
  std::ofstream(dir / "right.yaml")
      << "type: checkerboard\ncols: 6\nrows: 4\ntile_size_m: 0.03\n";
  const ProgramRun right =
      RunProgram("calibrate --images " + (dir / "images").string() +
                     " --board " + (dir / "right.yaml").string() + " --out " +
                     (dir / "camera.yaml").string(),
                 dir);
  EXPECT_EQ(right.exit_code, kExitOk) << right.out << right.err;
  EXPECT_TRUE(fs::exists(dir / "camera.yaml"));
  EXPECT_EQ(written, 10);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace puzzlecal
