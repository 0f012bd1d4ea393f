#include "evidence/view_consistency.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "util/failure.h"

namespace puzzlecal {
namespace {

// A view's 7 parameters: rotation (angle-axis) and translation applied on
// top of the calibrated pose, and the log of the focal scale.
struct ViewFit {
  Eigen::Matrix<double, 7, 1> x = Eigen::Matrix<double, 7, 1>::Zero();
};

Eigen::Isometry3d PoseOf(const Eigen::Isometry3d& start,
                         const Eigen::Matrix<double, 7, 1>& x) {
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = x.head<3>();
  if (w.norm() > 0) {
    delta.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).matrix();
  }
  delta.translation() = x.segment<3>(3);
  return delta * start;
}

// Residuals (projected minus observed, 2 per corner); false when a corner
// does not project.
bool Residuals(const Camera& camera, const Eigen::Isometry3d& start,
               const std::vector<Eigen::Vector3d>& board,
               const std::vector<Eigen::Vector2d>& image,
               const Eigen::Matrix<double, 7, 1>& x, Eigen::VectorXd* r) {
  Camera scaled = camera;
  const double scale = std::exp(x(6));
  scaled.params[0] *= scale;
  scaled.params[1] *= scale;
  const Eigen::Isometry3d pose = PoseOf(start, x);
  r->resize(2 * board.size());
  for (size_t i = 0; i < board.size(); ++i) {
    Eigen::Vector2d pixel;
    if (!scaled.Project(pose * board[i], &pixel)) return false;
    r->segment<2>(2 * i) = pixel - image[i];
  }
  return r->allFinite();
}

}  // namespace

bool ViewConsistencyOptions::Check(std::string* why) const {
  if (min_corners < 7) return Fail("min_corners must be >= 7", why);
  if (max_iterations < 1) return Fail("max_iterations must be >= 1", why);
  return true;
}

ViewConsistency ComputeViewConsistency(
    const std::vector<CalibrationView>& views, const CalibrationResult& result,
    const ViewConsistencyOptions& options) {
  ViewConsistency out;
  std::string why;
  if (!options.Check(&why)) {
    out.error = "view consistency options: " + why;
    return out;
  }
  const Camera& camera = result.camera;
  if (camera.params.size() < 4 || !(result.rms_px > 0)) {
    out.error = "no calibration to compare the views with";
    return out;
  }
  out.focal_px = camera.params[0];
  const Eigen::Vector2d principal(camera.params[2], camera.params[3]);
  const double noise = result.rms_px;
  for (size_t v = 0; v < views.size(); ++v) {
    if (v >= result.view_used.size() || !result.view_used[v] ||
        v >= result.inlier.size() || v >= result.cam_from_board.size()) {
      continue;
    }
    std::vector<Eigen::Vector3d> board;
    std::vector<Eigen::Vector2d> image;
    for (size_t i = 0;
         i < views[v].board_points.size() && i < result.inlier[v].size(); ++i) {
      if (!result.inlier[v][i]) continue;
      board.push_back(views[v].board_points[i]);
      image.push_back(views[v].image_points[i]);
    }
    if (static_cast<int>(board.size()) < options.min_corners) continue;
    const Eigen::Isometry3d& start = result.cam_from_board[v];
    // Gauss-Newton with numeric derivatives (central differences).
    Eigen::Matrix<double, 7, 1> x = Eigen::Matrix<double, 7, 1>::Zero();
    Eigen::VectorXd r;
    if (!Residuals(camera, start, board, image, x, &r)) continue;
    Eigen::MatrixXd jacobian(r.size(), 7);
    bool ok = true;
    double cost = r.squaredNorm();
    const double cost_held = cost;
    for (int iteration = 0; iteration < options.max_iterations && ok;
         ++iteration) {
      for (int k = 0; k < 7 && ok; ++k) {
        const double h = k < 3 ? 1e-6 : (k < 6 ? 1e-6 : 1e-7);
        Eigen::Matrix<double, 7, 1> plus = x, minus = x;
        plus(k) += h;
        minus(k) -= h;
        Eigen::VectorXd rp, rm;
        ok = Residuals(camera, start, board, image, plus, &rp) &&
             Residuals(camera, start, board, image, minus, &rm);
        if (ok) jacobian.col(k) = (rp - rm) / (2 * h);
      }
      if (!ok) break;
      const Eigen::Matrix<double, 7, 7> jtj = jacobian.transpose() * jacobian;
      const Eigen::LDLT<Eigen::Matrix<double, 7, 7>> ldlt(jtj);
      if (ldlt.info() != Eigen::Success) {
        ok = false;
        break;
      }
      const Eigen::Matrix<double, 7, 1> step =
          -ldlt.solve(jacobian.transpose() * r);
      Eigen::VectorXd trial;
      if (!step.allFinite() ||
          !Residuals(camera, start, board, image, x + step, &trial)) {
        ok = false;
        break;
      }
      const double trial_cost = trial.squaredNorm();
      if (trial_cost > cost) break;  // at the minimum to numeric precision
      x += step;
      r = trial;
      const bool converged = cost - trial_cost < 1e-12 * (1 + cost);
      cost = trial_cost;
      if (converged) break;
    }
    if (!ok) continue;
    const Eigen::Matrix<double, 7, 7> jtj = jacobian.transpose() * jacobian;
    const Eigen::FullPivLU<Eigen::Matrix<double, 7, 7>> lu(jtj);
    if (!lu.isInvertible()) continue;
    const double variance = lu.inverse()(6, 6) * noise * noise;
    if (!(variance > 0) || !std::isfinite(variance)) continue;
    ViewFocal focal;
    focal.view = static_cast<int>(v);
    focal.name = v < result.view_name.size() && !result.view_name[v].empty()
                     ? result.view_name[v]
                     : views[v].name;
    focal.corners = static_cast<int>(board.size());
    focal.scale = std::exp(x(6));
    focal.scale_sigma = focal.scale * std::sqrt(variance);
    double sum2 = 0;
    for (const Eigen::Vector2d& p : image) {
      sum2 += (p - principal).squaredNorm();
    }
    focal.radius_px = std::sqrt(sum2 / image.size());
    focal.gain_px =
        std::sqrt(std::max(0.0, cost_held - cost) / (2.0 * board.size()));
    out.views.push_back(focal);
  }
  out.fields = ComputeViewFields(views, result, options);
  if (out.views.size() < 3) {
    out.error = "fewer than three views could fit their own focal length";
    return out;
  }
  double weights = 0, weighted = 0;
  for (const ViewFocal& f : out.views) {
    const double w = 1.0 / (f.scale_sigma * f.scale_sigma);
    weights += w;
    weighted += w * f.scale;
  }
  out.mean_scale = weighted / weights;
  double effect2 = 0, expected2 = 0;
  for (ViewFocal& f : out.views) {
    f.z = (f.scale - out.mean_scale) / f.scale_sigma;
    out.chi2 += f.z * f.z;
    effect2 += f.gain_px * f.gain_px;
    expected2 += noise * noise / (2.0 * f.corners);
  }
  out.expected_effect_px = std::sqrt(expected2 / out.views.size());
  out.dof = static_cast<int>(out.views.size()) - 1;
  out.spread_ratio = std::sqrt(out.chi2 / out.dof);
  out.effect_px = std::sqrt(effect2 / out.views.size());
  out.ok = true;
  return out;
}

