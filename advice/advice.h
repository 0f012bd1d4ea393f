#ifndef PUZZLECAL_ADVICE_ADVICE_H_
#define PUZZLECAL_ADVICE_ADVICE_H_

// Capture advice: the board poses that would lower the projection
// uncertainty of a calibration the most, chosen by adding the information
// of each candidate view to the information of the views already taken
// (advice/view_information.h) and predicting the uncertainty map after it.
// A greedy choice over poses a person can hold: the board's centre at a
// grid of places in the image, at 0.5 to 3 times the distances already
// used, tilted up to 60 degrees in eight directions, the board's own size,
// its corners inside the image and the lens's field, its tiles large
// enough to detect. Each step takes the candidate that lowers the worst
// predicted uncertainty over the judged field the most and is not a near
// duplicate of an advised pose.
//
// The prediction is linear: the information of a view does not depend on
// the noise of its corners, only on where they fall, so it holds as long as
// the current intrinsics are close enough to the lens for the new view's
// corners to land near where they are predicted.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "calib/spline_prior.h"
#include "camera/calibration_view.h"
#include "camera/camera_models.h"
#include "target/board.h"

namespace puzzlecal {

struct AdviceOptions {
  // Board poses to advise. Default 4. >= 1.
  int count = 4;
  // The field over which the uncertainty is judged: the pixels within
  // field_radius_px of the principal point whose ray is at most field_deg
  // off the optical axis. field_radius_px 0 (the default): for a pinhole
  // camera the circle that reaches the nearer of the image's left and right
  // edges (the image corners beyond it are left out: their uncertainty is
  // a tail of the highest-order distortion coefficients that a linear
  // prediction does not follow: on the sample lens, 0.02 px predicted
  // against 0.36 px recalibrated at the very corners, where within the
  // circle the two agree); for a fisheye the circle the image holds
  // entirely, or the farthest corner seen when farther. In pixels, not
  // angles: a start whose distortion is poorly known puts the image's edge
  // at a wrong angle. field_deg 0 (the default): no limit. Not only the
  // observed field: the advice is there to extend it.
  double field_radius_px = 0.0;
  double field_deg = 0.0;
  // Pixels whose ray's field radius (FieldRadius) lies beyond this
  // fraction of the radius where the distortion folds over
  // (MaxMonotonicRadius) are not judged: near the fold a pixel's ray is
  // uncertain in itself (every estimate puts the fold elsewhere), and the
  // worst uncertainty there would be a property of the fold, not of the
  // views. The sample lens (barrel distortion k1 = -0.2) folds inside its
  // image; lenses whose fold lies beyond the image are not affected.
  // Default 0.9. (0, 1].
  double max_fold_fraction = 0.9;
  // Uncertainty samples: a grid over the image with about this many
  // points. Default 600. >= 16.
  int field_samples = 600;
  // Candidate places of the board's centre: a grid of position_cols x
  // position_rows cell centres over the image. Defaults 5 x 4. >= 1.
  int position_cols = 5;
  int position_rows = 4;
  // Candidate distances, as factors of the median distance of the views
  // already taken (camera to board centre). Default 0.5 to 3.
  std::vector<double> distance_factors = {0.5, 0.75, 1.0, 1.5, 2.0, 3.0};
  // Candidate tilts of the board away from facing the camera squarely
  // (its normal along the line of sight to its centre), degrees, each in
  // tilt_directions directions (which edge of the board is nearer the
  // camera). Defaults 0, 20, 40, 60 and 8. Tilts in [0, 80], directions
  // >= 1.
  std::vector<double> tilts_deg = {0.0, 20.0, 40.0, 60.0};
  int tilt_directions = 8;
  // A candidate is one a person can hold and the detector can use: the
  // angle between the line of sight to the board's centre and the board
  // plane at least min_view_angle_deg; at least min_visible_fraction of
  // its corners inside the image (image_margin_px from the border) and
  // within the lens's field (a board whose corners are not absolutely
  // identified, a plain checkerboard, must be wholly in view); its tiles at
  // least min_tile_px across where they are smallest. Defaults 25 degrees,
  // 0.75, 4 px and 6 px.
  double min_view_angle_deg = 25.0;
  double min_visible_fraction = 0.75;
  double image_margin_px = 4.0;
  double min_tile_px = 6.0;
  // Corners of a candidate used for its information: at most this many,
  // evenly spread over the board (the information scaled to the visible
  // count). Default 80. >= 4.
  int max_corners_per_view = 80;
  // Two poses are near duplicates when their board centres appear within
  // min_separation_fraction of the image diagonal of each other, their
  // board normals differ by less than min_separation_deg and their
  // distances by less than a factor of min_distance_ratio. Defaults 0.15,
  // 20 degrees and 1.4.
  double min_separation_fraction = 0.15;
  double min_separation_deg = 20.0;
  double min_distance_ratio = 1.4;
  // The uncertainty the estimate of photos needed aims at: every 10-degree
  // field-angle band's median at or below it (the verdict's
  // max_uncertainty_px), and at least target_min_views views in all (the
  // verdict's min_views). Defaults 0.25 px and 8.
  double target_uncertainty_px = 0.25;
  int target_min_views = 8;
  // The estimate stops looking beyond this many photos. Default 100.
  int max_estimate_views = 100;
  // Corner noise (pixels per coordinate). 0 (the default): the
  // calibration's own, its inlier RMS corrected for the parameters fitted.
  // The new views' corners are taken to be as precise as those of the
  // views taken. Steeply tilted and close views usually are not: on
  // renders (bench_advise) the calibration's stated noise rose from 0.020
  // to 0.031 px with four advised views of the sample lens, from 0.017 to
  // 0.038 px with the A4 board and from 0.023 to 0.042 px on the fisheye
  // with the A4 board, which makes the recalibrated uncertainty larger than
  // predicted in the same proportion. Modelling a
  // corner's noise by its tile size in pixels (the detector's precision
  // falls as tiles shrink) was tried and does not follow it: the extra
  // noise is a tail of corners off by 0.3-1 px (kept by the calibration's
  // 1 px rejection floor) in views of every tile size.
  double noise_sigma_px = 0.0;
  // The intrinsics' information gets a weak prior so that views which do
  // not determine them (all frontal, say) still give finite predictions:
  // standard deviations of prior_focal_fraction of the focal length,
  // prior_centre_fraction of the image size and prior_distortion for each
  // distortion coefficient. Defaults 1, 1 and 1: far weaker than any view.
  double prior_focal_fraction = 1.0;
  double prior_centre_fraction = 1.0;
  double prior_distortion = 1.0;
  // A splined camera's smoothness prior, as its calibration had it
  // (CalibrationOptions::spline_prior; the defaults are the same): the
  // control values where no corner was seen are held by it, and without it
  // the predictions there were those of free values (bench_advise
  // splined: 36 px worst predicted after the first advised view, where the
  // recalibration stated 0.049 px).
  SplinePriorOptions spline_prior;
  // Threads scoring the candidates (the result does not depend on it).
  // Default 1. >= 1.
  int num_threads = 1;

