#include "evidence/evidence.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <vector>

#include "calib/reprojection_error.h"
#include "util/angles.h"
#include "util/failure.h"
#include "util/parallel_for.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return kNaN;
  const size_t k = std::min(values.size() - 1,
                            static_cast<size_t>(q * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

// Every map and figure here is of the far field: a ray's direction, as
// Unproject gives it. Camera::Project takes a point, and a unit ray as a
// point is one metre away, where a non-central lens still shows its pupil
// shift (a 4 mm shift at 90 degrees moves such a point by about 1 px on a
// 300 px fisheye). So directions are projected as points this far along
// them (metres), where the shift moves them by about 1e-6 px; central models
// give the same pixel at any distance.
constexpr double kFarDistanceM = 1e6;

bool ProjectDirection(const Camera& camera, const Eigen::Vector3d& ray,
                      Eigen::Vector2d* pixel) {
  return camera.Project(kFarDistanceM * ray, pixel);
}

double FieldAngleDeg(const Eigen::Vector3d& ray) {
  return std::atan2(ray.head<2>().norm(), ray.z()) / kDegree;
}

// d pixel / d intrinsics (jacobian, 2 x n) and d pixel / d ray (point, 2 x
// 3) of the projection of the far point along `ray`: the solvers' own
// Jacobians (calib/reprojection_error.h) for the board point kFarDistanceM
// along the ray seen from the identity pose, whose translation derivative
// is the derivative by the point (compiled once there, for every model).
bool ProjectionJacobians(CameraModelId model, const double* params,
                         const Eigen::Vector3d& ray, Eigen::MatrixXd* jacobian,
                         Eigen::Matrix<double, 2, 3>* point) {
  const int n = CameraModelNumParams(model);
  std::vector<double> d_intrinsics(2 * n);
  double d_pose[2 * kPoseBlockSize];
  const double identity[kPoseBlockSize] = {0, 0, 0, 0, 0, 0};
  if (!ReprojectionJacobians(model, params, identity, kFarDistanceM * ray,
                             d_intrinsics.data(), d_pose)) {
    return false;
  }
  jacobian->resize(2, n);
  for (int r = 0; r < 2; ++r) {
    for (int k = 0; k < n; ++k) (*jacobian)(r, k) = d_intrinsics[r * n + k];
    for (int k = 0; k < 3; ++k) {
      (*point)(r, k) = kFarDistanceM * d_pose[r * kPoseBlockSize + 3 + k];
    }
  }
  return jacobian->allFinite() && point->allFinite();
}

// At `pixel`: J = d pixel / d intrinsics with the ray held fixed, and G =
// d pixel / d omega for a small rotation omega of the ray (ray + omega x ray).
bool PixelJacobians(const Camera& camera, const Eigen::Vector2d& pixel,
                    Eigen::MatrixXd* jacobian, Eigen::Matrix<double, 2, 3>* g) {
  Eigen::Vector3d ray;
  if (!camera.Unproject(pixel, &ray).converged) return false;
  Eigen::Matrix<double, 2, 3> point;
  if (!ProjectionJacobians(camera.model, camera.params.data(), ray, jacobian,
                           &point)) {
    return false;
  }
  Eigen::Matrix3d cross;  // omega x ray = -[ray]_x omega
  cross << 0, ray.z(), -ray.y(), -ray.z(), 0, ray.x(), ray.y(), -ray.x(), 0;
  *g = point * cross;
  return true;
}

// The grid of a map for `camera`, with each sample's field angle.
PixelMap EmptyMap(const Camera& camera, int step) {
  PixelMap map;
  map.step_px = step;
  map.cols = (camera.width - 1 + step - 1) / step + 1;
  map.rows = (camera.height - 1 + step - 1) / step + 1;
  map.values.assign(map.cols * map.rows, kNaN);
  map.angle_deg.assign(map.cols * map.rows, kNaN);
  for (int j = 0; j < map.rows; ++j) {
    for (int i = 0; i < map.cols; ++i) {
      Eigen::Vector3d ray;
      const Eigen::Vector2d pixel(std::min(i * step, camera.width - 1),
                                  std::min(j * step, camera.height - 1));
      if (camera.Unproject(pixel, &ray).converged) {
        map.angle_deg[j * map.cols + i] = FieldAngleDeg(ray);
      }
    }
  }
  return map;
}

Eigen::Vector2d MapPixel(const PixelMap& map, const Camera& camera, int i,
                         int j) {
  return Eigen::Vector2d(std::min(i * map.step_px, camera.width - 1),
                         std::min(j * map.step_px, camera.height - 1));
}

// A map of sqrt(tr(C(p)) * factor) for the camera's covariance.
PixelMap CovarianceTraceMap(const Camera& camera,
                            const Eigen::MatrixXd& covariance, int step,
                            double factor, const Eigen::MatrixXd* gauge) {
  PixelMap map = EmptyMap(camera, step);
  for (int j = 0; j < map.rows; ++j) {
    for (int i = 0; i < map.cols; ++i) {
      Eigen::Matrix2d cov;
      if (ProjectionCovariance(camera, covariance, MapPixel(map, camera, i, j),
                               &cov, gauge)) {
        map.values[j * map.cols + i] =
            std::sqrt(std::max(0.0, cov.trace() * factor));
      }
    }
  }
  return map;
}

// A hash of a view's corners (their image and board coordinates, bit for
// bit), salted: it orders the views of a split by their contents.
uint64_t ViewHash(const CalibrationView& view, uint64_t salt) {
  uint64_t hash = 14695981039346656037ull ^ (salt * 0x9e3779b97f4a7c15ull);
  auto mix = [&hash](double value) {
    uint64_t bits;
    std::memcpy(&bits, &value, sizeof(bits));
    for (int byte = 0; byte < 8; ++byte) {
      hash ^= (bits >> (8 * byte)) & 0xffu;
      hash *= 1099511628211ull;
    }
  };
  for (size_t i = 0; i < view.image_points.size(); ++i) {
    mix(view.image_points[i].x());
    mix(view.image_points[i].y());
    mix(view.board_points[i].x());
    mix(view.board_points[i].y());
    mix(view.board_points[i].z());
  }
  // A final avalanche, so that nearby salts give unrelated orders.
  hash ^= hash >> 33;
  hash *= 0xff51afd7ed558ccdull;
  hash ^= hash >> 33;
  return hash;
}

// The half (0 or 1) of each view in split `split`, -1 for views `result`
// did not use. One split (cross_validation_splits 1): the used views
// alternate by position. Several: split k orders the used views by their
// hash salted with k (ties by position) and alternates, so that no split
// depends on the order of the views.
std::vector<int> SplitHalves(const std::vector<CalibrationView>& views,
                             const CalibrationResult& result, int split,
                             int num_splits) {
  std::vector<std::pair<uint64_t, size_t>> order;
  for (size_t v = 0; v < views.size(); ++v) {
    if (v >= result.view_used.size() || !result.view_used[v]) continue;
    const uint64_t key =
        num_splits > 1 ? ViewHash(views[v], static_cast<uint64_t>(split)) : 0;
    order.push_back({key, v});
  }
  std::stable_sort(
      order.begin(), order.end(),
      [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<int> half(views.size(), -1);
  for (size_t k = 0; k < order.size(); ++k) {
    half[order[k].second] = static_cast<int>(k % 2);
  }
  return half;
}

// The views of one half of a split, with their poses in `result`.
std::vector<CalibrationView> Half(const std::vector<CalibrationView>& views,
                                  const CalibrationResult& result,
                                  const std::vector<int>& half_of, int half,
                                  std::vector<Eigen::Isometry3d>* poses) {
  std::vector<CalibrationView> out;
  poses->clear();
  for (size_t v = 0; v < views.size(); ++v) {
    if (half_of[v] != half) continue;
    out.push_back(views[v]);
    poses->push_back(result.cam_from_board[v]);
  }
  return out;
}

ResidualBin MakeBin(double lo, double hi, const std::vector<double>& radial,
                    const std::vector<double>& tangential) {
  ResidualBin bin;
  bin.lo = lo;
  bin.hi = hi;
  bin.count = static_cast<int>(radial.size());
  if (bin.count == 0) return bin;
  double sum2 = 0;
  for (size_t k = 0; k < radial.size(); ++k) {
    sum2 += radial[k] * radial[k] + tangential[k] * tangential[k];
  }
  bin.rms_px = std::sqrt(sum2 / (2.0 * bin.count));
  auto mean_se = [](const std::vector<double>& x, double* mean, double* se) {
    double sum = 0;
    for (double value : x) sum += value;
    *mean = sum / x.size();
    double ss = 0;
    for (double value : x) ss += (value - *mean) * (value - *mean);
    *se = x.size() > 1 ? std::sqrt(ss / (x.size() - 1) / x.size()) : kNaN;
  };
  mean_se(radial, &bin.mean_radial_px, &bin.se_radial_px);
  mean_se(tangential, &bin.mean_tangential_px, &bin.se_tangential_px);
  return bin;
}

}  // namespace

bool EvidenceOptions::Check(std::string* why) const {
  if (grid_step_px < 1) return Fail("grid_step_px must be >= 1", why);
  if (grid_min_samples < 0) return Fail("grid_min_samples must be >= 0", why);
  if (!(band_width_deg > 0)) return Fail("band_width_deg must be > 0", why);
  if (distance_bins < 1) return Fail("distance_bins must be >= 1", why);
  if (min_bin_count < 1) return Fail("min_bin_count must be >= 1", why);
  if (cross_validation_splits < 1 || cross_validation_splits > 16) {
    return Fail("cross_validation_splits must lie in 1-16", why);
  }
  if (report_azimuths < 1) return Fail("report_azimuths must be >= 1", why);
  for (double angle : report_angles_deg) {
    if (!(angle > 0 && angle < 180)) {
      return Fail("report_angles_deg must lie in (0, 180)", why);
    }
  }
  return view_consistency.Check(why);
}

int GridStep(const Camera& camera, const EvidenceOptions& options) {
  int step = options.grid_step_px;
  if (options.grid_min_samples > 0 && camera.width > 0 && camera.height > 0) {
    const double area = static_cast<double>(camera.width) * camera.height;
    step = std::min(step, std::max(1, static_cast<int>(std::floor(std::sqrt(
                                          area / options.grid_min_samples)))));
  }
  return std::max(1, step);
}

bool ProjectionJacobianParts(const Camera& camera, const Eigen::Vector2d& pixel,
                             Eigen::MatrixXd* jacobian,
                             Eigen::Matrix<double, 2, 3>* rotation) {
  const int n = CameraModelNumParams(camera.model);
  if (static_cast<int>(camera.params.size()) != n) return false;
  return PixelJacobians(camera, pixel, jacobian, rotation);
}

bool ProjectionJacobian(const Camera& camera, const Eigen::Vector2d& pixel,
                        const Eigen::MatrixXd* gauge,
                        Eigen::MatrixXd* jacobian) {
  Eigen::Matrix<double, 2, 3> g;
  if (!ProjectionJacobianParts(camera, pixel, jacobian, &g)) return false;
  const int n = CameraModelNumParams(camera.model);
  if (gauge != nullptr && gauge->rows() == 3 && gauge->cols() == n) {
    *jacobian -= g * *gauge;
  }
  return true;
}

bool ProjectionCovariance(const Camera& camera,
                          const Eigen::MatrixXd& covariance,
                          const Eigen::Vector2d& pixel, Eigen::Matrix2d* cov,
                          const Eigen::MatrixXd* gauge) {
  const int n = CameraModelNumParams(camera.model);
  if (covariance.rows() != n || covariance.cols() != n) return false;
  Eigen::MatrixXd jacobian;
  if (!ProjectionJacobian(camera, pixel, gauge, &jacobian)) return false;
  *cov = jacobian * covariance * jacobian.transpose();
  return cov->allFinite();
}

Eigen::MatrixXd RotationGauge(const Camera& camera, int step_px,
                              double max_angle_deg) {
  const int n = CameraModelNumParams(camera.model);
  if (static_cast<int>(camera.params.size()) != n || camera.width <= 0 ||
      camera.height <= 0 || step_px < 1) {
    return Eigen::MatrixXd();
  }
  const PixelMap map = EmptyMap(camera, step_px);
  Eigen::Matrix3d gtg = Eigen::Matrix3d::Zero();
  Eigen::MatrixXd gtj = Eigen::MatrixXd::Zero(3, n);
  int count = 0;
  for (int j = 0; j < map.rows; ++j) {
    for (int i = 0; i < map.cols; ++i) {
      const double angle = map.angle_deg[j * map.cols + i];
      if (!std::isfinite(angle) || angle > max_angle_deg) continue;
      Eigen::MatrixXd jacobian;
      Eigen::Matrix<double, 2, 3> g;
      if (!PixelJacobians(camera, MapPixel(map, camera, i, j), &jacobian, &g)) {
        continue;
      }
      gtg += g.transpose() * g;
      gtj += g.transpose() * jacobian;
      ++count;
    }
  }
  if (count < 3) return Eigen::MatrixXd();
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(gtg);
  if (!lu.isInvertible()) return Eigen::MatrixXd();
  return lu.solve(gtj);
}

std::vector<AngleBand> SummarizeByAngle(const PixelMap& map,
                                        double band_width_deg,
                                        double max_angle_deg) {
  std::vector<AngleBand> bands;
  if (!(band_width_deg > 0) || !(max_angle_deg > 0)) return bands;
  const int count =
      static_cast<int>(std::ceil(max_angle_deg / band_width_deg - 1e-9));
  for (int b = 0; b < count; ++b) {
    AngleBand band;
    band.lo_deg = b * band_width_deg;
    band.hi_deg = std::min(max_angle_deg, (b + 1) * band_width_deg);
    std::vector<double> values;
    for (size_t k = 0; k < map.values.size(); ++k) {
      const double angle = map.angle_deg[k];
      if (!std::isfinite(map.values[k]) || !std::isfinite(angle)) continue;
      const bool last = b + 1 == count;
      if (angle >= band.lo_deg &&
          (angle < band.hi_deg || (last && angle <= band.hi_deg))) {
        values.push_back(map.values[k]);
      }
    }
    band.count = static_cast<int>(values.size());
    band.median = Quantile(values, 0.5);
    band.p95 = Quantile(values, 0.95);
    band.max =
        values.empty() ? kNaN : *std::max_element(values.begin(), values.end());
    bands.push_back(band);
  }
  return bands;
}

SystematicResiduals ComputeSystematicResiduals(
    const std::vector<CalibrationView>& views, const CalibrationResult& result,
    const EvidenceOptions& options) {
  SystematicResiduals out;
  const Camera& camera = result.camera;
  if (camera.params.size() < 4) return out;
  const Eigen::Vector2d principal(camera.params[2], camera.params[3]);
  struct Sample {
    double angle_deg, distance_m, radial, tangential;
  };
  std::vector<Sample> samples;
  for (size_t v = 0; v < views.size(); ++v) {
    if (v >= result.view_used.size() || !result.view_used[v]) continue;
    if (v >= result.residuals.size() || v >= result.inlier.size() ||
        v >= result.cam_from_board.size()) {
      continue;
    }
    const CalibrationView& view = views[v];
    for (size_t i = 0; i < result.residuals[v].size(); ++i) {
      if (i >= result.inlier[v].size() || !result.inlier[v][i]) continue;
      if (i >= view.board_points.size()) continue;
      const Eigen::Vector3d point =
          result.cam_from_board[v] * view.board_points[i];
      const Eigen::Vector2d offset = view.image_points[i] - principal;
      const double norm = offset.norm();
      if (!(norm > 1e-9) || !point.allFinite()) continue;
      const Eigen::Vector2d radial_dir = offset / norm;
      // Counter-clockwise on the screen (y down): (x, y) -> (y, -x).
      const Eigen::Vector2d tangential_dir(radial_dir.y(), -radial_dir.x());
      const Eigen::Vector2d& r = result.residuals[v][i];
      samples.push_back({FieldAngleDeg(point), point.norm(), r.dot(radial_dir),
                         r.dot(tangential_dir)});
      out.max_angle_deg = std::max(out.max_angle_deg, samples.back().angle_deg);
    }
  }
  if (samples.empty()) return out;
  // By field angle: fixed-width bins up to the widest corner. A last bin
  // narrower than a quarter of the width (a sliver holding the few widest
  // corners, with no usable statistics) joins the one before it.
  int angle_bins = std::max(
      1, static_cast<int>(
             std::ceil(out.max_angle_deg / options.band_width_deg - 1e-9)));
  if (angle_bins > 1 &&
      out.max_angle_deg - (angle_bins - 1) * options.band_width_deg <
          0.25 * options.band_width_deg) {
    --angle_bins;
  }
  for (int b = 0; b < angle_bins; ++b) {
    const bool last = b + 1 == angle_bins;
    const double lo = b * options.band_width_deg;
    const double hi = last ? out.max_angle_deg : lo + options.band_width_deg;
    std::vector<double> radial, tangential;
    for (const Sample& s : samples) {
      if (s.angle_deg >= lo &&
          (s.angle_deg < hi || (last && s.angle_deg <= hi))) {
        radial.push_back(s.radial);
        tangential.push_back(s.tangential);
      }
    }
    out.by_angle.push_back(MakeBin(lo, hi, radial, tangential));
  }
  // By distance: quantile edges, so the bins hold about equal counts.
  std::vector<double> distances;
  for (const Sample& s : samples) distances.push_back(s.distance_m);
  std::sort(distances.begin(), distances.end());
  std::vector<double> edges;
  for (int b = 0; b <= options.distance_bins; ++b) {
    const size_t k = std::min(distances.size() - 1,
                              b * distances.size() / options.distance_bins);
    edges.push_back(b == options.distance_bins ? distances.back()
                                               : distances[k]);
  }
  for (int b = 0; b < options.distance_bins; ++b) {
    if (!(edges[b + 1] > edges[b])) continue;
    std::vector<double> radial, tangential;
    for (const Sample& s : samples) {
      const bool last = b + 1 == options.distance_bins;
      if (s.distance_m >= edges[b] &&
          (s.distance_m < edges[b + 1] ||
           (last && s.distance_m <= edges[b + 1]))) {
        radial.push_back(s.radial);
        tangential.push_back(s.tangential);
      }
    }
    out.by_distance.push_back(
        MakeBin(edges[b], edges[b + 1], radial, tangential));
  }
  return out;
}

ProjectionUncertainty ComputeProjectionUncertainty(
    const CalibrationResult& result, double max_angle_deg,
    const EvidenceOptions& options) {
  ProjectionUncertainty out;
  const Camera& camera = result.camera;
  if (!result.covariance_ok || camera.width <= 0 || camera.height <= 0) {
    return out;
  }
  const int step = GridStep(camera, options);
  out.gauge = RotationGauge(camera, step, max_angle_deg);
  out.rotation_removed = out.gauge.size() > 0;
  out.sigma_px =
      CovarianceTraceMap(camera, result.covariance, step, 0.5,
                         out.rotation_removed ? &out.gauge : nullptr);
  out.bands =
      SummarizeByAngle(out.sigma_px, options.band_width_deg, max_angle_deg);
  auto sigma_at = [&](const Eigen::Vector2d& pixel,
                      const Eigen::MatrixXd* gauge, double* sigma) {
    Eigen::Matrix2d cov;
    if (!ProjectionCovariance(camera, result.covariance, pixel, &cov, gauge)) {
      return false;
    }
    *sigma = std::sqrt(std::max(0.0, 0.5 * cov.trace()));
    return true;
  };
  const Eigen::MatrixXd* gauge = out.rotation_removed ? &out.gauge : nullptr;
  UncertaintyPoint centre;
  centre.label = "centre";
  const Eigen::Vector2d principal(camera.params[2], camera.params[3]);
  centre.in_image = sigma_at(principal, gauge, &centre.sigma_px) &&
                    sigma_at(principal, nullptr, &centre.camera_frame_sigma_px);
  out.points.push_back(centre);
  std::vector<std::pair<std::string, double>> angles;
  for (double angle : options.report_angles_deg) {
    angles.emplace_back(StringPrintf("%.0f deg", angle), angle);
  }
  if (max_angle_deg > 0) {
    angles.emplace_back(StringPrintf("rim (%.1f deg)", max_angle_deg),
                        max_angle_deg);
  }
  for (const auto& [label, angle] : angles) {
    UncertaintyPoint point;
    point.label = label;
    point.angle_deg = angle;
    for (int a = 0; a < options.report_azimuths; ++a) {
      const double phi = 2 * M_PI * a / options.report_azimuths;
      const Eigen::Vector3d ray(std::sin(angle * kDegree) * std::cos(phi),
                                std::sin(angle * kDegree) * std::sin(phi),
                                std::cos(angle * kDegree));
      Eigen::Vector2d pixel;
      if (!ProjectDirection(camera, ray, &pixel) || pixel.x() < 0 ||
          pixel.y() < 0 || pixel.x() > camera.width - 1 ||
          pixel.y() > camera.height - 1) {
        continue;
      }
      double sigma, fixed_frame;
      if (!sigma_at(pixel, gauge, &sigma) ||
          !sigma_at(pixel, nullptr, &fixed_frame)) {
        continue;
      }
      point.sigma_px = point.in_image ? std::max(point.sigma_px, sigma) : sigma;
      point.camera_frame_sigma_px =
          point.in_image ? std::max(point.camera_frame_sigma_px, fixed_frame)
                         : fixed_frame;
      point.in_image = true;
    }
    out.points.push_back(point);
  }
  out.ok = true;
  return out;
}

namespace {

// The Mahalanobis distance of the difference of two calibrations' free
// intrinsics under the sum of their covariances, and the number of free
// intrinsics (0 and 0 when the sum is singular).
void IntrinsicsChiSquare(const CalibrationResult& a, const CalibrationResult& b,
                         double* chi2, int* dof) {
  *chi2 = 0;
  *dof = 0;
  std::vector<int> free;
  for (size_t k = 0; k < a.camera.params.size(); ++k) {
    const bool fixed_a = k < a.param_fixed.size() && a.param_fixed[k];
    const bool fixed_b = k < b.param_fixed.size() && b.param_fixed[k];
    if (!fixed_a && !fixed_b) free.push_back(static_cast<int>(k));
  }
  const int n = static_cast<int>(free.size());
  const Eigen::Index num_params =
      static_cast<Eigen::Index>(a.camera.params.size());
  if (n == 0 || a.covariance.rows() < num_params ||
      b.covariance.rows() < num_params) {
    return;
  }
  Eigen::VectorXd d(n);
  Eigen::MatrixXd sum(n, n);
  for (int i = 0; i < n; ++i) {
    d(i) = a.camera.params[free[i]] - b.camera.params[free[i]];
    for (int j = 0; j < n; ++j) {
      sum(i, j) =
          a.covariance(free[i], free[j]) + b.covariance(free[i], free[j]);
    }
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(sum);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return;
  const double value = d.dot(ldlt.solve(d));
  if (!std::isfinite(value)) return;
  *chi2 = value;
  *dof = n;
}

}  // namespace

double ChiSquareZ(double chi2, int dof) {
  if (dof < 1 || !(chi2 >= 0)) return 0;
  const double v = 2.0 / (9.0 * dof);
  return (std::cbrt(chi2 / dof) - (1.0 - v)) / std::sqrt(v);
}

namespace {

// The two calibrations of split `split`'s halves, started from the full
// solution, each with its covariance, and the halves' view counts. False
// (with *error) when a half cannot be calibrated or does not determine the
// model.
bool CalibrateHalves(const std::vector<CalibrationView>& views,
                     const CalibrationResult& result,
                     const CalibrationOptions& calibration, int split,
                     int num_splits, int view_counts[2],
                     CalibrationResult halves[2], std::string* error_out) {
  const Camera& camera = result.camera;
  CalibrationOptions half_options = calibration;
  half_options.initial_params = camera.params;
  half_options.compute_covariance = true;
  if (result.trust_region_radius > 0) {
    half_options.initial_trust_region_radius = result.trust_region_radius;
  }
  // The two halves side by side, each on its share of the threads (a
  // calibration's result does not depend on its thread count).
  const int workers = std::min(2, std::max(1, calibration.num_threads));
  half_options.num_threads = std::max(1, calibration.num_threads / workers);
  // Each half starts from the full solution's intrinsics and its views'
  // poses: a few iterations from its own minimum.
  CalibrationOptions options_of[2] = {half_options, half_options};
  const std::vector<int> half_of =
      SplitHalves(views, result, split, num_splits);
  std::vector<CalibrationView> half[2] = {
      Half(views, result, half_of, 0, &options_of[0].initial_cam_from_board),
      Half(views, result, half_of, 1, &options_of[1].initial_cam_from_board)};
  view_counts[0] = static_cast<int>(half[0].size());
  view_counts[1] = static_cast<int>(half[1].size());
  std::string error[2];
  char ok[2] = {0, 0};
  ParallelFor(2, workers, [&](int h) {
    ok[h] = Calibrate(half[h], camera.model, camera.width, camera.height,
                      options_of[h], &halves[h], &error[h]);
  });
  for (int h = 0; h < 2; ++h) {
    const std::string name = h == 0 ? "A" : "B";
    if (!ok[h]) {
      *error_out = "half " + name + " (" + std::to_string(half[h].size()) +
                   " views): " + error[h];
      return false;
    }
    if (!halves[h].covariance_ok) {
      *error_out = "half " + name +
                   ": no covariance (the half does not determine the model)";
      return false;
    }
  }
  return true;
}

// The rays of two cameras at the grid pixels of `map` (camera A's grid)
// within the field limit (0: none): unprojected[k] where both cameras
// unproject the pixel; valid[k] where, besides, A projects its ray back
// (`reference`, the pixel the difference is measured from) and B's pixel
// Jacobian exists (g[k]: the derivative of B's projection with respect to
// a small rotation of the ray).
struct PairRays {
  std::vector<Eigen::Vector3d> a, b;
  std::vector<Eigen::Vector2d> reference;
  std::vector<Eigen::Matrix<double, 2, 3>> g;
  std::vector<bool> unprojected;
  std::vector<bool> valid;
};

PairRays RaysOfPair(const Camera& a, const Camera& b, const PixelMap& map,
                    double max_angle_deg) {
  PairRays rays;
  const size_t n = map.values.size();
  rays.a.resize(n);
  rays.b.resize(n);
  rays.reference.resize(n);
  rays.g.resize(n);
  rays.unprojected.assign(n, false);
  rays.valid.assign(n, false);
  for (int j = 0; j < map.rows; ++j) {
    for (int i = 0; i < map.cols; ++i) {
      const int k = j * map.cols + i;
      const double angle = map.angle_deg[k];
      if (!std::isfinite(angle) ||
          (max_angle_deg > 0 && angle > max_angle_deg)) {
        continue;
      }
      const Eigen::Vector2d pixel = MapPixel(map, a, i, j);
      if (!a.Unproject(pixel, &rays.a[k]).converged ||
          !b.Unproject(pixel, &rays.b[k]).converged) {
        continue;
      }
      rays.unprojected[k] = true;
      Eigen::MatrixXd unused;
      rays.valid[k] = ProjectDirection(a, rays.a[k], &rays.reference[k]) &&
                      PixelJacobians(b, pixel, &unused, &rays.g[k]);
    }
  }
  return rays;
}

// How well `b_from_a` aligns the cameras: the pixels where B does not
// project the turned ray, then the sum of squared differences where it does.
struct RotationCost {
  int unprojected = 0;
  double sum2 = 0;
  bool NoWorseThan(const RotationCost& other) const {
    return unprojected < other.unprojected ||
           (unprojected == other.unprojected && sum2 <= other.sum2);
  }
};

RotationCost CostOfRotation(const Camera& b, const PairRays& rays,
                            const Eigen::Matrix3d& b_from_a) {
  RotationCost cost;
  for (size_t k = 0; k < rays.valid.size(); ++k) {
    if (!rays.valid[k]) continue;
    Eigen::Vector2d projected;
    if (ProjectDirection(b, b_from_a * rays.a[k], &projected)) {
      cost.sum2 += (projected - rays.reference[k]).squaredNorm();
    } else {
      ++cost.unprojected;
    }
  }
  return cost;
}

// The rotation taking A's camera frame to B's that best aligns their rays.
// As mrcal does (projection_diff), the least-squares alignment of the unit
// rays of the two cameras at the same pixels (Kabsch) is a start, unless
// the identity aligns them no worse (a camera against itself); a few
// Gauss-Newton steps on the pixel differences themselves, the measure the
// expected figures use (RotationGauge), refine it.
Eigen::Matrix3d FitRotation(const Camera& b, const PairRays& rays) {
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < rays.valid.size(); ++k) {
    if (rays.unprojected[k]) cross += rays.b[k] * rays.a[k].transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) =
      (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d kabsch = svd.matrixU() * d * svd.matrixV().transpose();
  Eigen::Matrix3d b_from_a = Eigen::Matrix3d::Identity();
  if (!CostOfRotation(b, rays, b_from_a)
           .NoWorseThan(CostOfRotation(b, rays, kabsch))) {
    b_from_a = kabsch;
  }
  for (int iteration = 0; iteration < 3; ++iteration) {
    Eigen::Matrix3d gtg = Eigen::Matrix3d::Zero();
    Eigen::Vector3d gtr = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < rays.valid.size(); ++k) {
      Eigen::Vector2d projected;
      if (!rays.valid[k] ||
          !ProjectDirection(b, b_from_a * rays.a[k], &projected)) {
        continue;
      }
      gtg += rays.g[k].transpose() * rays.g[k];
      gtr += rays.g[k].transpose() * (projected - rays.reference[k]);
    }
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(gtg);
    if (!lu.isInvertible()) break;
    const Eigen::Vector3d omega = -lu.solve(gtr);
    if (!omega.allFinite() || omega.norm() == 0) break;
    b_from_a =
        Eigen::AngleAxisd(omega.norm(), omega.normalized()).toRotationMatrix() *
        b_from_a;
  }
  return b_from_a;
}

// What noise alone would give at each pixel of `difference`: the two
// cameras' projection covariances add (a camera without one adds nothing),
// each with its own rotation gauge removed over the same field, as the
// comparison removes the rotation between them.
PixelMap ExpectedDifference(const Camera& a,
                            const Eigen::MatrixXd* covariance_a,
                            const Camera& b,
                            const Eigen::MatrixXd* covariance_b,
                            const PixelMap& difference, double max_angle_deg) {
  const int step = difference.step_px;
  std::vector<double> variance(difference.values.size(), 0.0);
  for (const auto& [camera, covariance] :
       {std::pair(&a, covariance_a), std::pair(&b, covariance_b)}) {
    if (covariance == nullptr) continue;
    const Eigen::MatrixXd gauge = RotationGauge(*camera, step, max_angle_deg);
    const PixelMap sigma = CovarianceTraceMap(
        *camera, *covariance, step, 1.0, gauge.size() > 0 ? &gauge : nullptr);
    for (size_t k = 0; k < variance.size(); ++k) {
      variance[k] += sigma.values[k] * sigma.values[k];
    }
  }
  PixelMap expected = difference;
  for (size_t k = 0; k < difference.values.size(); ++k) {
    expected.values[k] =
        std::isfinite(difference.values[k]) ? std::sqrt(variance[k]) : kNaN;
  }
  return expected;
}

// Why a covariance cannot serve `camera` ("" when it can).
std::string CovarianceProblem(const Camera& camera,
                              const Eigen::MatrixXd* covariance,
                              const char* name) {
  const Eigen::Index n = CameraModelNumParams(camera.model);
  if (covariance == nullptr ||
      (covariance->rows() == n && covariance->cols() == n &&
       covariance->allFinite())) {
    return "";
  }
  return StringPrintf("the covariance of camera %s is not %d x %d and finite",
                      name, static_cast<int>(n), static_cast<int>(n));
}

}  // namespace

ProjectionDiff ProjectionDifference(const Camera& a, const Camera& b,
                                    double max_angle_deg,
                                    const EvidenceOptions& options,
                                    const Eigen::MatrixXd* covariance_a,
                                    const Eigen::MatrixXd* covariance_b) {
  ProjectionDiff out;
  std::string why;
  if (!options.Check(&why)) {
    out.error = "evidence options: " + why;
    return out;
  }
  if (a.width <= 0 || a.height <= 0 ||
      static_cast<int>(a.params.size()) != CameraModelNumParams(a.model) ||
      static_cast<int>(b.params.size()) != CameraModelNumParams(b.model)) {
    out.error =
        "a camera without an image size or with the wrong number of "
        "parameters";
    return out;
  }
  if (a.width != b.width || a.height != b.height) {
    out.error = StringPrintf(
        "the cameras image different sizes (%d x %d and %d x %d pixels)",
        a.width, a.height, b.width, b.height);
    return out;
  }
  for (const std::string& problem : {CovarianceProblem(a, covariance_a, "A"),
                                     CovarianceProblem(b, covariance_b, "B")}) {
    if (!problem.empty()) {
      out.error = problem;
      return out;
    }
  }
  PixelMap map = EmptyMap(a, GridStep(a, options));
  const PairRays rays = RaysOfPair(a, b, map, max_angle_deg);
  if (std::count(rays.valid.begin(), rays.valid.end(), true) < 3) {
    out.error = "fewer than 3 pixels of the grid have a ray in both cameras";
    return out;
  }
  out.b_from_a = FitRotation(b, rays);
  out.rotation_deg = Eigen::AngleAxisd(out.b_from_a).angle() / kDegree;
  for (size_t k = 0; k < map.values.size(); ++k) {
    Eigen::Vector2d projected;
    if (rays.valid[k] &&
        ProjectDirection(b, out.b_from_a * rays.a[k], &projected)) {
      map.values[k] = (projected - rays.reference[k]).norm();
      out.max_angle_deg = std::max(out.max_angle_deg, map.angle_deg[k]);
    }
  }
  // The bands and gauges reach the limit asked for, else the widest pixel
  // compared.
  const double field_deg =
      max_angle_deg > 0 ? max_angle_deg : out.max_angle_deg;
  out.difference_px = map;
  out.difference_bands =
      SummarizeByAngle(out.difference_px, options.band_width_deg, field_deg);
  if (covariance_a != nullptr || covariance_b != nullptr) {
    out.expected_ok = true;
    out.expected_px =
        ExpectedDifference(a, covariance_a, b, covariance_b, map, field_deg);
    out.expected_bands =
        SummarizeByAngle(out.expected_px, options.band_width_deg, field_deg);
  }
  out.ok = true;
  return out;
}

namespace {

// One split's comparison of its halves.
struct SplitComparison {
  bool ok = false;
  std::string error;
  int view_counts[2] = {0, 0};
  CalibrationResult halves[2];
  ProjectionDiff diff;
  double intrinsics_chi2 = 0;
  int intrinsics_dof = 0;
};

SplitComparison CompareSplit(const std::vector<CalibrationView>& views,
                             const CalibrationResult& result,
                             const CalibrationOptions& calibration, int split,
                             double max_angle_deg,
                             const EvidenceOptions& options) {
  SplitComparison out;
  if (!CalibrateHalves(views, result, calibration, split,
                       std::max(1, options.cross_validation_splits),
                       out.view_counts, out.halves, &out.error)) {
    return out;
  }
  IntrinsicsChiSquare(out.halves[0], out.halves[1], &out.intrinsics_chi2,
                      &out.intrinsics_dof);
  // |project_B(R * unproject_A(pixel)) - pixel| after the rotation between
  // the halves is taken out, against what their covariances predict.
  out.diff = ProjectionDifference(
      out.halves[0].camera, out.halves[1].camera, max_angle_deg, options,
      &out.halves[0].covariance, &out.halves[1].covariance);
  if (!out.diff.ok) {
    out.error = "comparing the halves: " + out.diff.error;
    return out;
  }
  out.ok = true;
  return out;
}

double MedianOfSplits(std::vector<double> values) {
  return values.empty() ? 0.0 : Quantile(std::move(values), 0.5);
}

// Per band, the difference and expected figures of the split whose ratio
// of the two medians is the median over the splits (the lower middle one
// for an even count): a band's figures stay one split's, so its ratio is
// theirs. The count is the smallest over the splits (the bands share their
// edges: one field limit, one width).
void MedianBands(const std::vector<const ProjectionDiff*>& splits,
                 std::vector<AngleBand>* difference,
                 std::vector<AngleBand>* expected) {
  *difference = splits.front()->difference_bands;
  *expected = splits.front()->expected_bands;
  for (size_t b = 0; b < difference->size() && b < expected->size(); ++b) {
    std::vector<std::pair<double, const ProjectionDiff*>> ratios;
    int count = (*difference)[b].count;
    for (const ProjectionDiff* split : splits) {
      if (b >= split->difference_bands.size() ||
          b >= split->expected_bands.size()) {
        continue;
      }
      const double e = split->expected_bands[b].median;
      const double d = split->difference_bands[b].median;
      count = std::min(count, split->difference_bands[b].count);
      ratios.push_back({e > 0 ? d / e : kNaN, split});
    }
    // NaN ratios (no prediction) last.
    std::sort(ratios.begin(), ratios.end(), [](const auto& x, const auto& y) {
      if (std::isnan(x.first) != std::isnan(y.first))
        return !std::isnan(x.first);
      return x.first < y.first;
    });
    const ProjectionDiff* middle = ratios[(ratios.size() - 1) / 2].second;
    (*difference)[b] = middle->difference_bands[b];
    (*expected)[b] = middle->expected_bands[b];
    (*difference)[b].count = count;
    (*expected)[b].count = std::min(count, (*expected)[b].count);
  }
}

}  // namespace

CrossValidation CrossValidate(const std::vector<CalibrationView>& views,
                              const CalibrationResult& result,
                              const CalibrationOptions& calibration,
                              double max_angle_deg,
                              const EvidenceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CrossValidation out;
  const int num_splits = std::max(1, options.cross_validation_splits);
  std::vector<SplitComparison> splits;
  for (int split = 0; split < num_splits; ++split) {
    splits.push_back(CompareSplit(views, result, calibration, split,
                                  max_angle_deg, options));
  }
  out.splits_tried = num_splits;
  const SplitComparison* first = nullptr;
  std::vector<const ProjectionDiff*> compared;
  std::vector<double> chi2;
  for (const SplitComparison& split : splits) {
    if (!split.ok) continue;
    if (first == nullptr) first = &split;
    compared.push_back(&split.diff);
    chi2.push_back(split.intrinsics_chi2);
  }
  if (first == nullptr) {
    out.error = splits.front().error;
    out.views_a = splits.front().view_counts[0];
    out.views_b = splits.front().view_counts[1];
    out.seconds = SecondsSince(start);
    return out;
  }
  out.splits = static_cast<int>(compared.size());
  out.views_a = first->view_counts[0];
  out.views_b = first->view_counts[1];
  out.camera_a = first->halves[0].camera;
  out.camera_b = first->halves[1].camera;
  out.rms_a_px = first->halves[0].rms_px;
  out.rms_b_px = first->halves[1].rms_px;
  out.b_from_a = first->diff.b_from_a;
  out.rotation_deg = first->diff.rotation_deg;
  out.difference_px = first->diff.difference_px;
  out.expected_px = first->diff.expected_px;
  MedianBands(compared, &out.difference_bands, &out.expected_bands);
  out.intrinsics_chi2 = MedianOfSplits(chi2);
  out.intrinsics_dof = first->intrinsics_dof;
  out.ok = true;
  out.seconds = SecondsSince(start);
  return out;
}

Evidence ComputeEvidence(const std::vector<CalibrationView>& views,
                         const CalibrationResult& result,
                         const CalibrationOptions& calibration,
                         const EvidenceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Evidence evidence;
  std::string why;
  if (!options.Check(&why)) {
    evidence.cross_validation.error = "evidence options: " + why;
    return evidence;
  }
  evidence.residuals = ComputeSystematicResiduals(views, result, options);
  evidence.view_consistency =
      ComputeViewConsistency(views, result, options.view_consistency);
  const double max_angle = evidence.residuals.max_angle_deg;
  evidence.uncertainty =
      ComputeProjectionUncertainty(result, max_angle, options);
  if (options.cross_validation) {
    evidence.cross_validation =
        CrossValidate(views, result, calibration, max_angle, options);
  } else {
    evidence.cross_validation.error = "not run";
  }
  evidence.seconds = SecondsSince(start);
  return evidence;
}

std::string ProjectionDifferenceText(const ProjectionDiff& diff,
                                     const std::string& indent) {
  if (!diff.ok) return indent + "projection difference: " + diff.error + "\n";
  std::ostringstream text;
  text << indent
       << StringPrintf(
              "rotation between the camera frames %.4f deg; compared up to "
              "%.1f deg off the axis\n",
              diff.rotation_deg, diff.max_angle_deg);
  text << indent << "field angle      median      p95      max"
       << (diff.expected_ok ? "   expected median      p95" : "") << "  (px)\n";
  for (size_t b = 0; b < diff.difference_bands.size(); ++b) {
    const AngleBand& d = diff.difference_bands[b];
    if (d.count == 0) continue;
    text << indent
         << StringPrintf("%11s %9.3f %8.3f %8.3f", BandLabel(d).c_str(),
                         d.median, d.p95, d.max);
    if (diff.expected_ok && b < diff.expected_bands.size()) {
      const AngleBand& e = diff.expected_bands[b];
      text << StringPrintf(" %17.3f %8.3f", e.median, e.p95);
    }
    text << "  n=" << d.count << "\n";
  }
  return text.str();
}

std::string AngleRangeLabel(double lo_deg, double hi_deg) {
  if (std::lround(lo_deg) == std::lround(hi_deg)) {
    return StringPrintf("%.0f-%.1f deg", lo_deg, hi_deg);
  }
  return StringPrintf("%.0f-%.0f deg", lo_deg, hi_deg);
}

std::string BandLabel(const AngleBand& band) {
  return AngleRangeLabel(band.lo_deg, band.hi_deg);
}

std::string EvidenceText(const Evidence& evidence) {
  std::ostringstream text;
  const CrossValidation& cv = evidence.cross_validation;
  if (cv.ok) {
    text << "cross-validation ("
         << (cv.splits > 1 ? "the median split's bands of " +
                                 std::to_string(cv.splits) + "; first split "
                           : std::string())
         << cv.views_a << " + " << cv.views_b << " views, RMS "
         << StringPrintf("%.3f / %.3f px", cv.rms_a_px, cv.rms_b_px)
         << ", rotation between the halves "
         << StringPrintf("%.3f deg", cv.rotation_deg) << "):\n";
    text << "  field angle   |A-B| median   p95   expected median   p95\n";
    for (size_t b = 0; b < cv.difference_bands.size(); ++b) {
      const AngleBand& d = cv.difference_bands[b];
      const AngleBand& e = cv.expected_bands[b];
      if (d.count == 0) continue;
      text << StringPrintf("  %11s   %8.3f   %8.3f", BandLabel(d).c_str(),
                           d.median, d.p95)
           << StringPrintf("   %8.3f   %8.3f px", e.median, e.p95)
           << "  n=" << d.count << "\n";
    }
    if (cv.intrinsics_dof > 0) {
      text << StringPrintf(
          "  intrinsics as a whole: chi-square %.1f for %d free "
          "parameters (z = %.1f)\n",
          cv.intrinsics_chi2, cv.intrinsics_dof,
          ChiSquareZ(cv.intrinsics_chi2, cv.intrinsics_dof));
    }
  } else {
    text << "cross-validation: " << cv.error << "\n";
  }
  const ProjectionUncertainty& u = evidence.uncertainty;
  if (u.ok) {
    text << "projection uncertainty (1-sigma, px per axis; rotation gauge "
            "removed / in the camera frame):";
    for (const UncertaintyPoint& p : u.points) {
      text << " " << p.label << " "
           << (p.in_image ? StringPrintf("%.3f / %.3f", p.sigma_px,
                                         p.camera_frame_sigma_px)
                          : "not in image")
           << ";";
    }
    text << "\n";
  } else {
    text << "projection uncertainty: no covariance\n";
  }
  auto bins = [&](const char* title, const std::vector<ResidualBin>& list,
                  const char* unit, int decimals) {
    text << title << "\n";
    for (const ResidualBin& b : list) {
      text << (decimals == 0 ? StringPrintf("  %5.0f-%5.0f ", b.lo, b.hi)
                             : StringPrintf("  %5.2f-%5.2f ", b.lo, b.hi))
           << unit
           << StringPrintf(
                  "  radial %+.3f +- %.3f  tangential %+.3f +- %.3f  RMS "
                  "%.3f px",
                  b.mean_radial_px, b.se_radial_px, b.mean_tangential_px,
                  b.se_tangential_px, b.rms_px)
           << "  n=" << b.count << "\n";
    }
  };
  const ViewConsistency& vc = evidence.view_consistency;
  if (vc.ok) {
    text << StringPrintf(
        "focal length per view (the rest held): %zu views, spread %.2f "
        "times their sigma (chi-square %.1f for %d), moving the corners "
        "by %.3f px RMS\n",
        vc.views.size(), vc.spread_ratio, vc.chi2, vc.dof, vc.effect_px);
    for (const ViewFocal& f : MostInconsistentViews(vc, 5)) {
      text << "  " << f.name
           << StringPrintf(": f = %.1f +- %.1f px (z = %+.1f)",
                           vc.focal_px * f.scale, vc.focal_px * f.scale_sigma,
                           f.z)
           << "\n";
    }
  } else {
    text << "focal length per view: " << vc.error << "\n";
  }
  if (!vc.fields.empty()) {
    std::vector<ViewField> fields = vc.fields;
    std::stable_sort(fields.begin(), fields.end(),
                     [](const ViewField& a, const ViewField& b) {
                       return a.smooth_rms_px / a.expected_smooth_px >
                              b.smooth_rms_px / b.expected_smooth_px;
                     });
    text << "residual fields across the board (smooth part / noise gives / "
            "rest, px), the strongest:\n";
    for (size_t k = 0; k < fields.size() && k < 5; ++k) {
      const ViewField& f = fields[k];
      text << "  " << f.name
           << StringPrintf(": %.3f / %.3f / %.3f, %d of %d corners rejected\n",
                           f.smooth_rms_px, f.expected_smooth_px, f.rest_rms_px,
                           f.outliers, f.corners);
    }
  }
  bins("residual means by field angle:", evidence.residuals.by_angle, "deg", 0);
  bins("residual means by distance:", evidence.residuals.by_distance, "m", 2);
  return text.str();
}

}  // namespace puzzlecal
