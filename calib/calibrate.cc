#include "calib/calibrate.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "calib/intrinsics_manifold.h"
#include "calib/marginal_covariance.h"
#include "calib/parallel_costs.h"
#include "calib/reprojection_error.h"
#include "calib/splined_reprojection.h"
#include "util/angles.h"
#include "util/enum_names.h"
#include "util/failure.h"
#include "util/statistics.h"
#include "util/string_format.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

using Pose = PoseBlock;

// Everything one Calibrate() call works on: its inputs, the current
// estimate, the correspondences in play and the last solve.
struct CalibrationState {
  CalibrationState(const std::vector<CalibrationView>& views_in,
                   CameraModelId model_in, int width_in, int height_in,
                   const CalibrationOptions& options_in,
                   CalibrationResult* result_in, std::string* error_in)
      : views(views_in),
        model(model_in),
        width(width_in),
        height(height_in),
        options(options_in),
        result(result_in),
        error(error_in),
        names(CameraModelParamNames(model_in)),
        trust_region_radius(options_in.initial_trust_region_radius) {}

  // Inputs.
  const std::vector<CalibrationView>& views;
  const CameraModelId model;
  const int width, height;
  const CalibrationOptions& options;
  CalibrationResult* const result;
  std::string* const error;
  const std::vector<std::string> names;  // parameter names of the model
  const Timer timer;

  // The estimate: intrinsics (model order), one pose per view, which
  // intrinsics are held.
  std::vector<double> params;
  std::vector<Pose> poses;
  std::vector<bool> fixed;
  // A splined model's problem: the spline cell each corner's cost was made
  // for, in the order the costs were added (see SplinedReprojectionCost).
  std::vector<std::array<int, 2>> spline_cells;
  // Views and correspondences in play.
  std::vector<bool> view_used;
  std::vector<std::vector<bool>> valid;   // finite input, usable at all
  std::vector<std::vector<bool>> inlier;  // currently in the problem
  // Residuals at the estimate (views in use only) and whether each corner
  // projects.
  std::vector<std::vector<Eigen::Vector2d>> residuals;
  std::vector<std::vector<bool>> projects;

  // The last solve; its problem is kept for the covariance and refers to
  // `loss`.
  std::unique_ptr<ceres::LossFunction> loss;
  std::unique_ptr<ceres::EvaluationCallback> evaluation;  // multi-threaded
  std::unique_ptr<ceres::Problem> problem;
  ceres::Solver::Summary summary;
  int iterations = 0;  // all solves
  int rounds = 0;      // outlier rejection rounds
  // Where the next solve's trust region starts: the options' radius, then
  // the radius the last solve ended with (a rejection round continues the
  // solve it follows; restarting at a small radius would damp its steps
  // for several iterations near the minimum).
  double trust_region_radius;

  // Filled by FillResult: the inlier sum of squares and free parameters.
  double sum2 = 0;
  int free_params = 0;
};

int CountUsed(const std::vector<bool>& used) {
  return static_cast<int>(std::count(used.begin(), used.end(), true));
}

void SetViewOutcome(CalibrationState* s, size_t v, ViewOutcome outcome,
                    const std::string& reason) {
  s->view_used[v] = false;
  s->result->view_outcome[v] = outcome;
  s->result->view_reason[v] = reason;
}

bool FailTooFewViews(const CalibrationState& s, int count) {
  return Fail("only " + std::to_string(count) + " usable view" +
                  (count == 1 ? "" : "s") + " (need at least " +
                  std::to_string(s.options.min_views) +
                  "): add views of the board at different positions and "
                  "tilted by 30 degrees or more",
              s.error);
}

bool FailParallelViews(const CalibrationState& s, double spread_deg) {
  return Fail(
      "all views show the board at nearly the same orientation "
      "(largest angle between board normals " +
          StringPrintf("%.1f", spread_deg) + " degrees, need " +
          StringPrintf("%.1f", s.options.min_orientation_spread_deg) +
          "), so the focal length is undetermined: add views with "
          "the board tilted by 30 degrees or more",
      s.error);
}

// Pixel error of one correspondence with the current estimate; false when
// the point cannot be projected.
bool Residual(const CalibrationState& s, size_t v, size_t i,
              Eigen::Vector2d* residual) {
  const CalibrationView& view = s.views[v];
  const Eigen::Isometry3d pose = IsometryFromPoseBlock(s.poses[v].data());
  Eigen::Vector2d pixel;
  if (!ProjectPoint(s.model, s.params.data(), pose * view.board_points[i],
                    &pixel)) {
    return false;
  }
  *residual = pixel - view.image_points[i];
  return residual->allFinite();
}

// ---------------------------------------------------------------------------
// Stage 1: check the views.

// Marks the finite correspondences of view v; true when the view can be used.
bool CheckView(CalibrationState* s, size_t v) {
  const CalibrationView& view = s->views[v];
  const size_t n = view.board_points.size();
  s->valid[v].assign(n, false);
  if (view.image_points.size() != n) {
    SetViewOutcome(s, v, ViewOutcome::kMismatchedPoints,
                   std::to_string(n) + " board points but " +
                       std::to_string(view.image_points.size()) +
                       " image points");
    s->valid[v].assign(std::max(n, view.image_points.size()), false);
    return false;
  }
  double extent = 0;
  for (size_t i = 0; i < n; ++i) {
    if (view.board_points[i].allFinite()) {
      extent = std::max(extent, view.board_points[i].head<2>().norm());
    }
  }
  bool planar = true;
  int good = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool finite =
        view.board_points[i].allFinite() && view.image_points[i].allFinite();
    if (finite && std::abs(view.board_points[i].z()) > 1e-9 * (1 + extent)) {
      planar = false;
    }
    s->valid[v][i] = finite;
    good += finite ? 1 : 0;
  }
  if (!planar) {
    SetViewOutcome(s, v, ViewOutcome::kNotPlanar,
                   "board points are not on the plane z = 0");
    return false;
  }
  if (good < s->options.min_corners_per_view) {
    SetViewOutcome(s, v, ViewOutcome::kTooFewCorners,
                   "only " + std::to_string(good) + " corners (need " +
                       std::to_string(s->options.min_corners_per_view) + ")");
    return false;
  }
  return true;
}

