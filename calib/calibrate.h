#ifndef PUZZLECAL_CALIB_CALIBRATE_H_
#define PUZZLECAL_CALIB_CALIBRATE_H_

// Calibration of one camera from views of a planar board: automatic
// initialisation (calib/initialization.h), then a Ceres bundle adjustment over
// the intrinsics and one cam_from_board pose per view (poses eliminated by
// the Schur complement), a robust loss, iterative k-sigma outlier rejection
// and parameter standard deviations (by default from a deterministic Schur
// complement of the Jacobian; ceres::Covariance when `deterministic` is
// false).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/initialization.h"
#include "calib/spline_prior.h"
#include "camera/calibration_view.h"
#include "camera/camera_models.h"

namespace puzzlecal {

enum class RobustLoss { kNone, kHuber, kCauchy };

// "none", "huber", "cauchy".
const char* RobustLossName(RobustLoss loss);
bool RobustLossFromName(const std::string& name, RobustLoss* loss);

struct CalibrationOptions {
  // Hold fx and fy at their initial values. Default false.
  bool fix_focal_length = false;
  // Hold cx and cy at their initial values. Default false.
  bool fix_principal_point = false;
  // Hold every distortion coefficient at its initial value (0 unless
  // initial_params says otherwise). Default false.
  bool fix_distortion = false;
  // One focal length: fy tied to fx (square pixels; OpenCV's
  // CALIB_FIX_ASPECT_RATIO with an aspect of 1). Both start at their mean
  // (at fx when fx is held); their standard deviations and covariance rows
  // are then the same. Default false.
  bool same_focal_length = false;
  // Individual parameters held at their initial values, by name ("k3",
  // "p1", ...; see CameraModelParamNames). Default empty.
  std::vector<std::string> fixed_params;
  // Starting intrinsics in the model's order; empty (the default) means
  // automatic initialisation.
  std::vector<double> initial_params;
  // Starting poses with initial_params: one cam_from_board per input view,
  // used instead of posing each view from the intrinsics. For a calibration
  // of views that an earlier one already posed (the cross-validation
  // halves start at the full solution, a few iterations from their own).
  // Empty (the default): the initialisation poses every view.
  std::vector<Eigen::Isometry3d> initial_cam_from_board;

  // Robust loss on each corner's pixel error. Default Huber.
  RobustLoss loss = RobustLoss::kHuber;
  // Scale of the robust loss in pixels: errors below it count quadratically.
  // Default 1 px.
  double loss_scale_px = 1.0;

  // Outlier rejection: after a solve, a corner whose pixel error (the 2-D
  // norm) exceeds max(outlier_k * sigma, min_outlier_threshold_px) is
  // dropped and the problem solved again from the last estimate. sigma is
  // the robust noise estimate per coordinate, 1.4826 * the median absolute
  // deviation of the residual coordinates of all corners in use. For
  // Gaussian noise outlier_k = 4 would drop exp(-8) = 0.03 % of good
  // corners, but corner errors are not Gaussian: on the bundled renders
  // (no wrong correspondences) the detection errors against the exact
  // corners have a median of 0.036 px, a 95th percentile of 0.16 px (4.3x
  // the median where a Gaussian has 2.1x) and a 99.9th of 0.86 px, so
  // 4 sigma alone (0.12 px) dropped 8 % of them. The floor keeps that tail.
  // Default 4; 0 turns rejection off.
  double outlier_k = 4.0;
  // At most this many rejection rounds. Default 3.
  int outlier_iterations = 3;
  // The rejection threshold never drops below this (pixels): sub-pixel
  // corner errors stay in, while a wrong correspondence, which is off by
  // about a tile (5 px or more at any usable board size), still goes.
  // Default 1 px. >= 0.
  double min_outlier_threshold_px = 1.0;

  // Before the first full solve, one on every coarse_stride-th corner of
  // each view, from the initialisation: the long walk from a rough start
  // at a fraction of the cost per iteration; the full solve continues from
  // there. 1 turns it off. Default 1: on the sample set a stride of 4 cut
  // the solve from 93 to 83 iterations and about 4x in time with the same
  // result to 1e-5 px, but on synthetic scenes it led the 12-parameter
  // rational model to a rank-deficient minimum and let gross outliers bias
  // the start. >= 1.
  int coarse_stride = 1;

