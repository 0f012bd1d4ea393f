#include "calib/calibrate.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "calib/reprojection_error.h"

namespace puzzlecal {
namespace {

using Pose = std::array<double, kPoseBlockSize>;

bool Fail(const std::string& message, std::string* error) {
  if (error != nullptr) *error = message;
  return false;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

Pose PoseFromIsometry(const Eigen::Isometry3d& cam_from_board) {
  Pose pose;
  const Eigen::Matrix3d rotation = cam_from_board.linear();
  ceres::RotationMatrixToAngleAxis(
      ceres::ColumnMajorAdapter3x3(rotation.data()), pose.data());
  for (int k = 0; k < 3; ++k) pose[3 + k] = cam_from_board.translation()(k);
  return pose;
}

Eigen::Isometry3d IsometryFromPose(const Pose& pose) {
  Eigen::Matrix3d rotation;
  ceres::AngleAxisToRotationMatrix(
      pose.data(), ceres::ColumnMajorAdapter3x3(rotation.data()));
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.linear() = rotation;
  result.translation() = Eigen::Vector3d(pose[3], pose[4], pose[5]);
  return result;
}

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

// The state the solves share.
struct Problem {
  const std::vector<CalibrationView>* views = nullptr;
  CameraModelId model = CameraModelId::kPinholeRadtan;
  std::vector<double> params;
  std::vector<Pose> poses;
  std::vector<bool> view_used;
  std::vector<std::vector<bool>> valid;   // finite input, usable at all
  std::vector<std::vector<bool>> inlier;  // currently in the problem
};

// Pixel error of one correspondence with the current state; false when the
// point cannot be projected.
bool Residual(const Problem& problem, size_t v, size_t i,
              Eigen::Vector2d* residual) {
  const CalibrationView& view = (*problem.views)[v];
  const Eigen::Isometry3d pose = IsometryFromPose(problem.poses[v]);
  Eigen::Vector2d pixel;
  if (!ProjectPoint(problem.model, problem.params.data(),
                    pose * view.board_points[i], &pixel)) {
    return false;
  }
  *residual = pixel - view.image_points[i];
  return residual->allFinite();
}

struct SolveOutcome {
  ceres::Solver::Summary summary;
  std::unique_ptr<ceres::Problem> problem;  // kept for the covariance
};

// One Levenberg-Marquardt solve over the current inliers; `fixed[k]` holds
// parameter k.
template <typename Model>
void Solve(Problem* state, const std::vector<bool>& fixed,
           const CalibrationOptions& options,
           std::unique_ptr<ceres::LossFunction>* loss, SolveOutcome* outcome) {
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  outcome->problem = std::make_unique<ceres::Problem>(problem_options);
  ceres::Problem& problem = *outcome->problem;
  loss->reset();
  if (options.loss == RobustLoss::kHuber) {
    loss->reset(new ceres::HuberLoss(options.loss_scale_px));
  } else if (options.loss == RobustLoss::kCauchy) {
    loss->reset(new ceres::CauchyLoss(options.loss_scale_px));
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  int num_residuals = 0;
  for (size_t v = 0; v < state->views->size(); ++v) {
    if (!state->view_used[v]) continue;
    const CalibrationView& view = (*state->views)[v];
    int view_residuals = 0;
    for (size_t i = 0; i < view.board_points.size(); ++i) {
      if (!state->inlier[v][i]) continue;
      problem.AddResidualBlock(ReprojectionError<Model>::Create(
                                   view.board_points[i], view.image_points[i]),
                               loss->get(), state->params.data(),
                               state->poses[v].data());
      ++view_residuals;
    }
    // Only blocks the problem holds may be named in the ordering.
    if (view_residuals > 0) {
      ordering->AddElementToGroup(state->poses[v].data(), 0);
    }
    num_residuals += view_residuals;
  }
  if (num_residuals == 0) {
    // Nothing to fit (and no intrinsics block to hold fixed): report a
    // failed solve instead of handing Ceres an empty problem.
    outcome->summary = ceres::Solver::Summary();
    outcome->summary.message = "no corners left to fit";
    return;
  }
  ordering->AddElementToGroup(state->params.data(), 1);
  std::vector<int> fixed_indices;
  for (int k = 0; k < Model::kNumParams; ++k) {
    if (fixed[k]) fixed_indices.push_back(k);
  }
  if (static_cast<int>(fixed_indices.size()) == Model::kNumParams) {
    problem.SetParameterBlockConstant(state->params.data());
  } else if (!fixed_indices.empty()) {
    problem.SetManifold(
        state->params.data(),
        new ceres::SubsetManifold(Model::kNumParams, fixed_indices));
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering = ordering;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.num_threads = options.deterministic ? 1 : options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solve(solver_options, &problem, &outcome->summary);
}

// Largest angle between the board normals of two used views, degrees.
double OrientationSpreadDeg(const std::vector<Eigen::Isometry3d>& poses,
                            const std::vector<bool>& used) {
  double spread = 0;
  for (size_t i = 0; i < poses.size(); ++i) {
    if (!used[i]) continue;
    const Eigen::Vector3d a = poses[i].linear().col(2);
    for (size_t j = i + 1; j < poses.size(); ++j) {
      if (!used[j]) continue;
      const Eigen::Vector3d b = poses[j].linear().col(2);
      spread = std::max(spread, std::atan2(a.cross(b).norm(), a.dot(b)));
    }
  }
  return spread * 180.0 / M_PI;
}

// Covariance of the intrinsics with the poses marginalised out, from the
// Jacobian at the solution: inverse of the Schur complement
// S = A - sum_v B_v C_v^-1 B_v' of J'J (A: intrinsics, C_v: pose v). Summed
// in a fixed order, so the result does not depend on threads. Fixed
// parameters get zero rows and columns. False when S is singular.
template <int kNumParams>
bool MarginalCovariance(ceres::Problem* problem, const Problem* state,
                        const std::vector<bool>& fixed,
                        double min_eigenvalue_ratio,
                        Eigen::Matrix<double, kNumParams, kNumParams>* cov) {
  std::vector<int> free_index;
  for (int k = 0; k < kNumParams; ++k) {
    if (!fixed[k]) free_index.push_back(k);
  }
  const int n = static_cast<int>(free_index.size());
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks.push_back(
      const_cast<double*>(state->params.data()));
  for (size_t v = 0; v < state->poses.size(); ++v) {
    if (!state->view_used[v]) continue;
    evaluate.parameter_blocks.push_back(
        const_cast<double*>(state->poses[v].data()));
  }
  evaluate.num_threads = 1;
  ceres::CRSMatrix jacobian;
  if (!problem->Evaluate(evaluate, nullptr, nullptr, nullptr, &jacobian)) {
    return false;
  }
  const int num_poses = static_cast<int>(evaluate.parameter_blocks.size()) - 1;
  if (jacobian.num_cols != n + kPoseBlockSize * num_poses) return false;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::MatrixXd> b(num_poses, Eigen::MatrixXd::Zero(n, 6));
  std::vector<Eigen::Matrix<double, 6, 6>> c(
      num_poses, Eigen::Matrix<double, 6, 6>::Zero());
  Eigen::VectorXd j_int(n);
  Eigen::Matrix<double, 6, 1> j_pose;
  for (int row = 0; row < jacobian.num_rows; ++row) {
    j_int.setZero();
    j_pose.setZero();
    int pose = -1;
    for (int e = jacobian.rows[row]; e < jacobian.rows[row + 1]; ++e) {
      const int col = jacobian.cols[e];
      if (col < n) {
        j_int(col) = jacobian.values[e];
      } else {
        pose = (col - n) / kPoseBlockSize;
        j_pose((col - n) % kPoseBlockSize) = jacobian.values[e];
      }
    }
    a.noalias() += j_int * j_int.transpose();
    if (pose >= 0) {
      b[pose].noalias() += j_int * j_pose.transpose();
      c[pose].noalias() += j_pose * j_pose.transpose();
    }
  }
  for (int v = 0; v < num_poses; ++v) {
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(c[v]);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) {
      return false;
    }
    a.noalias() -= b[v] * ldlt.solve(b[v].transpose());
  }
  // S is symmetric positive definite unless the intrinsics are
  // undetermined; refuse to invert a (numerically) singular S.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::VectorXd values = eig.eigenvalues();
  if (!(values(0) > min_eigenvalue_ratio * values(n - 1))) return false;
  const Eigen::MatrixXd inverse = eig.eigenvectors() *
                                  values.cwiseInverse().asDiagonal() *
                                  eig.eigenvectors().transpose();
  cov->setZero();
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      (*cov)(free_index[i], free_index[j]) = inverse(i, j);
    }
  }
  return true;
}

// Fraction of coverage-grid cells that hold at least one corner.
double Coverage(const std::vector<CalibrationView>& views,
                const std::vector<bool>& view_used,
                const std::vector<std::vector<bool>>& valid, int width,
                int height, int grid) {
  std::vector<bool> cell(grid * grid, false);
  for (size_t v = 0; v < views.size(); ++v) {
    if (!view_used[v]) continue;
    for (size_t i = 0; i < views[v].image_points.size(); ++i) {
      if (!valid[v][i]) continue;
      const Eigen::Vector2d& p = views[v].image_points[i];
      const int cx = static_cast<int>((p.x() + 0.5) * grid / width);
      const int cy = static_cast<int>((p.y() + 0.5) * grid / height);
      if (cx >= 0 && cx < grid && cy >= 0 && cy < grid) {
        cell[cy * grid + cx] = true;
      }
    }
  }
  return static_cast<double>(std::count(cell.begin(), cell.end(), true)) /
         (grid * grid);
}

template <typename Model>
bool CalibrateModel(const std::vector<CalibrationView>& views, int width,
                    int height, const CalibrationOptions& options,
                    CalibrationResult* result, std::string* error) {
  constexpr int kNumParams = Model::kNumParams;
  const CameraModelId model = Model::kId;
  const auto start = std::chrono::steady_clock::now();
  Problem state;
  state.views = &views;
  state.model = model;
  state.view_used.assign(views.size(), false);
  state.valid.resize(views.size());
  result->view_reason.assign(views.size(), "");

  // Input checks, per view.
  int usable = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    const CalibrationView& view = views[v];
    const size_t n = view.board_points.size();
    state.valid[v].assign(n, false);
    if (view.image_points.size() != n) {
      result->view_reason[v] = std::to_string(n) + " board points but " +
                               std::to_string(view.image_points.size()) +
                               " image points";
      state.valid[v].assign(std::max(n, view.image_points.size()), false);
      continue;
    }
    double extent = 0;
    bool planar = true;
    for (size_t i = 0; i < n; ++i) {
      if (view.board_points[i].allFinite()) {
        extent = std::max(extent, view.board_points[i].head<2>().norm());
      }
    }
    int good = 0;
    for (size_t i = 0; i < n; ++i) {
      const bool finite =
          view.board_points[i].allFinite() && view.image_points[i].allFinite();
      if (finite && std::abs(view.board_points[i].z()) > 1e-9 * (1 + extent)) {
        planar = false;
      }
      state.valid[v][i] = finite;
      good += finite ? 1 : 0;
    }
    if (!planar) {
      result->view_reason[v] = "board points are not on the plane z = 0";
      continue;
    }
    if (good < options.min_corners_per_view) {
      result->view_reason[v] =
          "only " + std::to_string(good) + " corners (need " +
          std::to_string(options.min_corners_per_view) + ")";
      continue;
    }
    state.view_used[v] = true;
    ++usable;
  }
  auto too_few_views = [&](int count) {
    return Fail("only " + std::to_string(count) + " usable view" +
                    (count == 1 ? "" : "s") + " (need at least " +
                    std::to_string(options.min_views) +
                    "): add views of the board at different positions and "
                    "tilted by 30 degrees or more",
                error);
  };
  if (usable < options.min_views) return too_few_views(usable);