// Fraction of coverage-grid cells that hold at least one corner.
double Coverage(const CalibrationState& s) {
  const int grid = s.options.coverage_grid;
  std::vector<bool> cell(grid * grid, false);
  for (size_t v = 0; v < s.views.size(); ++v) {
    if (!s.view_used[v]) continue;
    for (size_t i = 0; i < s.views[v].image_points.size(); ++i) {
      if (!s.valid[v][i]) continue;
      const Eigen::Vector2d& p = s.views[v].image_points[i];
      const int cx = static_cast<int>((p.x() + 0.5) * grid / s.width);
      const int cy = static_cast<int>((p.y() + 0.5) * grid / s.height);
      if (cx >= 0 && cx < grid && cy >= 0 && cy < grid) {
        cell[cy * grid + cx] = true;
      }
    }
  }
  return static_cast<double>(std::count(cell.begin(), cell.end(), true)) /
         (grid * grid);
}

// Every view checked; enough usable ones that cover the image.
bool CheckViews(CalibrationState* s) {
  const size_t num_views = s->views.size();
  s->view_used.assign(num_views, false);
  s->valid.resize(num_views);
  for (size_t v = 0; v < num_views; ++v) s->view_used[v] = CheckView(s, v);
  const int usable = CountUsed(s->view_used);
  if (usable < s->options.min_views) return FailTooFewViews(*s, usable);
  s->result->coverage = Coverage(*s);
  if (s->result->coverage < s->options.min_coverage) {
    return Fail("the corners cover only " +
                    StringPrintf("%.0f", 100 * s->result->coverage) +
                    " % of the image (need " +
                    StringPrintf("%.0f", 100 * s->options.min_coverage) +
                    " %): the views are all at one spot; move the board "
                    "towards the corners and borders of the image",
                s->error);
  }
  return true;
}

// ---------------------------------------------------------------------------
// Stage 2: initialise.

double OrientationSpreadDeg(const std::vector<Eigen::Isometry3d>& poses,
                            const std::vector<bool>& used);

// Fails when the usable views are too few or too parallel to calibrate.
bool CheckPosedViews(const CalibrationState& s) {
  const int usable = CountUsed(s.view_used);
  if (usable < s.options.min_views) return FailTooFewViews(s, usable);
  if (s.result->orientation_spread_deg < s.options.min_orientation_spread_deg) {
    return FailParallelViews(s, s.result->orientation_spread_deg);
  }
  return true;
}

// The intrinsics held at their initial values, from the options.
std::vector<bool> FixedParams(const CalibrationState& s) {
  const int num_params = static_cast<int>(s.names.size());
  std::vector<bool> fixed(num_params, false);
  for (int k = 0; k < num_params; ++k) {
    if (k < kPrincipalPointBegin)
      fixed[k] = s.options.fix_focal_length;
    else if (k < kDistortionBegin)
      fixed[k] = s.options.fix_principal_point;
    else
      fixed[k] = s.options.fix_distortion;
    const auto& named = s.options.fixed_params;
    if (std::find(named.begin(), named.end(), s.names[k]) != named.end() ||
        CameraModelParamIsStructural(s.model, k)) {
      fixed[k] = true;
    }
  }
  return fixed;
}

// The caller's intrinsics and poses (options.initial_cam_from_board) as the
// start.
bool InitialiseFromGivenPoses(CalibrationState* s) {
  const std::vector<Eigen::Isometry3d>& given =
      s->options.initial_cam_from_board;
  s->params = s->options.initial_params;
  s->poses.assign(s->views.size(), Pose{});
  for (size_t v = 0; v < s->views.size(); ++v) {
    if (s->view_used[v]) s->poses[v] = PoseBlockFromIsometry(given[v]);
  }
  s->result->initialization_method = "intrinsics and poses given by the caller";
  s->result->orientation_spread_deg = OrientationSpreadDeg(given, s->view_used);
  s->result->initialization_seconds = s->timer.Seconds();
  return CheckPosedViews(*s);
}

// Intrinsics and poses from calib/initialization.h on the finite
// correspondences only (or the caller's, when given); views without an
// initial pose drop out.
bool Initialise(CalibrationState* s) {
  if (!s->options.initial_cam_from_board.empty()) {
    return InitialiseFromGivenPoses(s);
  }
  const size_t num_views = s->views.size();
  std::vector<CalibrationView> clean(num_views);
  for (size_t v = 0; v < num_views; ++v) {
    if (!s->view_used[v]) continue;
    clean[v].name = s->views[v].name;
    for (size_t i = 0; i < s->views[v].board_points.size(); ++i) {
      if (s->valid[v][i]) {
        clean[v].board_points.push_back(s->views[v].board_points[i]);
        clean[v].image_points.push_back(s->views[v].image_points[i]);
      }
    }
  }
  InitializationResult init;
  std::string why;
  InitializationOptions init_options = s->options.initialization;
  init_options.num_threads = s->options.num_threads;
  const std::vector<bool> fixed = FixedParams(*s);
  for (size_t k = kDistortionBegin; k < fixed.size(); ++k) {
    if (fixed[k]) {
      init_options.held_distortion_params.push_back(static_cast<int>(k));
    }
  }
  if (!InitializeCalibration(clean, s->view_used, s->model, s->width, s->height,
                             s->options.initial_params, init_options, &init,
                             &why)) {
    return Fail("initialisation failed: " + why, s->error);
  }
  s->result->initialization_method = init.method;
  s->result->orientation_spread_deg = init.orientation_spread_deg;
  s->result->initialization_seconds = s->timer.Seconds();
  s->params = init.camera.params;
  s->poses.assign(num_views, Pose{});
  for (size_t v = 0; v < num_views; ++v) {
    if (!s->view_used[v]) continue;
    if (!init.view_ok[v]) {
      SetViewOutcome(s, v, ViewOutcome::kNoInitialPose,
                     "no initial pose: " + init.view_reason[v]);
      continue;
    }
    s->poses[v] = PoseBlockFromIsometry(init.cam_from_board[v]);
  }
  return CheckPosedViews(*s);
}

