#include "evidence/model_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "util/failure.h"
#include "util/statistics.h"
#include "util/string_format.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

// The widest angle from the optical axis of a used corner under the fitted
// poses, degrees.
double WidestFieldDeg(const std::vector<CalibrationView>& views,
                      const CalibrationResult& result) {
  double widest = 0;
  for (size_t v = 0; v < views.size() && v < result.view_used.size(); ++v) {
    if (!result.view_used[v]) continue;
    for (const Eigen::Vector3d& board : views[v].board_points) {
      const Eigen::Vector3d point = result.cam_from_board[v] * board;
      widest = std::max(
          widest, std::atan2(point.head<2>().norm(), point.z()) * 180.0 / M_PI);
    }
  }
  return widest;
}

}  // namespace

bool ModelSelectionOptions::Check(std::string* why) const {
  if (holdout_every < 2) return Fail("holdout_every must be >= 2", why);
  if (holdout_offset < 0 || holdout_offset >= holdout_every) {
    return Fail("holdout_offset must be in [0, holdout_every)", why);
  }
  for (const std::string& name : candidates) {
    CameraModelId id;
    if (!CameraModelIdFromName(name, &id)) {
      return Fail("unknown candidate model '" + name + "' (choose from " +
                      CameraModelNames() + ")",
                  why);
    }
  }
  if (!(pinhole_max_field_deg > 0 && pinhole_max_field_deg <= 90)) {
    return Fail("pinhole_max_field_deg must be in (0, 90]", why);
  }
  if (!(min_relative_gain >= 0)) {
    return Fail("min_relative_gain must be >= 0", why);
  }
  if (!(gross_error_k > 0)) return Fail("gross_error_k must be > 0", why);
  if (!(gross_error_floor_px >= 0)) {
    return Fail("gross_error_floor_px must be >= 0", why);
  }
  return true;
}

bool HoldoutError(const std::vector<CalibrationView>& views,
                  const Camera& camera, const CalibrationOptions& calibration,
                  double* rms_px, int* corners, std::string* error,
                  std::vector<std::vector<Eigen::Vector2d>>* residuals) {
  // Calibrate with every intrinsic held: only the poses move. The checks
  // meant for a calibration (views, spread, coverage, RMS) do not apply to
  // a pose fit; no corner is dropped, so a model that cannot follow the
  // lens pays for all of its corners.
  CalibrationOptions options = calibration;
  options.initial_params = camera.params;
  options.fix_focal_length = true;
  options.fix_principal_point = true;
  options.fix_distortion = true;
  options.outlier_k = 0;
  options.min_views = 1;
  options.min_orientation_spread_deg = 0;
  options.min_coverage = 0;
  options.max_rms_px = std::numeric_limits<double>::max();
  options.compute_covariance = false;
  CalibrationResult result;
  if (!Calibrate(views, camera.model, camera.width, camera.height, options,
                 &result, error)) {
    return false;
  }
  double sum2 = 0;
  int n = 0;
  if (residuals != nullptr) {
    residuals->assign(views.size(), {});
    for (size_t v = 0; v < views.size(); ++v) {
      (*residuals)[v].assign(
          views[v].board_points.size(),
          Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN()));
    }
  }
  for (size_t v = 0; v < result.residuals.size(); ++v) {
    if (!result.view_used[v]) continue;
    for (size_t i = 0; i < result.residuals[v].size(); ++i) {
      if (!result.inlier[v][i]) continue;
      sum2 += result.residuals[v][i].squaredNorm();
      ++n;
      if (residuals != nullptr) (*residuals)[v][i] = result.residuals[v][i];
    }
  }
  *corners = n;
  *rms_px = n > 0 ? std::sqrt(sum2 / (2.0 * n)) : 0.0;
  return n > 0 || Fail("no held-out corner projects", error);
}

