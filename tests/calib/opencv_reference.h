#ifndef PUZZLECAL_TESTS_CALIB_OPENCV_REFERENCE_H_
#define PUZZLECAL_TESTS_CALIB_OPENCV_REFERENCE_H_

// OpenCV's calibration on the same correspondences, for side-by-side
// comparisons in the calib/ tests and bench/bench_calib.cc.

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "camera/calibration_view.h"
#include "camera/camera_models.h"

namespace puzzlecal {
namespace testing {

struct OpenCvCalibration {
  bool ok = false;             // OpenCV returned without an exception
  std::string error;           // the exception text when !ok
  double rms_point_px = 0;     // OpenCV's returned RMS (per corner)
  std::vector<double> params;  // in puzzlecal's parameter order
};

// cv::calibrateCamera (5 coefficients, or 8 with CALIB_RATIONAL_MODEL) or
// cv::fisheye::calibrate, by model. `flags` are added to calibrateCamera's
// (CALIB_FIX_ASPECT_RATIO keeps fx / fy at 1).
inline OpenCvCalibration CalibrateWithOpenCv(
    const std::vector<CalibrationView>& views, CameraModelId model, int width,
    int height, int flags = 0) {
  OpenCvCalibration out;
  try {
    if (model == CameraModelId::kKannalaBrandt) {
      std::vector<std::vector<cv::Point3d>> object(views.size());
      std::vector<std::vector<cv::Point2d>> image(views.size());
      for (size_t v = 0; v < views.size(); ++v) {
        for (size_t i = 0; i < views[v].board_points.size(); ++i) {
          const auto& b = views[v].board_points[i];
          const auto& p = views[v].image_points[i];
          object[v].emplace_back(b.x(), b.y(), b.z());
          image[v].emplace_back(p.x(), p.y());
        }
      }
      cv::Matx33d k;
      cv::Vec4d d;
      std::vector<cv::Vec3d> rvecs, tvecs;
      out.rms_point_px = cv::fisheye::calibrate(
          object, image, cv::Size(width, height), k, d, rvecs, tvecs,
          cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW,
          cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100,
                           1e-12));
      out.params = {k(0, 0), k(1, 1), k(0, 2), k(1, 2), d[0], d[1], d[2], d[3]};
    } else {
      // calibrateCamera works in single precision.
      std::vector<std::vector<cv::Point3f>> object(views.size());
      std::vector<std::vector<cv::Point2f>> image(views.size());
      for (size_t v = 0; v < views.size(); ++v) {
        for (size_t i = 0; i < views[v].board_points.size(); ++i) {
          const auto& b = views[v].board_points[i];
          const auto& p = views[v].image_points[i];
          object[v].emplace_back(b.x(), b.y(), b.z());
          image[v].emplace_back(p.x(), p.y());
        }
      }
      const bool rational = model == CameraModelId::kPinholeRational;
      cv::Mat k = cv::Mat::eye(3, 3, CV_64F), d;
      std::vector<cv::Mat> rvecs, tvecs;
      out.rms_point_px = cv::calibrateCamera(
          object, image, cv::Size(width, height), k, d, rvecs, tvecs,
          (rational ? cv::CALIB_RATIONAL_MODEL : 0) | flags,
          cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100,
                           1e-12));
      out.params = {k.at<double>(0, 0), k.at<double>(1, 1), k.at<double>(0, 2),
                    k.at<double>(1, 2)};
      const int num = rational ? 8 : 5;
      for (int i = 0; i < num; ++i) out.params.push_back(d.at<double>(i));
    }
    out.ok = true;
  } catch (const cv::Exception& e) {
    out.ok = false;
    out.error = e.what();
  }
  return out;
}

}  // namespace testing
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_CALIB_OPENCV_REFERENCE_H_
