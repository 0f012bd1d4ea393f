#include "calib/initialization.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "calib/reprojection_error.h"
#include "util/failure.h"
#include "util/parallel_for.h"
#include "util/statistics.h"

namespace puzzlecal {
namespace {

// Angle between a unit ray and a direction (any length), radians.
double AngleBetween(const Eigen::Vector3d& ray, const Eigen::Vector3d& v) {
  return std::atan2(ray.cross(v).norm(), ray.dot(v));
}

// True when the board points span a plane region (not all on one line).
bool PointsSpanPlane(const std::vector<Eigen::Vector2d>& points,
                     const std::vector<bool>& use) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  int n = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (use[i]) {
      mean += points[i];
      ++n;
    }
  }
  if (n < 4) return false;
  mean /= n;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (size_t i = 0; i < points.size(); ++i) {
    if (use[i]) cov += (points[i] - mean) * (points[i] - mean).transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  const double small = eig.eigenvalues()(0), large = eig.eigenvalues()(1);
  return large > 0 && small > 1e-6 * large;
}

// One weighted DLT solve of ray x (H_norm * X_norm) = 0.
bool SolveDlt(const std::vector<Eigen::Vector3d>& board_norm,
              const std::vector<Eigen::Vector3d>& rays,
              const std::vector<bool>& use, Eigen::Matrix3d* h) {
  Eigen::Matrix<double, 9, 9> ata = Eigen::Matrix<double, 9, 9>::Zero();
  for (size_t i = 0; i < rays.size(); ++i) {
    if (!use[i]) continue;
    const Eigen::Vector3d& x = board_norm[i];
    const Eigen::Vector3d& d = rays[i];
    // d x (H x) = [d]_x (I kron x') h: three rows, rank two, whose
    // contribution to A'A is ([d]_x' [d]_x) kron (x x'), with
    // [d]_x' [d]_x = |d|^2 I - d d'.
    const Eigen::Matrix3d cross =
        d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose();
    const Eigen::Matrix3d xx = x * x.transpose();
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        ata.block<3, 3>(3 * a, 3 * b) += cross(a, b) * xx;
      }
    }
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eig(ata);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::Matrix<double, 9, 1> v = eig.eigenvectors().col(0);
  if (!v.allFinite()) return false;
  *h << v(0), v(1), v(2), v(3), v(4), v(5), v(6), v(7), v(8);
  return true;
}

// The camera a focal-length candidate stands for: fx = fy = f, principal
// point at the image centre, no distortion.
Camera CandidateCamera(CameraModelId model, int width, int height, double f) {
  Camera camera;
  camera.model = model;
  camera.width = width;
  camera.height = height;
  camera.params.assign(CameraModelNumParams(model), 0.0);
  camera.params[0] = camera.params[1] = f;
  camera.params[2] = 0.5 * (width - 1);
  camera.params[3] = 0.5 * (height - 1);
  return camera;
}

std::vector<Eigen::Vector2d> BoardXy(const CalibrationView& view) {
  std::vector<Eigen::Vector2d> xy(view.board_points.size());
  for (size_t i = 0; i < xy.size(); ++i) xy[i] = view.board_points[i].head<2>();
  return xy;
}

// Unprojects every image point; `ok[i]` false where the model gives no ray.
void UnprojectAll(const Camera& camera, const CalibrationView& view,
                  std::vector<Eigen::Vector3d>* rays, std::vector<bool>* ok) {
  rays->resize(view.image_points.size());
  ok->assign(view.image_points.size(), false);
  for (size_t i = 0; i < rays->size(); ++i) {
    (*ok)[i] = camera.Unproject(view.image_points[i], &(*rays)[i]).converged;
  }
}

// Pose of one view from rays only (no refinement); false if none.
bool PoseFromRays(const Camera& camera, const CalibrationView& view,
                  const InitializationOptions& options,
                  Eigen::Isometry3d* cam_from_board, std::string* why) {
  std::vector<Eigen::Vector3d> rays;
  std::vector<bool> ok;
  UnprojectAll(camera, view, &rays, &ok);
  std::vector<Eigen::Vector2d> xy_ok;
  std::vector<Eigen::Vector3d> rays_ok;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (ok[i]) {
      xy_ok.push_back(view.board_points[i].head<2>());
      rays_ok.push_back(rays[i]);
    }
  }
  if (xy_ok.size() < 4) {
    return Fail("fewer than 4 corners unproject with the current intrinsics",
                why);
  }
  Eigen::Matrix3d h;
  if (!EstimateBoardToRayHomography(xy_ok, rays_ok, options, &h, nullptr)) {
    return Fail("no board-to-ray homography (corners on a line?)", why);
  }
  if (!PoseFromBoardToRayHomography(h, xy_ok, rays_ok, cam_from_board)) {
    return Fail("the homography gives no pose", why);
  }
  return true;
}

