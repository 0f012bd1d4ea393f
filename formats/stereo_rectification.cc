#include "formats/stereo_rectification.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <vector>

#include "formats/yaml_emit.h"
#include "util/angles.h"
#include "util/failure.h"
#include "util/statistics.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// The pixel of `ray` (camera frame) when the camera sees it: it projects
// inside the image and, for a pinhole model, on the near side of the fold
// of its distortion polynomial (where the image radius still grows with
// the ray's angle; beyond it a ray lands on a pixel that is not its own).
bool SeesRay(const Camera& camera, const Eigen::Vector3d& ray,
             Eigen::Vector2d* pixel) {
  if (!camera.Project(ray, pixel) || !pixel->allFinite()) return false;
  if (pixel->x() < 0 || pixel->y() < 0 || pixel->x() > camera.width - 1 ||
      pixel->y() > camera.height - 1) {
    return false;
  }
  if (!CameraModelIsPinhole(camera.model)) return true;
  if (!(ray.z() > 0)) return false;
  // The image radius must grow all the way from the axis to the ray: a
  // ray beyond the fold (or where the polynomial turns negative and flips
  // the point through the centre) lands on a pixel that is not its own.
  const Eigen::Vector2d centre(camera.params[2], camera.params[3]);
  const Eigen::Vector2d normalized = ray.head<2>() / ray.z();
  double previous = 0;
  constexpr int kSteps = 16;
  for (int k = 1; k <= kSteps; ++k) {
    const double t = static_cast<double>(k) / kSteps;
    Eigen::Vector2d step_pixel;
    if (!camera.Project(
            Eigen::Vector3d(t * normalized.x(), t * normalized.y(), 1.0),
            &step_pixel)) {
      return false;
    }
    const Eigen::Vector2d offset = step_pixel - centre;
    const double radius = offset.norm();
    // Growing, and on the same side as the undistorted point.
    if (!(radius > previous) ||
        (normalized.norm() > 0 && offset.dot(normalized) < 0)) {
      return false;
    }
    previous = radius;
  }
  Eigen::Vector3d outward = ray;
  outward.head<2>() *= 1.0 + 1e-4;
  Eigen::Vector2d further;
  return camera.Project(outward, &further) &&
         (further - centre).norm() > (*pixel - centre).norm();
}

// The interval of angles (degrees, about the rectified y axis, positive
// towards +x) of the rectified horizontal plane that `camera` sees, its
// rays turned by camera_from_rectified. False when it sees none.
bool HorizontalCoverage(const Camera& camera,
                        const Eigen::Matrix3d& camera_from_rectified,
                        double* low_deg, double* high_deg) {
  bool any = false;
  for (double a = -89.5; a <= 89.5; a += 0.25) {
    const Eigen::Vector3d d(std::sin(a * kDegree), 0, std::cos(a * kDegree));
    Eigen::Vector2d pixel;
    if (!SeesRay(camera, camera_from_rectified * d, &pixel)) continue;
    if (!any) *low_deg = a;
    *high_deg = a;
    any = true;
  }
  return any;
}

// Share of the rectified image (K, width x height) that `camera` sees.
double ValidFraction(const Camera& camera,
                     const Eigen::Matrix3d& camera_from_rectified,
                     const Eigen::Matrix3d& k, int width, int height) {
  constexpr int kCols = 48, kRows = 36;
  const Eigen::Matrix3d k_inv = k.inverse();
  int seen = 0;
  for (int j = 0; j < kRows; ++j) {
    for (int i = 0; i < kCols; ++i) {
      const Eigen::Vector3d p((i + 0.5) * width / kCols - 0.5,
                              (j + 0.5) * height / kRows - 0.5, 1.0);
      Eigen::Vector2d pixel;
      seen += SeesRay(camera, camera_from_rectified * (k_inv * p), &pixel);
    }
  }
  return static_cast<double>(seen) / (kCols * kRows);
}

// Why cv::stereoRectify's crop cannot be used: "" or which camera's
// distortion folds over inside its image, and over how much of its border.
std::string FoldedBorder(const Camera& first, const Camera& second) {
  for (int c = 0; c < 2; ++c) {
    const double fraction = BorderFractionWithoutRay(c == 0 ? first : second);
    if (fraction > 0) {
      return StringPrintf(
          "camera %d's distortion folds over inside its image (%.1f%% of its "
          "border has no ray), so the crop to the undistorted border is "
          "wrong",
          c + 1, 100 * fraction);
    }
  }
  return "";
}

