#include "report/rig_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <vector>

#include "pipeline/image_io.h"
#include "report/overlay.h"
#include "util/atomic_file.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

}  // namespace

bool RigReportOptions::Check(std::string* why) const {
  if (line_spacing_px < 2) return Fail("line_spacing_px must be >= 2", why);
  return true;
}

cv::Mat RectifyImage(const cv::Mat& image, const Camera& lens,
                     const Eigen::Matrix3d& rectified_from_camera,
                     const Eigen::Matrix3d& projection, int width, int height) {
  // The scene is far away compared to the lens: a non-central camera acts
  // as its far-field part (the same camera for central models).
  const Camera camera = FarFieldCamera(lens);
  cv::Mat map_x(height, width, CV_32FC1), map_y(height, width, CV_32FC1);
  const Eigen::Matrix3d camera_from_pixel =
      rectified_from_camera.transpose() * projection.inverse();
  // Beyond the fold of a pinhole's distortion polynomial (where the image
  // radius stops growing with the ray's angle) a ray lands on a pixel that
  // is not its own: black.
  const bool pinhole = CameraModelIsPinhole(camera.model);
  const Eigen::Vector2d centre(camera.params[2], camera.params[3]);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector3d ray = camera_from_pixel * Eigen::Vector3d(u, v, 1);
      Eigen::Vector2d pixel;
      bool valid = camera.Project(ray, &pixel) && pixel.allFinite();
      if (valid && pinhole) {
        Eigen::Vector3d outward = ray;
        outward.head<2>() *= 1.0 + 1e-4;
        Eigen::Vector2d further;
        valid = camera.Project(outward, &further) &&
                (further - centre).norm() > (pixel - centre).norm();
      }
      if (!valid) {
        pixel.setConstant(-1e6);
      }
      map_x.at<float>(v, u) = static_cast<float>(pixel.x());
      map_y.at<float>(v, u) = static_cast<float>(pixel.y());
    }
  }
  cv::Mat rectified;
  cv::remap(image, rectified, map_x, map_y, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  return rectified;
}

StereoRectification ViewingRectification(
    const Camera& first, const Camera& second,
    const Eigen::Isometry3d& second_from_first) {
  const Eigen::Matrix3d r = second_from_first.linear();
  const Eigen::Vector3d centre =
      -(r.transpose() * second_from_first.translation());
  const Eigen::Vector3d x = centre.normalized();
  const Eigen::Vector3d axes =
      (Eigen::Vector3d::UnitZ() + r.transpose() * Eigen::Vector3d::UnitZ())
          .normalized();
  const Eigen::Vector3d z = (axes - x * x.dot(axes)).normalized();
  const Eigen::Vector3d y = z.cross(x);
  StereoRectification rect;
  rect.r1.row(0) = x.transpose();
  rect.r1.row(1) = y.transpose();
  rect.r1.row(2) = z.transpose();
  rect.r2 = rect.r1 * r.transpose();
  const double f = std::min(first.params[0], second.params[0]);
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = k(1, 1) = f;
  k(0, 2) = 0.5 * (first.width - 1);
  k(1, 2) = 0.5 * (first.height - 1);
  rect.p1.setZero();
  rect.p1.leftCols<3>() = k;
  rect.p2 = rect.p1;
  rect.p2(0, 3) = -f * centre.norm();
  rect.width = first.width;
  rect.height = first.height;
  rect.q.setZero();
  rect.essential.setZero();
  rect.fundamental.setZero();
  return rect;
}

cv::Mat RectifiedPairImage(const cv::Mat& first, const cv::Mat& second,
                           const Camera& first_camera,
                           const Camera& second_camera,
                           const StereoRectification& rect,
                           const RigReportOptions& options) {
  const Eigen::Matrix3d k1 = rect.p1.leftCols<3>();
  const Eigen::Matrix3d k2 = rect.p2.leftCols<3>();
  const cv::Mat a =
      RectifyImage(first, first_camera, rect.r1, k1, rect.width, rect.height);
  const cv::Mat b =
      RectifyImage(second, second_camera, rect.r2, k2, rect.width, rect.height);
  cv::Mat pair;
  cv::hconcat(a, b, pair);
  Overlay overlay;
  for (int y = options.line_spacing_px / 2; y < pair.rows;
       y += options.line_spacing_px) {
    OverlayMark line;
    line.kind = OverlayMark::Kind::kLine;
    line.at = Eigen::Vector2d(0, y);
    line.to = Eigen::Vector2d(pair.cols - 1, y);
    line.colour = cv::Scalar(0, 200, 0);
    overlay.marks.push_back(line);
  }
  return DrawOverlay(pair, overlay, OverlayOptions());
}

bool WriteRigReport(const std::string& dir, const RigReportInput& input,
                    const RigReportOptions& options, std::string* error) {
  std::string why;
  if (!options.Check(&why)) return Fail("rig report options: " + why, error);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Fail("cannot create '" + dir + "': " + ec.message(), error);
  std::ostringstream summary;
  summary << (input.calibration_ok
                  ? "calibration: ok\n"
                  : "calibration failed: " + input.calibration_error + "\n");
  if (input.result != nullptr && !input.result->cameras.empty() &&
      input.calibration_ok) {
    summary << RigCalibrationReport(*input.result);
  }
  summary << "time: " << input.seconds_total << " s on " << input.threads
          << " threads (images " << input.seconds_images << " s)\n";
  if (!WriteFileAtomically((fs::path(dir) / "summary.txt").string(),
                           summary.str(), error)) {
    return false;
  }
  if (!input.calibration_ok || input.result == nullptr ||
      input.result->cameras.size() < 2 || input.files.size() < 2) {
    return true;
  }
  const RigCalibrationResult& result = *input.result;
  // The frame both first cameras saw with the most corners between them.
  int best = -1, best_corners = 0;
  for (size_t f = 0; f < result.frame_used.size(); ++f) {
    if (f >= input.files[0].size() || f >= input.files[1].size()) break;
    if (!result.cameras[0].frame_used[f] || !result.cameras[1].frame_used[f]) {
      continue;
    }
    const int corners = static_cast<int>(result.cameras[0].inlier[f].size() +
                                         result.cameras[1].inlier[f].size());
    if (corners > best_corners) {
      best_corners = corners;
      best = static_cast<int>(f);
    }
  }
  if (best < 0) return true;
  const StereoRectification rect =
      ViewingRectification(result.cameras[0].camera, result.cameras[1].camera,
                           result.cameras[1].cam_from_rig *
                               result.cameras[0].cam_from_rig.inverse());
  cv::Mat first, second;
  if (!LoadGreyImage(input.files[0][best], ImageLoadOptions(), &first, error) ||
      !LoadGreyImage(input.files[1][best], ImageLoadOptions(), &second,
                     error)) {
    return false;
  }
  const cv::Mat pair =
      RectifiedPairImage(first, second, result.cameras[0].camera,
                         result.cameras[1].camera, rect, options);
  return WritePng((fs::path(dir) / "rectified_pair.png").string(), pair, error);
}

}  // namespace puzzlecal
