#ifndef PUZZLECAL_CALIB_INITIALIZATION_H_
#define PUZZLECAL_CALIB_INITIALIZATION_H_

// Starting values for the bundle adjustment without any guess from the user:
// - pinhole models: Zhang's closed form on board-to-image homographies (the
//   full five-parameter form when it is plausible, otherwise the form with
//   the principal point at the image centre and square pixels);
// - kannala-brandt: the equidistant model r = f * theta with the principal
//   point at the image centre; f by a 1D search that fits, for every view, a
//   board-to-ray homography to the rays the candidate f gives (works for rays
//   beyond 90 degrees, so for 190 degree lenses and partial views);
// - kannala-brandt-noncentral: as kannala-brandt, with the pupil shift at 0
//   (the rays are the far-field directions); Calibrate starts it from a
//   central kannala-brandt calibration instead;
// - per view: a pose "PnP through the model": pixels are unprojected to rays
//   with the current intrinsics, a board-to-ray homography gives the pose,
//   optionally polished by a small robust Ceres refinement
//   (pose_refine_iterations > 0; off by default);
// - then (no intrinsics from the caller) the start refinement: a joint solve
//   of fx, fy, cx, cy, k1, k2 and the poses on a subset of views and corners,
//   after which every view is posed again through the refined camera.
// Every estimate is robust to a few gross outliers (iteratively reweighted).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "camera/calibration_view.h"
#include "camera/camera_models.h"

namespace puzzlecal {

struct InitializationOptions {
  // Rounds of outlier down-weighting in every homography fit. Default 4.
  int reweight_iterations = 4;
  // A correspondence is dropped from a homography fit when its angular error
  // exceeds this many robust standard deviations (1.4826 * median). Default 3.
  double reweight_k = 3.0;
  // Fisheye focal search: candidate f from focal_search_min_ratio to
  // focal_search_max_ratio times the image diagonal, log-spaced. Defaults
  // 0.05 and 3.
  double focal_search_min_ratio = 0.05;
  double focal_search_max_ratio = 3.0;
  // Number of log-spaced candidates before the golden-section refinement.
  // Default 40.
  int focal_search_steps = 40;
  // Golden-section iterations after the scan: each narrows the bracket (two
  // scan steps) by 0.618, so 12 leave f to within 0.1 %, far less than the
  // solve that follows moves it. Default 12.
  int focal_search_refine_iterations = 12;
  // Outlier rounds of the homography fits inside the focal search (the
  // truncated cost already bounds the effect of outliers). Default 1.
  int focal_search_reweight_iterations = 1;
  // Pixel errors above this are truncated in the focal-search cost, so that
  // outliers and badly fitting views cannot dominate it. Default 8 px.
  double focal_search_truncation_px = 8.0;
  // At most this many views (evenly spread over the input) take part in the
  // focal search; all views get a pose afterwards. Default 60.
  int focal_search_max_views = 60;
  // Of each of those views, at most this many corners (evenly spread over
  // its corner list) take part in the search: a board's pose through a
  // candidate camera is fixed by far fewer than a large board has (a 23 x
  // 16 board: 368), and the search costs in proportion to them. The cost
  // that competes with the closed forms is taken on all corners. Default
  // 48. >= 8.
  int focal_search_max_corners_per_view = 48;
  // Of the search views, at most this many (evenly spread) take part in the
  // scan, which only brackets the minimum for the golden section on all of
  // them (the scan costs steps x views pose fits, the bulk of the search).
  // Default 16. >= 1.
  int focal_search_scan_max_views = 16;
  // When the scan ran on a subset, this many of its lowest local minima are
  // scored on all search views, and the best of them centres the golden
  // section's bracket. Default 3. >= 1.
  int focal_search_scan_candidates = 3;
  // Zhang's full solution (fx, fy, cx, cy free) is kept as a candidate only
  // when fx / fy lies in [1 / max_focal_aspect, max_focal_aspect] and the
  // principal point inside the image. Default 2. >= 1.
  double max_focal_aspect = 2.0;
  // Iterations of the per-view pose refinement (Ceres, Huber loss) after the
  // homography pose. Default 0: the bundle adjustment refines the poses
  // anyway, and the homography pose is close enough to start it.
  int pose_refine_iterations = 0;
  // Huber scale of the pose refinement, pixels. Default 2.
  double pose_refine_loss_px = 2.0;
  // Start refinement (without intrinsics from the caller): a joint solve of
  // fx, fy, cx, cy, k1, k2 and the poses on a subset of the posed views and
  // corners, from the distortion-free start; every view is then posed again
  // through the refined camera. The full bundle adjustment so starts near
  // its minimum instead of walking there over all corners. At most this
  // many Levenberg-Marquardt iterations; 0 turns it off. Default 100.
  int start_refine_iterations = 100;
  // At most this many posed views (evenly spread) take part. Default 20.
  int start_refine_max_views = 20;
  // At most this many corners per view (evenly spread over its list) take
  // part. Default 40.
  int start_refine_max_corners_per_view = 40;
  // Huber scale of the start refinement, pixels. Default 2.
  double start_refine_loss_px = 2.0;
  // Pose-refinement iterations (as pose_refine_iterations) for every view
  // after a successful start refinement. Default 0 (the homography pose through
  // the refined camera is close enough).
  int start_refine_pose_iterations = 0;
  // Distortion terms the start refinement holds at their start, 0, by
  // parameter index (CameraModelParamNames order): those the calibration
  // holds fixed, so that a term held fixed without a given start stays at 0
  // (as OpenCV's CALIB_FIX_K1..K6) instead of at the start refinement's
  // value. Calibrate sets it from CalibrationOptions' fixed parameters.
  // Indices before the distortion terms are ignored. Default: none.
  std::vector<int> held_distortion_params;
  // Worker threads for the focal-length search and the per-view poses; the
  // result is the same for any count (each view's work has its own slot).
  // Calibrate sets it from CalibrationOptions::num_threads. Default 1.
  int num_threads = 1;

