// One focal length (CalibrationOptions::same_focal_length) on synthetic
// correspondences of a square-pixel lens: fy equals fx exactly, both land
// on the truth, their standard deviations and covariance rows are one, the
// result equals OpenCV's calibrateCamera with CALIB_FIX_ASPECT_RATIO on the
// same corners, and a rig refuses the option.

#include <gtest/gtest.h>

#include "calib/calibrate.h"
#include "calib/rig_calibration.h"
#include "sim/synthetic_views.h"
#include "tests/calib/opencv_reference.h"

namespace puzzlecal {
namespace {

sim::SyntheticData SquarePixelData(Camera* truth) {
  *truth = sim::TruthRadtan();
  truth->params[1] = truth->params[0];  // square pixels
  sim::SyntheticScene scene;
  scene.camera = *truth;
  scene.num_views = 15;
  scene.noise_px = 0.1;
  return sim::MakeSyntheticData(scene);
}

TEST(SameFocalLength, TiesFyToFxAndMatchesOpenCvsFixedAspect) {
  Camera truth;
  const sim::SyntheticData data = SquarePixelData(&truth);
  CalibrationOptions options;
  options.same_focal_length = true;
  options.outlier_k = 0;  // OpenCV keeps every corner
  options.loss = RobustLoss::kNone;
  CalibrationResult result;
  std::string error;
  ASSERT_TRUE(Calibrate(data.views, truth.model, truth.width, truth.height,
                        options, &result, &error))
      << error;
  const std::vector<double>& p = result.camera.params;
  EXPECT_EQ(p[0], p[1]);
  EXPECT_NEAR(p[0], truth.params[0], 0.5);
  ASSERT_TRUE(result.covariance_ok);
  EXPECT_EQ(result.param_stddev[0], result.param_stddev[1]);
  EXPECT_GT(result.param_stddev[0], 0);
  EXPECT_EQ(result.covariance(1, 1), result.covariance(0, 0));
  EXPECT_EQ(result.covariance(1, 2), result.covariance(0, 2));

  const testing::OpenCvCalibration reference =
      testing::CalibrateWithOpenCv(data.views, truth.model, truth.width,
                                   truth.height, cv::CALIB_FIX_ASPECT_RATIO);
  ASSERT_TRUE(reference.ok) << reference.error;
  EXPECT_NEAR(reference.params[0], reference.params[1], 1e-9);
  for (size_t k = 0; k < p.size(); ++k) {
    // OpenCV solves in single precision: agreement to about 1e-4 of a
    // standard deviation is what the two solvers give on free focal
    // lengths too.
    EXPECT_NEAR(p[k], reference.params[k], 0.02 * result.param_stddev[k])
        << "parameter " << k;
  }

  // Free focal lengths fit the same corners at least as well.
  CalibrationResult free_result;
  options.same_focal_length = false;
  ASSERT_TRUE(Calibrate(data.views, truth.model, truth.width, truth.height,
                        options, &free_result, &error));
  EXPECT_NE(free_result.camera.params[0], free_result.camera.params[1]);
  EXPECT_LE(free_result.rms_px, result.rms_px);
}

TEST(SameFocalLength, ARigRefusesIt) {
  RigCalibrationOptions options;
  options.camera.same_focal_length = true;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;  // an options file may hold it
  RigCalibrationResult result;
  std::string error;
  EXPECT_FALSE(CalibrateRig({}, options, &result, &error));
  EXPECT_NE(error.find("same_focal_length"), std::string::npos) << error;
}

}  // namespace
}  // namespace puzzlecal