  bool Check(std::string* why = nullptr) const;
};

// The predicted projection uncertainty over the judged field (1-sigma per
// axis of the far-field projection after the best-fit rotation, as
// evidence/evidence.h defines it).
struct FieldUncertainty {
  double worst_px = 0;   // the largest over the field's samples
  double median_px = 0;  // their median
  // The largest median of a 10-degree field-angle band (the verdict's
  // figure); bands with fewer than 5 samples are left out.
  double worst_band_median_px = 0;
};

struct AdvisedView {
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  // the board centre
  double distance_m = 0;  // camera to the board centre
  // The board's tilt from squarely facing the camera (normal along the line
  // of sight), and the image
  // direction of its edge nearer the camera (0 right, 90 down).
  double tilt_deg = 0;
  double tilt_direction_deg = 0;
  int visible_corners = 0;  // corners inside the image and the field
  int board_corners = 0;
  // The board's printed border as the camera sees it (distortion
  // included), a closed polygon; points outside the image kept.
  std::vector<Eigen::Vector2d> outline_px;
  // "board about 0.6 m away, its centre in the top-left corner of the
  // image, tilted about 40 degrees with its left edge towards the camera".
  std::string words;
  // The predicted uncertainty with this view and the advised ones before
  // it added.
  FieldUncertainty after;
};

struct Advice {
  bool ok = false;
  std::string error;  // why not, when !ok
  Camera camera;      // the intrinsics the prediction linearises at
  double noise_sigma_px = 0;
  // The judged field: its radius about the principal point and its widest
  // ray.
  double field_radius_px = 0;
  double field_deg = 0;
  double reference_distance_m = 0;  // median distance of the views taken
  int views_taken = 0;
  FieldUncertainty now;  // with the views taken
  std::vector<AdvisedView> views;
  // Photos in all (taken, the advised ones, then more like them in turn)
  // that the prediction says reach target_uncertainty_px and
  // target_min_views; -1 when more than max_estimate_views would be needed.
  int photos_to_target = -1;
  double target_uncertainty_px = 0;
  // Every pose that passed the checks (the candidates the advised ones were
  // chosen from), for comparisons with other choices.
  std::vector<Eigen::Isometry3d> candidate_poses;
  double seconds = 0;

