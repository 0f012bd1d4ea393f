#include "advice/advice.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "advice/view_information.h"
#include "evidence/evidence.h"
#include "util/angles.h"
#include "util/failure.h"
#include "util/parallel_for.h"
#include "util/statistics.h"
#include "util/string_format.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

constexpr double kBandWidthDeg = 10.0;
constexpr int kMinBandSamples = 5;

double FieldAngleDeg(const Eigen::Vector3d& ray) {
  return std::atan2(ray.head<2>().norm(), ray.z()) / kDegree;
}

std::vector<int> FreeIndices(const std::vector<bool>& free) {
  std::vector<int> out;
  for (size_t k = 0; k < free.size(); ++k) {
    if (free[k]) out.push_back(static_cast<int>(k));
  }
  return out;
}

Eigen::MatrixXd FreeBlock(const Eigen::MatrixXd& full,
                          const std::vector<int>& free) {
  const int n = static_cast<int>(free.size());
  Eigen::MatrixXd out(n, n);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) out(r, c) = full(free[r], free[c]);
  }
  return out;
}

// The samples of the judged field: each pixel's gauged projection Jacobian
// over the free parameters (evidence/evidence.h), and its field angle.
struct FieldSamples {
  // Each sample's d pixel / d (free parameters) is jacobian - rotation *
  // gauge (evidence's ProjectionJacobian): `jacobian` kept as its non-zero
  // columns only (2 x columns[s].size()), since a splined model's pixel
  // depends on the 16 knots around it, a fifth of its parameters, and the
  // uncertainty at every sample for every candidate is most of the
  // advice's work; `gauge` (3 x free, or empty) is shared by the samples.
  std::vector<Eigen::MatrixXd> jacobian;
  std::vector<std::vector<int>> columns;  // free-parameter indices
  std::vector<Eigen::Matrix<double, 2, 3>> rotation;
  Eigen::MatrixXd gauge;
  std::vector<double> angle_deg;
  double field_deg = 0;
};

// The widest field angle on the circle about the principal point that the
// image holds entirely.
double InscribedFieldDeg(const Camera& camera) {
  const double cx = camera.params[2];
  const double cy = camera.params[3];
  const double radius = std::min(std::min(cx, camera.width - 1 - cx),
                                 std::min(cy, camera.height - 1 - cy));
  double widest = 0;
  for (int k = 0; k < 16; ++k) {
    const double phi = 2 * M_PI * k / 16;
    // Beyond the radius where the distortion folds over no pixel has a
    // ray: the circle then ends there.
    for (double r = radius; r > 0.05 * radius; r *= 0.97) {
      Eigen::Vector3d ray;
      const Eigen::Vector2d pixel(cx + r * std::cos(phi),
                                  cy + r * std::sin(phi));
      if (camera.Unproject(pixel, &ray).converged) {
        widest = std::max(widest, FieldAngleDeg(ray));
        break;
      }
    }
  }
  return widest;
}

// The field a board's corners can be seen in: every ray in front of a
// pinhole camera; for a fisheye, whose image circle may end anywhere, the
// wider of `observed_deg` (corners seen) and the circle about the principal
// point that the image holds entirely.
double LensFieldDeg(const Camera& camera, double observed_deg) {
  if (CameraModelIsPinhole(camera.model)) return 89.0;
  return std::max(observed_deg, InscribedFieldDeg(camera));
}

// The radius in pixels about the principal point of the judged field:
// options.field_radius_px when given; otherwise the circle that reaches the
// nearer of the image's left and right edges for a pinhole camera (the
// image corners beyond it are left out), and for a fisheye the wider of
// the circle the image holds entirely and `observed_px` (the farthest
// corner seen). In pixels, not in field angles: a start whose distortion
// is poorly known puts the image's edge at a wrong field angle, and a
// field of angles would then judge rays the lens does not show.
double JudgedRadiusPx(const Camera& camera, double observed_px,
                      const AdviceOptions& options) {
  if (options.field_radius_px > 0) return options.field_radius_px;
  const double cx = camera.params[2];
  const double cy = camera.params[3];
  const double width_radius = std::min(cx, camera.width - 1 - cx);
  if (CameraModelIsPinhole(camera.model)) return width_radius;
  const double inscribed =
      std::min(width_radius, std::min(cy, camera.height - 1 - cy));
  return std::max(inscribed, observed_px);
}