// Sum over views of truncated squared pixel errors when every view gets its
// pose from rays through `camera`: how well `camera` explains the views.
double ViewFitCost(const Camera& camera,
                   const std::vector<const CalibrationView*>& views,
                   const InitializationOptions& options) {
  const double truncation2 =
      options.focal_search_truncation_px * options.focal_search_truncation_px;
  std::vector<double> view_cost(views.size(), 0.0);
  ParallelFor(static_cast<int>(views.size()), options.num_threads, [&](int v) {
    const CalibrationView& view = *views[v];
    Eigen::Isometry3d pose;
    if (!PoseFromRays(camera, view, options, &pose, nullptr)) {
      view_cost[v] = truncation2 * view.board_points.size();
      return;
    }
    double cost = 0;
    for (size_t i = 0; i < view.board_points.size(); ++i) {
      Eigen::Vector2d pixel;
      double e2 = truncation2;
      if (camera.Project(pose * view.board_points[i], &pixel)) {
        e2 = std::min(e2, (pixel - view.image_points[i]).squaredNorm());
      }
      if (!std::isfinite(e2)) e2 = truncation2;
      cost += e2;
    }
    view_cost[v] = cost;
  });
  double cost = 0;
  for (double c : view_cost) cost += c;  // in view order: thread-independent
  return cost;
}

// An evenly spread subset of at most `max_views` of `used`.
std::vector<const CalibrationView*> SpreadSubset(
    const std::vector<const CalibrationView*>& used, int max_views) {
  std::vector<const CalibrationView*> subset;
  for (size_t i : EvenlySpreadIndices(used.size(), max_views)) {
    subset.push_back(used[i]);
  }
  return subset;
}

// The views with at most `max_corners` corners each (evenly spread over
// their corner lists), copies in `storage` where a view has more; the
// input pointers when none has.
std::vector<const CalibrationView*> ThinnedViews(
    const std::vector<const CalibrationView*>& views, int max_corners,
    std::vector<CalibrationView>* storage) {
  storage->clear();
  storage->reserve(views.size());  // the pointers below stay valid
  std::vector<const CalibrationView*> thinned;
  for (const CalibrationView* view : views) {
    const size_t n = view->board_points.size();
    if (n <= static_cast<size_t>(max_corners)) {
      thinned.push_back(view);
      continue;
    }
    CalibrationView fewer;
    fewer.name = view->name;
    for (size_t i : EvenlySpreadIndices(n, max_corners)) {
      fewer.board_points.push_back(view->board_points[i]);
      fewer.image_points.push_back(view->image_points[i]);
    }
    storage->push_back(std::move(fewer));
    thinned.push_back(&storage->back());
  }
  return thinned;
}

// The scan steps whose cost is a local minimum (not above either
// neighbour's), the lowest first, at most `count` of them.
std::vector<int> LowestLocalMinima(const std::vector<double>& cost, int count) {
  std::vector<int> minima;
  const int n = static_cast<int>(cost.size());
  for (int k = 0; k < n; ++k) {
    if ((k == 0 || cost[k] <= cost[k - 1]) &&
        (k == n - 1 || cost[k] <= cost[k + 1])) {
      minima.push_back(k);
    }
  }
  std::stable_sort(minima.begin(), minima.end(),
                   [&](int i, int j) { return cost[i] < cost[j]; });
  if (static_cast<int>(minima.size()) > count) minima.resize(count);
  return minima;
}