// The parameters without a tangent coordinate of their own: the fixed
// ones, and fy when it is tied to fx (same_focal_length).
std::vector<bool> CovarianceFixed(const CalibrationState& s) {
  std::vector<bool> fixed = s.fixed;
  if (s.options.same_focal_length && fixed.size() > 1) fixed[1] = true;
  return fixed;
}

// The correspondences that project through the initial camera start as
// inliers; a view with too few of them drops out.
bool SelectInitialInliers(CalibrationState* s) {
  s->inlier = s->valid;
  for (size_t v = 0; v < s->views.size(); ++v) {
    if (!s->view_used[v]) {
      std::fill(s->inlier[v].begin(), s->inlier[v].end(), false);
      continue;
    }
    int projecting = 0;
    for (size_t i = 0; i < s->inlier[v].size(); ++i) {
      Eigen::Vector2d r;
      if (s->inlier[v][i] && !Residual(*s, v, i, &r)) s->inlier[v][i] = false;
      projecting += s->inlier[v][i] ? 1 : 0;
    }
    if (projecting < s->options.min_corners_per_view) {
      SetViewOutcome(s, v, ViewOutcome::kTooFewProjecting,
                     "only " + std::to_string(projecting) +
                         " corners project through the initial camera (need " +
                         std::to_string(s->options.min_corners_per_view) + ")");
      std::fill(s->inlier[v].begin(), s->inlier[v].end(), false);
    }
  }
  const int usable = CountUsed(s->view_used);
  if (usable < s->options.min_views) return FailTooFewViews(*s, usable);
  return true;
}

// ---------------------------------------------------------------------------
// Stage 3: build the problem.

void ResetLoss(const CalibrationOptions& options,
               std::unique_ptr<ceres::LossFunction>* loss) {
  loss->reset();
  if (options.loss == RobustLoss::kHuber) {
    loss->reset(new ceres::HuberLoss(options.loss_scale_px));
  } else if (options.loss == RobustLoss::kCauchy) {
    loss->reset(new ceres::CauchyLoss(options.loss_scale_px));
  }
}

// The cost of corner i of view v, added to the problem: one intrinsics
// block, or for a splined model its blocks around the corner's cell (which
// `s->spline_cells` records).
template <typename Model>
void AddCornerCost(CalibrationState* s, size_t v, size_t i,
                   ParallelCosts* parallel) {
  const CalibrationView& view = s->views[v];
  double* pose = s->poses[v].data();
  ceres::CostFunction* cost = nullptr;
  std::vector<double*> blocks;
  if constexpr (CameraModelIsSplinedModel<Model>()) {
    const Eigen::Vector3d point_cam =
        IsometryFromPoseBlock(pose) * view.board_points[i];
    const std::array<int, 2> cell =
        SplineCellOf<Model>(s->params.data(), point_cam);
    s->spline_cells.push_back(cell);
    auto* splined = new SplinedReprojectionCost<Model>(
        view.board_points[i], view.image_points[i], cell);
    blocks = splined->Blocks(s->params.data(), pose);
    cost = splined;
  } else {
    cost = ReprojectionError<Model>::Create(view.board_points[i],
                                            view.image_points[i]);
    blocks = {s->params.data(), pose};
  }
  if (parallel != nullptr) cost = parallel->Add(cost, blocks);
  s->problem->AddResidualBlock(cost, s->loss.get(), blocks);
}

// Holds the intrinsics `fixed` marks: per intrinsics block (IntrinsicsBlocks)
// a manifold without them (fy tied to fx in the first block with
// same_focal_length), or the whole block constant.
void HoldFixedIntrinsics(CalibrationState* s, const std::vector<bool>& fixed) {
  for (const IntrinsicsBlock& block : IntrinsicsBlocks(s->model)) {
    double* values = s->params.data() + block.begin;
    if (!s->problem->HasParameterBlock(values)) continue;
    const std::vector<bool> held(fixed.begin() + block.begin,
                                 fixed.begin() + block.begin + block.size);
    std::vector<int> held_indices;
    for (int k = 0; k < block.size; ++k) {
      if (held[k]) held_indices.push_back(k);
    }
    if (s->options.same_focal_length && block.begin == 0) {
      auto manifold = std::make_unique<TiedFocalManifold>(block.size, held);
      if (manifold->TangentSize() == 0) {
        s->problem->SetParameterBlockConstant(values);
      } else {
        s->problem->SetManifold(values, manifold.release());
      }
    } else if (static_cast<int>(held_indices.size()) == block.size) {
      s->problem->SetParameterBlockConstant(values);
    } else if (!held_indices.empty()) {
      s->problem->SetManifold(
          values, new ceres::SubsetManifold(block.size, held_indices));
    }
  }
}

// A Ceres problem over the current inliers, with the poses in the first
// elimination group; `fixed[k]` holds intrinsic k. Returns the number of
// residual blocks (0: nothing to fit, and no intrinsics block added).
template <typename Model>
int BuildProblem(CalibrationState* s, const std::vector<bool>& fixed,
                 ceres::ParameterBlockOrdering* ordering) {
  // The old problem refers to the old loss and evaluation: release it
  // first.
  s->problem.reset();
  s->evaluation.reset();
  s->spline_cells.clear();
  ResetLoss(s->options, &s->loss);
  ParallelCosts* parallel = nullptr;
  if (s->options.deterministic && s->options.num_threads > 1) {
    parallel = new ParallelCosts(s->options.num_threads);
    s->evaluation.reset(parallel);
  }
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.evaluation_callback = s->evaluation.get();
  s->problem = std::make_unique<ceres::Problem>(problem_options);
  int num_residuals = 0;
  for (size_t v = 0; v < s->views.size(); ++v) {
    if (!s->view_used[v]) continue;
    int view_residuals = 0;
    for (size_t i = 0; i < s->views[v].board_points.size(); ++i) {
      if (!s->inlier[v][i]) continue;
      AddCornerCost<Model>(s, v, i, parallel);
      ++view_residuals;
    }
    // Only blocks the problem holds may be named in the ordering.
    if (view_residuals > 0) ordering->AddElementToGroup(s->poses[v].data(), 0);
    num_residuals += view_residuals;
  }
  if (num_residuals == 0) return 0;
  AddSplinePriorOnKnots(s->model, s->params.data(), s->options.spline_prior,
                        s->problem.get());
  for (const IntrinsicsBlock& block : IntrinsicsBlocks(s->model)) {
    double* values = s->params.data() + block.begin;
    if (s->problem->HasParameterBlock(values)) {
      ordering->AddElementToGroup(values, 1);
    }
  }
  HoldFixedIntrinsics(s, fixed);
  return num_residuals;
}