FieldSamples MakeFieldSamples(const Camera& camera,
                              const std::vector<int>& free, double radius_px,
                              const AdviceOptions& options) {
  FieldSamples out;
  const double max_deg = options.field_deg > 0 ? options.field_deg : 180.0;
  const double fold_radius =
      options.max_fold_fraction * MaxMonotonicRadius(camera);
  const Eigen::Vector2d centre(camera.params[2], camera.params[3]);
  const double area = static_cast<double>(camera.width) * camera.height;
  const int step = std::max(
      1, static_cast<int>(std::floor(std::sqrt(area / options.field_samples))));
  std::vector<Eigen::Vector2d> pixels;
  for (int y = step / 2; y < camera.height; y += step) {
    for (int x = step / 2; x < camera.width; x += step) {
      const Eigen::Vector2d pixel(x, y);
      if ((pixel - centre).norm() > radius_px) continue;
      Eigen::Vector3d ray;
      if (!camera.Unproject(pixel, &ray).converged) continue;
      const double angle = FieldAngleDeg(ray);
      if (angle > max_deg || FieldRadius(camera, ray) > fold_radius) continue;
      pixels.push_back(pixel);
      out.angle_deg.push_back(angle);
      out.field_deg = std::max(out.field_deg, angle);
    }
  }
  const Eigen::MatrixXd gauge = RotationGauge(camera, step, out.field_deg);
  std::vector<double> angles;
  if (gauge.size() > 0) {
    out.gauge.resize(3, free.size());
    for (size_t k = 0; k < free.size(); ++k) {
      out.gauge.col(k) = gauge.col(free[k]);
    }
  }
  for (size_t s = 0; s < pixels.size(); ++s) {
    Eigen::MatrixXd full;
    Eigen::Matrix<double, 2, 3> rotation;
    if (!ProjectionJacobianParts(camera, pixels[s], &full, &rotation)) {
      continue;
    }
    std::vector<int> columns;
    for (size_t k = 0; k < free.size(); ++k) {
      if (full.col(free[k]).cwiseAbs().maxCoeff() > 0) {
        columns.push_back(static_cast<int>(k));
      }
    }
    Eigen::MatrixXd jacobian(2, columns.size());
    for (size_t k = 0; k < columns.size(); ++k) {
      jacobian.col(k) = full.col(free[columns[k]]);
    }
    out.jacobian.push_back(jacobian);
    out.columns.push_back(std::move(columns));
    out.rotation.push_back(rotation);
    angles.push_back(out.angle_deg[s]);
  }
  out.angle_deg = angles;
  return out;
}

FieldUncertainty Evaluate(const FieldSamples& samples,
                          const Eigen::MatrixXd& covariance) {
  FieldUncertainty out;
  const size_t count = samples.jacobian.size();
  if (count == 0) return out;
  std::vector<double> sigma(count);
  // With the gauge, the sample's covariance J C J' for J = j - r G is
  // j C j' - j (C G') r' - r (G C) j' + r (G C G') r', j sparse.
  const Eigen::MatrixXd covariance_gauge =
      samples.gauge.size() > 0
          ? Eigen::MatrixXd(covariance.selfadjointView<Eigen::Lower>() *
                            samples.gauge.transpose())
          : Eigen::MatrixXd();
  const Eigen::Matrix3d gauge_covariance_gauge =
      samples.gauge.size() > 0
          ? Eigen::Matrix3d(samples.gauge * covariance_gauge)
          : Eigen::Matrix3d::Zero();
  Eigen::MatrixXd block, block_gauge;
  for (size_t s = 0; s < count; ++s) {
    const Eigen::MatrixXd& j = samples.jacobian[s];
    const std::vector<int>& columns = samples.columns[s];
    const int m = static_cast<int>(columns.size());
    // The covariance's block over the sample's columns (from its lower
    // triangle), and those rows of C G'.
    block.resize(m, m);
    for (int a = 0; a < m; ++a) {
      for (int b = 0; b <= a; ++b) {
        block(a, b) = block(b, a) = covariance(
            std::max(columns[a], columns[b]), std::min(columns[a], columns[b]));
      }
    }
    Eigen::Matrix2d pixel_covariance = j * block * j.transpose();
    if (samples.gauge.size() > 0) {
      block_gauge.resize(m, 3);
      for (int a = 0; a < m; ++a) {
        block_gauge.row(a) = covariance_gauge.row(columns[a]);
      }
      const Eigen::Matrix<double, 2, 3>& r = samples.rotation[s];
      const Eigen::Matrix2d cross = j * block_gauge * r.transpose();
      pixel_covariance += -cross - cross.transpose() +
                          r * gauge_covariance_gauge * r.transpose();
    }
    sigma[s] = std::sqrt(std::max(0.0, 0.5 * pixel_covariance.trace()));
  }
  out.worst_px = *std::max_element(sigma.begin(), sigma.end());
  out.median_px = Median(sigma);
  const int bands =
      static_cast<int>(std::ceil(samples.field_deg / kBandWidthDeg));
  for (int b = 0; b < bands; ++b) {
    std::vector<double> band;
    for (size_t s = 0; s < count; ++s) {
      if (samples.angle_deg[s] >= b * kBandWidthDeg &&
          samples.angle_deg[s] < (b + 1) * kBandWidthDeg) {
        band.push_back(sigma[s]);
      }
    }
    if (static_cast<int>(band.size()) >= kMinBandSamples) {
      out.worst_band_median_px =
          std::max(out.worst_band_median_px, Median(band));
    }
  }
  return out;
}

// The covariance for information `information` (free parameters);
// false when it is singular.
bool CovarianceOf(const Eigen::MatrixXd& information,
                  Eigen::MatrixXd* covariance) {
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(information);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) {
    return false;
  }
  *covariance = ldlt.solve(
      Eigen::MatrixXd::Identity(information.rows(), information.cols()));
  return covariance->allFinite();
}

// A pose a person could hold, with what it tells.
struct Candidate {
  Eigen::Isometry3d cam_from_board;
  Eigen::Vector2d centre_px;
  Eigen::Vector3d normal;  // the board's normal in the camera frame
  double distance_m = 0;
  double tilt_deg = 0;
  double tilt_direction_deg = 0;
  int visible = 0;
  Eigen::MatrixXd information;  // free parameters, unit noise
};