// 1D search for f (fx = fy = f, centred principal point, no distortion):
// log-spaced scan on an evenly spread subset of the views (it only brackets
// the minimum; its lowest local minima are scored again on all views, so a
// subset that misjudges which basin is deepest does not pick the bracket),
// then golden section on all of them around the best candidate.
double SearchFocalLength(CameraModelId model, int width, int height,
                         const std::vector<const CalibrationView*>& all_views,
                         const InitializationOptions& options,
                         double* best_cost) {
  std::vector<CalibrationView> thinned;
  const std::vector<const CalibrationView*> views = ThinnedViews(
      all_views, options.focal_search_max_corners_per_view, &thinned);
  const double diagonal = std::hypot(width, height);
  const double log_min = std::log(options.focal_search_min_ratio * diagonal);
  const double log_max = std::log(options.focal_search_max_ratio * diagonal);
  const int steps = options.focal_search_steps;
  InitializationOptions search_options = options;
  search_options.reweight_iterations = options.focal_search_reweight_iterations;
  auto cost_at = [&](double log_f,
                     const std::vector<const CalibrationView*>& fit_views) {
    return ViewFitCost(CandidateCamera(model, width, height, std::exp(log_f)),
                       fit_views, search_options);
  };
  const std::vector<const CalibrationView*> scan_views =
      SpreadSubset(views, options.focal_search_scan_max_views);
  const double step = (log_max - log_min) / (steps - 1);
  std::vector<double> scan_cost(steps);
  for (int k = 0; k < steps; ++k) {
    scan_cost[k] = cost_at(log_min + k * step, scan_views);
  }
  // The best scan step, its cost on all views.
  int best = 0;
  double best_value = std::numeric_limits<double>::infinity();
  const bool subset = scan_views.size() < views.size();
  for (int k : LowestLocalMinima(
           scan_cost, subset ? options.focal_search_scan_candidates : 1)) {
    const double value =
        subset ? cost_at(log_min + k * step, views) : scan_cost[k];
    if (value < best_value) {
      best_value = value;
      best = k;
    }
  }
  double a = log_min + std::max(0, best - 1) * step;
  double b = log_min + std::min(steps - 1, best + 1) * step;
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - ratio * (b - a), d = a + ratio * (b - a);
  double fc = cost_at(c, views), fd = cost_at(d, views);
  for (int it = 0; it < options.focal_search_refine_iterations; ++it) {
    if (fc < fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - ratio * (b - a);
      fc = cost_at(c, views);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + ratio * (b - a);
      fd = cost_at(d, views);
    }
  }
  double log_f = fc < fd ? c : d;
  double value = std::min(fc, fd);
  if (best_value < value) {  // the scan point itself was better
    log_f = log_min + best * step;
    value = best_value;
  }
  // The cost that competes with the other starts: on every corner.
  *best_cost = thinned.empty() ? value : cost_at(log_f, all_views);
  return std::exp(log_f);
}

// Zhang's v_ij vector for columns i, j of a homography.
Eigen::Matrix<double, 6, 1> ZhangV(const Eigen::Matrix3d& h, int i, int j) {
  Eigen::Matrix<double, 6, 1> v;
  v << h(0, i) * h(0, j), h(0, i) * h(1, j) + h(1, i) * h(0, j),
      h(1, i) * h(1, j), h(2, i) * h(0, j) + h(0, i) * h(2, j),
      h(2, i) * h(1, j) + h(1, i) * h(2, j), h(2, i) * h(2, j);
  return v;
}

// Homographies from the board plane to normalised pixel coordinates
// ((u - centre) / scale), one per view that gives one.
std::vector<Eigen::Matrix3d> NormalisedHomographies(
    const std::vector<const CalibrationView*>& views, double cx0, double cy0,
    double scale, const InitializationOptions& options) {
  std::vector<Eigen::Matrix3d> result;
  for (const CalibrationView* view : views) {
    std::vector<Eigen::Vector3d> rays(view->image_points.size());
    for (size_t i = 0; i < rays.size(); ++i) {
      rays[i] = Eigen::Vector3d((view->image_points[i].x() - cx0) / scale,
                                (view->image_points[i].y() - cy0) / scale, 1.0)
                    .normalized();
    }
    Eigen::Matrix3d h;
    if (EstimateBoardToRayHomography(BoardXy(*view), rays, options, &h,
                                     nullptr)) {
      result.push_back(h / h.norm());
    }
  }
  return result;
}

