// `puzzlecal undistort` and the choice of its target camera: on a render
// through a lens with strong barrel distortion the board's rows and columns,
// bent in the photo, come out straight; where the model has no inverse (the
// sample camera's image corners) the target covers the invertible region
// only, and every target pixel maps back to its own ray (no swirl).

#include "pipeline/undistort.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "formats/camera_yaml.h"
#include "pipeline/pipeline.h"
#include "sim/render.h"
#include "target/board.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

fs::path ProgramPath() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return self.parent_path().parent_path() / "apps" / "puzzlecal";
}

Camera BarrelCamera() {
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.params = {400.0, 400.0, 321.0, 238.0, -0.3, 0.08, 0.0, 0.0, 0.0};
  camera.width = 640;
  camera.height = 480;
  return camera;
}

// The sample set's camera as `scripts/demo.sh` calibrates it (90-degree
// field, k1 = -0.2): its radial distortion reaches a largest distorted radius
// of about 0.87, less than the image corners' 1.3: no inverse there.
Camera SampleCamera() {
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.params = {399.988,    400.383,     409.863,      294.090,    -0.199917,
                   0.00983836, 0.000606854, -0.000390849, 7.42599e-05};
  camera.width = 800;
  camera.height = 600;
  return camera;
}

// Largest distance of a board row's or column's corners from their
// straight line, over all rows and columns with 6 corners or more.
double WorstLineDeviation(const BoardObservation& observation) {
  std::map<int, std::vector<Eigen::Vector2d>> lines;
  for (size_t k = 0; k < observation.id.size(); ++k) {
    lines[observation.id[k].y()].push_back(observation.xy[k]);
    lines[100000 + observation.id[k].x()].push_back(observation.xy[k]);
  }
  double worst = 0;
  for (const auto& [key, points] : lines) {
    if (points.size() < 6) continue;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : points) mean += p;
    mean /= points.size();
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const auto& p : points) scatter += (p - mean) * (p - mean).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
    const Eigen::Vector2d normal = eig.eigenvectors().col(0);
    for (const auto& p : points) {
      worst = std::max(worst, std::abs(normal.dot(p - mean)));
    }
  }
  return worst;
}