  result->coverage = Coverage(views, state.view_used, state.valid, width,
                              height, options.coverage_grid);
  if (result->coverage < options.min_coverage) {
    return Fail("the corners cover only " +
                    Format("%.0f", 100 * result->coverage) +
                    " % of the image (need " +
                    Format("%.0f", 100 * options.min_coverage) +
                    " %): the views are all at one spot; move the board "
                    "towards the corners and borders of the image",
                error);
  }

  // Initialisation on the finite correspondences only.
  std::vector<CalibrationView> clean(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    if (!state.view_used[v]) continue;
    clean[v].name = views[v].name;
    for (size_t i = 0; i < views[v].board_points.size(); ++i) {
      if (state.valid[v][i]) {
        clean[v].board_points.push_back(views[v].board_points[i]);
        clean[v].image_points.push_back(views[v].image_points[i]);
      }
    }
  }
  InitializationResult init;
  std::string why;
  if (!InitializeCalibration(clean, state.view_used, model, width, height,
                             options.initial_params, options.initialization,
                             &init, &why)) {
    return Fail("initialisation failed: " + why, error);
  }
  result->initialization_method = init.method;
  result->orientation_spread_deg = init.orientation_spread_deg;
  result->initialization_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  state.params = init.camera.params;
  state.poses.assign(views.size(), Pose{});
  usable = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    if (!state.view_used[v]) continue;
    if (!init.view_ok[v]) {
      state.view_used[v] = false;
      result->view_reason[v] = "no initial pose: " + init.view_reason[v];
      continue;
    }
    state.poses[v] = PoseFromIsometry(init.cam_from_board[v]);
    ++usable;
  }
  if (usable < options.min_views) return too_few_views(usable);
  auto parallel_views = [&](double spread_deg) {
    return Fail(
        "all views show the board at nearly the same orientation "
        "(largest angle between board normals " +
            Format("%.1f", spread_deg) + " degrees, need " +
            Format("%.1f", options.min_orientation_spread_deg) +
            "), so the focal length is undetermined: add views with "
            "the board tilted by 30 degrees or more",
        error);
  };
  if (result->orientation_spread_deg < options.min_orientation_spread_deg) {
    return parallel_views(result->orientation_spread_deg);
  }