// The board's corners evenly subsampled to at most `max_count`.
std::vector<Eigen::Vector3d> SubsampledCorners(const Board& board,
                                               int max_count) {
  const double ratio =
      std::sqrt(static_cast<double>(board.NumCorners()) / max_count);
  const int stride = std::max(1, static_cast<int>(std::ceil(ratio)));
  std::vector<Eigen::Vector3d> out;
  for (int r = 0; r < board.rows; r += stride) {
    for (int c = 0; c < board.cols; c += stride) {
      out.push_back(board.Point(board.origin + Eigen::Vector2i(c, r)));
    }
  }
  return out;
}

Eigen::Vector3d BoardCentre(const Board& board) {
  return 0.5 * (board.Point(board.origin) +
                board.Point(board.origin +
                            Eigen::Vector2i(board.cols - 1, board.rows - 1)));
}

// The board's rotation for a tilt: squarely facing the camera along the
// line of sight `ray` to its centre (its normal along the ray, its x axis
// as near image x as the ray allows), turned by tilt_deg about the
// in-plane axis that brings its side in image direction tilt_direction_deg
// nearer the camera.
Eigen::Matrix3d TiltedRotation(const Eigen::Vector3d& ray, double tilt_deg,
                               double tilt_direction_deg) {
  const Eigen::Matrix3d face =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), ray)
          .toRotationMatrix();
  const Eigen::Vector3d toward =
      face * Eigen::Vector3d(std::cos(tilt_direction_deg * kDegree),
                             std::sin(tilt_direction_deg * kDegree), 0.0);
  // The normal leans towards `toward`: the board's points on that side come
  // nearer (see DescribePose).
  const Eigen::Vector3d axis = ray.cross(toward).normalized();
  return Eigen::AngleAxisd(tilt_deg * kDegree, axis).toRotationMatrix() * face;
}

// Where a corner can be seen: within the lens's field and, for lenses
// whose distortion folds over, inside the fold (beyond it the lens shows
// nothing the model could place).
struct LensLimits {
  double field_deg = 0;
  double max_radius = 0;  // MaxMonotonicRadius, computed once
};

bool Visible(const Camera& camera, const Eigen::Vector3d& point_cam,
             const LensLimits& lens, double margin, Eigen::Vector2d* pixel) {
  if (FieldAngleDeg(point_cam) > lens.field_deg) return false;
  if (!(FieldRadius(camera, point_cam) < lens.max_radius)) return false;
  if (!camera.Project(point_cam, pixel)) return false;
  return pixel->x() >= margin && pixel->y() >= margin &&
         pixel->x() <= camera.width - 1 - margin &&
         pixel->y() <= camera.height - 1 - margin;
}

// The smallest tile side in pixels among the visible neighbours of the
// full board at `pose` (sampled rows and columns).
double SmallestTilePx(const Camera& camera, const Board& board,
                      const Eigen::Isometry3d& pose, const LensLimits& lens) {
  double smallest = std::numeric_limits<double>::infinity();
  const int stride_c = std::max(1, board.cols / 6);
  const int stride_r = std::max(1, board.rows / 6);
  for (int r = 0; r + 1 < board.rows; r += stride_r) {
    for (int c = 0; c + 1 < board.cols; c += stride_c) {
      const Eigen::Vector2i id = board.origin + Eigen::Vector2i(c, r);
      Eigen::Vector2d p0, px, py;
      if (!Visible(camera, pose * board.Point(id), lens, 0, &p0)) {
        continue;
      }
      if (Visible(camera, pose * board.Point(id + Eigen::Vector2i(1, 0)), lens,
                  0, &px)) {
        smallest = std::min(smallest, (px - p0).norm());
      }
      if (Visible(camera, pose * board.Point(id + Eigen::Vector2i(0, 1)), lens,
                  0, &py)) {
        smallest = std::min(smallest, (py - p0).norm());
      }
    }
  }
  return smallest;
}

// The corners of `corners` that the board at `pose` puts inside the image
// (image_margin_px from the border) and the lens's field.
std::vector<Eigen::Vector3d> VisibleCorners(
    const Camera& camera, const std::vector<Eigen::Vector3d>& corners,
    const LensLimits& lens, const Eigen::Isometry3d& pose,
    const AdviceOptions& options) {
  std::vector<Eigen::Vector3d> visible;
  for (const Eigen::Vector3d& point : corners) {
    Eigen::Vector2d pixel;
    if (Visible(camera, pose * point, lens, options.image_margin_px, &pixel)) {
      visible.push_back(point);
    }
  }
  return visible;
}

// The information (free parameters, unit noise) of the board seen from
// `pose` through `visible`, the visible ones of a subsample of
// `num_subsampled` corners standing for all of the board's. False when the
// view tells nothing (fewer than 3 of them project).
bool SubsampleInformation(const Camera& camera, const Board& board,
                          const std::vector<Eigen::Vector3d>& visible,
                          size_t num_subsampled, const std::vector<int>& free,
                          const Eigen::Isometry3d& pose,
                          Eigen::MatrixXd* information) {
  Eigen::MatrixXd full;
  const double weight = static_cast<double>(board.NumCorners()) /
                        std::max<size_t>(1, num_subsampled);
  if (!ViewInformation(camera, visible, pose, weight, &full)) return false;
  *information = FreeBlock(full, free);
  return true;
}