// True when a splined model's corner has moved out of the cell its cost was
// made for (the problem is then built again; see SplinedReprojectionCost).
template <typename Model>
bool SplineCellsChanged(const CalibrationState& s) {
  if constexpr (!CameraModelIsSplinedModel<Model>()) {
    return false;
  } else {
    size_t next = 0;
    for (size_t v = 0; v < s.views.size(); ++v) {
      if (!s.view_used[v]) continue;
      const Eigen::Isometry3d cam_from_board =
          IsometryFromPoseBlock(s.poses[v].data());
      for (size_t i = 0; i < s.views[v].board_points.size(); ++i) {
        if (!s.inlier[v][i]) continue;
        if (next >= s.spline_cells.size()) return true;
        const std::array<int, 2> cell = SplineCellOf<Model>(
            s.params.data(), cam_from_board * s.views[v].board_points[i]);
        if (cell != s.spline_cells[next++]) return true;
      }
    }
    return false;
  }
}

// ---------------------------------------------------------------------------
// Stage 4: solve.

ceres::Solver::Options SolverOptions(
    const CalibrationOptions& options, double trust_region_radius,
    std::shared_ptr<ceres::ParameterBlockOrdering> ordering) {
  ceres::Solver::Options solver_options;
  solver_options.initial_trust_region_radius = trust_region_radius;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering = std::move(ordering);
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.num_threads = options.deterministic ? 1 : options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  return solver_options;
}

// One Levenberg-Marquardt solve over the current inliers, starting from the
// current estimate; `fixed[k]` holds intrinsic k.
template <typename Model>
void Solve(CalibrationState* s, const std::vector<bool>& fixed) {
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  if (BuildProblem<Model>(s, fixed, ordering.get()) == 0) {
    // Nothing to fit: report a failed solve instead of handing Ceres an
    // empty problem.
    s->summary = ceres::Solver::Summary();
    s->summary.message = "no corners left to fit";
    return;
  }
  ceres::Solve(SolverOptions(s->options, s->trust_region_radius, ordering),
               s->problem.get(), &s->summary);
  s->iterations += static_cast<int>(s->summary.iterations.size());
  if (!s->summary.iterations.empty()) {
    s->trust_region_radius = ContinuedTrustRegionRadius(
        s->summary.iterations.back().trust_region_radius, s->options);
  }
  s->result->trust_region_radius = s->trust_region_radius;
}

// The first solve, after one with the distortion held at zero when
// options.staged_distortion says so.
template <typename Model>
bool SolveFromInitialisation(CalibrationState* s) {
  if (s->options.staged_distortion && !s->options.fix_distortion) {
    std::vector<bool> staged = s->fixed;
    for (int k = kDistortionBegin; k < Model::kNumParams; ++k) staged[k] = true;
    Solve<Model>(s, staged);
    if (!s->summary.IsSolutionUsable()) {
      return Fail("the first solve (distortion held at zero) failed: " +
                      s->summary.message,
                  s->error);
    }
  }
  if (s->options.coarse_stride > 1) {
    // The walk from the initialisation on every coarse_stride-th corner of
    // each view: the same path at a fraction of the cost per iteration.
    const std::vector<std::vector<bool>> all = s->inlier;
    for (auto& view : s->inlier) {
      for (size_t i = 0; i < view.size(); ++i) {
        view[i] = view[i] && i % s->options.coarse_stride == 0;
      }
    }
    Solve<Model>(s, s->fixed);
    s->inlier = all;
  }
  Solve<Model>(s, s->fixed);
  return true;
}

// ---------------------------------------------------------------------------
// Stage 5: reject outliers.

// Residuals of every valid corner of the views in use at the estimate.
void ComputeResiduals(CalibrationState* s) {
  const size_t num_views = s->views.size();
  s->residuals.resize(num_views);
  s->projects.resize(num_views);
  for (size_t v = 0; v < num_views; ++v) {
    const size_t n = s->view_used[v] ? s->views[v].board_points.size() : 0;
    s->residuals[v].assign(n, Eigen::Vector2d::Zero());
    s->projects[v].assign(n, false);
    for (size_t i = 0; i < n; ++i) {
      if (!s->valid[v][i]) continue;
      Eigen::Vector2d r;
      if (Residual(*s, v, i, &r)) {
        s->residuals[v][i] = r;
        s->projects[v][i] = true;
      } else {
        s->residuals[v][i].setConstant(
            std::numeric_limits<double>::quiet_NaN());
      }
    }
  }
}

// max(outlier_k * sigma, floor), sigma = 1.4826 * the median absolute
// deviation of the residual coordinates over every corner of the views in
// use (not only the current inliers: the median is robust to the outliers
// already, and a sigma of the inliers alone shrinks with every round and
// trims good corners).
double RejectionThreshold(CalibrationState* s) {
  std::vector<double> coordinates;
  for (size_t v = 0; v < s->views.size(); ++v) {
    if (!s->view_used[v]) continue;
    for (size_t i = 0; i < s->residuals[v].size(); ++i) {
      if (s->projects[v][i]) {
        coordinates.push_back(s->residuals[v][i].x());
        coordinates.push_back(s->residuals[v][i].y());
      }
    }
  }
  const double sigma = MedianAbsoluteDeviationSigma(coordinates);
  s->result->noise_sigma_px = sigma;
  s->result->outlier_threshold_px = std::max(
      s->options.outlier_k * sigma, s->options.min_outlier_threshold_px);
  return s->result->outlier_threshold_px;
}