  // Fixed parameters.
  std::vector<bool> fixed(kNumParams, false);
  const std::vector<std::string> names = CameraModelParamNames(model);
  for (int k = 0; k < kNumParams; ++k) {
    if (k < kPrincipalPointBegin)
      fixed[k] = options.fix_focal_length;
    else if (k < kDistortionBegin)
      fixed[k] = options.fix_principal_point;
    else
      fixed[k] = options.fix_distortion;
    if (std::find(options.fixed_params.begin(), options.fixed_params.end(),
                  names[k]) != options.fixed_params.end()) {
      fixed[k] = true;
    }
  }

  // Correspondences that project at all start as inliers.
  state.inlier = state.valid;
  for (size_t v = 0; v < views.size(); ++v) {
    if (!state.view_used[v]) {
      std::fill(state.inlier[v].begin(), state.inlier[v].end(), false);
      continue;
    }
    int projecting = 0;
    for (size_t i = 0; i < state.inlier[v].size(); ++i) {
      Eigen::Vector2d r;
      if (state.inlier[v][i] && !Residual(state, v, i, &r)) {
        state.inlier[v][i] = false;
      }
      projecting += state.inlier[v][i] ? 1 : 0;
    }
    if (projecting < options.min_corners_per_view) {
      state.view_used[v] = false;
      std::fill(state.inlier[v].begin(), state.inlier[v].end(), false);
      result->view_reason[v] =
          "only " + std::to_string(projecting) +
          " corners project through the initial camera (need " +
          std::to_string(options.min_corners_per_view) + ")";
      --usable;
    }
  }
  if (usable < options.min_views) return too_few_views(usable);