// Zhang's closed form, all five parameters (skew dropped). Normalised units.
bool ZhangFull(const std::vector<Eigen::Matrix3d>& homographies, double* fx,
               double* fy, double* u0, double* v0) {
  if (homographies.size() < 3) return false;
  Eigen::MatrixXd v(2 * homographies.size(), 6);
  for (size_t k = 0; k < homographies.size(); ++k) {
    v.row(2 * k) = ZhangV(homographies[k], 0, 1).transpose();
    v.row(2 * k + 1) =
        (ZhangV(homographies[k], 0, 0) - ZhangV(homographies[k], 1, 1))
            .transpose();
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(v, Eigen::ComputeFullV);
  Eigen::VectorXd b = svd.matrixV().col(5);
  if (b(0) < 0) b = -b;
  const double b11 = b(0), b12 = b(1), b22 = b(2), b13 = b(3), b23 = b(4),
               b33 = b(5);
  const double den = b11 * b22 - b12 * b12;
  if (!(b11 > 0) || !(den > 0)) return false;
  *v0 = (b12 * b13 - b11 * b23) / den;
  const double lambda = b33 - (b13 * b13 + *v0 * (b12 * b13 - b11 * b23)) / b11;
  if (!(lambda / b11 > 0)) return false;
  *fx = std::sqrt(lambda / b11);
  *fy = std::sqrt(lambda * b11 / den);
  const double gamma = -b12 * (*fx) * (*fx) * (*fy) / lambda;
  *u0 = gamma * (*v0) / (*fy) - b13 * (*fx) * (*fx) / lambda;
  return std::isfinite(*fx) && std::isfinite(*fy) && std::isfinite(*u0) &&
         std::isfinite(*v0);
}

// Zhang's closed form with the principal point at the centre and square
// pixels: one unknown f^2, linear least squares. Normalised units.
bool ZhangCentred(const std::vector<Eigen::Matrix3d>& homographies, double* f) {
  double pq = 0, qq = 0;
  for (const Eigen::Matrix3d& h : homographies) {
    // h1' w h2 = 0 and h1' w h1 = h2' w h2 with w = diag(1, 1, f^2).
    const double p1 = h(0, 0) * h(0, 1) + h(1, 0) * h(1, 1);
    const double q1 = h(2, 0) * h(2, 1);
    const double p2 = h(0, 0) * h(0, 0) + h(1, 0) * h(1, 0) -
                      h(0, 1) * h(0, 1) - h(1, 1) * h(1, 1);
    const double q2 = h(2, 0) * h(2, 0) - h(2, 1) * h(2, 1);
    pq += p1 * q1 + p2 * q2;
    qq += q1 * q1 + q2 * q2;
  }
  if (!(qq > 0)) return false;
  const double f2 = -pq / qq;
  if (!(f2 > 0)) return false;
  *f = std::sqrt(f2);
  return std::isfinite(*f);
}

// Pose refinement with fixed intrinsics: robust reprojection error.
template <typename Model>
bool RefinePose(const Camera& camera, const CalibrationView& view,
                const InitializationOptions& options,
                Eigen::Isometry3d* cam_from_board) {
  PoseBlock pose = PoseBlockFromIsometry(*cam_from_board);
  std::vector<double> intrinsics = camera.params;
  ceres::Problem problem;
  for (size_t i = 0; i < view.board_points.size(); ++i) {
    problem.AddResidualBlock(ReprojectionError<Model>::Create(
                                 view.board_points[i], view.image_points[i]),
                             new ceres::HuberLoss(options.pose_refine_loss_px),
                             intrinsics.data(), pose.data());
  }
  problem.SetParameterBlockConstant(intrinsics.data());
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.pose_refine_iterations;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable() ||
      !(summary.final_cost <= summary.initial_cost)) {
    return false;
  }
  *cam_from_board = IsometryFromPoseBlock(pose.data());
  return true;
}

// Joint refinement of the starting intrinsics on a subset of the posed views
// and corners (evenly spread), with only fx, fy, cx, cy and the first two
// radial terms free (the other terms stay at their start, 0): the long walk
// from the distortion-free start, at a fraction of the cost of the full
// problem. `camera` is replaced only when the solve lowers the cost and the
// result is a plausible camera.
template <typename Model>
bool RefineStartOnSubset(const std::vector<const CalibrationView*>& views,
                         const std::vector<Eigen::Isometry3d>& poses,
                         const InitializationOptions& options, Camera* camera,
                         int* iterations) {
  std::vector<double> intrinsics = camera->params;
  std::vector<PoseBlock> blocks(views.size());
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::HuberLoss loss(options.start_refine_loss_px);
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  int residuals = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    blocks[v] = PoseBlockFromIsometry(poses[v]);
    const size_t n = views[v]->board_points.size();
    const size_t take = std::min<size_t>(
        n, static_cast<size_t>(options.start_refine_max_corners_per_view));
    int view_residuals = 0;
    for (size_t k = 0; k < take; ++k) {
      const size_t i = k * n / take;
      // Only corners that project through the start (as in the full solve).
      const Eigen::Vector3d point = poses[v] * views[v]->board_points[i];
      double pixel[2];
      if (!Model::Project(intrinsics.data(), point.data(), pixel)) continue;
      ++view_residuals;
      problem.AddResidualBlock(
          ReprojectionError<Model>::Create(views[v]->board_points[i],
                                           views[v]->image_points[i]),
          &loss, intrinsics.data(), blocks[v].data());
      ++residuals;
    }
    if (view_residuals > 0) ordering->AddElementToGroup(blocks[v].data(), 0);
  }
  if (residuals < Model::kNumParams + 6) return false;
  ordering->AddElementToGroup(intrinsics.data(), 1);
  std::vector<int> fixed;
  for (int k = kDistortionBegin; k < Model::kNumParams; ++k) {
    const bool held = std::find(options.held_distortion_params.begin(),
                                options.held_distortion_params.end(),
                                k) != options.held_distortion_params.end();
    if (k >= kDistortionBegin + 2 || held) fixed.push_back(k);
  }
  if (!fixed.empty()) {
    problem.SetManifold(intrinsics.data(),
                        new ceres::SubsetManifold(Model::kNumParams, fixed));
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering = ordering;
  solver_options.max_num_iterations = options.start_refine_iterations;
  solver_options.function_tolerance = 1e-6;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  *iterations = static_cast<int>(summary.iterations.size());
  if (!summary.IsSolutionUsable() ||
      !(summary.final_cost < summary.initial_cost)) {
    return false;
  }
  for (double value : intrinsics) {
    if (!std::isfinite(value)) return false;
  }
  if (!(intrinsics[0] > 0) || !(intrinsics[1] > 0)) return false;
  camera->params = intrinsics;
  return true;
}

}  // namespace

