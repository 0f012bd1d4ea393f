// A view with motion blur (sim's MotionBlur: a straight streak centred on
// the truth), rendered with truth: what the pipeline makes of it. The streak
// is point-symmetric, so it smears the corners without moving them; a
// moderate one leaves accurate corners (the calibration's verdict rightly
// keeps the view), a long one leaves too few corners and the image is
// refused with a reason.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "pipeline/pipeline.h"
#include "sim/render.h"
#include "tests/decode/truth_components.h"

namespace puzzlecal {
namespace {

struct BlurredView {
  ImageResult result;
  int matched = 0;           // detected corners with a truth corner within 3 px
  double rms_px = 0;         // their error, per coordinate
  double mean_along_px = 0;  // mean error along the streak (bias)
};

BlurredView DetectWithBlur(double length_px, double angle_deg) {
  const Board board = decode_testing::MakePuzzleBoard(23, 16, 50, 100, 0.03);
  const Eigen::Isometry3d pose =
      decode_testing::LookAt(board, {61, 107.5}, 0.7, 25, 10);
  RenderOptions options;
  options.noise_sigma = 0.01;
  options.motion_blur.length_px = length_px;
  options.motion_blur.angle_deg = angle_deg;
  RenderTruth truth;
  const cv::Mat image =
      RenderBoard(board, decode_testing::PinholeCamera(640, 480, 520), pose,
                  options, &truth);
  BlurredView view;
  ProcessGreyImage(image, board, PipelineOptions(), &view.result);
  const Eigen::Vector2d along(std::cos(angle_deg * M_PI / 180),
                              std::sin(angle_deg * M_PI / 180));
  double sum2 = 0, sum_along = 0;
  const BoardObservation& seen = view.result.decode.observation;
  for (size_t k = 0; k < seen.id.size(); ++k) {
    for (const TruthCorner& corner : truth.corners) {
      if (corner.id != seen.id[k]) continue;
      const Eigen::Vector2d error = seen.xy[k] - corner.xy;
      if (error.norm() > 3) break;
      ++view.matched;
      sum2 += error.squaredNorm();
      sum_along += error.dot(along);
      break;
    }
  }
  if (view.matched > 0) {
    view.rms_px = std::sqrt(sum2 / (2.0 * view.matched));
    view.mean_along_px = sum_along / view.matched;
  }
  return view;
}

TEST(MotionBlur, AModerateStreakSmearsCornersWithoutMovingThem) {
  const BlurredView sharp = DetectWithBlur(0, 0);
  ASSERT_EQ(sharp.result.outcome, ImageOutcome::kUsable) << sharp.result.reason;
  ASSERT_GT(sharp.matched, 150);
  EXPECT_LT(sharp.rms_px, 0.05);
  const BlurredView streak = DetectWithBlur(8, 20);
  ASSERT_EQ(streak.result.outcome, ImageOutcome::kUsable)
      << streak.result.reason;
  // Every decoded corner is the truth's corner of that id.
  EXPECT_EQ(streak.matched,
            static_cast<int>(streak.result.decode.observation.id.size()));
  EXPECT_GT(streak.matched, 0.8 * sharp.matched);
  ::testing::Test::RecordProperty("sharp_rms_px", std::to_string(sharp.rms_px));
  ::testing::Test::RecordProperty("streak_rms_px",
                                  std::to_string(streak.rms_px));
  ::testing::Test::RecordProperty("streak_bias_px",
                                  std::to_string(streak.mean_along_px));
  // Noisier, and unbiased along the streak.
  EXPECT_GT(streak.rms_px, sharp.rms_px);
  EXPECT_LT(streak.rms_px, 0.2);
  EXPECT_LT(std::abs(streak.mean_along_px),
            3 * streak.rms_px / std::sqrt(streak.matched) + 0.01);
}

TEST(MotionBlur, ALongStreakIsRefusedWithAReason) {
  const BlurredView streak = DetectWithBlur(24, 20);
  EXPECT_NE(streak.result.outcome, ImageOutcome::kUsable)
      << streak.result.decode.observation.id.size() << " corners";
  EXPECT_FALSE(streak.result.reason.empty());
  ::testing::Test::RecordProperty("reason", streak.result.reason);
}

TEST(MotionBlur, TheStreakIsPointSymmetric) {
  // The same streak drawn in the opposite direction gives the same image:
  // the exposure's middle is the truth.
  const Board board = decode_testing::MakePuzzleBoard(11, 8, 0, 0, 0.06);
  const Eigen::Isometry3d pose =
      decode_testing::LookAt(board, {5, 3.5}, 0.8, 20, 0);
  const Camera camera = decode_testing::PinholeCamera(320, 240, 260);
  RenderOptions a;
  a.noise_sigma = 0;
  a.motion_blur = {10, 30};
  RenderOptions b = a;
  b.motion_blur = {10, 210};
  const cv::Mat image_a = RenderBoard(board, camera, pose, a);
  const cv::Mat image_b = RenderBoard(board, camera, pose, b);
  ASSERT_FALSE(image_a.empty());
  cv::Mat difference;
  cv::absdiff(image_a, image_b, difference);
  double max_difference = 0;
  cv::minMaxLoc(difference, nullptr, &max_difference);
  EXPECT_LE(max_difference, 1);
  // And it blurs: the streaked image differs from the sharp one.
  RenderOptions sharp = a;
  sharp.motion_blur = {};
  cv::absdiff(image_a, RenderBoard(board, camera, pose, sharp), difference);
  cv::minMaxLoc(difference, nullptr, &max_difference);
  EXPECT_GT(max_difference, 50);
}

TEST(MotionBlur, OptionsAreChecked) {
  RenderOptions options;
  options.motion_blur.length_px = -1;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("motion_blur"), std::string::npos) << why;
  options.motion_blur.length_px = 5;
  options.motion_blur.angle_deg = std::nan("");
  EXPECT_FALSE(options.Check(&why));
}

}  // namespace
}  // namespace puzzlecal