// The candidate for a board centre at `centre_px`, `distance_m` away, with
// a tilt; false when a person could not use it (see AdviceOptions).
bool MakeCandidate(const Camera& camera, const Board& board,
                   const std::vector<Eigen::Vector3d>& corners,
                   const std::vector<int>& free, const LensLimits& lens,
                   const Eigen::Vector2d& centre_px, double distance_m,
                   double tilt_deg, double tilt_direction_deg,
                   const AdviceOptions& options, Candidate* out) {
  Eigen::Vector3d ray;
  if (!camera.Unproject(centre_px, &ray).converged) return false;
  if (FieldAngleDeg(ray) > lens.field_deg) return false;
  const Eigen::Matrix3d rotation =
      TiltedRotation(ray, tilt_deg, tilt_direction_deg);
  const Eigen::Vector3d normal = rotation.col(2);
  // The angle between the line of sight and the board plane.
  const double view_angle_deg = std::asin(std::abs(ray.dot(normal))) / kDegree;
  if (view_angle_deg < options.min_view_angle_deg) return false;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = distance_m * ray - rotation * BoardCentre(board);

  const std::vector<Eigen::Vector3d> visible =
      VisibleCorners(camera, corners, lens, pose, options);
  const double fraction =
      static_cast<double>(visible.size()) / std::max<size_t>(1, corners.size());
  const double needed =
      board.Traits().absolute_ids ? options.min_visible_fraction : 1.0;
  if (fraction < needed || visible.size() < 4) return false;
  if (SmallestTilePx(camera, board, pose, lens) < options.min_tile_px) {
    return false;
  }
  if (!SubsampleInformation(camera, board, visible, corners.size(), free, pose,
                            &out->information)) {
    return false;
  }
  out->cam_from_board = pose;
  out->centre_px = centre_px;
  out->normal = normal;
  out->distance_m = distance_m;
  out->tilt_deg = tilt_deg;
  out->tilt_direction_deg = tilt_direction_deg;
  out->visible = static_cast<int>(std::lround(fraction * board.NumCorners()));
  return true;
}

std::vector<Candidate> MakeCandidates(const Camera& camera, const Board& board,
                                      const std::vector<int>& free,
                                      const LensLimits& lens,
                                      double reference_m,
                                      const AdviceOptions& options) {
  const std::vector<Eigen::Vector3d> corners =
      SubsampledCorners(board, options.max_corners_per_view);
  struct Spec {
    Eigen::Vector2d centre;
    double distance, tilt, direction;
  };
  std::vector<Spec> specs;
  for (int r = 0; r < options.position_rows; ++r) {
    for (int c = 0; c < options.position_cols; ++c) {
      const Eigen::Vector2d centre(
          (c + 0.5) * camera.width / options.position_cols - 0.5,
          (r + 0.5) * camera.height / options.position_rows - 0.5);
      for (double factor : options.distance_factors) {
        for (double tilt : options.tilts_deg) {
          const int directions = tilt > 0 ? options.tilt_directions : 1;
          for (int d = 0; d < directions; ++d) {
            specs.push_back({centre, factor * reference_m, tilt,
                             360.0 * d / options.tilt_directions});
          }
        }
      }
    }
  }
  std::vector<Candidate> slots(specs.size());
  std::vector<char> ok(specs.size(), 0);
  ParallelFor(static_cast<int>(specs.size()), options.num_threads, [&](int i) {
    const Spec& s = specs[i];
    ok[i] = MakeCandidate(camera, board, corners, free, lens, s.centre,
                          s.distance, s.tilt, s.direction, options, &slots[i]);
  });
  std::vector<Candidate> out;
  for (size_t i = 0; i < specs.size(); ++i) {
    if (ok[i]) out.push_back(std::move(slots[i]));
  }
  return out;
}

bool NearDuplicate(const Candidate& a, const Candidate& b, double diagonal,
                   const AdviceOptions& options) {
  const double normal_deg =
      std::acos(std::clamp(a.normal.dot(b.normal), -1.0, 1.0)) / kDegree;
  const double ratio = std::max(a.distance_m, b.distance_m) /
                       std::min(a.distance_m, b.distance_m);
  return (a.centre_px - b.centre_px).norm() <
             options.min_separation_fraction * diagonal &&
         normal_deg < options.min_separation_deg &&
         ratio < options.min_distance_ratio;
}

// The weak prior's information (see AdviceOptions), free parameters.
Eigen::MatrixXd PriorInformation(const Camera& camera,
                                 const std::vector<int>& free,
                                 const AdviceOptions& options) {
  const int n = static_cast<int>(free.size());
  Eigen::MatrixXd prior = Eigen::MatrixXd::Zero(n, n);
  const double size = std::max(camera.width, camera.height);
  for (int k = 0; k < n; ++k) {
    const int p = free[k];
    double sigma = options.prior_distortion;
    if (p < 2)
      sigma = options.prior_focal_fraction * std::abs(camera.params[p]);
    if (p == 2 || p == 3) sigma = options.prior_centre_fraction * size;
    prior(k, k) = 1.0 / (sigma * sigma);
  }
  return prior;
}

double MedianDistance(const std::vector<CalibrationView>& views,
                      const CalibrationResult& result) {
  std::vector<double> distances;
  for (size_t v = 0; v < views.size() && v < result.view_used.size(); ++v) {
    if (!result.view_used[v] || views[v].board_points.empty()) continue;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : views[v].board_points) centre += p;
    centre /= static_cast<double>(views[v].board_points.size());
    distances.push_back((result.cam_from_board[v] * centre).norm());
  }
  return distances.empty() ? 0.0 : Median(distances);
}