// The rotations (and, for pinholes, the projections) of cv::stereoRectify.
bool OpenCvRectify(const Camera& first, const Camera& second,
                   const Eigen::Isometry3d& second_from_first,
                   bool with_distortion, StereoRectification* rect,
                   std::string* error) {
  cv::Mat cv_k1, cv_k2, cv_r, cv_t;
  cv::eigen2cv(CameraMatrixOf(first), cv_k1);
  cv::eigen2cv(CameraMatrixOf(second), cv_k2);
  const Eigen::Matrix3d r = second_from_first.linear();
  const Eigen::Vector3d t = second_from_first.translation();
  cv::eigen2cv(r, cv_r);
  cv::eigen2cv(t, cv_t);
  // cv::Mat over a std::vector does not copy: the vectors must outlive the
  // call.
  const std::vector<double> distortion1 = DistortionOf(first);
  const std::vector<double> distortion2 = DistortionOf(second);
  const cv::Mat d1 = with_distortion ? cv::Mat(distortion1) : cv::Mat();
  const cv::Mat d2 = with_distortion ? cv::Mat(distortion2) : cv::Mat();
  cv::Mat r1, r2, p1, p2, q;
  try {
    cv::stereoRectify(cv_k1, d1, cv_k2, d2, cv::Size(first.width, first.height),
                      cv_r, cv_t, r1, r2, p1, p2, q, cv::CALIB_ZERO_DISPARITY,
                      0.0);
  } catch (const cv::Exception& e) {
    return Fail(std::string("stereo rectification failed: ") + e.what(), error);
  }
  cv::cv2eigen(r1, rect->r1);
  cv::cv2eigen(r2, rect->r2);
  cv::cv2eigen(p1, rect->p1);
  cv::cv2eigen(p2, rect->p2);
  cv::cv2eigen(q, rect->q);
  return true;
}

// The pinhole target chosen here: the common horizontal field of the two
// cameras in the rectified frame, clipped to the options' field.
bool OwnTarget(const Camera& first, const Camera& second,
               const Eigen::Isometry3d& second_from_first,
               const StereoRectificationOptions& options,
               StereoRectification* rect, std::string* error) {
  double low1 = 0, high1 = 0, low2 = 0, high2 = 0;
  const bool sees1 =
      HorizontalCoverage(first, rect->r1.transpose(), &low1, &high1);
  const bool sees2 =
      HorizontalCoverage(second, rect->r2.transpose(), &low2, &high2);
  double low = std::max(low1, low2), high = std::min(high1, high2);
  if (!sees1 || !sees2 || !(high > low)) {
    return Fail(
        "the two cameras see no common direction along the baseline, so no "
        "rectified view holds both",
        error);
  }
  // A pinhole view stretches its rim without bound towards 90 degrees from
  // its axis: each side is clipped to half the largest field.
  const double half = 0.5 * options.max_field_of_view_deg;
  low = std::max(low, -half);
  high = std::min(high, half);
  if (!(high > low)) {
    return Fail(StringPrintf("the cameras' common field lies more than %.0f "
                             "deg from the rectified axis",
                             half),
                error);
  }
  const int w = first.width, h = first.height;
  const double f =
      (w - 1) / (std::tan(high * kDegree) - std::tan(low * kDegree));
  const double cx = -f * std::tan(low * kDegree);
  const double cy = 0.5 * (h - 1);
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = k(1, 1) = f;
  k(0, 2) = cx;
  k(1, 2) = cy;
  const double tx = (rect->r2 * second_from_first.translation()).x();
  rect->p1.setZero();
  rect->p1.leftCols<3>() = k;
  rect->p2 = rect->p1;
  rect->p2(0, 3) = f * tx;
  rect->q.setZero();
  rect->q(0, 0) = rect->q(1, 1) = 1;
  rect->q(0, 3) = -cx;
  rect->q(1, 3) = -cy;
  rect->q(2, 3) = f;
  rect->q(3, 2) = -1.0 / tx;
  rect->own_target = true;
  return true;
}

