#ifndef PUZZLECAL_EVIDENCE_RECHECK_H_
#define PUZZLECAL_EVIDENCE_RECHECK_H_

// An existing calibration re-checked on new views of a board (`puzzlecal
// check`):
// - held: the new views posed with the stored intrinsics held (only the
//   poses fitted, outliers rejected as a calibration rejects them): each
//   view's RMS, and the views that fit worse than the stored calibration's
//   noise (its RMS);
// - fresh: the same model calibrated on the new views, started from the
//   stored intrinsics, with its covariance;
// - the far-field projection difference between the stored camera (A) and
//   the fresh one (B) after the best-fitting rotation
//   (evidence/evidence.h ProjectionDifference), over the field the new
//   views observe, against what the fresh fit's uncertainty (and the stored
//   camera's, when its covariance is known) gives;
// - the verdict: still-valid, drifted (by how much, in which field-angle
//   bands) or not-enough-data.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "camera/calibration_view.h"
#include "camera/camera_models.h"
#include "evidence/evidence.h"

namespace puzzlecal {

struct RecheckOptions {
  // A view fits worse than the stored calibration when its RMS with the
  // stored intrinsics held (per coordinate, inlier corners, its pose
  // fitted) exceeds this multiple of the stored RMS. Default 1.5. > 0.
  double worse_view_factor = 1.5;
  // A field-angle band has drifted when the median of its projection
  // difference exceeds both drift_sigmas times the median of its expected
  // difference (what the uncertainties alone give) and min_drift_px: the
  // first says the change is real, the second that it matters. Defaults 3
  // (the RMS of a 2-D difference of noise exceeds 3 times its expected
  // value with a probability of exp(-9)) and 0.2 px. > 0, >= 0.
  double drift_sigmas = 3.0;
  double min_drift_px = 0.2;
  // A band tells that the camera is still valid only where the new views
  // determine the projection well enough to see a drift of this size:
  // drift_sigmas times its expected median at most this. Where no band
  // does, the verdict is not-enough-data. Default 1 px. > 0.
  double max_detectable_px = 1.0;
  // The grid, the bands (band_width_deg) and the fewest samples a band
  // needs to be judged (min_bin_count).
  EvidenceOptions evidence;

  bool Check(std::string* why = nullptr) const;
};

enum class RecheckVerdict { kStillValid, kDrifted, kNotEnoughData };

// "still-valid", "drifted", "not-enough-data".
const char* RecheckVerdictName(RecheckVerdict verdict);

// The stored calibration: its camera and what its file says of it.
struct StoredCalibration {
  Camera camera;
  // Its RMS (per coordinate; 0: unknown), its parameters' standard
  // deviations (empty: unknown; 0 marks a parameter it held fixed) and
  // covariance (empty: unknown).
  double rms_px = 0;
  std::vector<double> param_stddev;
  Eigen::MatrixXd covariance;
  // The photos it was calibrated from, as its file lists them (puzzlecal
  // camera files; empty when the file does not say).
  std::vector<std::string> view_files;
};

// One new view with the stored intrinsics held.
struct RecheckView {
  std::string name;
  bool used = false;   // posed (false: `reason` says why not)
  std::string reason;  // the calibration's reason when not used
  double rms_px = 0;   // per coordinate, inliers
  int corners = 0;     // inlier corners
  bool worse = false;  // rms_px > worse_view_factor x the stored RMS
};

struct Recheck {
  RecheckVerdict verdict = RecheckVerdict::kNotEnoughData;
  // One line: why this verdict, with the figures (the drifted bands with
  // their differences and expected differences, or what is missing).
  std::string reason;

  // The held fit: per input view, and over the used views.
  bool held_ok = false;
  std::string held_error;
  std::vector<RecheckView> views;
  double held_rms_px = 0;
  int views_used = 0;
  // Views worse than the stored noise, and their fraction of the used
  // views; -1 when the stored RMS is unknown.
  int worse_views = -1;
  double worse_fraction = -1;

  // The fresh fit and the comparison.
  bool fresh_ok = false;
  std::string fresh_error;
  CalibrationResult fresh;
  double observed_angle_deg = 0;  // widest field angle of a fresh inlier
  bool stored_covariance_used = false;
  ProjectionDiff difference;  // A = the stored camera, B = the fresh one
  // Per band of difference.difference_bands: judged (enough samples and
  // fine enough to see max_detectable_px) and drifted.
  std::vector<bool> band_resolved;
  std::vector<bool> band_drifted;
  // The band with the largest median difference among the drifted ones
  // (-1: none).
  int worst_band = -1;
  double seconds = 0;
};

// Re-checks `stored` on `views` (images of stored.camera's size) with
// `calibration`'s options for both fits (the held one with every intrinsic
// held and no view-count, spread, coverage or RMS limit; the fresh one
// holding the parameters the stored calibration held, by their standard
// deviation of 0). Invalid options give not-enough-data with the reason.
Recheck RecheckCalibration(const std::vector<CalibrationView>& views,
                           const StoredCalibration& stored,
                           const CalibrationOptions& calibration,
                           const RecheckOptions& options);

// Readable text of a re-check: the held fit (RMS, worse views by name), the
// fresh fit, the projection difference by band, and the verdict line.
std::string RecheckText(const Recheck& recheck,
                        const StoredCalibration& stored);

}  // namespace puzzlecal

#endif  // PUZZLECAL_EVIDENCE_RECHECK_H_