std::vector<ViewField> ComputeViewFields(
    const std::vector<CalibrationView>& views, const CalibrationResult& result,
    const ViewConsistencyOptions& options) {
  std::vector<ViewField> fields;
  const double sigma =
      result.noise_sigma_px > 0 ? result.noise_sigma_px : result.rms_px;
  const double threshold =
      result.outlier_threshold_px > 0 ? result.outlier_threshold_px : 4 * sigma;
  for (size_t v = 0; v < views.size(); ++v) {
    if (v >= result.view_used.size() || !result.view_used[v] ||
        v >= result.residuals.size() || v >= result.inlier.size()) {
      continue;
    }
    const std::vector<Eigen::Vector2d>& residuals = result.residuals[v];
    const int n = static_cast<int>(
        std::min(residuals.size(), views[v].board_points.size()));
    if (n < std::max(options.min_corners, 12)) continue;
    Eigen::Vector2d lo = views[v].board_points[0].head<2>(), hi = lo;
    for (int i = 0; i < n; ++i) {
      lo = lo.cwiseMin(views[v].board_points[i].head<2>());
      hi = hi.cwiseMax(views[v].board_points[i].head<2>());
    }
    const Eigen::Vector2d centre = 0.5 * (lo + hi);
    const Eigen::Vector2d half = (0.5 * (hi - lo)).cwiseMax(1e-9);
    Eigen::MatrixXd basis(n, 6);
    Eigen::MatrixXd r(n, 2);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d uv =
          (views[v].board_points[i].head<2>() - centre).cwiseQuotient(half);
      basis.row(i) << 1, uv.x(), uv.y(), uv.x() * uv.x(), uv.x() * uv.y(),
          uv.y() * uv.y();
      r.row(i) = residuals[i].transpose();
    }
    const Eigen::MatrixXd coefficients = basis.colPivHouseholderQr().solve(r);
    const Eigen::MatrixXd smooth = basis * coefficients;
    if (!smooth.allFinite()) continue;
    ViewField field;
    field.view = static_cast<int>(v);
    field.name = v < result.view_name.size() && !result.view_name[v].empty()
                     ? result.view_name[v]
                     : views[v].name;
    field.corners = n;
    for (int i = 0; i < n; ++i) {
      const bool inlier =
          i < static_cast<int>(result.inlier[v].size()) && result.inlier[v][i];
      if (inlier) continue;
      ++field.outliers;
      if ((r.row(i) - smooth.row(i)).norm() <= threshold) {
        ++field.outliers_explained;
      }
    }
    field.rms_px = std::sqrt(r.squaredNorm() / (2.0 * n));
    field.smooth_rms_px = std::sqrt(smooth.squaredNorm() / (2.0 * n));
    field.rest_rms_px =
        std::sqrt((r - smooth).squaredNorm() / std::max(1.0, 2.0 * n - 12));
    field.expected_smooth_px = sigma * std::sqrt(12.0 / (2.0 * n));
    fields.push_back(field);
  }
  return fields;
}

std::vector<ViewFocal> MostInconsistentViews(const ViewConsistency& vc,
                                             int count) {
  std::vector<ViewFocal> sorted = vc.views;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const ViewFocal& a, const ViewFocal& b) {
                     return std::abs(a.z) > std::abs(b.z);
                   });
  if (static_cast<int>(sorted.size()) > count) sorted.resize(count);
  return sorted;
}

}  // namespace puzzlecal
