#include "evidence/model_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "evidence/evidence.h"
#include "util/angles.h"
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
  if (!(min_gain_z >= 0)) return Fail("min_gain_z must be >= 0", why);
  if (!(conventional_max_field_deg > 0 && conventional_max_field_deg <= 90)) {
    return Fail("conventional_max_field_deg must be in (0, 90]", why);
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
  CalibrationOptions options = PoseFitOptions(calibration, camera.params);
  options.outlier_k = 0;
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
// out; `corners` receives their number, `view_sse` each view's sum of
// squares.
double HoldoutRms(const CornerResiduals& residuals,
                  const std::vector<std::vector<bool>>& gross, int* corners,
                  std::vector<double>* view_sse) {
  double sum2 = 0;
  int n = 0;
  view_sse->assign(residuals.size(), 0.0);
  for (size_t v = 0; v < residuals.size(); ++v) {
    for (size_t i = 0; i < residuals[v].size(); ++i) {
      if (!residuals[v][i].allFinite() || gross[v][i]) continue;
      sum2 += residuals[v][i].squaredNorm();
      (*view_sse)[v] += residuals[v][i].squaredNorm();
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
               int offset, std::vector<CalibrationView>* fit,
               std::vector<CalibrationView>* holdout) {
  int position = 0;
  for (const CalibrationView& view : views) {
    if (static_cast<int>(view.board_points.size()) < min_corners_per_view) {
      continue;
    }
    if (position++ % options.holdout_every == offset) {
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
      c.holdout_rms_px = HoldoutRms(residuals[m], gross, &c.holdout_corners,
                                    &c.holdout_view_sse);
    }
  }
}

// Preference order: the conventional family for the field first, then fewer
// parameters, then the candidates' order.
bool Preferred(const ModelCandidate& a, const ModelCandidate& b,
               bool pinhole_field) {
  const bool a_family = CameraModelIsPinhole(a.model) == pinhole_field;
  const bool b_family = CameraModelIsPinhole(b.model) == pinhole_field;
  if (a_family != b_family) return a_family;
  return a.num_params < b.num_params;
}

// The most preferred candidate that fitted, replaced by any that beats it
// on held-out views (the lowest such), until none does. Sets `reason`.
int ChooseCandidate(const std::vector<ModelCandidate>& candidates,
                    bool pinhole_field, const ModelSelectionOptions& options,
                    std::string* reason) {
  int chosen = -1, lowest = -1;
  for (size_t k = 0; k < candidates.size(); ++k) {
    const ModelCandidate& c = candidates[k];
    if (!c.ok) continue;
    if (chosen < 0 || Preferred(c, candidates[chosen], pinhole_field)) {
      chosen = static_cast<int>(k);
    }
    if (lowest < 0 || c.holdout_rms_px < candidates[lowest].holdout_rms_px) {
      lowest = static_cast<int>(k);
    }
  }
  if (chosen < 0) return -1;
  for (size_t round = 0; round < candidates.size(); ++round) {
    int winner = -1;
    for (size_t k = 0; k < candidates.size(); ++k) {
      if (!candidates[k].ok || static_cast<int>(k) == chosen) continue;
      if (!BeatsOnHeldOutViews(candidates[k], candidates[chosen], options)) {
        continue;
      }
      if (winner < 0 ||
          candidates[k].holdout_rms_px < candidates[winner].holdout_rms_px) {
        winner = static_cast<int>(k);
      }
    }
    if (winner < 0) break;
    chosen = winner;
  }
  const ModelCandidate& c = candidates[chosen];
  if (chosen == lowest) {
    *reason = "lowest held-out RMS";
  } else {
    double z = 0;
    BeatsOnHeldOutViews(candidates[lowest], c, options, &z);
    const ModelCandidate& l = candidates[lowest];
    *reason = StringPrintf(
        "%s has the lowest held-out RMS (%.4f px against %.4f px: %.1f %% "
        "lower; view by view, %.1f standard errors %s), not lower by both "
        "%.0f %% and %.1f standard errors: a tie, which goes to %s",
        CameraModelName(l.model), l.holdout_rms_px, c.holdout_rms_px,
        100 * (1 - l.holdout_rms_px / c.holdout_rms_px), std::abs(z),
        z < 0 ? "higher" : "lower", 100 * options.min_relative_gain,
        options.min_gain_z,
        CameraModelIsPinhole(c.model) == pinhole_field &&
                CameraModelIsPinhole(l.model) != pinhole_field
            ? (pinhole_field ? "the pinhole family (every corner within "
                               "the conventional field of a pinhole lens)"
                             : "the fisheye family (corners beyond the "
                               "conventional field of a pinhole lens)")
            : "the model with fewer parameters");
  }
  return chosen;
}

}  // namespace

bool BeatsOnHeldOutViews(const ModelCandidate& challenger,
                         const ModelCandidate& incumbent,
                         const ModelSelectionOptions& options, double* z) {
  if (z != nullptr) *z = 0;
  if (!challenger.ok || !incumbent.ok ||
      challenger.holdout_view_sse.size() != incumbent.holdout_view_sse.size() ||
      challenger.holdout_view_sse.empty()) {
    return false;
  }
  // Per view, the log of the ratio of the two RMS: views of every size
  // and position weigh alike, and one view where a model extrapolates
  // wildly cannot hide how the others compare.
  size_t n = 0;
  double sum = 0, sum2 = 0;
  for (size_t v = 0; v < challenger.holdout_view_sse.size(); ++v) {
    const double a = incumbent.holdout_view_sse[v];
    const double b = challenger.holdout_view_sse[v];
    if (!(a > 0) || !(b > 0)) continue;
    const double d = 0.5 * std::log(a / b);
    sum += d;
    sum2 += d * d;
    ++n;
  }
  if (n == 0) return false;
  const double mean = sum / n;
  const double variance =
      n > 1 ? std::max(0.0, (sum2 - n * mean * mean) / (n - 1)) : 0.0;
  const double se = std::sqrt(variance / n);
  const double zz =
      se > 0 ? mean / se
             : (mean > 0 ? std::numeric_limits<double>::infinity() : 0.0);
  if (z != nullptr) *z = zz;
  return challenger.holdout_rms_px <
             incumbent.holdout_rms_px * (1 - options.min_relative_gain) &&
         n > 1 && zz > options.min_gain_z;
}

const ModelCandidate* ModelSelection::Find(CameraModelId model) const {
  for (const ModelCandidate& c : candidates) {
    if (c.model == model) return &c;
  }
  return nullptr;
}

// The splined form of a model (its richer shape), or the model itself.
CameraModelId SplinedFormOf(CameraModelId model) {
  if (model == CameraModelId::kKannalaBrandt) {
    return CameraModelId::kKannalaBrandtSplined;
  }
  if (model == CameraModelId::kKannalaBrandtNoncentral) {
    return CameraModelId::kKannalaBrandtSplinedNoncentral;
  }
  return model;
}

// What the folds of a selection share while candidates are fitted.
struct SelectionRun {
  const std::vector<CalibrationView>* views = nullptr;
  int width = 0, height = 0;
  const CalibrationOptions* calibration = nullptr;
  const ModelSelectionOptions* options = nullptr;
  std::vector<CameraModelId> models;
  std::vector<CornerResiduals> residuals;  // per candidate
  std::vector<double> fit_sum2;            // per candidate
  double widest_deg = 0;
  int usable = 0;
};

// Fits the candidates `which` (indices into run->models) on every fold; the
// first call also counts the folds and views.
void FitOverFolds(const std::vector<size_t>& which, bool count,
                  SelectionRun* run, ModelSelection* selection) {
  const ModelSelectionOptions& options = *run->options;
  const int first_fold = options.all_folds ? 0 : options.holdout_offset;
  const int last_fold =
      options.all_folds ? options.holdout_every - 1 : options.holdout_offset;
  int folds = 0;
  for (int fold = first_fold; fold <= last_fold; ++fold) {
    std::vector<CalibrationView> fit, holdout;
    run->usable =
        SplitViews(*run->views, run->calibration->min_corners_per_view, options,
                   fold, &fit, &holdout);
    if (holdout.empty()) continue;
    ++folds;
    if (count) {
      ++selection->folds;
      selection->fit_views = static_cast<int>(fit.size());
      selection->holdout_views += static_cast<int>(holdout.size());
    }
    for (size_t m : which) {
      ModelCandidate& total = selection->candidates[m];
      if (!total.ok) continue;
      CornerResiduals fold_residuals;
      const ModelCandidate c = FitCandidate(
          run->models[m], fit, holdout, run->width, run->height,
          *run->calibration, options, &run->widest_deg, &fold_residuals);
      total.seconds += c.seconds;
      total.holdout_views += c.holdout_views;
      if (!c.ok) {
        total.ok = false;
        total.error =
            folds > 1 || options.all_folds
                ? StringPrintf("fold %d (%zu views fitted): ", fold + 1,
                               fit.size()) +
                      c.error
                : c.error;
        if (c.error.rfind("skipped", 0) == 0) total.error = c.error;
        continue;
      }
      run->fit_sum2[m] += c.fit_rms_px * c.fit_rms_px;
      run->residuals[m].insert(run->residuals[m].end(), fold_residuals.begin(),
                               fold_residuals.end());
    }
  }
}

// Compares the fitted candidates and chooses among them.
void Choose(SelectionRun* run, ModelSelection* selection) {
  for (size_t m = 0; m < run->models.size(); ++m) {
    ModelCandidate& c = selection->candidates[m];
    c.fit_rms_px = std::sqrt(run->fit_sum2[m] / std::max(1, selection->folds));
    if (!c.ok) run->residuals[m].clear();
  }
  CompareOnTheSameCorners(run->residuals, *run->options, selection);
  selection->widest_field_deg = run->widest_deg;
  // Pinhole candidates do not report their field (a fisheye candidate's
  // poses do); without a fisheye candidate the field is taken as
  // conventional.
  selection->pinhole_field =
      run->widest_deg <= run->options->conventional_max_field_deg;
  selection->chosen =
      ChooseCandidate(selection->candidates, selection->pinhole_field,
                      *run->options, &selection->reason);
}

// The largest 10-degree band median of the far-field difference between the
// calibrations of the two halves of the views (evidence/evidence.h
// CrossValidate) for `model` calibrated on all `views`, over the field its
// corners reach; false when a calibration fails.
bool WorstHalvesBandPx(const std::vector<CalibrationView>& views,
                       CameraModelId model, int width, int height,
                       const CalibrationOptions& calibration, double* worst) {
  CalibrationResult result;
  std::string why;
  if (!Calibrate(views, model, width, height, calibration, &result, &why)) {
    return false;
  }
  double field_deg = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    if (!result.view_used[v]) continue;
    for (const Eigen::Vector3d& point : views[v].board_points) {
      const Eigen::Vector3d p = result.cam_from_board[v] * point;
      field_deg =
          std::max(field_deg, std::atan2(p.head<2>().norm(), p.z()) / kDegree);
    }
  }
  const CrossValidation halves =
      CrossValidate(views, result, calibration, field_deg, EvidenceOptions());
  if (!halves.ok) return false;
  *worst = 0;
  for (const AngleBand& band : halves.difference_bands) {
    if (band.count > 0) *worst = std::max(*worst, band.median);
  }
  return true;
}

// A splined model chosen over the model it refines must also make the
// halves of the views agree no worse than that model does: its extra
// freedom must not buy the held-out gain with a projection the views
// determine less well (on the deltille photos the splined non-central model
// fitted the held-out views 2.4 % better than the non-central one while its
// halves differed by 0.30 px against 0.15 px at 110 degrees). Else the
// model it refines is chosen, and the reason says why.
void CheckSplinedChoiceOnHalves(const std::vector<CalibrationView>& views,
                                int width, int height,
                                const CalibrationOptions& calibration,
                                int leader, ModelSelection* selection) {
  if (selection->chosen < 0 || leader < 0 || selection->chosen == leader) {
    return;
  }
  ModelCandidate& spline = selection->candidates[selection->chosen];
  ModelCandidate& base = selection->candidates[leader];
  if (!CameraModelIsSplined(spline.model)) return;
  if (!WorstHalvesBandPx(views, spline.model, width, height, calibration,
                         &spline.halves_worst_px) ||
      !WorstHalvesBandPx(views, base.model, width, height, calibration,
                         &base.halves_worst_px)) {
    return;  // the halves cannot say; the held-out views decided
  }
  if (spline.halves_worst_px <= base.halves_worst_px) {
    selection->reason += StringPrintf(
        "; its halves agree as well (largest band median %.3f px against "
        "%.3f px)",
        spline.halves_worst_px, base.halves_worst_px);
    return;
  }
  selection->reason = StringPrintf(
      "%s fits the held-out views better (%.4f against %.4f px) but its "
      "halves agree worse (largest band median %.3f px against %.3f px): "
      "the views do not determine its extra shape well enough",
      CameraModelName(spline.model), spline.holdout_rms_px, base.holdout_rms_px,
      spline.halves_worst_px, base.halves_worst_px);
  selection->chosen = leader;
}

// When the candidate preferred for the field failed on a fold (not
// skipped), the others were compared without it: a fold of few views can
// be too few or too alike for a model that calibrates on all of them (five
// renders of a pinhole lens: pinhole-radtan failed on the 4 views of one
// fold, "all views show the board at nearly the same orientation", and
// kannala-brandt was chosen by default). Then that candidate is chosen
// without a comparison, when it calibrates on all the views.
void FallBackToThePreferredModel(const std::vector<CalibrationView>& views,
                                 int width, int height,
                                 const CalibrationOptions& calibration,
                                 const ModelSelectionOptions& options,
                                 ModelSelection* selection) {
  int preferred = -1;
  for (size_t k = 0; k < selection->candidates.size(); ++k) {
    const ModelCandidate& c = selection->candidates[k];
    if (!c.ok && c.error.rfind("skipped", 0) == 0) continue;
    if (preferred < 0 || Preferred(c, selection->candidates[preferred],
                                   selection->pinhole_field)) {
      preferred = static_cast<int>(k);
    }
  }
  if (preferred < 0 || selection->candidates[preferred].ok) return;
  const ModelCandidate& c = selection->candidates[preferred];
  CalibrationOptions all = calibration;
  all.compute_covariance = false;
  CalibrationResult result;
  std::string why;
  if (!Calibrate(views, c.model, width, height, all, &result, &why)) {
    return;  // it fails on all views too: the comparison stands
  }
  selection->reason = StringPrintf(
      "model selection could not compare the models: %s, the model for "
      "corners %s %.0f deg of the axis, failed on %s%s; it calibrates on all "
      "%zu views and is used without a comparison (more views, at other "
      "positions and tilts, let every fold calibrate it)",
      CameraModelName(c.model), selection->pinhole_field ? "within" : "beyond",
      options.conventional_max_field_deg,
      c.error.rfind("fold ", 0) == 0 ? "" : "a fold: ", c.error.c_str(),
      views.size());
  selection->chosen = preferred;
  selection->compared = false;
}

bool SelectModel(const std::vector<CalibrationView>& views, int width,
                 int height, const CalibrationOptions& calibration,
                 const ModelSelectionOptions& options,
                 ModelSelection* selection, std::string* error) {
  *selection = ModelSelection();
  selection->min_relative_gain = options.min_relative_gain;
  std::string why;
  if (!options.Check(&why))
    return Fail("model selection options: " + why, error);
  // Too few views fail every candidate's folds alike: said once, in the
  // calibration's words.
  const size_t needed = static_cast<size_t>(calibration.min_views) + 1;
  if (views.size() < needed) {
    return Fail(StringPrintf("only %zu usable view%s (need at least %zu to "
                             "compare models, which fits on some views and "
                             "holds others out; %d for one named model): add "
                             "views of the board at different positions and "
                             "tilted by 30 degrees or more",
                             views.size(), views.size() == 1 ? "" : "s", needed,
                             calibration.min_views),
                error);
  }
  SelectionRun run;
  run.views = &views;
  run.width = width;
  run.height = height;
  run.calibration = &calibration;
  run.options = &options;
  run.models = CandidateModels(options);
  run.residuals.resize(run.models.size());
  run.fit_sum2.assign(run.models.size(), 0.0);
  // The splined candidates refine the shape of kannala-brandt (or of its
  // non-central form): each is fitted only when the model it refines leads
  // after the others, and then has to beat it on the held-out views. (They
  // cost 5 to 15 times a kannala-brandt fit; on a lens another model leads,
  // a spline on kannala-brandt is not the way forward.)
  std::vector<size_t> first, splined;
  for (size_t m = 0; m < run.models.size(); ++m) {
    ModelCandidate candidate;
    candidate.model = run.models[m];
    candidate.num_params = CameraModelNumParams(run.models[m]);
    // A splined candidate takes part only once it has been fitted (below):
    // until then it must not enter the comparison of the others.
    candidate.ok = !CameraModelIsSplined(run.models[m]);
    selection->candidates.push_back(candidate);
    (CameraModelIsSplined(run.models[m]) ? splined : first).push_back(m);
  }
  selection->folds = 0;
  FitOverFolds(first, /*count=*/true, &run, selection);
  if (selection->holdout_views == 0) {
    return Fail("model selection: too few views to hold any out (" +
                    std::to_string(run.usable) + ")",
                error);
  }
  Choose(&run, selection);
  const CameraModelId leader =
      selection->chosen >= 0 ? selection->candidates[selection->chosen].model
                             : CameraModelId::kPinholeRadtan;
  std::vector<size_t> refine;
  for (size_t m : splined) {
    if (first.empty() || SplinedFormOf(leader) == run.models[m]) {
      selection->candidates[m].ok = true;
      refine.push_back(m);
      continue;
    }
    ModelCandidate& c = selection->candidates[m];
    c.ok = false;
    c.error = selection->chosen >= 0
                  ? std::string("skipped: it refines ") +
                        (run.models[m] == CameraModelId::kKannalaBrandtSplined
                             ? "kannala-brandt"
                             : "kannala-brandt-noncentral") +
                        ", which does not lead (" + CameraModelName(leader) +
                        " does)"
                  : "skipped: no other candidate could be calibrated";
  }
  if (!refine.empty()) {
    const int leader = first.empty() ? -1 : selection->chosen;
    if (first.empty()) selection->folds = 0;
    FitOverFolds(refine, /*count=*/first.empty(), &run, selection);
    Choose(&run, selection);
    CheckSplinedChoiceOnHalves(views, width, height, calibration, leader,
                               selection);
  }
  FallBackToThePreferredModel(views, width, height, calibration, options,
                              selection);
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
  table << "model selection: " << folds << (folds == 1 ? " fold" : " folds")
        << " of " << fit_views << " views fitted, " << holdout_views
        << " held out in all (poses fitted, intrinsics fixed)";
  if (widest_field_deg > 0) {
    table << StringPrintf("; corners reach %.1f deg off the axis",
                          widest_field_deg);
  }
  if (holdout_detection_errors > 0) {
    table << "; " << holdout_detection_errors
          << " held-out corner(s) off for every model left out as detection "
             "errors";
  }
  table << "\n";
  table
      << "  model                             params  fit RMS   held-out RMS  "
         "corners  time\n";
  for (size_t k = 0; k < candidates.size(); ++k) {
    const ModelCandidate& c = candidates[k];
    if (c.ok) {
      table << StringPrintf("%s %-33s %6d  %7.4f   %12.4f  %7d  %.1f s\n",
                            static_cast<int>(k) == chosen ? "*" : " ",
                            CameraModelName(c.model), c.num_params,
                            c.fit_rms_px, c.holdout_rms_px, c.holdout_corners,
                            c.seconds);
    } else {
      table << StringPrintf(
                   "  %-33s %6d  %s (%.1f s): ", CameraModelName(c.model),
                   c.num_params,
                   c.error.rfind("skipped", 0) == 0 ? "not fitted" : "failed",
                   c.seconds)
            << c.error << "\n";
    }
  }
  if (chosen >= 0) {
    table << "chosen: " << CameraModelName(candidates[chosen].model) << " ("
          << reason << ")\n";
  }
  return table.str();
}

}  // namespace puzzlecal