TEST(UndistortTest, BoardLinesBecomeStraight) {
  const fs::path dir = fs::temp_directory_path() /
                       ("puzzlecal_undistort_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  const Board board = MakeBoard(BoardType::kPuzzleBoard, 23, 16,
                                Eigen::Vector2i(50, 100), 0.03);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d centre = board.Point(
      board.origin + Eigen::Vector2i(board.cols / 2, board.rows / 2));
  pose.translation() = Eigen::Vector3d(0, 0, 0.55) - pose.linear() * centre;
  RenderOptions render;
  render.supersampling = 2;
  render.blur_sigma_px = 0.7;
  render.noise_sigma = 0.005;
  RenderSummary summary;
  const cv::Mat photo =
      RenderBoard(board, BarrelCamera(), pose, render, nullptr, &summary);
  ASSERT_TRUE(summary.ok) << summary.reason;
  ASSERT_TRUE(cv::imwrite((dir / "in" / "view.png").string(), photo));
  std::string error;
  ASSERT_TRUE(WriteCameraFile((dir / "camera.yaml").string(),
                              CameraFileFormat::kOpenCv, BarrelCamera(),
                              CameraFileStats(), &error))
      << error;

  const std::string command = ProgramPath().string() + " undistort --camera " +
                              (dir / "camera.yaml").string() + " --images " +
                              (dir / "in").string() + " --out " +
                              (dir / "out").string() + " > " +
                              (dir / "log").string() + " 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;
  const cv::Mat undistorted =
      cv::imread((dir / "out" / "view.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(undistorted.empty());
  Camera target;
  ASSERT_TRUE(ReadCameraFile((dir / "out" / "undistorted_camera.yaml").string(),
                             &target, &error))
      << error;
  for (size_t k = 4; k < target.params.size(); ++k) {
    EXPECT_EQ(target.params[k], 0.0);
  }

  ImageResult before, after;
  ProcessGreyImage(photo, board, PipelineOptions(), &before);
  ProcessGreyImage(undistorted, board, PipelineOptions(), &after);
  ASSERT_EQ(before.outcome, ImageOutcome::kUsable) << before.reason;
  ASSERT_EQ(after.outcome, ImageOutcome::kUsable) << after.reason;
  ASSERT_GT(after.decode.observation.id.size(), 100u);
  const double bent = WorstLineDeviation(before.decode.observation);
  const double straight = WorstLineDeviation(after.decode.observation);
  EXPECT_GT(bent, 3.0);       // the photo's rows bow by pixels
  EXPECT_LT(straight, 0.25);  // the undistorted rows are straight
  // The target camera puts each corner where a distortion-free pinhole with
  // the render's pose puts it.
  const auto& k = target.params;
  double worst = 0;
  for (size_t i = 0; i < after.decode.observation.id.size(); ++i) {
    const Eigen::Vector3d p =
        pose * board.Point(after.decode.observation.id[i]);
    const Eigen::Vector2d expected(k[0] * p.x() / p.z() + k[2],
                                   k[1] * p.y() / p.z() + k[3]);
    worst = std::max(worst, (expected - after.decode.observation.xy[i]).norm());
  }
  EXPECT_LT(worst, 0.3);
  fs::remove_all(dir);
}

TEST(UndistortTest, NoSwirlWhereTheModelHasNoInverse) {
  const Camera source = SampleCamera();
  // OpenCV's choice for alpha = 1 goes through the corners that have no
  // inverse and collapses the focal length (the premise of this test).
  const auto& p = source.params;
  const cv::Matx33d k(p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
  const cv::Mat cv_k = cv::getOptimalNewCameraMatrix(
      k, std::vector<double>{p[4], p[5], p[6], p[7], p[8]}, cv::Size(800, 600),
      1.0);
  EXPECT_LT(cv_k.at<double>(0, 0), 100.0);

  for (double alpha : {0.0, 0.5, 1.0}) {
    UndistortOptions options;
    options.alpha = alpha;
    const UndistortResult result = ChooseUndistortTarget(source, options);
    EXPECT_LT(result.border_invertible_fraction, 1.0);
    EXPECT_NE(result.Summary(options).find("no inverse"), std::string::npos)
        << result.Summary(options);
    // A field the invertible region fills: not a collapse towards 57 px.
    EXPECT_GT(result.target.params[0], 200.0) << "alpha " << alpha;
    EXPECT_LT(result.target.params[0], 400.0) << "alpha " << alpha;
    cv::Mat map_x, map_y;
    MakeUndistortMaps(source, result.target, options, &map_x, &map_y);
    // Every target pixel with a source pixel: that pixel's own inverse is
    // the target pixel's ray (one-to-one, nothing folded in).
    int checked = 0;
    double worst = 0;
    const auto& t = result.target.params;
    for (int v = 0; v < map_x.rows; v += 7) {
      for (int u = 0; u < map_x.cols; u += 7) {
        const float sx = map_x.at<float>(v, u), sy = map_y.at<float>(v, u);
        if (sx < -0.5f) continue;
        Eigen::Vector3d ray;
        const UnprojectStatus status =
            source.Unproject(Eigen::Vector2d(sx, sy), &ray);
        ASSERT_TRUE(status.converged) << u << "," << v << " alpha " << alpha;
        const Eigen::Vector2d back(t[0] * ray.x() / ray.z() + t[2],
                                   t[1] * ray.y() / ray.z() + t[3]);
        worst = std::max(worst, (back - Eigen::Vector2d(u, v)).norm());
        ++checked;
      }
    }
    EXPECT_GT(checked, 1000);
    EXPECT_LT(worst, 0.01) << "alpha " << alpha;
    if (alpha == 0.0) {
      EXPECT_GT(result.target_covered_fraction, 0.999);
    }
  }
}

TEST(UndistortTest, FisheyeTargetIsCutAtTheStatedAngle) {
  Camera fisheye;
  fisheye.model = CameraModelId::kKannalaBrandt;
  fisheye.params = {495.0, 494.2, 801.7, 598.4, 0.02, -0.005, 0.001, -0.0002};
  fisheye.width = 1600;
  fisheye.height = 1200;
  UndistortOptions options;
  // alpha 0: the target's corners sit on the 60-degree circle, and every
  // target pixel has a source pixel.
  const UndistortResult inner = ChooseUndistortTarget(fisheye, options);
  EXPECT_TRUE(inner.limited_by_max_angle);
  EXPECT_LE(inner.target_max_angle_deg, options.max_angle_deg + 0.5);
  EXPECT_GT(inner.target_max_angle_deg, options.max_angle_deg - 5);
  EXPECT_GT(inner.target_covered_fraction, 0.999);
  EXPECT_NE(inner.Summary(options).find("60.0 degrees off the axis"),
            std::string::npos)
      << inner.Summary(options);
  // alpha 1: the whole 60-degree disc, black around it.
  options.alpha = 1;
  const UndistortResult outer = ChooseUndistortTarget(fisheye, options);
  EXPECT_LT(outer.target.params[0], inner.target.params[0]);
  EXPECT_LT(outer.target_covered_fraction, 0.95);
}

}  // namespace
}  // namespace puzzlecal