// Inliers: the corners that project within `threshold`. False when nothing
// changes.
bool SelectInliers(CalibrationState* s, double threshold) {
  bool changed = false;
  for (size_t v = 0; v < s->views.size(); ++v) {
    if (!s->view_used[v]) continue;
    for (size_t i = 0; i < s->residuals[v].size(); ++i) {
      const bool keep =
          s->projects[v][i] && s->residuals[v][i].norm() <= threshold;
      changed |= keep != s->inlier[v][i];
      s->inlier[v][i] = keep;
    }
  }
  return changed;
}

// A view left with too few corners has no trustworthy pose: it drops out.
void DropDepletedViews(CalibrationState* s) {
  for (size_t v = 0; v < s->views.size(); ++v) {
    if (!s->view_used[v]) continue;
    const int kept = CountUsed(s->inlier[v]);
    if (kept < s->options.min_corners_per_view) {
      SetViewOutcome(s, v, ViewOutcome::kTooFewAfterRejection,
                     "only " + std::to_string(kept) +
                         " corners left after outlier rejection");
      std::fill(s->inlier[v].begin(), s->inlier[v].end(), false);
    }
  }
}

// Rounds of k-sigma rejection, each followed by a solve from the last
// estimate, until the inliers stop changing.
template <typename Model>
void RejectOutliers(CalibrationState* s) {
  ComputeResiduals(s);
  while (s->options.outlier_k > 0 &&
         s->rounds < s->options.outlier_iterations &&
         s->summary.IsSolutionUsable()) {
    if (!SelectInliers(s, RejectionThreshold(s))) break;
    DropDepletedViews(s);
    ++s->rounds;
    Solve<Model>(s, s->fixed);
    ComputeResiduals(s);
  }
}

// A splined model's corners whose ray left the cell their cost was made for
// (the costs then continued the cell's polynomial) get new costs and the
// problem is solved again, until every corner is in its cell: at most a few
// times (the cells are 25 degrees wide and the poses settle early). Each
// outlier round builds the problem afresh, so this runs once, at the end.
template <typename Model>
void SolveUntilSplineCellsHold(CalibrationState* s) {
  constexpr int kMaxSplineRebuilds = 3;
  for (int rebuild = 0;
       rebuild < kMaxSplineRebuilds && s->summary.IsSolutionUsable() &&
       SplineCellsChanged<Model>(*s);
       ++rebuild) {
    Solve<Model>(s, s->fixed);
    ComputeResiduals(s);
  }
}

// ---------------------------------------------------------------------------
// Stage 6: fill the result.

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

// Per-view poses and RMS, the totals, and what the solve did.
void FillResult(CalibrationState* s) {
  CalibrationResult* r = s->result;
  const size_t num_views = s->views.size();
  r->camera.params = s->params;
  r->view_used = s->view_used;
  r->residuals = s->residuals;
  r->inlier = s->inlier;
  r->param_fixed = s->fixed;
  r->outlier_rounds = s->rounds;
  r->iterations = s->iterations;
  r->termination = s->summary.message;
  s->sum2 = 0;
  int corners = 0, outliers = 0;
  for (size_t v = 0; v < num_views; ++v) {
    if (!s->view_used[v]) continue;
    r->view_outcome[v] = ViewOutcome::kUsed;
    r->cam_from_board[v] = IsometryFromPoseBlock(s->poses[v].data());
    double view_sum2 = 0;
    int view_corners = 0;
    for (size_t i = 0; i < s->residuals[v].size(); ++i) {
      if (s->inlier[v][i]) {
        view_sum2 += s->residuals[v][i].squaredNorm();
        ++view_corners;
      } else if (s->valid[v][i]) {
        ++outliers;
      }
    }
    s->sum2 += view_sum2;
    corners += view_corners;
    const int valid = CountUsed(s->valid[v]);
    r->view_rejected_fraction[v] =
        valid > 0 ? static_cast<double>(valid - view_corners) / valid : 0.0;
    r->view_rms_px[v] =
        view_corners > 0 ? std::sqrt(view_sum2 / (2.0 * view_corners)) : 0.0;
  }
  r->num_views_used = CountUsed(s->view_used);
  r->num_corners_used = corners;
  // The initial poses come from rough intrinsics; judge the orientations
  // again with the final ones.
  r->orientation_spread_deg =
      OrientationSpreadDeg(r->cam_from_board, s->view_used);
  r->num_outliers = outliers;
  r->rejected_fraction =
      corners + outliers > 0
          ? static_cast<double>(outliers) / (corners + outliers)
          : 0.0;
  r->rms_px = corners > 0 ? std::sqrt(s->sum2 / (2.0 * corners)) : 0.0;
  r->rms_point_px = corners > 0 ? std::sqrt(s->sum2 / corners) : 0.0;
  s->free_params = kPoseBlockSize * r->num_views_used;
  for (bool held : CovarianceFixed(*s)) s->free_params += held ? 0 : 1;
}

// ---------------------------------------------------------------------------
// Stage 7: covariance.

// ceres::Covariance (SuiteSparseQR) of the intrinsics block; it may thread
// internally, which changes the last bits from run to run.
template <typename Model>
bool CeresCovariance(CalibrationState* s, Eigen::MatrixXd* cov) {
  constexpr int kNumParams = Model::kNumParams;
  ceres::Covariance::Options covariance_options;
  covariance_options.num_threads = s->options.num_threads;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks = {
      {s->params.data(), s->params.data()}};
  // Heap-allocated: a splined model's block (209 x 209) is too big for
  // the stack.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>
      row_major(kNumParams, kNumParams);
  if (!covariance.Compute(blocks, s->problem.get()) ||
      !covariance.GetCovarianceBlock(s->params.data(), s->params.data(),
                                     row_major.data())) {
    return false;
  }
  *cov = row_major;
  return true;
}