namespace {

using CornerResiduals = std::vector<std::vector<Eigen::Vector2d>>;

// Which held-out corners are gross for every candidate (detection errors):
// [view][corner]. `residuals` holds each successful candidate's.
std::vector<std::vector<bool>> DetectionErrors(
    const std::vector<CornerResiduals>& residuals,
    const ModelSelectionOptions& options) {
  std::vector<std::vector<bool>> gross;
  if (residuals.empty()) return gross;
  gross.resize(residuals[0].size());
  for (size_t v = 0; v < residuals[0].size(); ++v) {
    gross[v].assign(residuals[0][v].size(), true);
  }
  for (const CornerResiduals& candidate : residuals) {
    std::vector<double> coordinates;
    for (const auto& view : candidate) {
      for (const Eigen::Vector2d& r : view) {
        if (!r.allFinite()) continue;
        coordinates.push_back(r.x());
        coordinates.push_back(r.y());
      }
    }
    const double threshold =
        std::max(options.gross_error_k * RobustSigmaAboutZero(coordinates),
                 options.gross_error_floor_px);
    for (size_t v = 0; v < candidate.size(); ++v) {
      for (size_t i = 0; i < candidate[v].size(); ++i) {
        // A corner the candidate cannot project says nothing about it.
        const Eigen::Vector2d& r = candidate[v][i];
        if (r.allFinite() && r.norm() <= threshold) gross[v][i] = false;
      }
    }
  }
  return gross;
}

// The RMS per coordinate of the corners that project, detection errors left
// out; `corners` receives their number.
double HoldoutRms(const CornerResiduals& residuals,
                  const std::vector<std::vector<bool>>& gross, int* corners) {
  double sum2 = 0;
  int n = 0;
  for (size_t v = 0; v < residuals.size(); ++v) {
    for (size_t i = 0; i < residuals[v].size(); ++i) {
      if (!residuals[v][i].allFinite() || gross[v][i]) continue;
      sum2 += residuals[v][i].squaredNorm();
      ++n;
    }
  }
  *corners = n;
  return n > 0 ? std::sqrt(sum2 / (2.0 * n)) : 0.0;
}

// The candidate models: options.candidates, or every model; fisheye models
// first (the widest field angle they see tells whether a pinhole model can
// hold the views at all).
std::vector<CameraModelId> CandidateModels(
    const ModelSelectionOptions& options) {
  std::vector<CameraModelId> models;
  if (options.candidates.empty()) {
    models.assign(kAllCameraModels.begin(), kAllCameraModels.end());
  } else {
    for (const std::string& name : options.candidates) {
      CameraModelId id;
      CameraModelIdFromName(name, &id);
      models.push_back(id);
    }
  }
  std::stable_partition(models.begin(), models.end(), [](CameraModelId id) {
    return !CameraModelIsPinhole(id);
  });
  return models;
}

// Every holdout_every-th view with enough corners is held out. Returns the
// number of such views.
int SplitViews(const std::vector<CalibrationView>& views,
               int min_corners_per_view, const ModelSelectionOptions& options,
               std::vector<CalibrationView>* fit,
               std::vector<CalibrationView>* holdout) {
  int position = 0;
  for (const CalibrationView& view : views) {
    if (static_cast<int>(view.board_points.size()) < min_corners_per_view) {
      continue;
    }
    if (position++ % options.holdout_every == options.holdout_offset) {
      holdout->push_back(view);
    } else {
      fit->push_back(view);
    }
  }
  return position;
}

// One candidate: calibrated on the fit views, then its held-out error
// (`residuals` per held-out corner). `widest_deg` is the widest field angle
// a fisheye candidate saw so far (it skips pinhole candidates beyond their
// field) and grows with this one's.
ModelCandidate FitCandidate(CameraModelId model,
                            const std::vector<CalibrationView>& fit,
                            const std::vector<CalibrationView>& holdout,
                            int width, int height,
                            const CalibrationOptions& calibration,
                            const ModelSelectionOptions& options,
                            double* widest_deg, CornerResiduals* residuals) {
  const Timer timer;
  ModelCandidate candidate;
  candidate.model = model;
  candidate.num_params = CameraModelNumParams(model);
  candidate.holdout_views = static_cast<int>(holdout.size());
  CalibrationOptions fit_options = calibration;
  fit_options.compute_covariance = false;
  CalibrationResult result;
  std::string fit_error;
  if (CameraModelIsPinhole(model) &&
      *widest_deg > options.pinhole_max_field_deg) {
    candidate.error = StringPrintf(
        "skipped: the corners reach %.1f deg off the axis "
        "(limit %.1f deg for a pinhole model)",
        *widest_deg, options.pinhole_max_field_deg);
  } else if (!Calibrate(fit, model, width, height, fit_options, &result,
                        &fit_error)) {
    candidate.error = "calibration failed: " + fit_error;
  } else {
    candidate.fit_rms_px = result.rms_px;
    if (!CameraModelIsPinhole(model)) {
      *widest_deg = std::max(*widest_deg, WidestFieldDeg(fit, result));
    }
    std::string holdout_error;
    if (HoldoutError(holdout, result.camera, calibration,
                     &candidate.holdout_rms_px, &candidate.holdout_corners,
                     &holdout_error, residuals)) {
      candidate.ok = true;
    } else {
      candidate.error = "held-out fit failed: " + holdout_error;
    }
  }
  candidate.seconds = timer.Seconds();
  return candidate;
}

// The candidates compared on the same corners: those that are not
// detection errors.
void CompareOnTheSameCorners(const std::vector<CornerResiduals>& residuals,
                             const ModelSelectionOptions& options,
                             ModelSelection* selection) {
  std::vector<CornerResiduals> fitted;
  for (size_t m = 0; m < residuals.size(); ++m) {
    if (selection->candidates[m].ok) fitted.push_back(residuals[m]);
  }
  const std::vector<std::vector<bool>> gross = DetectionErrors(fitted, options);
  for (const auto& view : gross) {
    selection->holdout_detection_errors +=
        static_cast<int>(std::count(view.begin(), view.end(), true));
  }
  for (size_t m = 0; m < residuals.size(); ++m) {
    ModelCandidate& c = selection->candidates[m];
    if (c.ok) {
      c.holdout_rms_px = HoldoutRms(residuals[m], gross, &c.holdout_corners);
    }
  }
}

// The lowest held-out error; a model with more parameters must beat the
// best one with fewer by min_relative_gain. -1 when no candidate succeeded.
int ChooseCandidate(const std::vector<ModelCandidate>& candidates,
                    double min_relative_gain) {
  double best = std::numeric_limits<double>::infinity();
  for (const ModelCandidate& c : candidates) {
    if (c.ok) best = std::min(best, c.holdout_rms_px);
  }
  int chosen = -1;
  for (size_t k = 0; k < candidates.size(); ++k) {
    const ModelCandidate& c = candidates[k];
    if (!c.ok || c.holdout_rms_px > best * (1 + min_relative_gain)) continue;
    if (chosen < 0 || c.num_params < candidates[chosen].num_params ||
        (c.num_params == candidates[chosen].num_params &&
         c.holdout_rms_px < candidates[chosen].holdout_rms_px)) {
      chosen = static_cast<int>(k);
    }
  }
  return chosen;
}

}  // namespace