  bool Check(std::string* why) const;
};

// What the initialisation produced and how.
struct InitializationResult {
  Camera camera;                                  // starting intrinsics
  std::vector<bool> view_ok;                      // pose found for the view
  std::vector<Eigen::Isometry3d> cam_from_board;  // per view (identity if !ok)
  std::vector<std::string> view_reason;           // why a view has no pose
  std::string method;  // how the intrinsics were made
  // Largest angle between the board normals of two posed views, degrees: a
  // small value means the focal length is poorly determined.
  double orientation_spread_deg = 0;
  // Iterations of the start refinement (0: not run), and whether its
  // camera replaced the closed-form / search start.
  int start_refine_iterations = 0;
  bool start_refined = false;
};

// Board-to-ray homography (ray ~ H * (X, Y, 1)) from board-plane points and
// unit rays (any direction, also beyond 90 degrees from the optical axis),
// with iterative outlier down-weighting. `inlier` (optional) returns the
// correspondences kept in the last round. False when fewer than 4 usable
// points remain or the points are degenerate (collinear).
bool EstimateBoardToRayHomography(const std::vector<Eigen::Vector2d>& board_xy,
                                  const std::vector<Eigen::Vector3d>& rays,
                                  const InitializationOptions& options,
                                  Eigen::Matrix3d* homography,
                                  std::vector<bool>* inlier);

// cam_from_board from a board-to-ray homography (H = s * [r1 r2 t]).
bool PoseFromBoardToRayHomography(const Eigen::Matrix3d& homography,
                                  const std::vector<Eigen::Vector2d>& board_xy,
                                  const std::vector<Eigen::Vector3d>& rays,
                                  Eigen::Isometry3d* cam_from_board);

// PnP through the model: the pose of one view for a known camera. Returns
// false with a reason when the view gives no pose.
bool EstimateViewPose(const Camera& camera, const CalibrationView& view,
                      const InitializationOptions& options,
                      Eigen::Isometry3d* cam_from_board, std::string* why);

// Starting intrinsics (see the file comment) and one pose per usable view.
// `use_view[i]` false skips view i. If `initial_params` is not empty it is
// used as the intrinsics and only the poses are estimated. False with a
// reason when no intrinsics can be found.
bool InitializeCalibration(const std::vector<CalibrationView>& views,
                           const std::vector<bool>& use_view,
                           CameraModelId model, int width, int height,
                           const std::vector<double>& initial_params,
                           const InitializationOptions& options,
                           InitializationResult* result, std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_INITIALIZATION_H_
