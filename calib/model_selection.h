#ifndef PUZZLECAL_CALIB_MODEL_SELECTION_H_
#define PUZZLECAL_CALIB_MODEL_SELECTION_H_

// Choosing the camera model by held-out error (`--model auto`): every
// candidate model is calibrated on most of the views; the views held out
// are then fitted with the intrinsics fixed (only their poses move) and the
// RMS of their corners is the candidate's held-out error. A model with more
// parameters than the lens needs fits the calibration views better but not
// the held-out ones; a model that cannot follow the lens fits neither.

#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "calib/calibration_view.h"
#include "calib/camera_models.h"

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

  bool Check(std::string* why = nullptr) const;
};

struct ModelCandidate {
  CameraModelId model = CameraModelId::kPinholeRadtan;
  int num_params = 0;
  bool ok = false;
  std::string error;          // why the candidate failed, when !ok
  double fit_rms_px = 0;      // calibration views, inliers, per coordinate
  double holdout_rms_px = 0;  // held-out views, every corner, per coordinate
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
bool HoldoutError(const std::vector<CalibrationView>& views,
                  const Camera& camera, const CalibrationOptions& calibration,
                  double* rms_px, int* corners, std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_MODEL_SELECTION_H_