bool SelectModel(const std::vector<CalibrationView>& views, int width,
                 int height, const CalibrationOptions& calibration,
                 const ModelSelectionOptions& options,
                 ModelSelection* selection, std::string* error) {
  *selection = ModelSelection();
  selection->min_relative_gain = options.min_relative_gain;
  std::string why;
  if (!options.Check(&why))
    return Fail("model selection options: " + why, error);
  const std::vector<CameraModelId> models = CandidateModels(options);
  std::vector<CalibrationView> fit, holdout;
  const int usable = SplitViews(views, calibration.min_corners_per_view,
                                options, &fit, &holdout);
  selection->fit_views = static_cast<int>(fit.size());
  selection->holdout_views = static_cast<int>(holdout.size());
  if (holdout.empty()) {
    return Fail("model selection: too few views to hold any out (" +
                    std::to_string(usable) + ")",
                error);
  }
  double widest_deg = 0;
  std::vector<CornerResiduals> residuals(models.size());
  for (size_t m = 0; m < models.size(); ++m) {
    selection->candidates.push_back(FitCandidate(models[m], fit, holdout, width,
                                                 height, calibration, options,
                                                 &widest_deg, &residuals[m]));
  }
  CompareOnTheSameCorners(residuals, options, selection);
  selection->chosen =
      ChooseCandidate(selection->candidates, options.min_relative_gain);
  if (selection->chosen < 0) {
    std::string reasons;
    for (const ModelCandidate& c : selection->candidates) {
      reasons += std::string("; ") + CameraModelName(c.model) + ": " + c.error;
    }
    return Fail(
        "model selection: no candidate model could be calibrated" + reasons,
        error);
  }
  return true;
}

std::string ModelSelection::Table() const {
  std::ostringstream table;
  table << "model selection: " << fit_views << " views fitted, "
        << holdout_views << " held out (poses fitted, intrinsics fixed)";
  if (holdout_detection_errors > 0) {
    table << "; " << holdout_detection_errors
          << " held-out corner(s) off for every model left out as detection "
             "errors";
  }
  table << "\n";
  table << "  model                       params  fit RMS   held-out RMS  "
           "corners  time\n";
  for (size_t k = 0; k < candidates.size(); ++k) {
    const ModelCandidate& c = candidates[k];
    if (c.ok) {
      table << StringPrintf("%s %-27s %6d  %7.4f   %12.4f  %7d  %.1f s\n",
                            static_cast<int>(k) == chosen ? "*" : " ",
                            CameraModelName(c.model), c.num_params,
                            c.fit_rms_px, c.holdout_rms_px, c.holdout_corners,
                            c.seconds);
    } else {
      table << StringPrintf("  %-27s %6d  failed (%.1f s): ",
                            CameraModelName(c.model), c.num_params, c.seconds)
            << c.error << "\n";
    }
  }
  if (chosen >= 0) {
    table << "chosen: " << CameraModelName(candidates[chosen].model)
          << " (lowest held-out RMS; candidates within "
          << static_cast<int>(std::lround(100 * min_relative_gain))
          << " % of it go to the one with fewer parameters)\n";
  }
  return table.str();
}

}  // namespace puzzlecal