// The intrinsics' covariance, scaled by the residual variance, and their
// standard deviations.
template <typename Model>
void ComputeCovariance(CalibrationState* s) {
  CalibrationResult* r = s->result;
  r->param_stddev.assign(Model::kNumParams, 0.0);
  r->covariance = Eigen::MatrixXd::Zero(Model::kNumParams, Model::kNumParams);
  r->covariance_requested =
      s->options.compute_covariance &&
      std::find(s->fixed.begin(), s->fixed.end(), false) != s->fixed.end();
  const int corners = r->num_corners_used;
  if (!r->covariance_requested || !s->problem ||
      !(2 * corners > s->free_params) || !s->summary.IsSolutionUsable()) {
    return;
  }
  const Timer timer;
  Eigen::MatrixXd block;
  bool ok;
  if (s->options.deterministic) {
    std::vector<double*> poses;
    for (size_t v = 0; v < s->poses.size(); ++v) {
      if (s->view_used[v]) poses.push_back(s->poses[v].data());
    }
    std::vector<double*> intrinsics;
    for (const IntrinsicsBlock& block : IntrinsicsBlocks(s->model)) {
      double* values = s->params.data() + block.begin;
      if (s->problem->HasParameterBlock(values) &&
          !s->problem->IsParameterBlockConstant(values)) {
        intrinsics.push_back(values);
      }
    }
    ok = MarginalCovariance(s->problem.get(), intrinsics, poses,
                            CovarianceFixed(*s),
                            s->options.covariance_min_eigenvalue_ratio, &block);
    if (ok && s->options.same_focal_length) {
      // fy is fx: its rows are fx's.
      block.row(1) = block.row(0);
      block.col(1) = block.col(0);
    }
  } else if (CameraModelIsSplinedModel<Model>()) {
    // ceres::Covariance of one block only; the splined model has many.
    ok = false;
  } else {
    ok = CeresCovariance<Model>(s, &block);
  }
  r->covariance_seconds = timer.Seconds();
  if (!ok) return;
  const double variance = s->sum2 / (2.0 * corners - s->free_params);
  r->covariance = block * variance;
  for (int k = 0; k < Model::kNumParams; ++k) {
    r->param_stddev[k] = std::sqrt(std::max(0.0, r->covariance(k, k)));
  }
  r->covariance_ok = true;
}

// ---------------------------------------------------------------------------
// Stage 8: judge.

// The failure checks on the final result.
bool Judge(const CalibrationState& s) {
  const CalibrationResult& r = *s.result;
  const CalibrationOptions& options = s.options;
  if (!s.summary.IsSolutionUsable()) {
    return Fail("the bundle adjustment failed: " + s.summary.message, s.error);
  }
  if (s.summary.termination_type == ceres::NO_CONVERGENCE) {
    return Fail("the bundle adjustment did not converge within " +
                    std::to_string(options.max_iterations) +
                    " iterations: raise the iteration limit or check the "
                    "correspondences (RMS " +
                    StringPrintf("%.3f", r.rms_px) + " px)",
                s.error);
  }
  if (r.num_views_used < options.min_views) {
    return FailTooFewViews(s, r.num_views_used);
  }
  if (r.orientation_spread_deg < options.min_orientation_spread_deg) {
    return FailParallelViews(s, r.orientation_spread_deg);
  }
  // Both focal lengths (indices 0 and 1: fx, fy in every model) must be
  // determined unless held fixed.
  for (int k = 0; k < 2; ++k) {
    if (r.covariance_ok && !s.fixed[k] &&
        !(r.param_stddev[k] <=
          options.max_focal_relative_stddev * std::abs(s.params[k]))) {
      return Fail("the views do not determine the focal length (" + s.names[k] +
                      " = " + StringPrintf("%.1f", s.params[k]) + " +- " +
                      StringPrintf("%.3g", r.param_stddev[k]) +
                      " px): add views with the board tilted by 30 degrees "
                      "or more, near the image borders too",
                  s.error);
    }
  }
  if (!(r.rms_px <= options.max_rms_px)) {
    return Fail("the reprojection RMS is " + StringPrintf("%.2f", r.rms_px) +
                    " px (limit " + StringPrintf("%.2f", options.max_rms_px) +
                    " px): the correspondences do not fit the " +
                    CameraModelName(s.model) +
                    " model; check the board definition and the model",
                s.error);
  }
  return true;
}

template <typename Model>
bool CalibrateModel(CalibrationState* s) {
  if (!CheckViews(s) || !Initialise(s)) return false;
  s->fixed = FixedParams(*s);
  if (s->options.same_focal_length) {
    // fy follows fx from here on (TiedFocalManifold keeps their offset).
    const double focal =
        s->fixed[0] ? s->params[0] : 0.5 * (s->params[0] + s->params[1]);
    s->params[0] = s->params[1] = focal;
  }
  if (!SelectInitialInliers(s) || !SolveFromInitialisation<Model>(s)) {
    return false;
  }
  RejectOutliers<Model>(s);
  SolveUntilSplineCellsHold<Model>(s);
  FillResult(s);
  ComputeCovariance<Model>(s);
  s->result->solve_seconds = s->timer.Seconds();
  return Judge(*s);
}

// Checks on the arguments that need no view: options, image size, fixed
// parameter names and the length of initial_params.
bool CheckArguments(CameraModelId model, int width, int height,
                    const CalibrationOptions& options, std::string* error) {
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
  if (!options.initial_params.empty() && CameraModelIsSplined(model) &&
      !(options.initial_params[KannalaBrandtSplinedModel::kGridRadiusIndex] >
        0)) {
    return Fail(std::string("calibration options: initial_params must give ") +
                    CameraModelName(model) + " a grid_radius > 0",
                error);
  }
  return true;
}

// The model whose calibration starts one of `model` when no initial_params
// are given: kannala-brandt for kannala-brandt-noncentral and
// kannala-brandt-splined, kannala-brandt-noncentral for
// kannala-brandt-splined-noncentral. The others start from
// calib/initialization.h (`model` itself is returned).
CameraModelId StartModel(CameraModelId model) {
  switch (model) {
    case CameraModelId::kPinholeRadtan:
    case CameraModelId::kPinholeRational:
    case CameraModelId::kKannalaBrandt:
      return model;
    case CameraModelId::kKannalaBrandtNoncentral:
    case CameraModelId::kKannalaBrandtSplined:
      return CameraModelId::kKannalaBrandt;
    case CameraModelId::kKannalaBrandtSplinedNoncentral:
      return CameraModelId::kKannalaBrandtNoncentral;
  }
  return model;
}