// The widest field angle of the inlier corners of the used views and their
// farthest pixel from the principal point.
void ObservedField(const std::vector<CalibrationView>& views,
                   const CalibrationResult& result, double* widest_deg,
                   double* farthest_px) {
  const Eigen::Vector2d centre(result.camera.params[2],
                               result.camera.params[3]);
  for (size_t v = 0; v < views.size() && v < result.view_used.size(); ++v) {
    if (!result.view_used[v]) continue;
    for (size_t i = 0; i < views[v].board_points.size(); ++i) {
      if (!result.inlier[v][i]) continue;
      *widest_deg = std::max(
          *widest_deg,
          FieldAngleDeg(result.cam_from_board[v] * views[v].board_points[i]));
      *farthest_px =
          std::max(*farthest_px, (views[v].image_points[i] - centre).norm());
    }
  }
}

// The widest field radius (FieldRadius) of the image: its corners' rays,
// or the fold's radius when a corner has none.
double ImageEdgeRadius(const Camera& camera) {
  double widest = 0;
  const double max_radius = MaxMonotonicRadius(camera);
  for (const Eigen::Vector2d& corner :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(camera.width - 1, 0),
        Eigen::Vector2d(0, camera.height - 1),
        Eigen::Vector2d(camera.width - 1, camera.height - 1)}) {
    Eigen::Vector3d ray;
    widest = std::max(widest, camera.Unproject(corner, &ray).converged
                                  ? FieldRadius(camera, ray)
                                  : max_radius);
  }
  return std::min(widest, max_radius);
}

// Where a point of the board's outline is drawn: its projection inside
// the image's field; beyond it (pinhole cameras only: no distortion was
// observed there, and extrapolating a polynomial bends the outline into
// waves) the edge's projection continued along the radial line.
bool OutlinePixel(const Camera& camera, const Eigen::Vector3d& point_cam,
                  double edge_radius, Eigen::Vector2d* pixel) {
  const double radius = FieldRadius(camera, point_cam);
  if (radius <= edge_radius) return camera.Project(point_cam, pixel);
  if (!CameraModelIsPinhole(camera.model) || point_cam.z() <= 0) return false;
  const double shrink = edge_radius / radius;
  const Eigen::Vector3d at_edge(shrink * point_cam.x(), shrink * point_cam.y(),
                                point_cam.z());
  Eigen::Vector2d edge;
  if (!camera.Project(at_edge, &edge)) return false;
  const Eigen::Vector2d centre(camera.params[2], camera.params[3]);
  *pixel = centre + (edge - centre) / shrink;
  return true;
}

std::vector<Eigen::Vector2d> Outline(const Camera& camera, const Board& board,
                                     const Eigen::Isometry3d& pose) {
  // The printed area: the outer inner corners grown by the board's border.
  const double border = board.Traits().border_tiles * board.tile_size_m;
  const Eigen::Vector3d lo =
      board.Point(board.origin) - Eigen::Vector3d(border, border, 0);
  const Eigen::Vector3d hi =
      board.Point(board.origin +
                  Eigen::Vector2i(board.cols - 1, board.rows - 1)) +
      Eigen::Vector3d(border, border, 0);
  const Eigen::Vector3d corners[4] = {
      lo, {hi.x(), lo.y(), 0}, hi, {lo.x(), hi.y(), 0}};
  const double edge_radius = ImageEdgeRadius(camera);
  std::vector<Eigen::Vector2d> out;
  constexpr int kStepsPerSide = 24;
  for (int side = 0; side < 4; ++side) {
    for (int s = 0; s < kStepsPerSide; ++s) {
      const double t = static_cast<double>(s) / kStepsPerSide;
      const Eigen::Vector3d p =
          (1 - t) * corners[side] + t * corners[(side + 1) % 4];
      Eigen::Vector2d pixel;
      if (OutlinePixel(camera, pose * p, edge_radius, &pixel)) {
        out.push_back(pixel);
      }
    }
  }
  return out;
}

// Index of the candidate whose information lowers the worst predicted
// uncertainty most (ties: the lower index), skipping `used` and near
// duplicates of `advised`; -1 when none is left.
int BestCandidate(const std::vector<Candidate>& candidates,
                  const std::vector<int>& advised,
                  const Eigen::MatrixXd& information,
                  const FieldSamples& samples, double diagonal,
                  const AdviceOptions& options) {
  std::vector<double> score(candidates.size(),
                            std::numeric_limits<double>::infinity());
  ParallelFor(
      static_cast<int>(candidates.size()), options.num_threads, [&](int c) {
        for (int a : advised) {
          if (a == c ||
              NearDuplicate(candidates[a], candidates[c], diagonal, options)) {
            return;
          }
        }
        Eigen::MatrixXd covariance;
        if (!CovarianceOf(information + candidates[c].information,
                          &covariance)) {
          return;
        }
        const FieldUncertainty u = Evaluate(samples, covariance);
        // The median breaks near ties of the worst value.
        score[c] = u.worst_px + 1e-3 * u.median_px;
      });
  int best = -1;
  for (size_t c = 0; c < candidates.size(); ++c) {
    if (std::isfinite(score[c]) && (best < 0 || score[c] < score[best])) {
      best = static_cast<int>(c);
    }
  }
  return best;
}

// What the predictions for a calibration start from: its free parameters,
// the corner noise, the judged field and the information of the views
// taken (with the priors), in units of that noise.
struct PredictionStart {
  std::vector<int> free_index;
  double noise = 0;
  double precision = 0;  // 1 / noise^2
  double observed_deg = 0;
  double field_radius_px = 0;
  LensLimits lens;
  FieldSamples samples;
  Eigen::MatrixXd information;
  Eigen::MatrixXd covariance;
};