  std::unique_ptr<ceres::LossFunction> loss;
  SolveOutcome outcome;
  int iterations = 0;
  if (options.staged_distortion && !options.fix_distortion) {
    std::vector<bool> staged = fixed;
    for (int k = kDistortionBegin; k < kNumParams; ++k) staged[k] = true;
    Solve<Model>(&state, staged, options, &loss, &outcome);
    iterations += outcome.summary.iterations.size();
    if (!outcome.summary.IsSolutionUsable()) {
      return Fail("the first solve (distortion held at zero) failed: " +
                      outcome.summary.message,
                  error);
    }
  }
  Solve<Model>(&state, fixed, options, &loss, &outcome);
  iterations += outcome.summary.iterations.size();

  // k-sigma outlier rejection.
  int rounds = 0;
  std::vector<std::vector<Eigen::Vector2d>> residuals(views.size());
  auto compute_residuals = [&](std::vector<std::vector<bool>>* projects) {
    projects->resize(views.size());
    for (size_t v = 0; v < views.size(); ++v) {
      residuals[v].assign(state.view_used[v] ? views[v].board_points.size() : 0,
                          Eigen::Vector2d::Zero());
      (*projects)[v].assign(residuals[v].size(), false);
      for (size_t i = 0; i < residuals[v].size(); ++i) {
        if (!state.valid[v][i]) continue;
        Eigen::Vector2d r;
        if (Residual(state, v, i, &r)) {
          residuals[v][i] = r;
          (*projects)[v][i] = true;
        } else {
          residuals[v][i].setConstant(std::numeric_limits<double>::quiet_NaN());
        }
      }
    }
  };
  std::vector<std::vector<bool>> projects;
  compute_residuals(&projects);
  while (options.outlier_k > 0 && rounds < options.outlier_iterations &&
         outcome.summary.IsSolutionUsable()) {
    // sigma from every corner of the used views, not only the current
    // inliers: the median is robust to the outliers already, and a sigma of
    // the inliers alone shrinks with every round and trims good corners.
    std::vector<double> magnitudes;
    for (size_t v = 0; v < views.size(); ++v) {
      if (!state.view_used[v]) continue;
      for (size_t i = 0; i < residuals[v].size(); ++i) {
        if (projects[v][i]) {
          magnitudes.push_back(std::abs(residuals[v][i].x()));
          magnitudes.push_back(std::abs(residuals[v][i].y()));
        }
      }
    }
    const double sigma = 1.4826 * Median(magnitudes);
    const double threshold =
        std::max(options.outlier_k * sigma, options.min_outlier_threshold_px);
    std::vector<std::vector<bool>> next = state.inlier;
    bool changed = false;
    for (size_t v = 0; v < views.size(); ++v) {
      if (!state.view_used[v]) continue;
      for (size_t i = 0; i < residuals[v].size(); ++i) {
        next[v][i] = projects[v][i] && residuals[v][i].norm() <= threshold;
        changed |= next[v][i] != state.inlier[v][i];
      }
    }
    if (!changed) break;
    state.inlier = next;
    // A view left with too few corners has no trustworthy pose.
    for (size_t v = 0; v < views.size(); ++v) {
      if (!state.view_used[v]) continue;
      const int kept =
          std::count(state.inlier[v].begin(), state.inlier[v].end(), true);
      if (kept < options.min_corners_per_view) {
        state.view_used[v] = false;
        std::fill(state.inlier[v].begin(), state.inlier[v].end(), false);
        result->view_reason[v] = "only " + std::to_string(kept) +
                                 " corners left after outlier rejection";
      }
    }
    ++rounds;
    Solve<Model>(&state, fixed, options, &loss, &outcome);
    iterations += outcome.summary.iterations.size();
    compute_residuals(&projects);
  }