bool InitializationOptions::Check(std::string* why) const {
  if (num_threads < 1) {
    return Fail("initialization.num_threads must be >= 1", why);
  }
  if (reweight_iterations < 0) {
    return Fail("initialization.reweight_iterations must be >= 0", why);
  }
  if (!(reweight_k > 0))
    return Fail("initialization.reweight_k must be > 0", why);
  if (!(max_focal_aspect >= 1)) {
    return Fail("initialization.max_focal_aspect must be >= 1", why);
  }
  if (!(focal_search_min_ratio > 0) ||
      !(focal_search_max_ratio > focal_search_min_ratio)) {
    return Fail(
        "initialization.focal_search_min_ratio must be > 0 and below "
        "focal_search_max_ratio",
        why);
  }
  if (focal_search_steps < 3) {
    return Fail("initialization.focal_search_steps must be >= 3", why);
  }
  if (focal_search_refine_iterations < 0) {
    return Fail("initialization.focal_search_refine_iterations must be >= 0",
                why);
  }
  if (focal_search_reweight_iterations < 0) {
    return Fail("initialization.focal_search_reweight_iterations must be >= 0",
                why);
  }
  if (!(focal_search_truncation_px > 0)) {
    return Fail("initialization.focal_search_truncation_px must be > 0", why);
  }
  if (focal_search_max_views < 1) {
    return Fail("initialization.focal_search_max_views must be >= 1", why);
  }
  if (focal_search_scan_max_views < 1) {
    return Fail("initialization.focal_search_scan_max_views must be >= 1", why);
  }
  if (focal_search_max_corners_per_view < 8) {
    return Fail("initialization.focal_search_max_corners_per_view must be >= 8",
                why);
  }
  if (focal_search_scan_candidates < 1) {
    return Fail("initialization.focal_search_scan_candidates must be >= 1",
                why);
  }
  if (pose_refine_iterations < 0) {
    return Fail("initialization.pose_refine_iterations must be >= 0", why);
  }
  if (!(pose_refine_loss_px > 0)) {
    return Fail("initialization.pose_refine_loss_px must be > 0", why);
  }
  if (start_refine_iterations < 0) {
    return Fail("initialization.start_refine_iterations must be >= 0", why);
  }
  if (start_refine_max_views < 1) {
    return Fail("initialization.start_refine_max_views must be >= 1", why);
  }
  if (start_refine_max_corners_per_view < 1) {
    return Fail("initialization.start_refine_max_corners_per_view must be >= 1",
                why);
  }
  if (!(start_refine_loss_px > 0)) {
    return Fail("initialization.start_refine_loss_px must be > 0", why);
  }
  if (start_refine_pose_iterations < 0) {
    return Fail("initialization.start_refine_pose_iterations must be >= 0",
                why);
  }
  return true;
}

bool EstimateBoardToRayHomography(const std::vector<Eigen::Vector2d>& board_xy,
                                  const std::vector<Eigen::Vector3d>& rays,
                                  const InitializationOptions& options,
                                  Eigen::Matrix3d* homography,
                                  std::vector<bool>* inlier) {
  const size_t n = board_xy.size();
  if (n < 4 || rays.size() != n) return false;
  std::vector<bool> use(n, false);
  for (size_t i = 0; i < n; ++i) {
    use[i] =
        board_xy[i].allFinite() && rays[i].allFinite() && rays[i].norm() > 0.5;
  }
  if (!PointsSpanPlane(board_xy, use)) return false;
  // Normalise the board coordinates (centroid, mean distance sqrt 2).
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  int count = 0;
  for (size_t i = 0; i < n; ++i) {
    if (use[i]) {
      mean += board_xy[i];
      ++count;
    }
  }
  mean /= count;
  double spread = 0;
  for (size_t i = 0; i < n; ++i) {
    if (use[i]) spread += (board_xy[i] - mean).norm();
  }
  spread /= count;
  const double s = std::sqrt(2.0) / spread;
  Eigen::Matrix3d normalise;
  normalise << s, 0, -s * mean.x(), 0, s, -s * mean.y(), 0, 0, 1;
  std::vector<Eigen::Vector3d> board_norm(n);
  for (size_t i = 0; i < n; ++i) {
    board_norm[i] = normalise * board_xy[i].homogeneous();
  }
  Eigen::Matrix3d h_norm;
  if (!SolveDlt(board_norm, rays, use, &h_norm)) return false;
  std::vector<double> error(n, 0.0);
  for (int round = 0; round < options.reweight_iterations; ++round) {
    double sign_sum = 0;
    for (size_t i = 0; i < n; ++i) {
      if (use[i]) sign_sum += rays[i].dot(h_norm * board_norm[i]);
    }
    if (sign_sum < 0) h_norm = -h_norm;
    std::vector<double> kept_errors;
    for (size_t i = 0; i < n; ++i) {
      error[i] = rays[i].allFinite() && board_xy[i].allFinite()
                     ? AngleBetween(rays[i], h_norm * board_norm[i])
                     : std::numeric_limits<double>::infinity();
      if (use[i]) kept_errors.push_back(error[i]);
    }
    // Floor: exact data must not lose points to rounding.
    const double threshold =
        std::max(options.reweight_k * RobustSigmaAboutZero(kept_errors), 1e-9);
    std::vector<bool> next(n, false);
    for (size_t i = 0; i < n; ++i) next[i] = error[i] <= threshold;
    if (next == use) break;
    if (!PointsSpanPlane(board_xy, next)) break;
    Eigen::Matrix3d h_next;
    if (!SolveDlt(board_norm, rays, next, &h_next)) break;
    use = next;
    h_norm = h_next;
  }
  double sign_sum = 0;
  for (size_t i = 0; i < n; ++i) {
    if (use[i]) sign_sum += rays[i].dot(h_norm * board_norm[i]);
  }
  if (sign_sum < 0) h_norm = -h_norm;
  *homography = h_norm * normalise;
  if (!homography->allFinite()) return false;
  if (inlier != nullptr) *inlier = use;
  return true;
}