  // Trust-region radius of the first solve (Ceres's default, 1e4); later
  // solves (the outlier-rejection rounds) continue with the radius the
  // solve before them ended with. A start already near the minimum (the
  // cross-validation halves start at the full solution: their caller
  // passes its trust_region_radius) can take a larger one: near a minimum
  // a small radius damps the steps, and the cost then falls by a few
  // times per iteration instead of converging quadratically. > 0.
  double initial_trust_region_radius = 1e4;
  // Levenberg-Marquardt iterations per solve. Default 200 (the first solve
  // from a rough start can take more than 100 on wide-angle cameras).
  int max_iterations = 200;
  // Relative cost change that ends a solve. Default 1e-9: the parameters
  // then move by about 1e-4 of their standard deviations per iteration
  // (measured on the sample set: the result agrees with 1e-12 to 1e-5 px in
  // f), while 1e-12 took dozens of iterations of no consequence. > 0.
  double function_tolerance = 1e-9;
  // Ceres's gradient and parameter tolerances (max-norm of the projected
  // gradient; relative step size) that also end a solve. Defaults 1e-10
  // and 1e-9. > 0.
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-9;
  // The intrinsics' covariance is refused as singular when the smallest
  // eigenvalue of their (Schur) information matrix, scaled to a unit
  // diagonal (so that the parameters' units do not matter), is below this
  // fraction of the largest. Default 1e-14. > 0.
  double covariance_min_eigenvalue_ratio = 1e-14;
  // Threads. With `deterministic` (the default) they evaluate the corners'
  // residuals and Jacobians ahead of a single-threaded Ceres solve, each
  // corner into its own slot (calib/parallel_costs.h), so the result
  // is bit for bit the same for any count. Without it they go to Ceres's
  // solve and ceres::Covariance, which sum in the order the threads finish
  // and change the last bits from run to run. Default 1. >= 1.
  int num_threads = 1;
  // Keep the output independent of num_threads (see there), and compute
  // the covariance with puzzlecal's own sequential Schur complement instead
  // of ceres::Covariance (whose SuiteSparseQR may thread internally).
  // Default true.
  bool deterministic = true;

  // A view needs at least this many corners to be used. Default 6.
  int min_corners_per_view = 6;
  // Fewer usable views than this is a failure. Default 3.
  int min_views = 3;
  // The board normals of the posed views must span at least this angle
  // (degrees), otherwise the focal length is undetermined. Default 5.
  double min_orientation_spread_deg = 5.0;
  // The corners must touch at least this fraction of the cells of a
  // coverage_grid x coverage_grid grid over the image. Default 0.1.
  double min_coverage = 0.1;
  // When the covariance is available: a focal length whose standard
  // deviation exceeds this fraction of its value is a failure (the views
  // do not determine it). Default 0.05.
  double max_focal_relative_stddev = 0.05;
  // Cells per image side for the coverage figure. Default 8.
  int coverage_grid = 8;
  // A final RMS above this (pixels, per coordinate) is a failure: the
  // correspondences or the model do not fit. Default 3 px.
  double max_rms_px = 3.0;

  // Fit fx, fy, cx, cy first with the distortion held at zero, then all.
  // Default false: every test scene converges from the initialisation
  // without it.
  bool staged_distortion = false;
  // Compute the parameter covariance and standard deviations. Default true.
  bool compute_covariance = true;
  // A non-central model starts from a calibration of its central far-field
  // model. That is only a start, so it stops at this relative cost change
  // (instead of function_tolerance) and runs this many outlier-rejection
  // rounds (instead of outlier_iterations): on a lens the central model
  // cannot follow, its convergence is slow, and a full-precision central
  // solve would cost more than the non-central one. Defaults 1e-6 and 0.
  double far_field_start_function_tolerance = 1e-6;
  int far_field_start_outlier_iterations = 0;
  // The central start uses at most this many views, evenly spread over the
  // input (0: all): a start needs the intrinsics roughly, not from every
  // view. Default 32.
  int far_field_start_max_views = 32;

  // The prior on a splined model's correction (calib/spline_prior.h).
  SplinePriorOptions spline_prior;
  // A splined model's grid covers the field the corners were seen in: its
  // grid_radius is this factor times the largest |e_x| or |e_y| of a corner
  // under the kannala-brandt start (e the equidistant image point), so that
  // the outermost corners are inside the grid rather than on its edge.
  // Unused when initial_params gives grid_radius. Default 1.05. >= 1.
  double spline_grid_margin = 1.05;
  // The knot spacing of a splined model, in degrees of the equidistant image
  // (0: from the data, as spline_grid_margin says). The grid has a fixed
  // count of knots (kSplineKnots per side, kSplineKnots - 3 cells), so a
  // spacing sets its radius, (kSplineKnots - 3) / 2 times the spacing. A
  // spacing wider than the data's makes the correction smoother, its outer
  // cells then seen by fewer corners (the prior decides there); one so fine
  // that the grid would not reach the widest corner is refused (the grid
  // holds its edge value beyond). Unused when initial_params gives
  // grid_radius. Default 0. 0, or in [1, 360 / (kSplineKnots - 3)].
  double spline_knot_spacing_deg = 0;

