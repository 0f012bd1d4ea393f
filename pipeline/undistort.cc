#include "pipeline/undistort.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "util/angles.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

// Map value of target pixels without a source pixel (outside every image).
constexpr float kNoSource = -1000.0f;

// Pixel of the normalised point (x, y, 1); false when the model refuses it.
bool ProjectNormalized(const Camera& camera, double x, double y,
                       Eigen::Vector2d* pixel) {
  return camera.Project(Eigen::Vector3d(x, y, 1.0), pixel);
}

// Determinant of d(pixel) / d(x, y) at the normalised point (x, y):
// positive where the distortion keeps its orientation, 0 at its fold.
double JacobianDeterminant(const Camera& camera, double x, double y) {
  const double h = 1e-6;
  Eigen::Vector2d p0, px, py;
  if (!ProjectNormalized(camera, x, y, &p0) ||
      !ProjectNormalized(camera, x + h, y, &px) ||
      !ProjectNormalized(camera, x, y + h, &py)) {
    return -1;
  }
  const Eigen::Vector2d dx = (px - p0) / h;
  const Eigen::Vector2d dy = (py - p0) / h;
  return dx.x() * dy.y() - dx.y() * dy.x();
}

// True when the segment from the axis to the normalised point (x, y) stays
// on the near side of the distortion's fold (the model is one-to-one there,
// with min_area_ratio to spare) and within max_angle_deg of the axis.
bool InsideFold(const Camera& camera, double x, double y,
                const UndistortOptions& options) {
  if (std::atan(std::hypot(x, y)) > options.max_angle_deg * kDegree)
    return false;
  const double on_axis = JacobianDeterminant(camera, 0, 0);
  constexpr int kSteps = 8;
  for (int k = 1; k <= kSteps; ++k) {
    const double t = static_cast<double>(k) / kSteps;
    if (!(JacobianDeterminant(camera, t * x, t * y) >=
          options.min_area_ratio * on_axis)) {
      return false;
    }
  }
  return true;
}

// The normalised point behind source pixel `pixel`, when the model inverts
// it there (Unproject converges, the ray is within max_angle_deg and inside
// the fold). `beyond_angle` tells whether the ray was refused for its angle.
bool InvertPixel(const Camera& camera, const Eigen::Vector2d& pixel,
                 const UndistortOptions& options, Eigen::Vector2d* normalized,
                 bool* beyond_angle = nullptr) {
  Eigen::Vector3d ray;
  const UnprojectStatus status = camera.Unproject(pixel, &ray);
  if (!status.converged || !(status.residual_px <= options.tolerance_px)) {
    return false;
  }
  const double angle = std::atan2(ray.head<2>().norm(), ray.z());
  if (angle > options.max_angle_deg * kDegree) {
    if (beyond_angle != nullptr) *beyond_angle = true;
    return false;
  }
  *normalized = ray.head<2>() / ray.z();
  return InsideFold(camera, normalized->x(), normalized->y(), options);
}

// The last invertible point on the line from the principal point to
// `pixel` (bisection), as a normalised point.
Eigen::Vector2d LastInvertible(const Camera& camera,
                               const Eigen::Vector2d& pixel,
                               const UndistortOptions& options) {
  const Eigen::Vector2d centre(camera.params[2], camera.params[3]);
  double lo = 0, hi = 1;
  Eigen::Vector2d best(0, 0), n;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (InvertPixel(camera, centre + mid * (pixel - centre), options, &n)) {
      lo = mid;
      best = n;
    } else {
      hi = mid;
    }
  }
  return best;
}

// The source pixel of the target's normalised point (x, y): false when it is
// outside the source image, beyond the fold or max_angle_deg, or when the
// model's own inverse does not lead back to (x, y) (within a few times its
// tolerance, in pixels of the source focal length).
bool SourcePixel(const Camera& source, double x, double y,
                 const UndistortOptions& options, Eigen::Vector2d* pixel) {
  if (!ProjectNormalized(source, x, y, pixel)) return false;
  if (pixel->x() < -0.5 || pixel->y() < -0.5 ||
      pixel->x() > source.width - 0.5 || pixel->y() > source.height - 0.5) {
    return false;
  }
  if (!InsideFold(source, x, y, options)) return false;
  Eigen::Vector3d ray;
  const UnprojectStatus status = source.Unproject(*pixel, &ray);
  return status.converged && status.residual_px <= options.tolerance_px &&
         ray.z() > 0 &&
         (ray.head<2>() / ray.z() - Eigen::Vector2d(x, y)).norm() *
                 source.params[0] <=
             5 * options.tolerance_px;
}