// The check (see the header); fills the figures of `rect`.
bool CheckRectification(const Camera& first, const Camera& second,
                        const Eigen::Isometry3d& second_from_first,
                        const StereoRectificationOptions& options,
                        StereoRectification* rect, std::string* why) {
  const bool finite = rect->r1.allFinite() && rect->r2.allFinite() &&
                      rect->p1.allFinite() && rect->p2.allFinite() &&
                      rect->q.allFinite();
  if (!finite) return Fail("the rectification is not finite", why);
  const Eigen::Matrix3d k1 = rect->p1.leftCols<3>();
  const Eigen::Matrix3d k2 = rect->p2.leftCols<3>();
  const double f = k1(0, 0);
  for (const Camera* camera : {&first, &second}) {
    const double own = camera->params[0];
    if (!(f >= own / options.max_focal_ratio &&
          f <= own * options.max_focal_ratio) ||
        !(k1(1, 1) >= own / options.max_focal_ratio &&
          k1(1, 1) <= own * options.max_focal_ratio)) {
      return Fail(StringPrintf("the rectified focal length %.4g px is not "
                               "within %.0fx of the camera's own %.4g px",
                               f, options.max_focal_ratio, own),
                  why);
    }
  }
  rect->field_of_view_deg =
      (std::atan((rect->width - 1 - k1(0, 2)) / f) + std::atan(k1(0, 2) / f)) /
      kDegree;
  rect->vertical_field_of_view_deg =
      (std::atan((rect->height - 1 - k1(1, 2)) / k1(1, 1)) +
       std::atan(k1(1, 2) / k1(1, 1))) /
      kDegree;
  rect->valid_fraction[0] =
      ValidFraction(first, rect->r1.transpose(), k1, rect->width, rect->height);
  rect->valid_fraction[1] = ValidFraction(second, rect->r2.transpose(), k2,
                                          rect->width, rect->height);
  for (int c = 0; c < 2; ++c) {
    if (!(rect->valid_fraction[c] >= options.min_valid_fraction)) {
      return Fail(StringPrintf("camera %d covers %.1f%% of its rectified "
                               "image (at least %.1f%% needed)",
                               c + 1, 100 * rect->valid_fraction[c],
                               100 * options.min_valid_fraction),
                  why);
    }
  }
  // Points over the first rectified view at several depths.
  const double baseline = second_from_first.translation().norm();
  const Eigen::Matrix3d k_inv = k1.inverse();
  std::vector<double> rows;
  for (double depth : {3.0, 10.0, 50.0}) {
    for (int j = 0; j < 12; ++j) {
      for (int i = 0; i < 16; ++i) {
        const Eigen::Vector3d p((i + 0.5) * rect->width / 16 - 0.5,
                                (j + 0.5) * rect->height / 12 - 0.5, 1.0);
        const Eigen::Vector3d x1 =
            rect->r1.transpose() * (depth * baseline * (k_inv * p));
        const Eigen::Vector3d x2 = second_from_first * x1;
        Eigen::Vector2d pixel1, pixel2, a, b;
        if (!SeesRay(first, x1, &pixel1) || !SeesRay(second, x2, &pixel2)) {
          continue;
        }
        if (!RectifyPixel(first, rect->r1, rect->p1, pixel1, &a) ||
            !RectifyPixel(second, rect->r2, rect->p2, pixel2, &b)) {
          continue;
        }
        rows.push_back(std::abs(a.y() - b.y()));
      }
    }
  }
  rect->num_check_points = static_cast<int>(rows.size());
  if (rows.empty()) {
    return Fail("no point in front of the pair is seen by both cameras", why);
  }
  rect->max_row_difference_px = *std::max_element(rows.begin(), rows.end());
  rect->median_row_difference_px = Median(rows);
  if (!(rect->max_row_difference_px <= options.max_row_difference_px)) {
    return Fail(StringPrintf("rectified rows of the same point differ by up "
                             "to %.3g px (limit %.3g px)",
                             rect->max_row_difference_px,
                             options.max_row_difference_px),
                why);
  }
  return true;
}

}  // namespace

bool StereoRectificationOptions::Check(std::string* why) const {
  if (!(max_field_of_view_deg > 0 && max_field_of_view_deg <= 170)) {
    return Fail("max_field_of_view_deg must be in (0, 170]", why);
  }
  if (!(max_row_difference_px > 0)) {
    return Fail("max_row_difference_px must be > 0", why);
  }
  if (!(max_focal_ratio > 1)) return Fail("max_focal_ratio must be > 1", why);
  if (!(min_valid_fraction > 0 && min_valid_fraction < 1)) {
    return Fail("min_valid_fraction must be in (0, 1)", why);
  }
  return true;
}