bool PoseFromBoardToRayHomography(const Eigen::Matrix3d& homography,
                                  const std::vector<Eigen::Vector2d>& board_xy,
                                  const std::vector<Eigen::Vector3d>& rays,
                                  Eigen::Isometry3d* cam_from_board) {
  Eigen::Matrix3d h = homography;
  double sign_sum = 0;
  for (size_t i = 0; i < board_xy.size(); ++i) {
    if (board_xy[i].allFinite() && rays[i].allFinite()) {
      sign_sum += rays[i].dot(h * board_xy[i].homogeneous());
    }
  }
  if (sign_sum < 0) h = -h;
  const double norm1 = h.col(0).norm(), norm2 = h.col(1).norm();
  if (!(norm1 > 0) || !(norm2 > 0)) return false;
  const double scale = 2.0 / (norm1 + norm2);
  Eigen::Matrix3d r;
  r.col(0) = h.col(0) * scale;
  r.col(1) = h.col(1) * scale;
  r.col(2) = r.col(0).cross(r.col(1));
  // The nearest rotation (polar decomposition).
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) = -u.col(2);
    rotation = u * svd.matrixV().transpose();
  }
  if (!rotation.allFinite()) return false;
  cam_from_board->setIdentity();
  cam_from_board->linear() = rotation;
  cam_from_board->translation() = h.col(2) * scale;
  return cam_from_board->matrix().allFinite();
}

bool EstimateViewPose(const Camera& camera, const CalibrationView& view,
                      const InitializationOptions& options,
                      Eigen::Isometry3d* cam_from_board, std::string* why) {
  if (!PoseFromRays(camera, view, options, cam_from_board, why)) return false;
  if (options.pose_refine_iterations > 0) {
    // A failed refinement keeps the homography pose: it is still a start.
    DispatchCameraModel(camera.model, [&](auto model) {
      return RefinePose<decltype(model)>(camera, view, options, cam_from_board);
    });
  }
  return true;
}

