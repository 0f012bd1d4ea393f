#include "calib/calibrate.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "calib/camera_models.h"
#include "tests/calib/synthetic_views.h"

namespace puzzlecal {
namespace {

using testing::MakeSyntheticData;
using testing::SyntheticData;
using testing::SyntheticScene;

// Number of free parameters: intrinsics plus six per used view.
int NumFreeParams(const CalibrationResult& result) {
  int free = 6 * result.num_views_used;
  for (bool fixed : result.param_fixed) free += fixed ? 0 : 1;
  return free;
}

double NoiseFloor(const CalibrationResult& result, double sigma) {
  return sigma *
         std::sqrt(1.0 - NumFreeParams(result) /
                             (2.0 * result.num_corners_used));
}

void ExpectAccurate(const Camera& truth, const CalibrationResult& result,
                    double sigma) {
  const auto& p = result.camera.params;
  const auto& t = truth.params;
  EXPECT_LE(std::abs(p[0] - t[0]) / t[0], 5e-4) << "fx " << p[0];
  EXPECT_LE(std::abs(p[1] - t[1]) / t[1], 5e-4) << "fy " << p[1];
  EXPECT_LE(std::abs(p[2] - t[2]), 0.3) << "cx " << p[2];
  EXPECT_LE(std::abs(p[3] - t[3]), 0.3) << "cy " << p[3];
  const double floor = NoiseFloor(result, sigma);
  EXPECT_NEAR(result.rms_px / floor, 1.0, 0.03)
      << "rms " << result.rms_px << " floor " << floor;
}

SyntheticScene PinholeScene(const Camera& camera) {
  SyntheticScene scene;
  scene.camera = camera;
  scene.num_views = 20;
  scene.max_direction_deg = 32;
  scene.min_visible_fraction = 1.0;
  return scene;
}

SyntheticScene FisheyeScene() {
  SyntheticScene scene;
  scene.camera = testing::TruthFisheye190();
  scene.num_views = 20;
  scene.max_direction_deg = 85;
  scene.max_corner_angle_deg = 95;
  scene.min_visible_fraction = 0.3;
  scene.min_tilt_deg = 0;
  scene.max_tilt_deg = 60;
  scene.min_distance = 0.8;
  scene.max_distance = 1.6;
  return scene;
}

struct ModelCase {
  const char* name;
  SyntheticScene scene;
};

class AccuracyTest : public ::testing::TestWithParam<int> {};

SyntheticScene SceneFor(int index) {
  switch (index) {
    case 0:
      return PinholeScene(testing::TruthRadtan());
    case 1:
      return PinholeScene(testing::TruthRational());
    default:
      return FisheyeScene();
  }
}

TEST_P(AccuracyTest, ReachesTheNoiseFloor) {
  const SyntheticScene scene = SceneFor(GetParam());
  const SyntheticData data = MakeSyntheticData(scene);
  ASSERT_EQ(static_cast<int>(data.views.size()), scene.num_views);
  CalibrationResult result;
  std::string error;
  ASSERT_TRUE(Calibrate(data.views, scene.camera.model, scene.camera.width,
                        scene.camera.height, CalibrationOptions(), &result,
                        &error))
      << error;
  std::printf("%s\n", result.report.c_str());
  ExpectAccurate(scene.camera, result, scene.noise_px);
  EXPECT_EQ(result.num_views_used, scene.num_views);
  // Every visible corner of every view counts (partial views included);
  // only a handful of Gaussian tails may be rejected.
  EXPECT_GE(result.num_corners_used, data.num_corners - 3);
  // The standard deviations explain the actual errors.
  for (int k = 0; k < 4; ++k) {
    EXPECT_GT(result.param_stddev[k], 0);
    EXPECT_LE(std::abs(result.camera.params[k] - scene.camera.params[k]),
              5 * result.param_stddev[k])
        << CameraModelParamNames(scene.camera.model)[k];
  }
}

INSTANTIATE_TEST_SUITE_P(Models, AccuracyTest, ::testing::Values(0, 1, 2));

}  // namespace
}  // namespace puzzlecal