  // Fill the result.
  result->camera.model = model;
  result->camera.width = width;
  result->camera.height = height;
  result->camera.params = state.params;
  result->view_used = state.view_used;
  result->cam_from_board.assign(views.size(), Eigen::Isometry3d::Identity());
  result->residuals = residuals;
  result->inlier = state.inlier;
  result->view_rms_px.assign(views.size(), 0.0);
  result->param_fixed = fixed;
  result->outlier_rounds = rounds;
  result->iterations = iterations;
  result->termination = outcome.summary.message;
  double sum2 = 0;
  int corners = 0, outliers = 0, used = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    if (!state.view_used[v]) continue;
    ++used;
    result->cam_from_board[v] = IsometryFromPose(state.poses[v]);
    double view_sum2 = 0;
    int view_corners = 0;
    for (size_t i = 0; i < residuals[v].size(); ++i) {
      if (state.inlier[v][i]) {
        view_sum2 += residuals[v][i].squaredNorm();
        ++view_corners;
      } else if (state.valid[v][i]) {
        ++outliers;
      }
    }
    sum2 += view_sum2;
    corners += view_corners;
    result->view_rms_px[v] =
        view_corners > 0 ? std::sqrt(view_sum2 / (2.0 * view_corners)) : 0.0;
  }
  result->num_views_used = used;
  result->num_corners_used = corners;
  // The initial poses come from rough intrinsics; judge the orientations
  // again with the final ones.
  result->orientation_spread_deg =
      OrientationSpreadDeg(result->cam_from_board, state.view_used);
  result->num_outliers = outliers;
  result->rms_px = corners > 0 ? std::sqrt(sum2 / (2.0 * corners)) : 0.0;
  result->rms_point_px = corners > 0 ? std::sqrt(sum2 / corners) : 0.0;

  // Covariance of the intrinsics, scaled by the residual variance.
  int free_params = kPoseBlockSize * used;
  for (int k = 0; k < kNumParams; ++k) free_params += fixed[k] ? 0 : 1;
  result->param_stddev.assign(kNumParams, 0.0);
  result->covariance = Eigen::MatrixXd::Zero(kNumParams, kNumParams);
  const bool any_free =
      std::find(fixed.begin(), fixed.end(), false) != fixed.end();
  if (options.compute_covariance && any_free && outcome.problem &&
      2 * corners > free_params && outcome.summary.IsSolutionUsable()) {
    Eigen::Matrix<double, kNumParams, kNumParams> block;
    bool ok;
    if (options.deterministic) {
      ok = MarginalCovariance(outcome.problem.get(), &state, fixed,
                              options.covariance_min_eigenvalue_ratio, &block);
    } else {
      // ceres::Covariance (SuiteSparseQR) may thread internally, which
      // changes the last bits from run to run.
      ceres::Covariance::Options covariance_options;
      covariance_options.num_threads = options.num_threads;
      ceres::Covariance covariance(covariance_options);
      std::vector<std::pair<const double*, const double*>> blocks = {
          {state.params.data(), state.params.data()}};
      Eigen::Matrix<double, kNumParams, kNumParams, Eigen::RowMajor> row_major;
      ok = covariance.Compute(blocks, outcome.problem.get()) &&
           covariance.GetCovarianceBlock(state.params.data(),
                                         state.params.data(), row_major.data());
      block = row_major;
    }
    if (ok) {
      const double variance = sum2 / (2.0 * corners - free_params);
      result->covariance = block * variance;
      for (int k = 0; k < kNumParams; ++k) {
        result->param_stddev[k] =
            std::sqrt(std::max(0.0, result->covariance(k, k)));
      }
      result->covariance_ok = true;
    }
  }
  result->solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();

  // Report.
  std::ostringstream report;
  report << "model: " << CameraModelName(model) << ", image " << width << "x"
         << height << "\n";
  report << "initialisation: " << result->initialization_method << "\n";
  for (int k = 0; k < kNumParams; ++k) {
    report << "  " << names[k] << " = " << Format("%.10g", state.params[k]);
    if (fixed[k]) {
      report << " (fixed)";
    } else if (result->covariance_ok) {
      report << " +- " << Format("%.3g", result->param_stddev[k]);
    }
    report << "\n";
  }
  if (options.compute_covariance && any_free && !result->covariance_ok) {
    report << "covariance: not available (the problem is rank deficient; "
              "some parameters are not determined by these views)\n";
  }
  report << "rms: " << Format("%.4f", result->rms_px) << " px per coordinate ("
         << Format("%.4f", result->rms_point_px) << " px per corner)\n";
  report << "views used: " << used << " of " << views.size()
         << ", corners used: " << corners << ", outliers rejected: " << outliers
         << " (" << rounds << " rejection rounds)\n";
  report << "coverage: " << Format("%.0f", 100 * result->coverage)
         << " % of the image, board orientation spread "
         << Format("%.1f", result->orientation_spread_deg) << " degrees\n";
  report << "solver: " << iterations << " iterations, "
         << Format("%.3f", result->solve_seconds) << " s, "
         << outcome.summary.message << "\n";
  for (size_t v = 0; v < views.size(); ++v) {
    if (!result->view_reason[v].empty()) {
      report << "view " << v << " (" << views[v].name
             << ") not used: " << result->view_reason[v] << "\n";
    }
  }
  result->report = report.str();

  if (!outcome.summary.IsSolutionUsable()) {
    return Fail("the bundle adjustment failed: " + outcome.summary.message,
                error);
  }
  if (outcome.summary.termination_type == ceres::NO_CONVERGENCE) {
    return Fail("the bundle adjustment did not converge within " +
                    std::to_string(options.max_iterations) +
                    " iterations: raise the iteration limit or check the "
                    "correspondences (RMS " +
                    Format("%.3f", result->rms_px) + " px)",
                error);
  }
  if (used < options.min_views) return too_few_views(used);
  if (result->orientation_spread_deg < options.min_orientation_spread_deg) {
    return parallel_views(result->orientation_spread_deg);
  }
  // Both focal lengths (indices 0 and 1: fx, fy in every model) must be
  // determined unless held fixed.
  for (int k = 0; k < 2; ++k) {
    if (result->covariance_ok && !fixed[k] &&
        !(result->param_stddev[k] <=
          options.max_focal_relative_stddev * std::abs(state.params[k]))) {
      return Fail("the views do not determine the focal length (" + names[k] +
                      " = " + Format("%.1f", state.params[k]) + " +- " +
                      Format("%.3g", result->param_stddev[k]) +
                      " px): add views with the board tilted by 30 degrees "
                      "or more, near the image borders too",
                  error);
    }
  }
  if (!(result->rms_px <= options.max_rms_px)) {
    return Fail("the reprojection RMS is " + Format("%.2f", result->rms_px) +
                    " px (limit " + Format("%.2f", options.max_rms_px) +
                    " px): the correspondences do not fit the " +
                    CameraModelName(model) +
                    " model; check the board definition and the model",
                error);
  }
  return true;
}