// False with `error` when the calibration gives no prediction.
bool StartPrediction(const std::vector<CalibrationView>& views,
                     const CalibrationResult& result,
                     const AdviceOptions& options, PredictionStart* start,
                     std::string* error) {
  const Camera& camera = result.camera;
  std::vector<bool> free(result.param_fixed.size());
  for (size_t k = 0; k < free.size(); ++k) free[k] = !result.param_fixed[k];
  start->free_index = FreeIndices(free);
  if (start->free_index.empty()) {
    *error = "every intrinsic is held: there is nothing to determine";
    return false;
  }
  start->noise = options.noise_sigma_px > 0 ? options.noise_sigma_px
                                            : StatedNoiseSigma(result);
  double observed_px = 0;
  ObservedField(views, result, &start->observed_deg, &observed_px);
  start->field_radius_px = JudgedRadiusPx(camera, observed_px, options);
  start->lens = {LensFieldDeg(camera, start->observed_deg),
                 MaxMonotonicRadius(camera)};
  start->samples = MakeFieldSamples(camera, start->free_index,
                                    start->field_radius_px, options);
  if (start->samples.jacobian.empty()) {
    *error = "no pixel of the judged field has a ray";
    return false;
  }
  // Information in units of the corner noise.
  start->precision = 1.0 / (start->noise * start->noise);
  start->information =
      start->precision * (TakenInformation(views, result) +
                          FreeBlock(SplinePriorInformation(
                                        camera.model, camera.params[0],
                                        camera.params[1], options.spline_prior),
                                    start->free_index)) +
      PriorInformation(camera, start->free_index, options);
  if (!CovarianceOf(start->information, &start->covariance)) {
    *error = "the information of the views taken is not usable";
    return false;
  }
  return true;
}

}  // namespace

bool AdviceOptions::Check(std::string* why) const {
  if (count < 1) return Fail("count must be >= 1", why);
  if (!spline_prior.Check(why)) return false;
  if (!(field_deg >= 0 && field_deg < 180)) {
    return Fail("field_deg must lie in [0, 180)", why);
  }
  if (!(field_radius_px >= 0)) return Fail("field_radius_px must be >= 0", why);
  if (!(max_fold_fraction > 0 && max_fold_fraction <= 1)) {
    return Fail("max_fold_fraction must lie in (0, 1]", why);
  }
  if (field_samples < 16) return Fail("field_samples must be >= 16", why);
  if (position_cols < 1 || position_rows < 1) {
    return Fail("position_cols and position_rows must be >= 1", why);
  }
  if (distance_factors.empty()) {
    return Fail("distance_factors must not be empty", why);
  }
  for (double factor : distance_factors) {
    if (!(factor > 0)) return Fail("distance_factors must be > 0", why);
  }
  if (tilts_deg.empty()) return Fail("tilts_deg must not be empty", why);
  for (double tilt : tilts_deg) {
    if (!(tilt >= 0 && tilt <= 80)) {
      return Fail("tilts_deg must lie in [0, 80]", why);
    }
  }
  if (tilt_directions < 1) return Fail("tilt_directions must be >= 1", why);
  if (!(min_view_angle_deg >= 0 && min_view_angle_deg < 90)) {
    return Fail("min_view_angle_deg must lie in [0, 90)", why);
  }
  if (!(min_visible_fraction > 0 && min_visible_fraction <= 1)) {
    return Fail("min_visible_fraction must lie in (0, 1]", why);
  }
  if (!(image_margin_px >= 0)) return Fail("image_margin_px must be >= 0", why);
  if (!(min_tile_px >= 0)) return Fail("min_tile_px must be >= 0", why);
  if (max_corners_per_view < 4) {
    return Fail("max_corners_per_view must be >= 4", why);
  }
  if (!(min_separation_fraction >= 0) || !(min_separation_deg >= 0) ||
      !(min_distance_ratio >= 1)) {
    return Fail(
        "min_separation_fraction and min_separation_deg must be >= 0, "
        "min_distance_ratio >= 1",
        why);
  }
  if (!(target_uncertainty_px > 0)) {
    return Fail("target_uncertainty_px must be > 0", why);
  }
  if (target_min_views < 0) return Fail("target_min_views must be >= 0", why);
  if (max_estimate_views < 1) {
    return Fail("max_estimate_views must be >= 1", why);
  }
  if (!(noise_sigma_px >= 0)) return Fail("noise_sigma_px must be >= 0", why);
  if (!(prior_focal_fraction > 0) || !(prior_centre_fraction > 0) ||
      !(prior_distortion > 0)) {
    return Fail("the prior's standard deviations must be > 0", why);
  }
  if (num_threads < 1) return Fail("num_threads must be >= 1", why);
  return true;
}

double StatedNoiseSigma(const CalibrationResult& result) {
  const int corners = result.num_corners_used;
  int fitted = 0;
  for (bool fixed : result.param_fixed) fitted += fixed ? 0 : 1;
  for (bool used : result.view_used) fitted += used ? 6 : 0;
  const double dof = 2.0 * corners - fitted;
  if (!(dof > 0)) return result.rms_px;
  return result.rms_px * std::sqrt(2.0 * corners / dof);
}