// The grid radius of a splined model over the field of the views' corners
// as `camera` sees them: `margin` times the largest |e_x| or |e_y|, e the
// equidistant image point of a corner's ray. 0 when no corner unprojects.
double SplineGridRadius(const Camera& camera,
                        const std::vector<CalibrationView>& views,
                        double margin) {
  double widest = 0;
  for (const CalibrationView& view : views) {
    for (const Eigen::Vector2d& pixel : view.image_points) {
      if (!pixel.allFinite()) continue;
      Eigen::Vector3d ray;
      if (!camera.Unproject(pixel, &ray).converged) continue;
      const double r = ray.head<2>().norm();
      if (!(r > 0)) continue;
      const double theta = std::atan2(r, ray.z());
      widest = std::max(
          widest, theta * std::max(std::abs(ray.x()), std::abs(ray.y())) / r);
    }
  }
  return margin * widest;
}

// The grid radius of a splined model over the views' corners as `camera`
// (the start's far field) sees them: from the data (spline_grid_margin), or
// from the asked knot spacing when the grid then reaches every corner.
bool SplineGridFromOptions(const Camera& camera,
                           const std::vector<CalibrationView>& views,
                           const CalibrationOptions& options,
                           CameraModelId start_model, CameraModelId model,
                           double* radius, std::string* error) {
  const double widest = SplineGridRadius(camera, views, 1.0);
  if (!(widest > 0)) {
    return Fail(std::string("no corner unprojects through the ") +
                    CameraModelName(start_model) + " calibration that starts " +
                    CameraModelName(model) +
                    ", so its spline grid has no field to cover",
                error);
  }
  const double cells = kSplineKnots - 3;
  if (options.spline_knot_spacing_deg == 0) {
    *radius = options.spline_grid_margin * widest;
    return true;
  }
  *radius = options.spline_knot_spacing_deg * kDegree * cells / 2;
  if (*radius < widest) {
    return Fail(
        StringPrintf("a knot spacing of %.1f deg gives the %dx%d spline grid "
                     "a reach of +-%.1f deg, short of the corners seen out to "
                     "%.1f deg (equidistant image): a spacing of at least "
                     "%.1f deg covers them",
                     options.spline_knot_spacing_deg, kSplineKnots,
                     kSplineKnots, *radius / kDegree, widest / kDegree,
                     2 * widest / cells / kDegree),
        error);
  }
  return true;
}

// A model that StartModel gives another model for, without initial_params,
// starts from that model's calibration: `options` gets initial_params (the
// start's parameters by name, 0 for the rest, and a splined model's grid
// radius over the corners' field) and the start solve's final trust-region
// radius, and `method` says so. Unchanged (and `method` empty) for the
// other models and given initial_params.
bool StartFromSimplerModel(const std::vector<CalibrationView>& views,
                           CameraModelId model, int width, int height,
                           CalibrationOptions* options, std::string* method,
                           std::string* error) {
  const CameraModelId start_model = StartModel(model);
  if (start_model == model || !options->initial_params.empty()) return true;
  const std::vector<std::string> start_names =
      CameraModelParamNames(start_model);
  CalibrationOptions start = *options;
  start.compute_covariance = false;
  start.function_tolerance = options->far_field_start_function_tolerance;
  start.outlier_iterations = options->far_field_start_outlier_iterations;
  start.fixed_params.clear();
  for (const std::string& name : options->fixed_params) {
    if (std::find(start_names.begin(), start_names.end(), name) !=
        start_names.end()) {
      start.fixed_params.push_back(name);
    }
  }
  const size_t max_views =
      static_cast<size_t>(options->far_field_start_max_views);
  std::vector<CalibrationView> spread;
  if (max_views > 0 && views.size() > max_views) {
    for (size_t i : EvenlySpreadIndices(views.size(), max_views)) {
      spread.push_back(views[i]);
    }
  }
  CalibrationResult result;
  std::string why;
  if (!Calibrate(spread.empty() ? views : spread, start_model, width, height,
                 start, &result, &why)) {
    return Fail(std::string("the ") + CameraModelName(start_model) +
                    " calibration that starts " + CameraModelName(model) +
                    " failed: " + why,
                error);
  }
  const std::vector<std::string> names = CameraModelParamNames(model);
  options->initial_params.assign(names.size(), 0.0);
  for (size_t k = 0; k < names.size(); ++k) {
    const auto found =
        std::find(start_names.begin(), start_names.end(), names[k]);
    if (found != start_names.end()) {
      options->initial_params[k] =
          result.camera.params[found - start_names.begin()];
    }
  }
  std::string what_else;
  if (CameraModelIsSplined(model)) {
    double radius = 0;
    if (!SplineGridFromOptions(FarFieldCamera(result.camera), views, *options,
                               start_model, model, &radius, error)) {
      return false;
    }
    options->initial_params[KannalaBrandtSplinedModel::kGridRadiusIndex] =
        radius;
    what_else += StringPrintf(
        ", correction 0 on a grid over +-%.0f deg (knots %.1f deg apart%s)",
        radius / kDegree, 2 * radius / (kSplineKnots - 3) / kDegree,
        options->spline_knot_spacing_deg > 0 ? ", as asked" : "");
  }
  if (!CameraModelIsCentral(model) && CameraModelIsCentral(start_model)) {
    what_else += ", pupil shift 0";
  }
  // The solve continues the start's: near its minimum, where a restart at
  // a small radius damps the first steps (deltille, kannala-brandt ->
  // kannala-brandt-noncentral: 11 -> 9 iterations from the start's final
  // radius).
  options->initial_trust_region_radius = std::max(
      options->initial_trust_region_radius, result.trust_region_radius);
  *method = std::string("the ") +
            (CameraModelIsCentral(start_model) ? "central " : "") +
            CameraModelName(start_model) + " calibration (" +
            (spread.empty() ? std::string("all views")
                            : std::to_string(spread.size()) + " of " +
                                  std::to_string(views.size()) + " views") +
            ", RMS " + StringPrintf("%.3f", result.rms_px) + " px)" + what_else;
  return true;
}