// A non-central model without initial_params starts from the central
// calibration of its far-field model (kannala-brandt for
// kannala-brandt-noncentral) with the pupil shift at 0: `options` gets
// initial_params from it, and `method` says so. Unchanged (and `method`
// empty) for central models and given initial_params.
bool StartFromFarFieldModel(const std::vector<CalibrationView>& views,
                            CameraModelId model, int width, int height,
                            CalibrationOptions* options, std::string* method,
                            std::string* error) {
  if (CameraModelIsCentral(model) || !options->initial_params.empty()) {
    return true;
  }
  Camera far;
  far.model = model;
  far.params.assign(CameraModelNumParams(model), 0.0);
  far = FarFieldCamera(far);
  const std::vector<std::string> far_names = CameraModelParamNames(far.model);
  CalibrationOptions central = *options;
  central.compute_covariance = false;
  central.fixed_params.clear();
  for (const std::string& name : options->fixed_params) {
    if (std::find(far_names.begin(), far_names.end(), name) !=
        far_names.end()) {
      central.fixed_params.push_back(name);
    }
  }
  CalibrationResult result;
  std::string why;
  if (!Calibrate(views, far.model, width, height, central, &result, &why)) {
    return Fail(std::string("the central ") + CameraModelName(far.model) +
                    " calibration that starts " + CameraModelName(model) +
                    " failed: " + why,
                error);
  }
  options->initial_params = result.camera.params;
  options->initial_params.resize(CameraModelNumParams(model), 0.0);
  *method = std::string("the central ") + CameraModelName(far.model) +
            " calibration (RMS " + Format("%.3f", result.rms_px) +
            " px), pupil shift 0";
  return true;
}

}  // namespace