Eigen::MatrixXd TakenInformation(const std::vector<CalibrationView>& views,
                                 const CalibrationResult& result) {
  std::vector<bool> free(result.param_fixed.size());
  for (size_t k = 0; k < free.size(); ++k) free[k] = !result.param_fixed[k];
  const std::vector<int> free_index = FreeIndices(free);
  const int n = CameraModelNumParams(result.camera.model);
  Eigen::MatrixXd total = Eigen::MatrixXd::Zero(n, n);
  for (size_t v = 0; v < views.size() && v < result.view_used.size(); ++v) {
    if (!result.view_used[v]) continue;
    std::vector<Eigen::Vector3d> inliers;
    for (size_t i = 0; i < views[v].board_points.size(); ++i) {
      if (result.inlier[v][i]) inliers.push_back(views[v].board_points[i]);
    }
    Eigen::MatrixXd information;
    if (ViewInformation(result.camera, inliers, result.cam_from_board[v], 1.0,
                        &information)) {
      total += information;
    }
  }
  return FreeBlock(total, free_index);
}

FieldUncertainty PredictFieldUncertainty(const Camera& camera,
                                         const std::vector<bool>& free,
                                         const Eigen::MatrixXd& free_covariance,
                                         const AdviceOptions& options) {
  return Evaluate(
      MakeFieldSamples(camera, FreeIndices(free),
                       JudgedRadiusPx(camera, 0.0, options), options),
      free_covariance);
}

std::string DescribePose(const Camera& camera, const Eigen::Vector2d& centre_px,
                         double distance_m, double tilt_deg,
                         double tilt_direction_deg) {
  const char* const kRows[3] = {"top", "middle", "bottom"};
  const char* const kCols[3] = {"left", "centre", "right"};
  const int col = std::clamp(
      static_cast<int>(3 * (centre_px.x() + 0.5) / camera.width), 0, 2);
  const int row = std::clamp(
      static_cast<int>(3 * (centre_px.y() + 0.5) / camera.height), 0, 2);
  // Within the middle third, a shift of more than a twelfth of the image
  // is said ("a little above the centre"): two advised poses can differ
  // by that alone.
  const double right = centre_px.x() / camera.width - 0.5;
  const double down = centre_px.y() / camera.height - 0.5;
  std::string shift;
  if (row == 1 && std::abs(down) > 1.0 / 12) {
    shift = down < 0 ? "above" : "below";
  }
  if (col == 1 && std::abs(right) > 1.0 / 12) {
    shift += std::string(shift.empty() ? "" : " and ") +
             (right < 0 ? "left of" : "right of");
  }
  // "At the edge" and "in the corner" only within the outer sixth of the
  // image (a centre a third of the way in was "at the left edge"); the
  // rest of an outer third is said as such.
  const bool near_side = std::abs(right) > 1.0 / 3;
  const bool near_top_bottom = std::abs(down) > 1.0 / 3;
  std::string place;
  if (row == 1 && col == 1) {
    place = shift.empty() ? "in the centre of the image"
                          : "a little " + shift + " the centre of the image";
  } else if (row == 1) {
    place = near_side
                ? std::string("at the ") + kCols[col] + " edge of the image"
                : std::string("in the ") + kCols[col] + " third of the image";
  } else if (col == 1) {
    place = near_top_bottom
                ? std::string("at the ") + kRows[row] + " edge of the image"
                : std::string("in the ") + kRows[row] + " third of the image";
  } else {
    place = std::string("in the ") + kRows[row] + "-" + kCols[col] +
            (near_side && near_top_bottom ? " corner of the image"
                                          : " part of the image");
  }
  // Centimetres for a board held close, where "0.073 m" reads badly.
  const std::string distance = distance_m < 0.3
                                   ? StringPrintf("%.0f cm", 100 * distance_m)
                                   : StringPrintf("%.2g m", distance_m);
  std::string words = StringPrintf("board about %s away, its centre %s",
                                   distance.c_str(), place.c_str());
  if (tilt_deg < 5) return words + ", facing the camera squarely";
  // The edge nearer the camera, by the direction in the image (y down).
  const char* const kEdges[8] = {
      "right edge", "bottom-right corner", "bottom edge", "bottom-left corner",
      "left edge",  "top-left corner",     "top edge",    "top-right corner"};
  const int octant = static_cast<int>(std::lround(
                         std::fmod(tilt_direction_deg + 360.0, 360.0) / 45.0)) %
                     8;
  return words + StringPrintf(
                     ", tilted about %.0f degrees with its %s "
                     "towards the camera",
                     tilt_deg, kEdges[octant]);
}

