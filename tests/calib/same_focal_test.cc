// One focal length (CalibrationOptions::same_focal_length) on synthetic
// correspondences of a square-pixel lens: fy equals fx exactly, both land
// on the truth, their standard deviations and covariance rows are one, the
// result equals OpenCV's calibrateCamera with CALIB_FIX_ASPECT_RATIO on the
// same corners; a rig ties each camera's and equals cv::stereoCalibrate
// with that flag.

#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "calib/calibrate.h"
#include "calib/rig_calibration.h"
#include "sim/synthetic_views.h"
#include "tests/calib/opencv_reference.h"
#include "tests/calib/stereo_reference.h"

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

// A stereo rig of two square-pixel pinholes, every frame showing the whole
// board to both: with one focal length per camera the joint solve is
// cv::stereoCalibrate's with CALIB_FIX_ASPECT_RATIO (each camera started
// from calibrateCamera with the same flag) on the same corners.
TEST(SameFocalLength, ARigTiesEachCameraAndMatchesOpenCvsStereoCalibrate) {
  RigSceneSpec scene = testing::WholeBoardStereoRig();
  for (RigSceneCamera& camera : scene.cameras) {
    camera.camera.params[1] = camera.camera.params[0];  // square pixels
  }
  testing::SharedStereoFrames shared;
  ASSERT_TRUE(testing::CollectSharedStereoFrames(
      RigCorrespondences(scene, 0.05, 17), &shared));
  const std::vector<RigCameraInput>& inputs = shared.inputs;
  const auto& object = shared.object;
  const auto& image = shared.image;
  ASSERT_GE(object.size(), 10u);

  RigCalibrationOptions options;
  options.camera.same_focal_length = true;
  options.camera.loss = RobustLoss::kNone;  // OpenCV's objective
  options.camera.outlier_k = 0;
  RigCalibrationResult result;
  std::string error;
  ASSERT_TRUE(CalibrateRig(inputs, options, &result, &error)) << error;
  ASSERT_TRUE(result.covariance_ok);

  const cv::Size size(scene.cameras[0].camera.width,
                      scene.cameras[0].camera.height);
  const cv::TermCriteria criteria(
      cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-14);
  cv::Mat k[2], d[2];
  for (int c = 0; c < 2; ++c) {
    k[c] = cv::Mat::eye(3, 3, CV_64F);  // the aspect held: 1
    std::vector<cv::Mat> rvecs, tvecs;
    cv::calibrateCamera(object, image[c], size, k[c], d[c], rvecs, tvecs,
                        cv::CALIB_FIX_ASPECT_RATIO, criteria);
  }
  cv::Mat r, t, e, fundamental;
  cv::stereoCalibrate(
      object, image[0], image[1], k[0], d[0], k[1], d[1], size, r, t, e,
      fundamental, cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_FIX_ASPECT_RATIO,
      criteria);

  for (int c = 0; c < 2; ++c) {
    SCOPED_TRACE("camera " + result.cameras[c].name);
    const RigCameraResult& cam = result.cameras[c];
    const std::vector<double>& p = cam.camera.params;
    EXPECT_EQ(p[0], p[1]);
    EXPECT_EQ(cam.param_stddev[0], cam.param_stddev[1]);
    EXPECT_GT(cam.param_stddev[0], 0);
    EXPECT_LT(std::abs(p[0] - scene.cameras[c].camera.params[0]),
              4 * cam.param_stddev[0]);
    EXPECT_NEAR(k[c].at<double>(0, 0), k[c].at<double>(1, 1), 1e-9);
    // Two solvers of one objective: far closer than its uncertainty.
    EXPECT_NEAR(p[0], k[c].at<double>(0, 0), 0.05 * cam.param_stddev[0]);
    EXPECT_NEAR(p[2], k[c].at<double>(0, 2), 0.05 * cam.param_stddev[2]);
    EXPECT_NEAR(p[3], k[c].at<double>(1, 2), 0.05 * cam.param_stddev[3]);
  }
  Eigen::Matrix3d r_cv;
  Eigen::Vector3d t_cv;
  cv::cv2eigen(r, r_cv);
  cv::cv2eigen(t, t_cv);
  const RigCameraResult& second = result.cameras[1];
  EXPECT_LT(RotationDifferenceDeg(second.cam_from_rig.linear(), r_cv),
            0.05 * second.rotation_stddev_deg);
  for (int a = 0; a < 3; ++a) {
    EXPECT_LT(std::abs(second.cam_from_rig.translation()(a) - t_cv(a)),
              0.05 * second.translation_stddev_m(a))
        << "axis " << a;
  }
  std::printf(
      "rig with one focal length per camera: fx %.4f / %.4f px (sigma %.4f / "
      "%.4f), OpenCV %.4f / %.4f; rotation difference to OpenCV %.2g deg "
      "(sigma %.2g)\n",
      result.cameras[0].camera.params[0], second.camera.params[0],
      result.cameras[0].param_stddev[0], second.param_stddev[0],
      k[0].at<double>(0, 0), k[1].at<double>(0, 0),
      RotationDifferenceDeg(second.cam_from_rig.linear(), r_cv),
      second.rotation_stddev_deg);
}

}  // namespace
}  // namespace puzzlecal