namespace {

// A pose for every used view through `camera` (view_ok, cam_from_board and
// view_reason of `result`).
void PoseAllViews(const Camera& camera,
                  const std::vector<CalibrationView>& views,
                  const std::vector<bool>& use_view,
                  const InitializationOptions& options,
                  InitializationResult* result) {
  result->view_ok.assign(views.size(), false);
  result->cam_from_board.assign(views.size(), Eigen::Isometry3d::Identity());
  result->view_reason.assign(views.size(), "");
  std::vector<char> ok(views.size(), 0);
  ParallelFor(static_cast<int>(views.size()), options.num_threads, [&](int i) {
    if (!use_view[i]) {
      result->view_reason[i] = "not used";
      return;
    }
    std::string view_why;
    // view_ok is a vector<bool>, whose bits share words: the threads write
    // `ok`, copied into it afterwards.
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    if (EstimateViewPose(camera, views[i], options, &pose, &view_why)) {
      result->cam_from_board[i] = pose;
      ok[i] = 1;
    } else {
      result->view_reason[i] = view_why;
    }
  });
  for (size_t i = 0; i < views.size(); ++i) result->view_ok[i] = ok[i] != 0;
}

// A distortion-free starting camera, how it was found, and its fit to the
// search views (ViewFitCost).
struct StartCandidate {
  Camera camera;
  std::string method;
  double cost = 0;
};

// The distortion-free starting cameras: the focal-length search with a
// centred principal point, then Zhang's closed forms (full, and with a
// centred principal point) where they give a plausible camera.
std::vector<StartCandidate> StartingCandidates(
    CameraModelId model, int width, int height,
    const std::vector<const CalibrationView*>& search_views,
    const InitializationOptions& options) {
  std::vector<StartCandidate> candidates(1);
  const double f_search = SearchFocalLength(model, width, height, search_views,
                                            options, &candidates[0].cost);
  candidates[0].camera = CandidateCamera(model, width, height, f_search);
  candidates[0].method =
      "focal-length search (f = " + std::to_string(f_search) +
      " px, centred principal point)";
  const double cx0 = 0.5 * (width - 1), cy0 = 0.5 * (height - 1);
  const double scale = 0.5 * std::max(width, height);
  const std::vector<Eigen::Matrix3d> homographies =
      NormalisedHomographies(search_views, cx0, cy0, scale, options);
  double fx, fy, u0, v0;
  if (ZhangFull(homographies, &fx, &fy, &u0, &v0)) {
    Camera full = CandidateCamera(model, width, height, fx * scale);
    full.params[1] = fy * scale;
    full.params[2] = cx0 + u0 * scale;
    full.params[3] = cy0 + v0 * scale;
    const bool plausible = fx / fy > 1.0 / options.max_focal_aspect &&
                           fx / fy < options.max_focal_aspect &&
                           full.params[2] > 0 && full.params[2] < width &&
                           full.params[3] > 0 && full.params[3] < height;
    if (plausible) {
      candidates.push_back({full, "Zhang closed form",
                            ViewFitCost(full, search_views, options)});
    }
  }
  double f;
  if (ZhangCentred(homographies, &f)) {
    const Camera centred = CandidateCamera(model, width, height, f * scale);
    candidates.push_back({centred, "Zhang closed form, centred principal point",
                          ViewFitCost(centred, search_views, options)});
  }
  return candidates;
}

// The candidate that fits the search views best (the first among equals).
size_t BestCandidate(const std::vector<StartCandidate>& candidates) {
  size_t best = 0;
  for (size_t i = 1; i < candidates.size(); ++i) {
    if (candidates[i].cost < candidates[best].cost) best = i;
  }
  return best;
}

// "k1, k2 free", or which of the two the start refinement holds at 0.
std::string StartRefineFreeTerms(CameraModelId model,
                                 const InitializationOptions& options) {
  const std::vector<std::string> names = CameraModelParamNames(model);
  std::string free, held;
  for (int k = kDistortionBegin;
       k < kDistortionBegin + 2 && k < static_cast<int>(names.size()); ++k) {
    const auto& list = options.held_distortion_params;
    std::string& text =
        std::find(list.begin(), list.end(), k) != list.end() ? held : free;
    text += (text.empty() ? "" : ", ") + names[k];
  }
  if (held.empty()) return free + " free";
  if (free.empty()) return "no distortion term free (" + held + " held at 0)";
  return free + " free (" + held + " held at 0)";
}

// The distortion-free start refined on a subset of the posed views (k1, k2
// free); then every view is posed again through the refined camera, which
// replaces the start when it poses any view.
void RefineStart(const std::vector<CalibrationView>& views,
                 const std::vector<bool>& use_view, CameraModelId model,
                 const InitializationOptions& options, Camera* camera,
                 InitializationResult* result) {
  std::vector<const CalibrationView*> posed;
  std::vector<Eigen::Isometry3d> posed_poses;
  for (size_t i = 0; i < views.size(); ++i) {
    if (result->view_ok[i]) {
      posed.push_back(&views[i]);
      posed_poses.push_back(result->cam_from_board[i]);
    }
  }
  std::vector<const CalibrationView*> subset;
  std::vector<Eigen::Isometry3d> subset_poses;
  for (size_t i :
       EvenlySpreadIndices(posed.size(), options.start_refine_max_views)) {
    subset.push_back(posed[i]);
    subset_poses.push_back(posed_poses[i]);
  }
  Camera refined = *camera;
  int iterations = 0;
  const bool improved = DispatchCameraModel(model, [&](auto m) {
    return RefineStartOnSubset<decltype(m)>(subset, subset_poses, options,
                                            &refined, &iterations);
  });
  result->start_refine_iterations = iterations;
  if (!improved) return;
  InitializationOptions pose_options = options;
  pose_options.pose_refine_iterations = std::max(
      options.pose_refine_iterations, options.start_refine_pose_iterations);
  InitializationResult refined_result;
  PoseAllViews(refined, views, use_view, pose_options, &refined_result);
  if (std::count(refined_result.view_ok.begin(), refined_result.view_ok.end(),
                 true) == 0) {
    return;
  }
  *camera = refined;
  result->view_ok = refined_result.view_ok;
  result->cam_from_board = refined_result.cam_from_board;
  result->view_reason = refined_result.view_reason;
  result->start_refined = true;
  result->method += ", refined on " + std::to_string(subset.size()) +
                    " views with " + StartRefineFreeTerms(model, options);
}

// The start: the candidates of StartingCandidates, posed and refined
// (RefineStart). A pinhole model's candidates compete before refining: a
// distortion-free pinhole is already the model near the axis. A fisheye
// model's compete only after it (without refining, the search's start is
// taken): without distortion the search's truncated cost
// can prefer a false basin on a narrow lens (steep views of a 70 deg lens
// gave f = 139 px for 457), so each candidate is refined with k1, k2 free
// and the best fit to the search views wins.
void StartFromCandidates(
    const std::vector<CalibrationView>& views,
    const std::vector<bool>& use_view, CameraModelId model, int width,
    int height, const std::vector<const CalibrationView*>& search_views,
    const InitializationOptions& options, Camera* camera,
    InitializationResult* result) {
  std::vector<StartCandidate> candidates =
      StartingCandidates(model, width, height, search_views, options);
  const bool refine = options.start_refine_iterations > 0;
  const bool pinhole = CameraModelIsPinhole(model);
  if (pinhole || !refine || candidates.size() == 1) {
    // Unrefined, a fisheye model's start is the search's own.
    const StartCandidate& best =
        candidates[pinhole ? BestCandidate(candidates) : 0];
    *camera = best.camera;
    result->method = best.method;
    PoseAllViews(*camera, views, use_view, options, result);
    if (refine) RefineStart(views, use_view, model, options, camera, result);
    return;
  }
  std::vector<InitializationResult> starts(candidates.size());
  for (size_t i = 0; i < candidates.size(); ++i) {
    starts[i].method = candidates[i].method;
    PoseAllViews(candidates[i].camera, views, use_view, options, &starts[i]);
    RefineStart(views, use_view, model, options, &candidates[i].camera,
                &starts[i]);
    candidates[i].cost =
        ViewFitCost(candidates[i].camera, search_views, options);
  }
  const size_t best = BestCandidate(candidates);
  *camera = candidates[best].camera;
  *result = std::move(starts[best]);
}

// The largest angle between the board normals of two posed views (radians);
// false when no view is posed.
bool OrientationSpread(const InitializationResult& result, double* spread) {
  std::vector<Eigen::Vector3d> normals;
  for (size_t i = 0; i < result.view_ok.size(); ++i) {
    if (result.view_ok[i]) {
      normals.push_back(result.cam_from_board[i].linear().col(2));
    }
  }
  if (normals.empty()) return false;
  *spread = 0;
  for (size_t i = 0; i < normals.size(); ++i) {
    for (size_t j = i + 1; j < normals.size(); ++j) {
      *spread = std::max(*spread, AngleBetween(normals[i], normals[j]));
    }
  }
  return true;
}

}  // namespace

