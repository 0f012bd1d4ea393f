#include "sim/render.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "sim/scenes.h"
#include "target/puzzleboard.h"

namespace puzzlecal {
namespace {

Camera PinholeCamera() {
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.params = {620.0, 615.0,  322.5,   236.0, -0.12,
                   0.05,  0.0008, -0.0005, 0.0};
  camera.width = 640;
  camera.height = 480;
  return camera;
}

// Equidistant-like lens with a field of view beyond 180 degrees.
Camera FisheyeCamera() {
  Camera camera;
  camera.model = CameraModelId::kKannalaBrandt;
  camera.params = {190.0, 190.0, 319.5, 240.5, 0.02, -0.006, 0.001, -0.0001};
  camera.width = 640;
  camera.height = 480;
  return camera;
}

Board PuzzleBoard11x8() {
  Board board =
      MakeBoard(BoardType::kPuzzleBoard, 11, 8, Eigen::Vector2i(0, 0), 0.06);
  return board;
}

// Board centre at `distance` in front of the camera, rotated by `angles`
// (radians about x, then y) about its centre, shifted sideways by `shift`.
Eigen::Isometry3d LookAtBoard(
    const Board& board, double distance, double angle_x, double angle_y,
    const Eigen::Vector3d& shift = Eigen::Vector3d::Zero()) {
  const Eigen::Vector3d board_center(
      (board.origin.x() + 0.5 * (board.cols - 1)) * board.tile_size_m,
      (board.origin.y() + 0.5 * (board.rows - 1)) * board.tile_size_m, 0.0);
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(angle_x, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(angle_y, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() =
      Eigen::Vector3d(0, 0, distance) + shift - rotation * board_center;
  return pose;
}

RenderOptions SharpOptions() {
  RenderOptions options;
  options.supersampling = 4;
  options.blur_sigma_px = 1.2;
  options.noise_sigma = 0.0;
  return options;
}

// Starts cv::cornerSubPix at the rounded truth of every visible corner whose
// refinement window stays clear of the discs, and returns the errors.
std::vector<double> CornerSubPixErrors(const cv::Mat& image,
                                       const RenderTruth& truth,
                                       const Board& board) {
  std::vector<double> errors;
  constexpr int kHalfWindow = 5;
  for (const TruthCorner& corner : truth.corners) {
    if (!corner.visible) continue;
    // Keep only corners whose window is smaller than a third of the local
    // tile size (the discs start s/3 from each corner) and inside the image.
    double min_tile_px = 1e9;
    for (const Eigen::Vector2i& step :
         {Eigen::Vector2i(1, 0), Eigen::Vector2i(0, 1), Eigen::Vector2i(-1, 0),
          Eigen::Vector2i(0, -1)}) {
      Eigen::Vector2d neighbour;
      const Eigen::Vector3d p =
          truth.cam_from_board * board.Point(corner.id + step);
      if (!truth.camera.Project(p, &neighbour)) continue;
      min_tile_px = std::min(min_tile_px, (neighbour - corner.xy).norm());
    }
    if (min_tile_px / 3.0 < kHalfWindow + 5) continue;
    if (corner.xy.x() < kHalfWindow + 3 || corner.xy.y() < kHalfWindow + 3 ||
        corner.xy.x() > image.cols - kHalfWindow - 4 ||
        corner.xy.y() > image.rows - kHalfWindow - 4) {
      continue;
    }
    std::vector<cv::Point2f> points = {
        cv::Point2f(static_cast<float>(std::round(corner.xy.x())),
                    static_cast<float>(std::round(corner.xy.y())))};
    cv::cornerSubPix(
        image, points, cv::Size(kHalfWindow, kHalfWindow), cv::Size(-1, -1),
        cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100,
                         1e-4));
    errors.push_back(
        std::hypot(points[0].x - corner.xy.x(), points[0].y - corner.xy.y()));
  }
  return errors;
}

double Max(const std::vector<double>& values) {
  double m = 0;
  for (double v : values) m = std::max(m, v);
  return m;
}

double Percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(fraction * (values.size() - 1))];
}

TEST(RenderBoardTest, PinholeCornersAgreeWithTruth) {
  const Board board = PuzzleBoard11x8();
  const Camera camera = PinholeCamera();
  RenderTruth truth;
  RenderSummary summary;
  const cv::Mat image =
      RenderBoard(board, camera, LookAtBoard(board, 0.9, 0.35, -0.25),
                  SharpOptions(), &truth, &summary);
  ASSERT_TRUE(summary.ok) << summary.reason;
  ASSERT_EQ(image.type(), CV_8UC1);
  ASSERT_EQ(image.cols, 640);
  ASSERT_EQ(image.rows, 480);
  ASSERT_EQ(truth.corners.size(), 88u);
  const std::vector<double> errors = CornerSubPixErrors(image, truth, board);
  EXPECT_GE(errors.size(), 60u);
  EXPECT_LT(Max(errors), 0.05);
}

TEST(RenderBoardTest, FisheyeCornersAgreeWithTruth) {
  const Board board = PuzzleBoard11x8();
  const Camera camera = FisheyeCamera();
  RenderTruth truth;
  RenderSummary summary;
  const cv::Mat image =
      RenderBoard(board, camera, LookAtBoard(board, 0.3, 0.3, 0.4),
                  SharpOptions(), &truth, &summary);
  ASSERT_TRUE(summary.ok) << summary.reason;
  const std::vector<double> errors = CornerSubPixErrors(image, truth, board);
  EXPECT_GE(errors.size(), 20u);
  // cv::cornerSubPix itself is biased by a few hundredths of a pixel on the
  // curved, non-orthogonal junctions of a strong fisheye (the error does not
  // change between 1 and 16 supersamples, so it is not the render); the
  // exact geometry check is FisheyeEdgesAreExact.
  EXPECT_LT(Percentile(errors, 0.9), 0.05);
  EXPECT_LT(Max(errors), 0.08);
}

// Exact check of the anti-aliased edges: across a vertical tile edge, the sum
// of a row's pixel values (scaled to white fraction) over a segment that
// crosses only that edge equals the white length, i.e. the edge position.
// Without blur this holds for box-filtered pixels whatever the distortion.
// Returns the largest error in pixels over all rows checked.
double MaxEdgeIntegralError(const Board& board, const Camera& camera,
                            const Eigen::Isometry3d& pose, int* num_rows) {
  RenderOptions options;
  options.supersampling = 4;
  options.blur_sigma_px = 0.0;
  options.black_level = 0.0;
  options.white_level = 1.0;
  RenderTruth truth;
  const cv::Mat image = RenderBoard(board, camera, pose, options, &truth);
  EXPECT_FALSE(image.empty());
  double max_error = 0.0;
  *num_rows = 0;
  auto project = [&](const Eigen::Vector2i& id, double t,
                     Eigen::Vector2d* pixel) {
    const Eigen::Vector3d p =
        board.Point(id) + Eigen::Vector3d(0, t * board.tile_size_m, 0);
    return camera.Project(pose * p, pixel);
  };
  for (int row = 0; row + 1 < board.rows; ++row) {
    for (int col = 0; col < board.cols; ++col) {
      const Eigen::Vector2i id = board.origin + Eigen::Vector2i(col, row);
      Eigen::Vector2d top, bottom;
      if (!project(id, 0.0, &top) || !project(id, 1.0, &bottom)) continue;
      const double tile_px = (bottom - top).norm();
      if (tile_px < 12) continue;
      // Rows through the middle of the edge, away from its corners.
      const int y_begin =
          static_cast<int>(std::ceil(top.y() + 0.35 * (bottom.y() - top.y())));
      const int y_end =
          static_cast<int>(std::floor(top.y() + 0.65 * (bottom.y() - top.y())));
      for (int y = y_begin; y <= y_end; ++y) {
        // Edge position on this row: bisection on t along the edge.
        double lo = 0.0, hi = 1.0;
        Eigen::Vector2d pixel;
        for (int it = 0; it < 60; ++it) {
          const double mid = 0.5 * (lo + hi);
          project(id, mid, &pixel);
          ((pixel.y() < y) == (top.y() < bottom.y()) ? lo : hi) = mid;
        }
        project(id, 0.5 * (lo + hi), &pixel);
        const int half = static_cast<int>(0.25 * tile_px);
        const int xa = static_cast<int>(std::round(pixel.x())) - half;
        const int xb = static_cast<int>(std::round(pixel.x())) + half;
        if (xa < 0 || xb >= image.cols || y < 0 || y >= image.rows) continue;
        double white = 0.0;
        for (int x = xa; x <= xb; ++x) white += image.at<uint8_t>(y, x) / 255.0;
        // Tile (col - 1, row) lies left of the edge on the page; the image
        // may be mirrored by the pose, so look at which side is white.
        const bool left_white =
            image.at<uint8_t>(y, xa) > image.at<uint8_t>(y, xb);
        const double expected =
            left_white ? pixel.x() - (xa - 0.5) : (xb + 0.5) - pixel.x();
        max_error = std::max(max_error, std::abs(white - expected));
        ++*num_rows;
      }
    }
  }
  return max_error;
}

Board Checkerboard11x8() {
  Board board =
      MakeBoard(BoardType::kCheckerboard, 11, 8, Eigen::Vector2i::Zero(), 0.06);
  return board;
}

TEST(RenderBoardTest, PinholeEdgesAreExact) {
  int num_rows = 0;
  const Board board = Checkerboard11x8();
  const double error = MaxEdgeIntegralError(
      board, PinholeCamera(), LookAtBoard(board, 0.9, 0.35, -0.25), &num_rows);
  EXPECT_GE(num_rows, 500);
  EXPECT_LT(error, 0.01) << num_rows;
}

TEST(RenderBoardTest, FisheyeEdgesAreExact) {
  int num_rows = 0;
  const Board board = Checkerboard11x8();
  const double error = MaxEdgeIntegralError(
      board, FisheyeCamera(), LookAtBoard(board, 0.3, 0.3, 0.4), &num_rows);
  EXPECT_GE(num_rows, 500);
  EXPECT_LT(error, 0.01) << num_rows;
}

// Grey of the render at the projection of board point (u, v) (tile units).
int GreyAtBoardPoint(const cv::Mat& image, const Board& board,
                     const Camera& camera, const Eigen::Isometry3d& pose,
                     double u, double v) {
  Eigen::Vector2d pixel;
  const Eigen::Vector3d p(u * board.tile_size_m, v * board.tile_size_m, 0);
  if (!camera.Project(pose * p, &pixel)) return -1;
  return image.at<uint8_t>(static_cast<int>(std::lround(pixel.y())),
                           static_cast<int>(std::lround(pixel.x())));
}

RenderOptions CleanOptions() {
  RenderOptions options;
  options.blur_sigma_px = 0.0;
  options.black_level = 0.0;
  options.white_level = 1.0;
  return options;
}

// Counts tiles and discs whose rendered grey matches the true pattern, with
// the pattern variant `as_if` applied to the expectation.
struct PatternAgreement {
  int tiles = 0, tiles_ok = 0, discs = 0, discs_ok = 0;
};
PatternAgreement CheckPattern(const cv::Mat& image, const Board& board,
                              const Camera& camera,
                              const Eigen::Isometry3d& pose, bool mirrored,
                              bool inverted) {
  PatternAgreement a;
  const int x0 = board.origin.x(), y0 = board.origin.y();
  auto expect = [&](bool white) { return (white != inverted) ? 255 : 0; };
  // Under mirroring, the print at board position u shows the true pattern
  // at m - u.
  const double m = 2.0 * x0 + board.cols - 1;
  auto print_u = [&](double u) { return mirrored ? m - u : u; };
  for (int y = y0; y + 1 < y0 + board.rows; ++y) {
    for (int x = x0; x + 1 < x0 + board.cols; ++x) {
      const double u = x + 0.5, v = y + 0.5;
      const int tile_x = static_cast<int>(std::floor(print_u(u)));
      ++a.tiles;
      a.tiles_ok += GreyAtBoardPoint(image, board, camera, pose, u, v) ==
                    expect(!PuzzleBoardTileIsBlack(tile_x, y));
    }
  }
  for (int y = y0; y < y0 + board.rows; ++y) {
    for (int x = x0; x < x0 + board.cols; ++x) {
      if (y + 1 < y0 + board.rows) {
        const int px = static_cast<int>(std::lround(print_u(x)));
        ++a.discs;
        a.discs_ok +=
            GreyAtBoardPoint(image, board, camera, pose, x, y + 0.5) ==
            expect(PuzzleBoardVerticalEdgeBit(px, y) == 1);
      }
      if (x + 1 < x0 + board.cols) {
        const int px = static_cast<int>(std::floor(print_u(x + 0.5)));
        ++a.discs;
        a.discs_ok +=
            GreyAtBoardPoint(image, board, camera, pose, x + 0.5, y) ==
            expect(PuzzleBoardHorizontalEdgeBit(px, y) == 1);
      }
    }
  }
  return a;
}

TEST(RenderBoardTest, TilesAndDiscsShowTheCode) {
  Board board = PuzzleBoard11x8();
  board.origin = Eigen::Vector2i(200, 37);
  const Camera camera = PinholeCamera();
  const Eigen::Isometry3d pose = LookAtBoard(board, 1.0, 0.2, 0.1);
  RenderOptions options = CleanOptions();
  const cv::Mat image = RenderBoard(board, camera, pose, options);
  ASSERT_FALSE(image.empty());
  PatternAgreement a = CheckPattern(image, board, camera, pose, false, false);
  EXPECT_EQ(a.tiles, 70);
  EXPECT_EQ(a.discs, 11 * 7 + 10 * 8);
  EXPECT_EQ(a.tiles_ok, a.tiles);
  EXPECT_EQ(a.discs_ok, a.discs);

  options.variant.inverted = true;
  a = CheckPattern(RenderBoard(board, camera, pose, options), board, camera,
                   pose, false, true);
  EXPECT_EQ(a.tiles_ok, a.tiles);
  EXPECT_EQ(a.discs_ok, a.discs);

  options.variant.inverted = false;
  options.variant.mirrored = true;
  a = CheckPattern(RenderBoard(board, camera, pose, options), board, camera,
                   pose, true, false);
  EXPECT_EQ(a.tiles_ok, a.tiles);
  EXPECT_EQ(a.discs_ok, a.discs);

  // Another code: the tiles stay, about half the discs change.
  options.variant.mirrored = false;
  options.variant.random_code_seed = 99;
  a = CheckPattern(RenderBoard(board, camera, pose, options), board, camera,
                   pose, false, false);
  EXPECT_EQ(a.tiles_ok, a.tiles);
  EXPECT_GT(a.discs - a.discs_ok, a.discs / 4);
  EXPECT_LT(a.discs - a.discs_ok, 3 * a.discs / 4);
}

TEST(RenderBoardTest, SameImageForAnyThreadCount) {
  const Board board = PuzzleBoard11x8();
  RenderOptions options;
  options.noise_sigma = 0.05;
  options.vignetting = 0.3;
  options.occluders.push_back({Eigen::Vector2d(300, 200), 30, 0.3});
  const Eigen::Isometry3d pose = LookAtBoard(board, 0.5, 0.3, 0.4);
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const cv::Mat one = RenderBoard(board, FisheyeCamera(), pose, options);
  cv::setNumThreads(std::max(threads, 2));
  const cv::Mat many = RenderBoard(board, FisheyeCamera(), pose, options);
  cv::setNumThreads(threads);
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(cv::norm(one, many, cv::NORM_INF), 0.0);
  options.seed = 2;
  const cv::Mat other = RenderBoard(board, FisheyeCamera(), pose, options);
  EXPECT_GT(cv::norm(one, other, cv::NORM_INF), 0.0);  // noise follows seed
}

TEST(RenderBoardTest, OccludersHideCornersAndPixels) {
  const Board board = PuzzleBoard11x8();
  const Camera camera = PinholeCamera();
  const Eigen::Isometry3d pose = LookAtBoard(board, 0.9, 0.0, 0.0);
  RenderTruth clear;
  RenderBoard(board, camera, pose, CleanOptions(), &clear);
  const TruthCorner& target = clear.corners[3 * 11 + 4];
  ASSERT_TRUE(target.visible);
  RenderOptions options = CleanOptions();
  options.occluders.push_back({target.xy, 25.0, 0.4});
  RenderTruth truth;
  RenderSummary summary;
  const cv::Mat image =
      RenderBoard(board, camera, pose, options, &truth, &summary);
  EXPECT_FALSE(truth.corners[3 * 11 + 4].visible);
  EXPECT_EQ(image.at<uint8_t>(static_cast<int>(target.xy.y()),
                              static_cast<int>(target.xy.x())),
            std::lround(0.4 * 255));
  EXPECT_LT(summary.num_visible_corners, 88);
  EXPECT_GT(summary.num_visible_corners, 80);
}

TEST(RenderBoardTest, CornersOutsideTheImageOrBehindAreNotVisible) {
  const Board board = PuzzleBoard11x8();
  const Camera camera = PinholeCamera();
  // Board shifted right: part of it leaves the image.
  const Eigen::Isometry3d pose =
      LookAtBoard(board, 0.9, 0.0, 0.0, Eigen::Vector3d(0.35, 0, 0));
  RenderTruth truth;
  RenderBoard(board, camera, pose, CleanOptions(), &truth);
  int inside = 0, outside = 0;
  for (const TruthCorner& c : truth.corners) {
    const bool in_image = c.xy.x() >= 0.5 && c.xy.x() <= 638.5;
    EXPECT_EQ(c.visible, in_image) << c.xy.transpose();
    (in_image ? inside : outside) += 1;
  }
  EXPECT_GT(inside, 10);
  EXPECT_GT(outside, 10);
  // Seen from behind: the back of the paper shows no corners.
  Eigen::Isometry3d behind = LookAtBoard(board, 0.9, M_PI, 0.0);
  RenderSummary summary;
  const cv::Mat image =
      RenderBoard(board, camera, behind, CleanOptions(), &truth, &summary);
  ASSERT_TRUE(summary.ok);
  EXPECT_EQ(summary.num_visible_corners, 0);
  EXPECT_GT(summary.num_pixels_on_board, 1000);
}

TEST(RenderBoardTest, BadInputGivesAnEmptyImageAndAReason) {
  const Board board = PuzzleBoard11x8();
  Camera camera = PinholeCamera();
  const Eigen::Isometry3d pose = LookAtBoard(board, 0.9, 0.0, 0.0);
  RenderSummary summary;
  camera.params.resize(5);
  EXPECT_TRUE(
      RenderBoard(board, camera, pose, RenderOptions(), nullptr, &summary)
          .empty());
  EXPECT_FALSE(summary.ok);
  EXPECT_NE(summary.reason.find("parameters"), std::string::npos);
  camera = PinholeCamera();
  camera.width = 0;
  EXPECT_TRUE(
      RenderBoard(board, camera, pose, RenderOptions(), nullptr, &summary)
          .empty());
  EXPECT_NE(summary.reason.find("size"), std::string::npos);
  Eigen::Isometry3d nan_pose = pose;
  nan_pose.translation().x() = std::nan("");
  EXPECT_TRUE(RenderBoard(board, PinholeCamera(), nan_pose, RenderOptions(),
                          nullptr, &summary)
                  .empty());
  EXPECT_NE(summary.reason.find("cam_from_board"), std::string::npos);
  RenderOptions options;
  options.black_level = 0.9;
  options.white_level = 0.1;
  EXPECT_TRUE(
      RenderBoard(board, PinholeCamera(), pose, options, nullptr, &summary)
          .empty());
  EXPECT_NE(summary.reason.find("black_level"), std::string::npos);
  Board bad_board = board;
  bad_board.tile_size_m = -1;
  EXPECT_TRUE(RenderBoard(bad_board, PinholeCamera(), pose, RenderOptions(),
                          nullptr, &summary)
                  .empty());
  EXPECT_NE(summary.reason.find("tile_size_m"), std::string::npos);
}

// A non-central lens close up: the rendered corners sit where the rays with
// their origins put them (the truth), not where the far-field (central) part
// of the model would, several pixels away at large field angles.
TEST(RenderBoardTest,
     NoncentralLensShowsCornersWhereItsRaysWithOriginsPutThem) {
  const SceneSpec scene = NoncentralFisheyeScene(960, 720);
  const Camera far = FarFieldCamera(scene.camera);
  RenderOptions options = scene.render;
  options.noise_sigma = 0;
  int checked = 0, far_off = 0;
  std::vector<double> errors;  // refined corner to truth, pixels
  for (const SceneViewSpec& spec : SceneViewSpecs(scene)) {
    RenderTruth truth;
    RenderSummary summary;
    const cv::Mat image =
        RenderBoard(scene.board, scene.camera, spec.cam_from_board, options,
                    &truth, &summary);
    ASSERT_TRUE(summary.ok) << summary.reason;
    for (const TruthCorner& corner : truth.corners) {
      if (!corner.visible) continue;
      const Eigen::Vector3d point =
          spec.cam_from_board * scene.board.Point(corner.id);
      Eigen::Vector2d central;
      ASSERT_TRUE(far.Project(point, &central));
      // Tiles of at least 8 px around the corner, away from the border.
      Eigen::Vector2d next;
      ASSERT_TRUE(scene.camera.Project(
          spec.cam_from_board *
              scene.board.Point(corner.id + Eigen::Vector2i(1, 0)),
          &next));
      if ((next - corner.xy).norm() < 8 || corner.xy.x() < 10 ||
          corner.xy.y() < 10 || corner.xy.x() > image.cols - 10 ||
          corner.xy.y() > image.rows - 10) {
        continue;
      }
      std::vector<cv::Point2f> refined = {
          cv::Point2f(static_cast<float>(corner.xy.x() + 0.6),
                      static_cast<float>(corner.xy.y() - 0.4))};
      cv::cornerSubPix(
          image, refined, cv::Size(3, 3), cv::Size(-1, -1),
          cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50,
                           1e-4));
      const Eigen::Vector2d found(refined[0].x, refined[0].y);
      errors.push_back((found - corner.xy).norm());
      ++checked;
      if ((found - central).norm() > 1.0) ++far_off;
    }
  }
  ASSERT_GT(checked, 200);
  // (cornerSubPix itself strays on a few strongly foreshortened corners.)
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.05);
  EXPECT_LT(errors[errors.size() * 99 / 100], 0.25);
  // The pupil shift shows: many corners lie over a pixel from the central
  // projection.
  EXPECT_GT(far_off, checked / 10) << far_off << " of " << checked;
}

}  // namespace
}  // namespace puzzlecal