const char* RobustLossName(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::kNone:
      return "none";
    case RobustLoss::kHuber:
      return "huber";
    case RobustLoss::kCauchy:
      return "cauchy";
  }
  return "none";
}

bool RobustLossFromName(const std::string& name, RobustLoss* loss) {
  for (RobustLoss candidate :
       {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy}) {
    if (name == RobustLossName(candidate)) {
      *loss = candidate;
      return true;
    }
  }
  return false;
}

bool CalibrationOptions::Check(std::string* why) const {
  if (!(loss_scale_px > 0)) return Fail("loss_scale_px must be > 0", why);
  if (!(outlier_k >= 0)) return Fail("outlier_k must be >= 0", why);
  if (outlier_iterations < 0) {
    return Fail("outlier_iterations must be >= 0", why);
  }
  if (max_iterations < 1) return Fail("max_iterations must be >= 1", why);
  if (!(function_tolerance > 0)) {
    return Fail("function_tolerance must be > 0", why);
  }
  if (!(gradient_tolerance > 0)) {
    return Fail("gradient_tolerance must be > 0", why);
  }
  if (!(parameter_tolerance > 0)) {
    return Fail("parameter_tolerance must be > 0", why);
  }
  if (!(covariance_min_eigenvalue_ratio > 0)) {
    return Fail("covariance_min_eigenvalue_ratio must be > 0", why);
  }
  if (!(min_outlier_threshold_px >= 0)) {
    return Fail("min_outlier_threshold_px must be >= 0", why);
  }
  if (num_threads < 1) return Fail("num_threads must be >= 1", why);
  if (min_corners_per_view < 4) {
    return Fail("min_corners_per_view must be >= 4", why);
  }
  if (min_views < 1) return Fail("min_views must be >= 1", why);
  if (!(min_orientation_spread_deg >= 0)) {
    return Fail("min_orientation_spread_deg must be >= 0", why);
  }
  if (!(min_coverage >= 0 && min_coverage <= 1)) {
    return Fail("min_coverage must be in [0, 1]", why);
  }
  if (coverage_grid < 1) return Fail("coverage_grid must be >= 1", why);
  if (!(max_focal_relative_stddev > 0)) {
    return Fail("max_focal_relative_stddev must be > 0", why);
  }
  if (!(max_rms_px > 0)) return Fail("max_rms_px must be > 0", why);
  return initialization.Check(why);
}