std::string StereoRectification::Summary() const {
  const std::string how =
      own_target ? "a pinhole target chosen for the pair's common field (" +
                       own_target_reason + ")"
                 : std::string("cv::stereoRectify (alpha 0)");
  return StringPrintf(
      "%s, %d x %d, focal length %.2f px, field %.1f x %.1f deg; the cameras "
      "cover %.0f%% and %.0f%% of their rectified images; rows of points "
      "seen by both agree to %.2g px",
      how.c_str(), width, height, p1(0, 0), field_of_view_deg,
      vertical_field_of_view_deg, 100 * valid_fraction[0],
      100 * valid_fraction[1], max_row_difference_px);
}

bool RectifyPixel(const Camera& camera, const Eigen::Matrix3d& r,
                  const Eigen::Matrix<double, 3, 4>& p,
                  const Eigen::Vector2d& pixel, Eigen::Vector2d* rectified) {
  const Camera central = FarFieldCamera(camera);
  Eigen::Vector3d ray;
  const UnprojectStatus status = central.Unproject(pixel, &ray);
  if (!status.converged || !ray.allFinite()) return false;
  const Eigen::Vector3d turned = r * ray;
  if (!(turned.z() > 0)) return false;
  *rectified = (p.leftCols<3>() * turned).hnormalized();
  return rectified->allFinite();
}

bool StereoRectify(const Camera& first, const Camera& second,
                   const Eigen::Isometry3d& second_from_first,
                   StereoRectification* rectification, std::string* error) {
  return StereoRectify(first, second, second_from_first,
                       StereoRectificationOptions(), rectification, error);
}

bool StereoRectify(const Camera& first_lens, const Camera& second_lens,
                   const Eigen::Isometry3d& second_from_first,
                   const StereoRectificationOptions& options,
                   StereoRectification* rect, std::string* error) {
  std::string why;
  if (!options.Check(&why)) {
    return Fail("stereo rectification options: " + why, error);
  }
  const Camera first = FarFieldCamera(first_lens);
  const Camera second = FarFieldCamera(second_lens);
  const Eigen::Matrix3d r = second_from_first.linear();
  const Eigen::Vector3d t = second_from_first.translation();
  if (!(t.norm() > 0)) {
    return Fail("the two cameras share one centre: no stereo rectification",
                error);
  }
  *rect = StereoRectification();
  const Eigen::Matrix3d k1 = CameraMatrixOf(first), k2 = CameraMatrixOf(second);
  rect->essential = Skew(t) * r;
  rect->fundamental = k2.inverse().transpose() * rect->essential * k1.inverse();
  rect->width = first.width;
  rect->height = first.height;
  const bool pinholes =
      CameraModelIsPinhole(first.model) && CameraModelIsPinhole(second.model);
  // A fisheye's coefficients mean nothing to cv::stereoRectify: leave the
  // distortion out (the rotations do not depend on it).
  if (!OpenCvRectify(first, second, second_from_first, pinholes, rect, error)) {
    return false;
  }
  // cv::stereoRectify crops (alpha 0) to the undistorted image border; where
  // a camera's distortion folds over, part of that border has no ray and
  // the crop follows a border that is not there (bb2: 1.5 times the
  // focal length, the principal point far off-centre, a view of a corner
  // of the scene). The target chosen here takes only rays the camera sees.
  const std::string folded = FoldedBorder(first, second);
  std::string opencv_why;
  if (pinholes && folded.empty() &&
      CheckRectification(first, second, second_from_first, options, rect,
                         &opencv_why)) {
    return true;
  }
  rect->own_target_reason =
      !pinholes ? "a fisheye's coefficients mean nothing to cv::stereoRectify"
      : !folded.empty() ? "cv::stereoRectify not used: " + folded
                        : "cv::stereoRectify failed the check: " + opencv_why;
  if (!OwnTarget(first, second, second_from_first, options, rect, &why) ||
      !CheckRectification(first, second, second_from_first, options, rect,
                          &why)) {
    return Fail(
        "no usable stereo rectification: " + why +
            (opencv_why.empty() ? std::string()
                                : " (cv::stereoRectify: " + opencv_why + ")"),
        error);
  }
  return true;
}

}  // namespace puzzlecal
