#include "calib/initialization.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/synthetic_views.h"
#include "tests/calib/scenes.h"
#include "util/statistics.h"

namespace puzzlecal {
namespace {

using sim::MakeCamera;
using sim::MakeSyntheticData;
using sim::SyntheticData;
using sim::SyntheticScene;

// A 90-degree wide-angle lens with barrel distortion, boards close, off-axis
// and cut by the image border (the recipe of the bundled sample set).
SyntheticScene WideAngleScene() {
  SyntheticScene scene;
  scene.camera = MakeCamera(
      CameraModelId::kPinholeRadtan, 800, 600,
      {400.0, 400.4, 409.8, 294.1, -0.2, 0.01, 0.0006, -0.0004, 0.0003});
  scene.board_cols = 23;
  scene.board_rows = 16;
  scene.num_views = 15;
  scene.max_direction_deg = 35;
  scene.min_tilt_deg = 35;
  scene.max_tilt_deg = 70;
  scene.min_distance = 0.5;
  scene.max_distance = 1.2;
  scene.min_visible_fraction = 0.4;
  scene.noise_px = 0.05;
  return scene;
}

InitializationResult Initialise(const SyntheticData& data, const Camera& truth,
                                const InitializationOptions& options) {
  InitializationResult result;
  std::string error;
  EXPECT_TRUE(InitializeCalibration(
      data.views, std::vector<bool>(data.views.size(), true), truth.model,
      truth.width, truth.height, {}, options, &result, &error))
      << error;
  return result;
}

double RelativeFocalError(const Camera& camera, const Camera& truth) {
  return std::max(
      std::abs(camera.params[0] - truth.params[0]) / truth.params[0],
      std::abs(camera.params[1] - truth.params[1]) / truth.params[1]);
}

TEST(InitializationTest, RefinedStartOfWideAngleLensIsCloseToTruth) {
  const SyntheticScene scene = WideAngleScene();
  const SyntheticData data = MakeSyntheticData(scene);
  const Camera& truth = scene.camera;

  InitializationOptions unrefined_options;
  unrefined_options.start_refine_iterations = 0;
  const InitializationResult unrefined =
      Initialise(data, truth, unrefined_options);
  EXPECT_FALSE(unrefined.start_refined);
  // The distortion-free start: focal length far off, no distortion.
  EXPECT_EQ(unrefined.camera.params[4], 0.0);

  const InitializationResult refined =
      Initialise(data, truth, InitializationOptions());
  ASSERT_TRUE(refined.start_refined);
  EXPECT_GT(refined.start_refine_iterations, 0);
  const Camera& camera = refined.camera;
  EXPECT_LT(RelativeFocalError(camera, truth), 0.01);
  EXPECT_LT(RelativeFocalError(camera, truth),
            RelativeFocalError(unrefined.camera, truth));
  EXPECT_NEAR(camera.params[2], truth.params[2], 5.0);
  EXPECT_NEAR(camera.params[3], truth.params[3], 5.0);
  EXPECT_NEAR(camera.params[4], truth.params[4], 0.03);
  // The terms beyond k1, k2 stay at zero.
  for (int k = kDistortionBegin + 2; k < 9; ++k) {
    EXPECT_EQ(camera.params[k], 0.0);
  }
  // Every view is posed through the refined camera: the poses are close to
  // the truth.
  for (size_t v = 0; v < data.views.size(); ++v) {
    ASSERT_TRUE(refined.view_ok[v]);
    const Eigen::Isometry3d& pose = refined.cam_from_board[v];
    const Eigen::Isometry3d& true_pose = data.cam_from_board[v];
    const double translation_error =
        (pose.translation() - true_pose.translation()).norm() /
        true_pose.translation().norm();
    EXPECT_LT(translation_error, 0.02) << "view " << v;
    const double angle =
        Eigen::AngleAxisd(pose.linear().transpose() * true_pose.linear())
            .angle();
    EXPECT_LT(angle, 0.5 * M_PI / 180) << "view " << v;
  }
}

TEST(InitializationTest, RefinedStartOfFisheyeIsCloseToTruth) {
  const SyntheticScene scene = testing_scenes::Fisheye190Scene(30);
  const SyntheticData data = MakeSyntheticData(scene);
  const InitializationResult result =
      Initialise(data, scene.camera, InitializationOptions());
  ASSERT_TRUE(result.start_refined);
  EXPECT_LT(RelativeFocalError(result.camera, scene.camera), 0.01);
  EXPECT_NEAR(result.camera.params[2], scene.camera.params[2], 3.0);
  EXPECT_NEAR(result.camera.params[3], scene.camera.params[3], 3.0);
}

// The focal-length search scans on a spread subset of the views and runs
// its golden section on all of them: on a fisheye scene with gross
// outliers, that finds the focal length of the scan over every view (to
// the bracket the golden section leaves), close to the truth's.
TEST(InitializationTest, FocalScanOnASubsetFindsTheFullScansFocalLength) {
  SyntheticScene scene = testing_scenes::Fisheye190Scene(30);
  scene.num_views = 40;
  scene.outlier_fraction = 0.05;
  const SyntheticData data = MakeSyntheticData(scene);
  InitializationOptions subset_scan;
  subset_scan.start_refine_iterations = 0;  // the search's own camera
  ASSERT_LT(subset_scan.focal_search_scan_max_views, scene.num_views);
  InitializationOptions full_scan = subset_scan;
  full_scan.focal_search_scan_max_views = full_scan.focal_search_max_views;
  full_scan.focal_search_refine_iterations = 30;
  const double f_subset =
      Initialise(data, scene.camera, subset_scan).camera.params[0];
  const double f_full =
      Initialise(data, scene.camera, full_scan).camera.params[0];
  EXPECT_NEAR(f_subset / f_full, 1.0, 2e-3);
  // The distortion-free search lands near the truth's focal length (the
  // refined start and the solve take it the rest of the way).
  EXPECT_NEAR(f_full / scene.camera.params[0], 1.0, 0.06);
}

// When the scan's subset misjudges which basin is deepest, its lowest
// local minima scored on all views pick the right bracket. Views of two
// lenses (focal lengths f and 1.6 f): the spread subset holds mostly the
// first lens's views, all views mostly the second's.
TEST(InitializationTest, FocalScanCandidatesAreScoredOnAllViews) {
  SyntheticScene scene = testing_scenes::Fisheye190Scene(30);
  scene.num_views = 40;
  const SyntheticData first = MakeSyntheticData(scene);
  SyntheticScene longer = scene;
  longer.camera.params[0] *= 1.6;
  longer.camera.params[1] *= 1.6;
  longer.seed += 1;
  const SyntheticData second = MakeSyntheticData(longer);
  InitializationOptions options;
  options.start_refine_iterations = 0;  // the search's own camera
  const std::vector<size_t> in_subset =
      EvenlySpreadIndices(scene.num_views, options.focal_search_scan_max_views);
  SyntheticData mixed = second;
  for (size_t k = 0; k < in_subset.size(); ++k) {
    if (k % 4 != 0) mixed.views[in_subset[k]] = first.views[in_subset[k]];
  }
  InitializationOptions full_scan = options;
  full_scan.focal_search_scan_max_views = full_scan.focal_search_max_views;
  InitializationOptions one_candidate = options;
  one_candidate.focal_search_scan_candidates = 1;
  const double f_full =
      Initialise(mixed, scene.camera, full_scan).camera.params[0];
  const double f_one =
      Initialise(mixed, scene.camera, one_candidate).camera.params[0];
  const double f_default =
      Initialise(mixed, scene.camera, options).camera.params[0];
  // The full scan follows the majority (the longer lens); the subset alone
  // follows the first lens; its candidates scored on all views do not.
  EXPECT_NEAR(f_full / longer.camera.params[0], 1.0, 0.1);
  EXPECT_NEAR(f_one / scene.camera.params[0], 1.0, 0.1);
  EXPECT_NEAR(f_default / f_full, 1.0, 2e-3);
}

TEST(InitializationTest, GivenIntrinsicsAreKept) {
  const SyntheticScene scene = WideAngleScene();
  const SyntheticData data = MakeSyntheticData(scene);
  InitializationResult result;
  std::string error;
  ASSERT_TRUE(InitializeCalibration(
      data.views, std::vector<bool>(data.views.size(), true),
      scene.camera.model, scene.camera.width, scene.camera.height,
      scene.camera.params, InitializationOptions(), &result, &error))
      << error;
  EXPECT_FALSE(result.start_refined);
  EXPECT_EQ(result.camera.params, scene.camera.params);
}

TEST(InitializationTest, CheckRejectsBadStartRefineOptions) {
  std::string why;
  InitializationOptions options;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.start_refine_iterations = -1;
  EXPECT_FALSE(options.Check(&why));
  options = InitializationOptions();
  options.start_refine_max_views = 0;
  EXPECT_FALSE(options.Check(&why));
  options = InitializationOptions();
  options.start_refine_max_corners_per_view = 0;
  EXPECT_FALSE(options.Check(&why));
  options = InitializationOptions();
  options.start_refine_loss_px = 0;
  EXPECT_FALSE(options.Check(&why));
  options = InitializationOptions();
  options.start_refine_pose_iterations = -1;
  EXPECT_FALSE(options.Check(&why));
  options = InitializationOptions();
  options.focal_search_scan_max_views = 0;
  EXPECT_FALSE(options.Check(&why));
  options = InitializationOptions();
  options.focal_search_scan_candidates = 0;
  EXPECT_FALSE(options.Check(&why));
  options = InitializationOptions();
  options.focal_search_max_corners_per_view = 7;
  EXPECT_FALSE(options.Check(&why));
}

}  // namespace
}  // namespace puzzlecal