  // Readable text: the uncertainty now, each advised view's words and
  // predicted uncertainty, and the estimate.
  std::string Text() const;
};

// The corner noise (pixels per coordinate) a calibration's covariance is
// scaled by: its inlier RMS with the fitted parameters' share restored
// (the RMS when no degrees of freedom are left).
double StatedNoiseSigma(const CalibrationResult& result);

// The information matrix of the intrinsics (free ones only, in the order
// of the free parameters of `result`) of the used views' inlier corners at
// the solution, for unit noise: sigma^2 times its inverse is the
// calibration's covariance.
Eigen::MatrixXd TakenInformation(const std::vector<CalibrationView>& views,
                                 const CalibrationResult& result);

// The predicted uncertainty of `camera` with the free parameters'
// covariance `free_covariance` (`free`: which of the model's parameters it
// covers) over the judged field.
FieldUncertainty PredictFieldUncertainty(const Camera& camera,
                                         const std::vector<bool>& free,
                                         const Eigen::MatrixXd& free_covariance,
                                         const AdviceOptions& options);

// The advice for the views taken (`views`, with `result` their calibration
// or pose fit: camera, poses, inliers, fixed parameters) of `board`.
Advice AdviseViews(const std::vector<CalibrationView>& views,
                   const CalibrationResult& result, const Board& board,
                   const AdviceOptions& options);

// The predicted uncertainty over the judged field after adding views of
// `board` from `poses` (cam_from_board) to the views taken, as AdviseViews
// predicts it for its candidates: for poses of the caller's choosing (a
// comparison of the advised views with others). Poses of which too little
// is seen add nothing. False with `error` when the views taken give no
// prediction.
bool PredictWithPoses(const std::vector<CalibrationView>& views,
                      const CalibrationResult& result, const Board& board,
                      const std::vector<Eigen::Isometry3d>& poses,
                      const AdviceOptions& options, FieldUncertainty* after,
                      std::string* error);

// Words for a pose: distance, where the centre appears, tilt.
std::string DescribePose(const Camera& camera, const Eigen::Vector2d& centre_px,
                         double distance_m, double tilt_deg,
                         double tilt_direction_deg);

}  // namespace puzzlecal

#endif  // PUZZLECAL_ADVICE_ADVICE_H_
