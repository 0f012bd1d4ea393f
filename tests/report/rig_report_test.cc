// The rig report's rectification: RectifyImage resamples like OpenCV's
// initUndistortRectifyMap (pinhole) and fisheye::initUndistortRectifyMap
// (kannala-brandt) for the same rotation and intrinsics, and the viewing
// rectification puts every point on the same row in both views.

#include "report/rig_report.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/rig_scenes.h"

namespace puzzlecal {
namespace {

// An image whose value is its x (or y) coordinate: bilinear resampling of
// it returns the sampled position (to the 1/32 pixel of cv::remap's
// interpolation table).
cv::Mat Ramp(int width, int height, bool along_y) {
  cv::Mat ramp(height, width, CV_32FC1);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) ramp.at<float>(y, x) = along_y ? y : x;
  }
  return ramp;
}

void ExpectSameResampling(const Camera& camera, const Eigen::Matrix3d& r,
                          const Eigen::Matrix3d& k) {
  const cv::Mat ours_x =
      RectifyImage(Ramp(camera.width, camera.height, false), camera, r, k,
                   camera.width, camera.height);
  const cv::Mat ours_y =
      RectifyImage(Ramp(camera.width, camera.height, true), camera, r, k,
                   camera.width, camera.height);
  cv::Mat cv_k, cv_r, cv_p;
  const std::vector<double>& p = camera.params;
  cv::eigen2cv(Eigen::Matrix3d(Eigen::Matrix3d::Identity()), cv_k);
  cv_k.at<double>(0, 0) = p[0];
  cv_k.at<double>(1, 1) = p[1];
  cv_k.at<double>(0, 2) = p[2];
  cv_k.at<double>(1, 2) = p[3];
  cv::eigen2cv(r, cv_r);
  cv::eigen2cv(k, cv_p);
  const std::vector<double> d(p.begin() + 4, p.end());
  cv::Mat map_x, map_y;
  const cv::Size size(camera.width, camera.height);
  if (camera.model == CameraModelId::kKannalaBrandt) {
    cv::fisheye::initUndistortRectifyMap(cv_k, d, cv_r, cv_p, size, CV_32FC1,
                                         map_x, map_y);
  } else {
    cv::initUndistortRectifyMap(cv_k, d, cv_r, cv_p, size, CV_32FC1, map_x,
                                map_y);
  }
  const cv::Mat valid =
      RectifyImage(cv::Mat(camera.height, camera.width, CV_32FC1, 1.0f), camera,
                   r, k, camera.width, camera.height);
  int compared = 0, folded = 0;
  for (int y = 0; y < camera.height; y += 7) {
    for (int x = 0; x < camera.width; x += 7) {
      const float mx = map_x.at<float>(y, x), my = map_y.at<float>(y, x);
      if (!(mx > 1 && my > 1 && mx < camera.width - 2 &&
            my < camera.height - 2)) {
        continue;
      }
      // Beyond the fold of the pinhole's distortion RectifyImage draws
      // black where OpenCV's map still points into the image.
      if (valid.at<float>(y, x) < 1) {
        ++folded;
        continue;
      }
      EXPECT_NEAR(ours_x.at<float>(y, x), mx, 0.04) << "at " << x << ", " << y;
      EXPECT_NEAR(ours_y.at<float>(y, x), my, 0.04) << "at " << x << ", " << y;
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000);
  EXPECT_LT(folded, compared / 50);
}

TEST(RigReportTest, RectifyImageResamplesLikeOpenCv) {
  const RigSceneSpec scene = FisheyePinholeRig();
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, 1, 0.1).normalized())
          .toRotationMatrix();
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = k(1, 1) = 300;
  k(0, 2) = 330;
  k(1, 2) = 235;
  ExpectSameResampling(scene.cameras[1].camera, r, k);  // pinhole-radtan
  k(0, 0) = k(1, 1) = 120;
  ExpectSameResampling(scene.cameras[0].camera, r, k);  // kannala-brandt
}

TEST(RigReportTest, ViewingRectificationPutsPointsOnOneRow) {
  const RigSceneSpec scene = FisheyePinholeRig();
  const Eigen::Isometry3d& second_from_first = scene.cameras[1].cam_from_rig;
  const StereoRectification rect = ViewingRectification(
      scene.cameras[0].camera, scene.cameras[1].camera, second_from_first);
  for (const Eigen::Vector3d& x :
       {Eigen::Vector3d(0.3, -0.1, 0.6), Eigen::Vector3d(0.5, 0.2, 0.9),
        Eigen::Vector3d(0.2, 0.05, 1.2)}) {
    const Eigen::Vector2d a =
        (rect.p1.leftCols<3>() * rect.r1 * x).hnormalized();
    const Eigen::Vector2d b =
        (rect.p2.leftCols<3>() * rect.r2 * (second_from_first * x))
            .hnormalized();
    EXPECT_NEAR(a.y(), b.y(), 1e-9);
    EXPECT_GT(a.x(), b.x());  // positive disparity in front of the rig
  }
  EXPECT_TRUE((rect.r1 * rect.r1.transpose()).isIdentity(1e-12));
}

}  // namespace
}  // namespace puzzlecal