Advice AdviseViews(const std::vector<CalibrationView>& views,
                   const CalibrationResult& result, const Board& board,
                   const AdviceOptions& options) {
  const Timer timer;
  Advice advice;
  if (!options.Check(&advice.error)) return advice;
  advice.camera = result.camera;
  const Camera& camera = result.camera;
  advice.reference_distance_m = MedianDistance(views, result);
  if (!(advice.reference_distance_m > 0)) {
    advice.error = "no view of the board was posed";
    return advice;
  }
  for (bool used : result.view_used) advice.views_taken += used ? 1 : 0;
  PredictionStart start;
  if (!StartPrediction(views, result, options, &start, &advice.error)) {
    return advice;
  }
  advice.noise_sigma_px = start.noise;
  advice.target_uncertainty_px = options.target_uncertainty_px;
  advice.field_radius_px = start.field_radius_px;
  advice.field_deg = start.samples.field_deg;
  const FieldSamples& samples = start.samples;
  const double precision = start.precision;
  Eigen::MatrixXd information = start.information;
  Eigen::MatrixXd covariance = start.covariance;
  advice.now = Evaluate(samples, covariance);

  std::vector<Candidate> candidates =
      MakeCandidates(camera, board, start.free_index, start.lens,
                     advice.reference_distance_m, options);
  for (Candidate& c : candidates) c.information *= precision;
  for (const Candidate& c : candidates) {
    advice.candidate_poses.push_back(c.cam_from_board);
  }
  if (candidates.empty()) {
    advice.error =
        "no candidate pose keeps the board in view with tiles large enough "
        "to detect";
    return advice;
  }
  const double diagonal = std::hypot(camera.width, camera.height);
  std::vector<int> advised;
  FieldUncertainty current = advice.now;
  for (int k = 0; k < options.count; ++k) {
    const int best = BestCandidate(candidates, advised, information, samples,
                                   diagonal, options);
    if (best < 0) break;
    advised.push_back(best);
    information += candidates[best].information;
    CovarianceOf(information, &covariance);
    current = Evaluate(samples, covariance);
    const Candidate& c = candidates[best];
    AdvisedView view;
    view.cam_from_board = c.cam_from_board;
    view.centre_px = c.centre_px;
    view.distance_m = c.distance_m;
    view.tilt_deg = c.tilt_deg;
    view.tilt_direction_deg = c.tilt_direction_deg;
    view.visible_corners = c.visible;
    view.board_corners = board.NumCorners();
    view.outline_px = Outline(camera, board, c.cam_from_board);
    view.words = DescribePose(camera, c.centre_px, c.distance_m, c.tilt_deg,
                              c.tilt_direction_deg);
    view.after = current;
    advice.views.push_back(view);
  }
  // The estimate: more photos like the advised ones, in turn.
  auto reached = [&](const FieldUncertainty& u, int photos) {
    return u.worst_band_median_px <= options.target_uncertainty_px &&
           photos >= options.target_min_views;
  };
  int photos = advice.views_taken;
  FieldUncertainty estimate = advice.now;
  Eigen::MatrixXd running = information - [&] {
    Eigen::MatrixXd added =
        Eigen::MatrixXd::Zero(information.rows(), information.cols());
    for (int a : advised) added += candidates[a].information;
    return added;
  }();
  for (int step = 0; !advised.empty(); ++step) {
    if (reached(estimate, photos)) {
      advice.photos_to_target = photos;
      break;
    }
    if (photos >= options.max_estimate_views) break;
    running += candidates[advised[step % advised.size()]].information;
    ++photos;
    if (!CovarianceOf(running, &covariance)) break;
    estimate = Evaluate(samples, covariance);
  }
  advice.ok = !advice.views.empty();
  if (!advice.ok) advice.error = "no candidate pose lowers the uncertainty";
  advice.seconds = timer.Seconds();
  return advice;
}

bool PredictWithPoses(const std::vector<CalibrationView>& views,
                      const CalibrationResult& result, const Board& board,
                      const std::vector<Eigen::Isometry3d>& poses,
                      const AdviceOptions& options, FieldUncertainty* after,
                      std::string* error) {
  if (!options.Check(error)) return false;
  PredictionStart start;
  if (!StartPrediction(views, result, options, &start, error)) return false;
  const std::vector<Eigen::Vector3d> corners =
      SubsampledCorners(board, options.max_corners_per_view);
  Eigen::MatrixXd information = start.information;
  for (const Eigen::Isometry3d& pose : poses) {
    const std::vector<Eigen::Vector3d> visible =
        VisibleCorners(result.camera, corners, start.lens, pose, options);
    Eigen::MatrixXd view;
    if (SubsampleInformation(result.camera, board, visible, corners.size(),
                             start.free_index, pose, &view)) {
      information += start.precision * view;
    }
  }
  Eigen::MatrixXd covariance;
  if (!CovarianceOf(information, &covariance)) {
    *error = "the information with the added views is not usable";
    return false;
  }
  *after = Evaluate(start.samples, covariance);
  return true;
}

std::string Advice::Text() const {
  std::ostringstream out;
  if (!ok) return "no advice: " + error + "\n";
  out << StringPrintf(
      "projection uncertainty now (%d views; field: within %.0f px of the "
      "principal point, rays up to %.0f deg): worst %.3f px, median %.3f px, "
      "worst band median %.3f px\n",
      views_taken, field_radius_px, field_deg, now.worst_px, now.median_px,
      now.worst_band_median_px);
  for (size_t k = 0; k < views.size(); ++k) {
    const AdvisedView& v = views[k];
    out << StringPrintf("next %zu: %s\n", k + 1, v.words.c_str());
    out << StringPrintf(
        "        then: worst %.3f px, median %.3f px, worst band median "
        "%.3f px\n",
        v.after.worst_px, v.after.median_px, v.after.worst_band_median_px);
  }
  if (photos_to_target >= 0) {
    out << StringPrintf(
        "about %d photos in all (%d more) reach %.2f px in every field band\n",
        photos_to_target, std::max(0, photos_to_target - views_taken),
        target_uncertainty_px);
  } else {
    out << "the advised kind of photo alone does not reach the target "
           "uncertainty within the estimate's limit\n";
  }
  out << StringPrintf(
      "(predicted with a corner noise of %.3f px for the new photos, as "
      "for those taken; a steeply tilted or close board usually gives "
      "noisier corners, and the calibration's figures then grow in "
      "proportion)\n",
      noise_sigma_px);
  return out.str();
}

}  // namespace puzzlecal
