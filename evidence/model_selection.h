#ifndef PUZZLECAL_EVIDENCE_MODEL_SELECTION_H_
#define PUZZLECAL_EVIDENCE_MODEL_SELECTION_H_

// Choosing the camera model by held-out error (`--model auto`): every
// candidate model is calibrated on most of the views; the views held out
// are then fitted with the intrinsics fixed (only their poses move) and the
// RMS of their corners is the candidate's held-out error. A model with more
// parameters than the lens needs fits the calibration views better but not
// the held-out ones; a model that cannot follow the lens fits neither.
// By default every view is held out once (one fold per holdout_every), so
// small sets still compare the candidates on all of their corners.
//
// The choice: the candidates are ranked by preference (the conventional
// family for the observed field first: pinhole models when every corner
// stays within conventional_max_field_deg of the axis, fisheye models
// beyond; then fewer parameters). The most preferred candidate that fits is
// chosen unless another beats it on held-out error by more than
// min_relative_gain and by more than min_gain_z standard errors of the
// per-view difference (noise); then the winner must be beaten in turn.
//
// The splined models refine kannala-brandt's shape (and its non-central
// form's): each is fitted only when the model it refines leads after the
// other candidates, and is then chosen only when it beats that model as
// above and the halves of the views (CrossValidate) agree no worse under it
// than under that model. Otherwise it is listed as skipped, with the leader
// named, or the model it refines is chosen with the halves' figures as the
// reason.

#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "camera/calibration_view.h"
#include "camera/camera_models.h"

namespace puzzlecal {

struct ModelSelectionOptions {
  // Views at positions holdout_offset, holdout_offset + holdout_every, ...
  // (among the views with enough corners) are held out. Defaults 4 and 3:
  // every 4th view. holdout_every >= 2, 0 <= holdout_offset < holdout_every.
  int holdout_every = 4;
  int holdout_offset = 3;
  // Hold out every fold in turn (offsets 0 .. holdout_every - 1: each view
  // is held out once, at holdout_every calibrations per candidate) instead
  // of only the holdout_offset one. Default true.
  bool all_folds = true;
  // Candidate model names; empty (the default) means every model.
  std::vector<std::string> candidates;
  // Pinhole candidates are skipped when a fisheye candidate's corners reach
  // beyond this angle from the optical axis (degrees): a pinhole model
  // cannot project rays at 90 degrees or more, and its fit fails slowly.
  // Default 85. In (0, 90].
  double pinhole_max_field_deg = 85.0;
  // A less preferred candidate must beat the chosen one's held-out RMS by
  // more than this fraction to be chosen instead. Default 0.02. >= 0.
  double min_relative_gain = 0.02;
  // ... and by a mean over the held-out views of the log of the ratio of
  // the two candidates' RMS in the view of more than this many standard
  // errors (corner errors within a view are not independent, so the views
  // are the samples; the log lets every view weigh alike). Default 2. >= 0.
  double min_gain_z = 2.0;
  // The field within which pinhole models are the conventional family: when
  // the widest corner (under any fitted candidate's poses) stays within it,
  // pinhole models are preferred on near-ties, beyond it fisheye models.
  // Default 55 degrees. In (0, 90].
  double conventional_max_field_deg = 55.0;
  // A held-out corner whose error is gross for every candidate that fits
  // is a detection error (a false corner), not a model's failure: it is left
  // out of every candidate's held-out RMS, so that one such corner cannot
  // drown the differences between models (its squared error counts as much
  // as thousands of good corners'). Gross: above gross_error_k times the
  // candidate's own robust sigma of its held-out residual coordinates
  // (1.4826 x their median absolute value) and above gross_error_floor_px.
  // A corner only some candidates miss stays: that is what a model that
  // cannot follow the lens looks like. Defaults 10 and 3 px; k > 0, floor
  // >= 0.
  double gross_error_k = 10.0;
  double gross_error_floor_px = 3.0;