bool Calibrate(const std::vector<CalibrationView>& views, CameraModelId model,
               int width, int height, const CalibrationOptions& options,
               CalibrationResult* result, std::string* error) {
  // Per-view fields are sized to the input from the start, so that a
  // failure at any step still returns a result a report can describe (every
  // view unused, with its reason where one is known).
  *result = CalibrationResult();
  result->camera.model = model;
  result->camera.width = width;
  result->camera.height = height;
  result->view_used.assign(views.size(), false);
  result->view_reason.assign(views.size(), "");
  result->cam_from_board.assign(views.size(), Eigen::Isometry3d::Identity());
  result->view_rms_px.assign(views.size(), 0.0);
  result->residuals.resize(views.size());  // empty: no view used yet
  result->inlier.resize(views.size());
  std::string why;
  if (!options.Check(&why)) return Fail("calibration options: " + why, error);
  if (width <= 0 || height <= 0) {
    return Fail("the image size must be positive (got " +
                    std::to_string(width) + "x" + std::to_string(height) + ")",
                error);
  }
  const std::vector<std::string> names = CameraModelParamNames(model);
  for (const std::string& name : options.fixed_params) {
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      return Fail("calibration options: fixed parameter '" + name +
                      "' is not a parameter of " + CameraModelName(model),
                  error);
    }
  }
  if (!options.initial_params.empty() &&
      options.initial_params.size() != names.size()) {
    return Fail("calibration options: initial_params has " +
                    std::to_string(options.initial_params.size()) +
                    " values, " + CameraModelName(model) + " needs " +
                    std::to_string(names.size()),
                error);
  }
  CalibrationOptions start = options;
  std::string start_method;
  if (!StartFromFarFieldModel(views, model, width, height, &start,
                              &start_method, error)) {
    return false;
  }
  const bool ok = DispatchCameraModel(model, [&](auto model_struct) {
    return CalibrateModel<decltype(model_struct)>(views, width, height, start,
                                                  result, error);
  });
  if (!start_method.empty()) {
    const std::string line = "initialisation: " + result->initialization_method;
    const size_t at = result->report.find(line);
    if (at != std::string::npos) {
      result->report.replace(at, line.size(),
                             "initialisation: " + start_method);
    }
    result->initialization_method = start_method;
  }
  return ok;
}

}  // namespace puzzlecal
