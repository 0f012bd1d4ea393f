#ifndef PUZZLECAL_EVIDENCE_MODEL_SELECTION_H_
#define PUZZLECAL_EVIDENCE_MODEL_SELECTION_H_

// Choosing the camera model by held-out error (`--model auto`): every
// candidate model is calibrated on most of the views; the views held out
// are then fitted with the intrinsics fixed (only their poses move) and the
// RMS of their corners is the candidate's held-out error. A model with more
// parameters than the lens needs fits the calibration views better but not
// the held-out ones; a model that cannot follow the lens fits neither.

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
  // Candidate model names; empty (the default) means every model.
  std::vector<std::string> candidates;
  // Pinhole candidates are skipped when a fisheye candidate's corners reach
  // beyond this angle from the optical axis (degrees): a pinhole model
  // cannot project rays at 90 degrees or more, and its fit fails slowly.
  // Default 85. In (0, 90].
  double pinhole_max_field_deg = 85.0;
  // A candidate must beat the best held-out error by more than this
  // fraction to be preferred over one with fewer parameters. Default 0.02.
  double min_relative_gain = 0.02;
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
  // Held-out views, per coordinate, every corner the candidate projects but
  // the detection errors (ModelSelectionOptions::gross_error_k).
  double holdout_rms_px = 0;
  int holdout_views = 0;
  int holdout_corners = 0;
  double seconds = 0;
};

struct ModelSelection {
  std::vector<ModelCandidate> candidates;
  int chosen = -1;  // index into candidates, -1 when none succeeded
  int fit_views = 0;
  int holdout_views = 0;
  double min_relative_gain = 0;  // the options' tie margin, for Table()
  // Held-out corners left out as gross for every candidate.
  int holdout_detection_errors = 0;

  // The comparison table (one line per candidate, the chosen one marked).
  std::string Table() const;
};

// Splits the views, calibrates each candidate and picks the lowest held-out
// error (ties within min_relative_gain go to fewer parameters). False when
// no candidate succeeds or the options are invalid.
bool SelectModel(const std::vector<CalibrationView>& views, int width,
                 int height, const CalibrationOptions& calibration,
                 const ModelSelectionOptions& options,
                 ModelSelection* selection, std::string* error);

// The held-out error of `camera` on `views`: each view's pose fitted with
// the intrinsics fixed; RMS per coordinate over all corners that project.
// `residuals`, when given, receives every corner's residual ([view][corner],
// NaN where the corner does not project or its view was not fitted).
bool HoldoutError(
    const std::vector<CalibrationView>& views, const Camera& camera,
    const CalibrationOptions& calibration, double* rms_px, int* corners,
    std::string* error,
    std::vector<std::vector<Eigen::Vector2d>>* residuals = nullptr);

}  // namespace puzzlecal

#endif  // PUZZLECAL_EVIDENCE_MODEL_SELECTION_H_