  bool Check(std::string* why = nullptr) const;
};

struct ModelCandidate {
  CameraModelId model = CameraModelId::kPinholeRadtan;
  int num_params = 0;
  bool ok = false;
  std::string error;      // why the candidate failed, when !ok
  double fit_rms_px = 0;  // calibration views, inliers, per coordinate
                          // (over the folds)
  // Held-out views, per coordinate, every corner the candidate projects but
  // the detection errors (ModelSelectionOptions::gross_error_k).
  double holdout_rms_px = 0;
  int holdout_views = 0;
  int holdout_corners = 0;
  // Sum of squared residual lengths per held-out view (the corners of
  // holdout_rms_px), in held-out order: the paired comparison's samples.
  std::vector<double> holdout_view_sse;
  double seconds = 0;
  // A splined candidate chosen over the model it refines, and that model:
  // the largest band median of their halves' far-field difference
  // (CrossValidate on all views), pixels; -1 when not computed.
  double halves_worst_px = -1;
};

struct ModelSelection {
  std::vector<ModelCandidate> candidates;
  int chosen = -1;        // index into candidates, -1 when none succeeded
  int fit_views = 0;      // per fold
  int holdout_views = 0;  // over all folds
  int folds = 1;
  double min_relative_gain = 0;  // the options' tie margin, for Table()
  // Held-out corners left out as gross for every candidate.
  int holdout_detection_errors = 0;
  // The widest field angle of a corner seen by a fitted candidate, degrees,
  // and whether the pinhole family is the conventional one for it.
  double widest_field_deg = 0;
  bool pinhole_field = true;
  // Why `chosen` was chosen, in words ("lowest held-out RMS", or the
  // candidate with the lowest and why it was not enough).
  std::string reason;
  // False when the comparison could not be made: the model preferred for
  // the field (the conventional family's with the fewest parameters:
  // pinhole-radtan within conventional_max_field_deg, kannala-brandt
  // beyond) failed on a fold (with few views a fold's fit views can be too
  // few or too alike) but calibrates on all the views. Then `chosen` is
  // that model, without a held-out error of its own (its candidate is not
  // ok), and `reason` says why no comparison was made.
  bool compared = true;

  // The candidate of that model (nullptr when it was not a candidate).
  const ModelCandidate* Find(CameraModelId model) const;

  // The comparison table (one line per candidate, the chosen one marked).
  std::string Table() const;
};

// Splits the views, calibrates each candidate and chooses one (see the top
// of this file). When the model preferred for the field failed on a fold
// but calibrates on all the views, it is chosen without a comparison
// (ModelSelection::compared). False when no candidate succeeds (and the
// preferred model does not calibrate on all views) or the options are
// invalid.
bool SelectModel(const std::vector<CalibrationView>& views, int width,
                 int height, const CalibrationOptions& calibration,
                 const ModelSelectionOptions& options,
                 ModelSelection* selection, std::string* error);

// The held-out error of `camera` on `views`: each view's pose fitted with
// the intrinsics fixed; RMS per coordinate over all corners that project.
// `residuals`, when given, receives every corner's residual ([view][corner],
// NaN where the corner does not project or its view was not fitted).
// Whether `challenger` beats `incumbent` on held-out error by more than
// min_relative_gain and min_gain_z standard errors of the per-view log RMS
// ratio (both must have fitted, on the same held-out corners); `z` receives
// the mean log ratio in standard errors.
bool BeatsOnHeldOutViews(const ModelCandidate& challenger,
                         const ModelCandidate& incumbent,
                         const ModelSelectionOptions& options,
                         double* z = nullptr);

bool HoldoutError(
    const std::vector<CalibrationView>& views, const Camera& camera,
    const CalibrationOptions& calibration, double* rms_px, int* corners,
    std::string* error,
    std::vector<std::vector<Eigen::Vector2d>>* residuals = nullptr);

}  // namespace puzzlecal

#endif  // PUZZLECAL_EVIDENCE_MODEL_SELECTION_H_