  InitializationOptions initialization;

  bool Check(std::string* why) const;
};

// What became of one input view.
enum class ViewOutcome {
  kUsed,                  // in the final solve
  kNotReached,            // the calibration stopped before judging it
  kMismatchedPoints,      // board and image point counts differ
  kNotPlanar,             // board points off the plane z = 0
  kTooFewCorners,         // fewer finite corners than min_corners_per_view
  kNoInitialPose,         // the initialisation could not pose it
  kTooFewProjecting,      // too few corners project through the initial camera
  kTooFewAfterRejection,  // outlier rejection left too few corners
};

// "used", "not reached", "mismatched points", ...
const char* ViewOutcomeName(ViewOutcome outcome);

struct CalibrationResult {
  Camera camera;  // model, estimated parameters, image size
  // Per input view: its name, whether it took part, and why not (the
  // outcome, and a sentence with the figures; empty when used or not
  // reached).
  std::vector<std::string> view_name;
  std::vector<bool> view_used;
  std::vector<ViewOutcome> view_outcome;
  std::vector<std::string> view_reason;
  std::vector<Eigen::Isometry3d> cam_from_board;  // identity when not used
  // RMS of the inlier residual coordinates (sqrt(sum(dx^2 + dy^2) / 2N)):
  // for Gaussian corner noise sigma per axis it tends to
  // sigma * sqrt(1 - P / 2N).
  double rms_px = 0;
  // OpenCV's figure (sqrt(sum(dx^2 + dy^2) / N)), for comparisons.
  double rms_point_px = 0;
  std::vector<double> view_rms_px;  // per view, per coordinate, inliers
  // Per view and corner: projected minus observed pixel (empty for views
  // not used), and whether the corner was kept.
  std::vector<std::vector<Eigen::Vector2d>> residuals;
  std::vector<std::vector<bool>> inlier;
  // Standard deviation of every parameter (0 for fixed ones) and the
  // covariance of the intrinsics, scaled by the residual variance.
  std::vector<double> param_stddev;
  Eigen::MatrixXd covariance;
  // The covariance was asked for (options.compute_covariance and at least
  // one free parameter) and whether it was obtained.
  bool covariance_requested = false;
  bool covariance_ok = false;
  std::vector<bool> param_fixed;
  int num_views_used = 0;
  int num_corners_used = 0;  // inlier corners of the used views
  int num_outliers = 0;
  // Rejected fraction of the valid corners, per view (0 for views not used)
  // and over the used views.
  std::vector<double> view_rejected_fraction;
  double rejected_fraction = 0;
  // The last rejection round's robust noise estimate (per coordinate) and
  // threshold on the corner error, pixels (0 when no round ran).
  double noise_sigma_px = 0;
  double outlier_threshold_px = 0;
  int outlier_rounds = 0;  // solves after the first one
  int iterations = 0;      // Levenberg-Marquardt iterations, all solves
  // The trust-region radius the last solve ended with (see
  // CalibrationOptions::initial_trust_region_radius).
  double trust_region_radius = 0;
  // Seconds from the start of Calibrate: to the end of the initialisation,
  // and to the end of the solve and the covariance; and the covariance step
  // alone.
  double solve_seconds = 0;
  double initialization_seconds = 0;
  double covariance_seconds = 0;
  std::string initialization_method;
  double orientation_spread_deg = 0;
  double coverage = 0;      // fraction of coverage-grid cells with corners
  std::string termination;  // Ceres' message of the last solve

  // Readable summary of all of the above (CalibrationReport).
  std::string FullReport() const;
};

// The readable summary of a result: model, parameters with their standard
// deviations, RMS, views and corners used, outliers, coverage, solver, and
// one line per view not used.
std::string CalibrationReport(const CalibrationResult& result);

// The trust-region radius a solve that continues an earlier one starts
// with: the radius the earlier one ended with, at least
// options.initial_trust_region_radius and at most 1e12.
double ContinuedTrustRegionRadius(double last_radius,
                                  const CalibrationOptions& options);

// The options of a pose fit: `options` with every intrinsic held at
// `intrinsics` (only the poses move, each view posed from them), no
// starting poses, no covariance, and none of the checks meant for a
// calibration (view count, orientation spread, coverage, RMS limit).
CalibrationOptions PoseFitOptions(const CalibrationOptions& options,
                                  const std::vector<double>& intrinsics);

// Calibrates `model` for images of width x height pixels. Returns false with
// a reason (which says what to change) when the views are too few or
// degenerate or the solve fails; `result` then holds what is known so far.
bool Calibrate(const std::vector<CalibrationView>& views, CameraModelId model,
               int width, int height, const CalibrationOptions& options,
               CalibrationResult* result, std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_CALIBRATE_H_