// Focal length and principal point (one axis) that map [lo, hi] in
// normalised coordinates onto the pixels [-0.5, size - 0.5].
void FitAxis(double lo, double hi, int size, double* f, double* c) {
  *f = size / std::max(hi - lo, 1e-12);
  *c = -0.5 - *f * lo;
}

}  // namespace

bool UndistortOptions::Check(std::string* why) const {
  if (!(alpha >= 0 && alpha <= 1)) return Fail("alpha must be in [0, 1]", why);
  if (!(max_angle_deg > 0 && max_angle_deg <= 89)) {
    return Fail("max_angle_deg must be in (0, 89]", why);
  }
  if (!(min_area_ratio > 0 && min_area_ratio < 1)) {
    return Fail("min_area_ratio must be in (0, 1)", why);
  }
  if (border_samples < 4) return Fail("border_samples must be >= 4", why);
  if (!(tolerance_px > 0)) return Fail("tolerance_px must be positive", why);
  return true;
}

UndistortResult ChooseUndistortTarget(const Camera& source_camera,
                                      const UndistortOptions& options) {
  // The scene is far away compared to the lens: a non-central camera acts
  // as its far-field part (the same camera for central models).
  const Camera source = FarFieldCamera(source_camera);
  UndistortResult result;
  const int w = source.width, h = source.height;
  // The source border, side by side: each sample as a normalised point,
  // pulled in towards the principal point where the model has no inverse.
  std::vector<Eigen::Vector2d> left, right, top, bottom;
  int invertible = 0, samples = 0;
  auto trace = [&](const Eigen::Vector2d& pixel,
                   std::vector<Eigen::Vector2d>* side) {
    Eigen::Vector2d n;
    bool beyond_angle = false;
    ++samples;
    if (InvertPixel(source, pixel, options, &n, &beyond_angle)) {
      ++invertible;
      side->push_back(n);
      return;
    }
    result.limited_by_max_angle |= beyond_angle;
    side->push_back(LastInvertible(source, pixel, options));
  };
  const int n = options.border_samples;
  for (int k = 0; k <= n; ++k) {
    const double s = static_cast<double>(k) / n;
    trace(Eigen::Vector2d(-0.5, -0.5 + s * h), &left);
    trace(Eigen::Vector2d(w - 0.5, -0.5 + s * h), &right);
    trace(Eigen::Vector2d(-0.5 + s * w, -0.5), &top);
    trace(Eigen::Vector2d(-0.5 + s * w, h - 0.5), &bottom);
  }
  result.border_invertible_fraction =
      static_cast<double>(invertible) / std::max(1, samples);

  // Inner rectangle: inside every side (alpha 0); outer: around all of them
  // (alpha 1), as cv::getOptimalNewCameraMatrix does with its own inverse.
  double inner[4] = {-1e300, 1e300, -1e300, 1e300};  // x0 x1 y0 y1
  double outer[4] = {1e300, -1e300, 1e300, -1e300};
  for (const auto* side : {&left, &right, &top, &bottom}) {
    for (const Eigen::Vector2d& p : *side) {
      outer[0] = std::min(outer[0], p.x());
      outer[1] = std::max(outer[1], p.x());
      outer[2] = std::min(outer[2], p.y());
      outer[3] = std::max(outer[3], p.y());
    }
  }
  for (const Eigen::Vector2d& p : left) inner[0] = std::max(inner[0], p.x());
  for (const Eigen::Vector2d& p : right) inner[1] = std::min(inner[1], p.x());
  for (const Eigen::Vector2d& p : top) inner[2] = std::max(inner[2], p.y());
  for (const Eigen::Vector2d& p : bottom) inner[3] = std::min(inner[3], p.y());

  double fx0, cx0, fy0, cy0, fx1, cx1, fy1, cy1;
  FitAxis(inner[0], inner[1], w, &fx0, &cx0);
  FitAxis(inner[2], inner[3], h, &fy0, &cy0);
  FitAxis(outer[0], outer[1], w, &fx1, &cx1);
  FitAxis(outer[2], outer[3], h, &fy1, &cy1);
  const double a = options.alpha;
  Camera& target = result.target;
  target.model = CameraModelId::kPinholeRadtan;
  target.width = w;
  target.height = h;
  target.params.assign(CameraModelNumParams(target.model), 0.0);
  target.params[0] = (1 - a) * fx0 + a * fx1;
  target.params[1] = (1 - a) * fy0 + a * fy1;
  target.params[2] = (1 - a) * cx0 + a * cx1;
  target.params[3] = (1 - a) * cy0 + a * cy1;

  for (double u : {-0.5, w - 0.5}) {
    for (double v : {-0.5, h - 0.5}) {
      const double x = (u - target.params[2]) / target.params[0];
      const double y = (v - target.params[3]) / target.params[1];
      result.target_max_angle_deg = std::max(
          result.target_max_angle_deg, std::atan(std::hypot(x, y)) / kDegree);
    }
  }
  // Coverage on every 4th pixel.
  int covered = 0, counted = 0;
  for (int v = 0; v < h; v += 4) {
    for (int u = 0; u < w; u += 4) {
      Eigen::Vector2d pixel;
      covered += SourcePixel(source, (u - target.params[2]) / target.params[0],
                             (v - target.params[3]) / target.params[1], options,
                             &pixel);
      ++counted;
    }
  }
  result.target_covered_fraction =
      static_cast<double>(covered) / std::max(1, counted);
  return result;
}