bool InitializeCalibration(const std::vector<CalibrationView>& views,
                           const std::vector<bool>& use_view,
                           CameraModelId model, int width, int height,
                           const std::vector<double>& initial_params,
                           const InitializationOptions& options,
                           InitializationResult* result, std::string* error) {
  std::string why;
  if (!options.Check(&why)) return Fail(why, error);
  if (width <= 0 || height <= 0) {
    return Fail("image size must be positive", error);
  }
  if (use_view.size() != views.size()) {
    return Fail("use_view must have one entry per view", error);
  }
  *result = InitializationResult();
  std::vector<const CalibrationView*> used;
  for (size_t i = 0; i < views.size(); ++i) {
    if (use_view[i]) used.push_back(&views[i]);
  }
  if (used.empty()) return Fail("no views to initialise from", error);

  Camera camera;
  if (!initial_params.empty()) {
    if (static_cast<int>(initial_params.size()) !=
        CameraModelNumParams(model)) {
      return Fail(
          "initial parameters: " + std::to_string(initial_params.size()) +
              " values given, model " + CameraModelName(model) + " has " +
              std::to_string(CameraModelNumParams(model)),
          error);
    }
    camera.model = model;
    camera.width = width;
    camera.height = height;
    camera.params = initial_params;
    result->method = "given by the caller";
    PoseAllViews(camera, views, use_view, options, result);
  } else {
    StartFromCandidates(views, use_view, model, width, height,
                        SpreadSubset(used, options.focal_search_max_views),
                        options, &camera, result);
  }
  result->camera = camera;
  double spread = 0;
  if (!OrientationSpread(*result, &spread)) {
    return Fail("no view gives a pose with the initial intrinsics (" +
                    result->method + ")",
                error);
  }
  result->orientation_spread_deg = spread * 180.0 / M_PI;
  return true;
}

}  // namespace puzzlecal