// Per-view fields sized to the input, so that a failure at any step still
// returns a result a report can describe (every view unused, with its
// outcome).
void ResetResult(const std::vector<CalibrationView>& views, CameraModelId model,
                 int width, int height, CalibrationResult* result) {
  *result = CalibrationResult();
  result->camera.model = model;
  result->camera.width = width;
  result->camera.height = height;
  result->view_name.resize(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    result->view_name[v] = views[v].name;
  }
  result->view_used.assign(views.size(), false);
  result->view_outcome.assign(views.size(), ViewOutcome::kNotReached);
  result->view_reason.assign(views.size(), "");
  result->cam_from_board.assign(views.size(), Eigen::Isometry3d::Identity());
  result->view_rms_px.assign(views.size(), 0.0);
  result->view_rejected_fraction.assign(views.size(), 0.0);
  result->residuals.resize(views.size());  // empty: no view used yet
  result->inlier.resize(views.size());
}

}  // namespace

constexpr EnumName<RobustLoss> kRobustLossNames[] = {
    {RobustLoss::kNone, "none"},
    {RobustLoss::kHuber, "huber"},
    {RobustLoss::kCauchy, "cauchy"},
};

const char* RobustLossName(RobustLoss loss) {
  return NameOf(kRobustLossNames, loss, "none");
}

bool RobustLossFromName(const std::string& name, RobustLoss* loss) {
  return ValueOf(kRobustLossNames, name, loss);
}

constexpr EnumName<ViewOutcome> kViewOutcomeNames[] = {
    {ViewOutcome::kUsed, "used"},
    {ViewOutcome::kNotReached, "not reached"},
    {ViewOutcome::kMismatchedPoints, "mismatched points"},
    {ViewOutcome::kNotPlanar, "board points not planar"},
    {ViewOutcome::kTooFewCorners, "too few corners"},
    {ViewOutcome::kNoInitialPose, "no initial pose"},
    {ViewOutcome::kTooFewProjecting, "too few corners project"},
    {ViewOutcome::kTooFewAfterRejection,
     "too few corners after outlier rejection"},
};

const char* ViewOutcomeName(ViewOutcome outcome) {
  return NameOf(kViewOutcomeNames, outcome, "not reached");
}

bool CalibrationOptions::Check(std::string* why) const {
  if (!(loss_scale_px > 0)) return Fail("loss_scale_px must be > 0", why);
  if (!(outlier_k >= 0)) return Fail("outlier_k must be >= 0", why);
  if (!(initial_trust_region_radius > 0)) {
    return Fail("initial_trust_region_radius must be > 0", why);
  }
  if (outlier_iterations < 0) {
    return Fail("outlier_iterations must be >= 0", why);
  }
  if (!(far_field_start_function_tolerance > 0)) {
    return Fail("far_field_start_function_tolerance must be > 0", why);
  }
  if (far_field_start_max_views < 0) {
    return Fail("far_field_start_max_views must be >= 0", why);
  }
  if (far_field_start_outlier_iterations < 0) {
    return Fail("far_field_start_outlier_iterations must be >= 0", why);
  }
  if (max_iterations < 1) return Fail("max_iterations must be >= 1", why);
  if (coarse_stride < 1) return Fail("coarse_stride must be >= 1", why);
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
  if (!(spline_grid_margin >= 1)) {
    return Fail("spline_grid_margin must be >= 1", why);
  }
  const double widest_spacing_deg = 360.0 / (kSplineKnots - 3);
  if (!(spline_knot_spacing_deg == 0 ||
        (spline_knot_spacing_deg >= 1 &&
         spline_knot_spacing_deg <= widest_spacing_deg))) {
    return Fail(StringPrintf("spline_knot_spacing_deg must be 0 (from the "
                             "data) or in [1, %.1f] degrees",
                             widest_spacing_deg),
                why);
  }
  if (!spline_prior.Check(why)) return false;
  return initialization.Check(why);
}

double ContinuedTrustRegionRadius(double last_radius,
                                  const CalibrationOptions& options) {
  // The upper bound (Ceres's own is 1e16) is large enough for Gauss-Newton
  // steps near a minimum and leaves room for the radius to shrink within a
  // few steps should one fail.
  constexpr double kMaxContinuedRadius = 1e12;
  return std::min(kMaxContinuedRadius,
                  std::max(last_radius, options.initial_trust_region_radius));
}

CalibrationOptions PoseFitOptions(const CalibrationOptions& options,
                                  const std::vector<double>& intrinsics) {
  CalibrationOptions fit = options;
  fit.initial_params = intrinsics;
  fit.initial_cam_from_board.clear();
  fit.fix_focal_length = true;
  fit.fix_principal_point = true;
  fit.fix_distortion = true;
  fit.same_focal_length = false;  // the intrinsics are as given
  fit.compute_covariance = false;
  fit.min_views = 1;
  fit.min_orientation_spread_deg = 0;
  fit.min_coverage = 0;
  fit.max_rms_px = std::numeric_limits<double>::max();
  return fit;
}

bool Calibrate(const std::vector<CalibrationView>& views, CameraModelId model,
               int width, int height, const CalibrationOptions& options,
               CalibrationResult* result, std::string* error) {
  ResetResult(views, model, width, height, result);
  if (!CheckArguments(model, width, height, options, error)) return false;
  if (!options.initial_cam_from_board.empty() &&
      (options.initial_params.empty() ||
       options.initial_cam_from_board.size() != views.size())) {
    return Fail(
        "calibration options: initial_cam_from_board needs "
        "initial_params and one pose per view (" +
            std::to_string(options.initial_cam_from_board.size()) +
            " poses for " + std::to_string(views.size()) + " views)",
        error);
  }
  CalibrationOptions start = options;
  std::string start_method;
  if (!StartFromSimplerModel(views, model, width, height, &start, &start_method,
                             error)) {
    return false;
  }
  CalibrationState state(views, model, width, height, start, result, error);
  const bool ok = DispatchCameraModel(model, [&](auto model_struct) {
    return CalibrateModel<decltype(model_struct)>(&state);
  });
  // The report names the real start: the central fit, not "given by the
  // caller".
  if (!start_method.empty()) result->initialization_method = start_method;
  return ok;
}

}  // namespace puzzlecal