void MakeUndistortMaps(const Camera& source_camera, const Camera& target,
                       const UndistortOptions& options, cv::Mat* map_x,
                       cv::Mat* map_y) {
  // The scene is far away compared to the lens: a non-central camera acts
  // as its far-field part (the same camera for central models).
  const Camera source = FarFieldCamera(source_camera);
  map_x->create(target.height, target.width, CV_32FC1);
  map_y->create(target.height, target.width, CV_32FC1);
  const auto& k = target.params;
  for (int v = 0; v < target.height; ++v) {
    float* mx = map_x->ptr<float>(v);
    float* my = map_y->ptr<float>(v);
    for (int u = 0; u < target.width; ++u) {
      Eigen::Vector2d pixel;
      const bool ok = SourcePixel(source, (u - k[2]) / k[0], (v - k[3]) / k[1],
                                  options, &pixel);
      mx[u] = ok ? static_cast<float>(pixel.x()) : kNoSource;
      my[u] = ok ? static_cast<float>(pixel.y()) : kNoSource;
    }
  }
}

std::string UndistortResult::Summary(const UndistortOptions& options) const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  const auto& p = target.params;
  const double hfov = (std::atan((0.5 + p[2]) / p[0]) +
                       std::atan((target.width - 0.5 - p[2]) / p[0])) /
                      kDegree;
  const double vfov = (std::atan((0.5 + p[3]) / p[1]) +
                       std::atan((target.height - 0.5 - p[3]) / p[1])) /
                      kDegree;
  out << "target: pinhole without distortion, " << target.width << "x"
      << target.height << ", fx " << p[0] << " fy " << p[1] << " cx " << p[2]
      << " cy " << p[3] << " (alpha " << options.alpha << ")\n";
  out << "field: " << hfov << " x " << vfov << " degrees, corners "
      << target_max_angle_deg << " degrees from the axis; "
      << 100.0 * target_covered_fraction
      << " % of the target pixels have a source pixel\n";
  if (border_invertible_fraction < 1) {
    out << "the camera model has no inverse on "
        << 100.0 * (1 - border_invertible_fraction)
        << " % of the image border (the distortion folds over or has no "
           "preimage there";
    if (limited_by_max_angle) {
      out << ", or the rays are more than " << options.max_angle_deg
          << " degrees off the axis, which a pinhole image cannot hold "
             "usefully";
    }
    out << "): the target covers the invertible region only\n";
  }
  return out.str();
}

}  // namespace puzzlecal
