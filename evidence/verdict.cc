#include "evidence/verdict.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "util/failure.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

struct Finding {
  VerdictKind kind;
  std::string text;
};

constexpr char kViewErrorsNextStep[] =
    "drop or retake those photos: a view-level error moves the whole view, "
    "not single corners (keep the board flat and still, the focus fixed)";

constexpr char kInconsistentViewsNextStep[] =
    "the photos do not share one camera: the focal length changed between "
    "them (autofocus, zoom) or the board was swapped. Fix focus and zoom "
    "(autofocus off), use one board, and retake; or calibrate the photos "
    "taken alike on their own";

// True when the bin's mean (radial or tangential) is systematic.
bool Systematic(const ResidualBin& bin, int min_count,
                const VerdictOptions& options, double* worst_px) {
  if (bin.count < min_count) return false;
  bool found = false;
  *worst_px = 0;
  for (const auto& [mean, se] :
       {std::pair<double, double>(bin.mean_radial_px, bin.se_radial_px),
        std::pair<double, double>(bin.mean_tangential_px,
                                  bin.se_tangential_px)}) {
    if (std::abs(mean) > options.residual_se_factor * se &&
        std::abs(mean) > options.residual_floor_px) {
      found = true;
      *worst_px = std::max(*worst_px, std::abs(mean));
    }
  }
  return found;
}

std::string BinText(const ResidualBin& bin, const char* unit, bool metres) {
  const bool radial =
      std::abs(bin.mean_radial_px) / std::max(1e-12, bin.se_radial_px) >=
      std::abs(bin.mean_tangential_px) / std::max(1e-12, bin.se_tangential_px);
  const double mean = radial ? bin.mean_radial_px : bin.mean_tangential_px;
  const double se = radial ? bin.se_radial_px : bin.se_tangential_px;
  return std::string(radial ? "radial" : "tangential") + " residual mean " +
         StringPrintf("%+.3f +- %.3f px", mean, se) + " at " +
         (metres ? StringPrintf("%.2f-%.2f ", bin.lo, bin.hi)
                 : StringPrintf("%.0f-%.0f ", bin.lo, bin.hi)) +
         unit + StringPrintf(" (n=%d)", bin.count);
}

// " (the median of 5 splits of the views)" when the cross-validation's
// figures are the median split's of several (CrossValidation), else "".
std::string OverSplits(const CrossValidation& cv) {
  return cv.splits > 1 ? StringPrintf(" (the median of %d splits of the views)",
                                      cv.splits)
                       : std::string();
}

// The judged band (min_count samples or more, a positive prediction) where
// the halves agree best: the smallest ratio of difference to prediction.
// Null when no band is judged; `num_bands` (optional) counts them.
const AngleBand* BestAgreeingBand(const CrossValidation& cv, int min_count,
                                  double* ratio, int* num_bands = nullptr) {
  const AngleBand* best = nullptr;
  int bands = 0;
  for (size_t b = 0; b < cv.difference_bands.size(); ++b) {
    const AngleBand& d = cv.difference_bands[b];
    const AngleBand& e = cv.expected_bands[b];
    if (d.count < min_count || !(e.median > 0)) continue;
    ++bands;
    if (best == nullptr || d.median / e.median < *ratio) {
      best = &d;
      *ratio = d.median / e.median;
    }
  }
  if (num_bands != nullptr) *num_bands = bands;
  return best;
}

// The factor by which the halves differ more than predicted in every judged
// band (VerdictOptions::halves_min_bands): the smallest band ratio, at least
// 1; 1 with fewer judged bands.
double HalvesScale(const CrossValidation& cv, int min_count,
                   const VerdictOptions& options) {
  if (!cv.ok || options.halves_min_bands == 0) return 1.0;
  int bands = 0;
  double smallest = 0;
  BestAgreeingBand(cv, min_count, &smallest, &bands);
  if (bands < options.halves_min_bands) return 1.0;
  return std::max(1.0, smallest);
}

// ---- the findings of MakeVerdict, one function per kind of evidence ----

// Inconsistent views: the halves differ by more than shared corner errors
// can explain in every band (VerdictOptions::halves_max_scale), by a
// difference that matters in pixels.
void AddUniformHalvesFinding(const CrossValidation& cv, double halves_scale,
                             int min_count, const VerdictOptions& options,
                             std::vector<Finding>* findings) {
  if (!cv.ok || halves_scale <= options.halves_max_scale) return;
  double best_ratio = 0;
  const AngleBand* best = BestAgreeingBand(cv, min_count, &best_ratio);
  if (best == nullptr || !(best->median > options.halves_uniform_floor_px)) {
    return;
  }
  findings->push_back(
      {VerdictKind::kInconsistentViews,
       "the two halves of the views" + OverSplits(cv) +
           StringPrintf(" differ %.1f times more than their uncertainty "
                        "predicts in every field-angle band (where they "
                        "agree best, at ",
                        halves_scale) +
           BandLabel(*best) +
           StringPrintf(": %.2f px against %.2f px predicted); corner "
                        "errors shared within views explain up to about "
                        "%.0f times, so the halves do not see one camera",
                        best->median, best->median / halves_scale,
                        options.halves_max_scale)});
}

// Model error: a field-angle band where the halves differ far beyond their
// (scaled) predicted difference.
void AddHalvesFindings(const CrossValidation& cv, double halves_scale,
                       int min_count, const VerdictOptions& options,
                       std::vector<Finding>* findings) {
  if (!cv.ok) return;
  double worst_ratio = 0;
  std::string halves_text;
  for (size_t b = 0; b < cv.difference_bands.size(); ++b) {
    const AngleBand& d = cv.difference_bands[b];
    const AngleBand& e = cv.expected_bands[b];
    if (d.count < min_count || !(e.median > 0)) continue;
    const double ratio = d.median / (halves_scale * e.median);
    if (ratio > options.halves_factor && d.median > options.halves_floor_px &&
        ratio > worst_ratio) {
      worst_ratio = ratio;
      halves_text = "the two halves of the views" + OverSplits(cv) +
                    StringPrintf(" differ by %.3f px (median) at ", d.median) +
                    BandLabel(d) +
                    StringPrintf(
                        ", %.1f times what their uncertainty predicts "
                        "(%.3f px)",
                        ratio, halves_scale * e.median);
      if (halves_scale > 1) {
        halves_text += StringPrintf(
            ", the prediction scaled by %.2f, the best-agreeing band's "
            "excess",
            halves_scale);
      }
    }
  }
  if (halves_text.empty()) return;
  if (cv.intrinsics_dof > 0) {
    const double z = ChiSquareZ(
        cv.intrinsics_chi2 / (halves_scale * halves_scale), cv.intrinsics_dof);
    if (options.halves_min_z > 0 && z <= options.halves_min_z) return;
    halves_text += StringPrintf(
        "; their intrinsics differ with chi-square %.1f for %d parameters "
        "(z = %.1f)",
        cv.intrinsics_chi2 / (halves_scale * halves_scale), cv.intrinsics_dof,
        z);
  }
  findings->push_back({VerdictKind::kModelError, halves_text});
}

// Model error: binned residual means far from zero (by field angle, by
// board distance) and errors that grow as the board comes closer. Returns
// whether the errors depend on closeness (for the model to suggest).
bool AddSystematicResidualFindings(const SystematicResiduals& residuals,
                                   int min_count, const VerdictOptions& options,
                                   std::vector<Finding>* findings) {
  double worst_angle = 0, worst_distance = 0;
  const ResidualBin* angle_bin = nullptr;
  const ResidualBin* distance_bin = nullptr;
  for (const ResidualBin& bin : residuals.by_angle) {
    double worst;
    if (Systematic(bin, min_count, options, &worst) && worst > worst_angle) {
      worst_angle = worst;
      angle_bin = &bin;
    }
  }
  const size_t nd = residuals.by_distance.size();
  for (size_t b = 0; b < nd; ++b) {
    const ResidualBin& bin = residuals.by_distance[b];
    double worst;
    if (Systematic(bin, min_count, options, &worst) && worst > worst_distance) {
      worst_distance = worst;
      distance_bin = &bin;
    }
  }
  // Errors that grow as the board comes closer: the nearest bin's residual
  // RMS well above the farthest's.
  double near_rms = 0, far_rms = 0;
  const ResidualBin* nearest = nullptr;
  for (const ResidualBin& bin : residuals.by_distance) {
    if (bin.count < min_count) continue;
    if (nearest == nullptr) {
      nearest = &bin;
      near_rms = bin.rms_px;
    }
    far_rms = bin.rms_px;
  }
  double nearest_worst = 0;
  const bool nearest_systematic =
      nd >= 2 && nearest != nullptr &&
      Systematic(*nearest, min_count, options, &nearest_worst);
  const bool rms_grows = nd >= 2 && far_rms > 0 &&
                         near_rms > options.closeness_rms_ratio * far_rms;
  if (angle_bin != nullptr) {
    findings->push_back({VerdictKind::kModelError,
                         "systematic " + BinText(*angle_bin, "deg", false)});
  }
  if (distance_bin != nullptr &&
      !(nearest_systematic && distance_bin == nearest)) {
    findings->push_back({VerdictKind::kModelError,
                         "systematic " + BinText(*distance_bin, "m", true)});
  }
  const bool other_model_error = !findings->empty();
  if (nearest_systematic) {
    findings->push_back(
        {VerdictKind::kModelError,
         "the corners closest to the camera carry a systematic error: " +
             BinText(*nearest, "m", true)});
  } else if (rms_grows &&
             (other_model_error || near_rms > options.closeness_floor_px)) {
    findings->push_back(
        {VerdictKind::kModelError,
         StringPrintf(
             "the residuals grow as the board comes closer (RMS %.3f px "
             "for the nearest corners, %.3f px for the farthest)",
             near_rms, far_rms)});
  }
  return nearest_systematic || rms_grows;
}

// How one used view's corners fit (standing kFits, to be judged): the RMS
// of its inliers, and its rejected corners with the largest of their
// errors.
ViewJudgement FitOfView(const CalibrationResult& result, size_t v) {
  ViewJudgement fit;
  fit.standing = ViewStanding::kFits;
  double sum2 = 0;
  int inliers = 0;
  const std::vector<Eigen::Vector2d>& residuals = result.residuals[v];
  for (size_t i = 0; i < residuals.size(); ++i) {
    const bool inlier = v >= result.inlier.size() ||
                        i >= result.inlier[v].size() || result.inlier[v][i];
    ++fit.corners;
    if (inlier) {
      sum2 += residuals[i].squaredNorm();
      ++inliers;
    } else {
      ++fit.rejected;
      fit.worst_rejected_px =
          std::max(fit.worst_rejected_px, residuals[i].norm());
    }
  }
  fit.inlier_rms_px = inliers > 0 ? std::sqrt(sum2 / (2.0 * inliers)) : 0.0;
  return fit;
}

// Bad detections: too many outliers, or a few views far worse than the
// median view (their inliers fit badly, many of their corners were rejected,
// or the rejection emptied them). Views whose few rejected corners were
// handled go to `notes`. Every view's standing goes to verdict->views
// (view-level errors are marked by AddViewErrorFindings' caller). Returns
// the number of views that stand out.
int AddBadDetectionFindings(const CalibrationResult& result,
                            const std::vector<int>& view_errors,
                            const VerdictOptions& options,
                            std::vector<Finding>* findings,
                            std::vector<std::string>* notes, Verdict* verdict) {
  // Views by their file name, as every finding and table names them.
  auto view_label = [&](size_t v) {
    return v < result.view_name.size() && !result.view_name[v].empty()
               ? result.view_name[v]
               : "view " + std::to_string(v);
  };
  auto is_view_error = [&](size_t v) {
    return std::find(view_errors.begin(), view_errors.end(),
                     static_cast<int>(v)) != view_errors.end();
  };
  // The corners of views with a view-level error are that view's matter.
  int all_corners = result.num_corners_used + result.num_outliers;
  int num_outliers = result.num_outliers;
  for (int v : view_errors) {
    if (v >= static_cast<int>(result.inlier.size())) continue;
    for (bool inlier : result.inlier[v]) {
      --all_corners;
      if (!inlier) --num_outliers;
    }
  }
  const double outlier_fraction =
      all_corners > 0 ? static_cast<double>(num_outliers) / all_corners : 0.0;
  if (outlier_fraction > options.max_outlier_fraction) {
    findings->push_back(
        {VerdictKind::kBadDetections,
         StringPrintf("%.1f %% of the corners were rejected as outliers (limit "
                      "%.1f %%",
                      100 * outlier_fraction,
                      100 * options.max_outlier_fraction) +
             (view_errors.empty()
                  ? std::string(")")
                  : StringPrintf("; %.1f %% with the %zu view(s) of "
                                 "view-level errors, counted apart)",
                                 100.0 * result.num_outliers /
                                     std::max(1, result.num_corners_used +
                                                     result.num_outliers),
                                 view_errors.size()))});
  }
  std::vector<ViewJudgement>& judged = verdict->views;
  judged.assign(result.view_used.size(), ViewJudgement());
  std::vector<double> inlier_rms;
  for (size_t v = 0; v < result.view_used.size(); ++v) {
    if (!result.view_used[v] || v >= result.residuals.size()) continue;
    judged[v] = FitOfView(result, v);
    inlier_rms.push_back(judged[v].inlier_rms_px);
  }
  if (inlier_rms.empty()) return 0;
  std::vector<double> sorted = inlier_rms;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2,
                   sorted.end());
  const double median = sorted[sorted.size() / 2];
  const double limit =
      std::max(options.view_rms_factor * median, options.view_rms_floor_px);
  verdict->median_view_rms_px = median;
  verdict->view_rms_limit_px = limit;
  std::string bad_views, handled_views;
  int num_bad_views = 0, num_handled_views = 0;
  auto add_bad = [&](size_t v, const std::string& why) {
    judged[v].standing = ViewStanding::kStandsOut;
    judged[v].why = why;
    ++num_bad_views;
    if (num_bad_views <= 5) {
      bad_views +=
          (bad_views.empty() ? "" : ", ") + view_label(v) + " (" + why + ")";
    }
  };
  for (size_t v = 0; v < result.view_used.size(); ++v) {
    if (is_view_error(v)) continue;
    // A view the outlier rejection emptied (Calibrate's reason says so)
    // is as bad as one can be.
    if (!result.view_used[v] && v < result.view_reason.size() &&
        result.view_reason[v].find("outlier") != std::string::npos) {
      add_bad(v, "dropped: " + result.view_reason[v]);
      continue;
    }
    if (!result.view_used[v] || v >= result.residuals.size()) continue;
    ViewJudgement& view = judged[v];
    const std::string rejected_text =
        StringPrintf("%d of %d corners rejected", view.rejected, view.corners);
    if (view.inlier_rms_px > limit) {
      add_bad(v, StringPrintf("inliers %.2f px", view.inlier_rms_px) +
                     (view.rejected > 0 ? ", " + rejected_text : ""));
    } else if (view.rejected >
               options.max_view_outlier_fraction * view.corners) {
      add_bad(v, rejected_text);
    } else if (view.rejected > 0) {
      view.standing = ViewStanding::kHandled;
      view.why = rejected_text +
                 StringPrintf(", up to %.1f px off; the rest fit at %.2f px",
                              view.worst_rejected_px, view.inlier_rms_px);
      ++num_handled_views;
      if (num_handled_views <= 5) {
        handled_views += (handled_views.empty() ? "" : ", ") + view_label(v) +
                         " (" + view.why + ")";
      }
    }
  }
  if (num_bad_views > 0 &&
      num_bad_views <= options.max_bad_view_fraction * inlier_rms.size()) {
    findings->push_back(
        {VerdictKind::kBadDetections,
         StringPrintf(
             "%d view(s) stand out, with more than %.0f %% of their "
             "corners rejected, or with inliers above %.2f px (%.0f x the "
             "median view's %.3f px): ",
             num_bad_views, 100 * options.max_view_outlier_fraction, limit,
             options.view_rms_factor, median) +
             bad_views});
  }
  if (num_handled_views > 0) {
    notes->push_back(
        StringPrintf("isolated rejected corners, taken out by the outlier "
                     "rejection, in %d view(s) whose other corners fit: ",
                     num_handled_views) +
        handled_views + (num_handled_views > 5 ? ", ..." : ""));
  }
  return num_bad_views;
}

// Insufficient data: few views, little coverage, no covariance, a large
// projection uncertainty, an undetermined parameter, halves that cannot be
// calibrated.
void AddInsufficientDataFindings(const CalibrationResult& result,
                                 const Evidence& evidence,
                                 const VerdictOptions& options,
                                 std::vector<Finding>* findings,
                                 std::vector<std::string>* notes) {
  const Camera& camera = result.camera;
  if (result.num_views_used < options.min_views) {
    findings->push_back(
        {VerdictKind::kInsufficientData,
         StringPrintf("only %d views used (want %d or more)",
                      result.num_views_used, options.min_views)});
  }
  if (result.coverage < options.min_coverage) {
    findings->push_back(
        {VerdictKind::kInsufficientData,
         StringPrintf("the corners cover %.0f %% of the image (want %.0f %%)",
                      100 * result.coverage, 100 * options.min_coverage)});
  }
  if (!result.covariance_ok) {
    findings->push_back({VerdictKind::kInsufficientData,
                         "no parameter covariance: the views do not determine "
                         "every parameter"});
  }
  if (evidence.uncertainty.ok) {
    double worst = 0;
    const AngleBand* at = nullptr;
    for (const AngleBand& band : evidence.uncertainty.bands) {
      if (band.count > 0 && band.median > worst) {
        worst = band.median;
        at = &band;
      }
    }
    if (at != nullptr && worst > options.max_uncertainty_px) {
      findings->push_back(
          {VerdictKind::kInsufficientData,
           StringPrintf("the projection uncertainty reaches %.3f px (median "
                        "at ",
                        worst) +
               BandLabel(*at) +
               StringPrintf("; limit %.2f px)", options.max_uncertainty_px)});
    }
  }
  std::string undetermined_coefficients, undetermined_names;
  if (result.covariance_ok) {
    const std::vector<std::string> names = CameraModelParamNames(camera.model);
    for (size_t k = 0; k < names.size() && k < result.param_stddev.size() &&
                       k < camera.params.size();
         ++k) {
      if (k < result.param_fixed.size() && result.param_fixed[k]) continue;
      const double sigma = result.param_stddev[k];
      const bool distortion = static_cast<int>(k) >= kDistortionBegin;
      if (!(sigma > std::abs(camera.params[k]) &&
            (!distortion ||
             sigma > options.min_undetermined_distortion_stddev))) {
        continue;
      }
      const std::string text =
          names[k] + StringPrintf(" (%.4g +- %.3g)", camera.params[k], sigma);
      if (distortion && !options.check_distortion_determined) {
        undetermined_coefficients +=
            (undetermined_coefficients.empty() ? "" : ", ") + text;
        undetermined_names +=
            (undetermined_names.empty() ? "" : ",") + names[k];
      } else {
        findings->push_back(
            {VerdictKind::kInsufficientData,
             names[k] + StringPrintf(" is undetermined (%.4g +- %.3g)",
                                     camera.params[k], sigma)});
      }
    }
  }
  // Said, not judged: coupled coefficients can each be undetermined while
  // the projection they make is determined (its uncertainty is judged above).
  if (!undetermined_coefficients.empty()) {
    notes->push_back(
        "coefficients undetermined one by one: " + undetermined_coefficients +
        "; their values mean nothing alone (the projection they make is "
        "judged by its uncertainty); if a model with fewer coefficients is "
        "wanted, --fix " +
        undetermined_names + " holds them at their start (zero)");
  }
  const CrossValidation& cv = evidence.cross_validation;
  if (!cv.ok && cv.error != "not run") {
    findings->push_back(
        {VerdictKind::kInsufficientData,
         "the halves of the views cannot be calibrated alone: " + cv.error});
  }
}

// Inconsistent views: the views' own focal lengths spread far beyond their
// standard deviations, by more than noise in pixels.
void AddInconsistentViewFindings(const ViewConsistency& vc,
                                 const VerdictOptions& options,
                                 std::vector<Finding>* findings) {
  if (!vc.ok) return;
  if (!(vc.spread_ratio > options.view_focal_spread_factor) ||
      !(vc.effect_px > vc.expected_effect_px + options.view_focal_floor_px)) {
    return;
  }
  std::string named;
  for (const ViewFocal& f :
       MostInconsistentViews(vc, options.max_named_views)) {
    named += (named.empty() ? "" : ", ") + f.name +
             StringPrintf(" (f = %.1f +- %.1f px)", vc.focal_px * f.scale,
                          vc.focal_px * f.scale_sigma);
  }
  findings->push_back(
      {VerdictKind::kInconsistentViews,
       StringPrintf(
           "the views disagree on the focal length: fitted per view (the "
           "rest held) it spreads %.1f times its standard deviation "
           "(chi-square %.0f for %d views), and a focal length of "
           "their own moves the views' corners by %.3f px RMS (noise "
           "alone: %.3f px); ",
           vc.spread_ratio, vc.chi2, vc.dof + 1, vc.effect_px,
           vc.expected_effect_px) +
           StringPrintf("the calibration's is %.1f px, most different: ",
                        vc.focal_px) +
           named});
}

// View-level errors: views whose residuals are mostly a smooth field
// across the board, well above noise, in a few views only. Returns the
// flagged views (their corners do not count as outliers).
std::vector<int> AddViewErrorFindings(const ViewConsistency& vc,
                                      size_t used_views,
                                      const VerdictOptions& options,
                                      std::vector<Finding>* findings) {
  // Real views all carry some field (errors shared by a view's corners):
  // a view-level error stands out from the median view's as well.
  std::vector<double> smooth;
  for (const ViewField& f : vc.fields) smooth.push_back(f.smooth_rms_px);
  if (smooth.empty()) return {};
  std::nth_element(smooth.begin(), smooth.begin() + smooth.size() / 2,
                   smooth.end());
  const double median = smooth[smooth.size() / 2];
  std::vector<const ViewField*> flagged;
  for (const ViewField& f : vc.fields) {
    if (f.smooth_rms_px > options.view_field_factor *
                              std::max(f.expected_smooth_px, median) &&
        f.smooth_rms_px > options.view_field_floor_px &&
        f.smooth_rms_px > f.rest_rms_px) {
      flagged.push_back(&f);
    }
  }
  if (flagged.empty() ||
      flagged.size() > options.max_bad_view_fraction * used_views) {
    return {};
  }
  std::stable_sort(flagged.begin(), flagged.end(),
                   [](const ViewField* a, const ViewField* b) {
                     return a->smooth_rms_px > b->smooth_rms_px;
                   });
  std::string named;
  std::vector<int> views;
  for (const ViewField* f : flagged) {
    views.push_back(f->view);
    if (static_cast<int>(views.size()) > options.max_named_views) continue;
    named +=
        (named.empty() ? "" : "; ") + f->name +
        StringPrintf(
            " (its residuals form a smooth field of %.2f px RMS "
            "across the board, the median view's %.3f px, noise "
            "gives %.3f px, %.2f px left beside it",
            f->smooth_rms_px, median, f->expected_smooth_px, f->rest_rms_px);
    if (f->outliers > 0) {
      named += StringPrintf(
          "; %d of its %d corners were rejected as outliers, "
          "%d of them follow the field",
          f->outliers, f->corners, f->outliers_explained);
    }
    named += ")";
  }
  findings->push_back(
      {VerdictKind::kViewErrors,
       StringPrintf("view-level errors in %zu view(s), a bent board, a focus "
                    "change or motion rather than bad corners: ",
                    views.size()) +
           named});
  return views;
}

// Marks the views with a view-level error in `views` (their figures were
// filled by AddBadDetectionFindings).
void MarkViewErrors(const ViewConsistency& vc, const std::vector<int>& flagged,
                    std::vector<ViewJudgement>* views) {
  for (const ViewField& f : vc.fields) {
    if (f.view < 0 || f.view >= static_cast<int>(views->size()) ||
        std::find(flagged.begin(), flagged.end(), f.view) == flagged.end()) {
      continue;
    }
    ViewJudgement& view = (*views)[f.view];
    view.standing = ViewStanding::kViewError;
    view.why = StringPrintf(
        "a smooth residual field of %.2f px RMS across the board (noise "
        "gives %.3f px): a bent board, a focus change or motion",
        f.smooth_rms_px, f.expected_smooth_px);
  }
}

// The verdict's kind and reason: the findings of the highest-ranked kind
// (model-error, bad-detections, insufficient-data); good when none.
void RankFindings(const std::vector<Finding>& findings, Verdict* verdict) {
  for (const Finding& f : findings) verdict->findings.push_back(f.text);
  for (VerdictKind kind :
       {VerdictKind::kModelError, VerdictKind::kInconsistentViews,
        VerdictKind::kViewErrors, VerdictKind::kBadDetections,
        VerdictKind::kInsufficientData}) {
    std::string reason;
    for (const Finding& f : findings) {
      if (f.kind != kind) continue;
      reason += (reason.empty() ? "" : "; ") + f.text;
    }
    if (reason.empty()) continue;
    verdict->kind = kind;
    verdict->reason = reason;
    return;
  }
}

// Model error: the next step names the model to try.
void SuggestModel(CameraModelId model, bool grows_with_closeness,
                  double max_angle_deg, const VerdictOptions& options,
                  Verdict* verdict) {
  verdict->suggested_model =
      NextModel(model, grows_with_closeness, max_angle_deg, options);
  if (verdict->suggested_model.empty()) {
    verdict->next_step =
        "no richer model is available; check the board's flatness and "
        "its definition (tile size)";
    return;
  }
  verdict->next_step = "calibrate with --model " + verdict->suggested_model;
  if (verdict->suggested_model == "kannala-brandt-noncentral" ||
      (verdict->suggested_model == "kannala-brandt-splined-noncentral" &&
       grows_with_closeness)) {
    verdict->next_step +=
        " (a central model cannot follow a lens whose errors change as the "
        "board comes closer)";
  } else if (verdict->suggested_model == "kannala-brandt-splined" ||
             verdict->suggested_model == "kannala-brandt-splined-noncentral") {
    verdict->next_step +=
        " (kannala-brandt's polynomial leaves structured residuals; the "
        "spline follows a shape it cannot take)";
  } else if (CameraModelIsPinhole(model) &&
             verdict->suggested_model == "kannala-brandt") {
    verdict->next_step += StringPrintf(
        " (corners reach %.0f deg off the axis, beyond the %.0f deg a "
        "pinhole model is meant for)",
        max_angle_deg, options.pinhole_max_field_deg);
  }
}

// Good: the reason gives the figures that back it.
std::string GoodReason(const CalibrationResult& result,
                       const CrossValidation& cv, double halves_scale,
                       int min_count) {
  double worst_diff = 0, worst_expected = 0;
  for (size_t b = 0; b < cv.difference_bands.size(); ++b) {
    if (cv.difference_bands[b].count < min_count) continue;
    if (cv.difference_bands[b].median > worst_diff) {
      worst_diff = cv.difference_bands[b].median;
      worst_expected = cv.expected_bands[b].median;
    }
  }
  std::string reason = StringPrintf("RMS %.3f px", result.rms_px);
  if (cv.ok && halves_scale > 1) {
    // Not "the halves agree" alone: they do only once their uncertainty
    // is scaled, and the stated one is what the camera file carries.
    reason +=
        "; the halves" + OverSplits(cv) +
        StringPrintf(
            " agree only with their stated uncertainty scaled by "
            "%.2f, the factor by which they differ more than it in every band "
            "(largest band median %.3f px, the stated uncertainty predicts "
            "%.3f px): corner errors shared within views, so the stated "
            "uncertainty is optimistic by about that factor",
            halves_scale, worst_diff, worst_expected);
  } else if (cv.ok) {
    reason += "; the halves" + OverSplits(cv) +
              StringPrintf(
                  " agree (largest band median %.3f px, noise predicts "
                  "%.3f px)",
                  worst_diff, worst_expected);
  }
  return reason + "; no systematic residuals";
}

}  // namespace

const char* VerdictKindName(VerdictKind kind) {
  switch (kind) {
    case VerdictKind::kGood:
      return "good";
    case VerdictKind::kModelError:
      return "model-error";
    case VerdictKind::kInsufficientData:
      return "insufficient-data";
    case VerdictKind::kBadDetections:
      return "bad-detections";
    case VerdictKind::kInconsistentViews:
      return "inconsistent-views";
    case VerdictKind::kViewErrors:
      return "view-errors";
  }
  return "good";
}

bool VerdictOptions::Check(std::string* why) const {
  if (!(halves_factor > 0)) return Fail("halves_factor must be > 0", why);
  if (!(halves_floor_px >= 0)) return Fail("halves_floor_px must be >= 0", why);
  if (halves_min_bands < 0) return Fail("halves_min_bands must be >= 0", why);
  if (!(halves_max_scale >= 1) || !std::isfinite(halves_max_scale)) {
    return Fail("halves_max_scale must be >= 1", why);
  }
  if (!(halves_uniform_floor_px >= 0) ||
      !std::isfinite(halves_uniform_floor_px)) {
    return Fail("halves_uniform_floor_px must be >= 0", why);
  }
  if (!std::isfinite(halves_min_z)) {
    return Fail("halves_min_z must be finite", why);
  }
  if (!(residual_se_factor > 0)) {
    return Fail("residual_se_factor must be > 0", why);
  }
  if (!(residual_floor_px >= 0)) {
    return Fail("residual_floor_px must be >= 0", why);
  }
  if (!(pinhole_max_field_deg > 0 && pinhole_max_field_deg < 90)) {
    return Fail("pinhole_max_field_deg must be in (0, 90)", why);
  }
  if (!(max_outlier_fraction >= 0 && max_outlier_fraction <= 1)) {
    return Fail("max_outlier_fraction must be in [0, 1]", why);
  }
  if (!(view_rms_factor > 1)) return Fail("view_rms_factor must be > 1", why);
  if (!(view_rms_floor_px >= 0)) {
    return Fail("view_rms_floor_px must be >= 0", why);
  }
  if (!(max_view_outlier_fraction >= 0 && max_view_outlier_fraction <= 1)) {
    return Fail("max_view_outlier_fraction must be in [0, 1]", why);
  }
  if (!(max_bad_view_fraction >= 0 && max_bad_view_fraction <= 1)) {
    return Fail("max_bad_view_fraction must be in [0, 1]", why);
  }
  if (min_views < 1) return Fail("min_views must be >= 1", why);
  if (!(view_focal_spread_factor > 0)) {
    return Fail("view_focal_spread_factor must be > 0", why);
  }
  if (!(view_focal_floor_px >= 0)) {
    return Fail("view_focal_floor_px must be >= 0", why);
  }
  if (max_named_views < 1) return Fail("max_named_views must be >= 1", why);
  if (!(view_field_factor > 0)) {
    return Fail("view_field_factor must be > 0", why);
  }
  if (!(view_field_floor_px >= 0)) {
    return Fail("view_field_floor_px must be >= 0", why);
  }
  if (!(min_coverage >= 0 && min_coverage <= 1)) {
    return Fail("min_coverage must be in [0, 1]", why);
  }
  if (!(max_uncertainty_px > 0)) {
    return Fail("max_uncertainty_px must be > 0", why);
  }
  if (!(min_undetermined_distortion_stddev >= 0)) {
    return Fail("min_undetermined_distortion_stddev must be >= 0", why);
  }
  return true;
}

std::string Verdict::Line() const {
  return std::string("verdict: ") + VerdictKindName(kind) + " \u2014 " +
         reason + " \u2014 " + next_step;
}

std::string NextModel(CameraModelId model, bool grows_with_closeness,
                      double max_field_deg, const VerdictOptions& options) {
  const bool conventional_field =
      max_field_deg <= options.pinhole_max_field_deg;
  if (CameraModelIsPinhole(model)) {
    // Within the conventional field a lens is never called a fisheye: the
    // pinhole family's richest model is the last to try.
    if (!conventional_field) return "kannala-brandt";
    if (model == CameraModelId::kPinholeRadtan) return "pinhole-rational";
    return "";
  }
  // A fisheye model on a lens within the conventional field: the pinhole
  // family's richest model.
  if (conventional_field) return "pinhole-rational";
  // What a central fisheye model cannot follow: a lens whose entrance pupil
  // moves with the field angle (errors that change as the board comes
  // closer: the non-central form models it), or a projection kannala-brandt's
  // odd polynomial cannot take (the splined form). A model that has one of
  // the two gets the other on top.
  switch (model) {
    case CameraModelId::kKannalaBrandt:
      return grows_with_closeness ? "kannala-brandt-noncentral"
                                  : "kannala-brandt-splined";
    case CameraModelId::kKannalaBrandtNoncentral:
      return "kannala-brandt-splined-noncentral";
    case CameraModelId::kKannalaBrandtSplined:
      return grows_with_closeness ? "kannala-brandt-splined-noncentral" : "";
    default:
      return "";
  }
}

// A pinhole calibration whose fitted distortion folds over inside the
// image: a note (the verdict judges the field the corners covered, where
// the model may be right), because undistorted and rectified images are
// wrong beyond the fold and a user cannot see it from the figures.
void AddFoldNote(const Camera& camera, std::vector<std::string>* notes) {
  if (!CameraModelIsPinhole(camera.model)) return;  // fisheye: image circle
  const double without = BorderFractionWithoutRay(camera);
  if (!(without > 0)) return;
  notes->push_back(StringPrintf(
      "the fitted distortion folds over inside the image: %.1f %% of the "
      "image border has no ray (the model has no inverse there): "
      "undistorted and rectified images are wrong towards the image's "
      "corners. Unless the lens itself shows nothing there, views with the "
      "board in the image's corners pin the distortion down",
      100 * without));
}

Verdict MakeVerdict(const CalibrationResult& result, const Evidence& evidence,
                    const EvidenceOptions& evidence_options,
                    const VerdictOptions& options) {
  std::string why;
  if (!options.Check(&why)) {
    Verdict invalid;
    invalid.kind = VerdictKind::kInsufficientData;
    invalid.reason = "verdict options: " + why;
    invalid.next_step = "fix the options";
    return invalid;
  }
  const int min_count = evidence_options.min_bin_count;
  const CrossValidation& cv = evidence.cross_validation;
  const double halves_scale = HalvesScale(cv, min_count, options);
  std::vector<Finding> findings;
  AddHalvesFindings(cv, halves_scale, min_count, options, &findings);
  AddUniformHalvesFinding(cv, halves_scale, min_count, options, &findings);
  AddInconsistentViewFindings(evidence.view_consistency, options, &findings);
  const bool grows_with_closeness = AddSystematicResidualFindings(
      evidence.residuals, min_count, options, &findings);
  const std::vector<int> view_errors = AddViewErrorFindings(
      evidence.view_consistency, static_cast<size_t>(result.num_views_used),
      options, &findings);
  std::vector<std::string> notes;
  Verdict verdict;
  const int num_bad_views = AddBadDetectionFindings(
      result, view_errors, options, &findings, &notes, &verdict);
  MarkViewErrors(evidence.view_consistency, view_errors, &verdict.views);
  AddInsufficientDataFindings(result, evidence, options, &findings, &notes);

  AddFoldNote(result.camera, &notes);
  RankFindings(findings, &verdict);
  verdict.notes = notes;
  for (const Finding& f : findings) {
    if (f.kind == VerdictKind::kInconsistentViews) {
      verdict.inconsistent_views = f.text;
      verdict.inconsistent_views_next_step = kInconsistentViewsNextStep;
    } else if (f.kind == VerdictKind::kViewErrors) {
      verdict.view_errors = f.text;
      verdict.view_errors_next_step = kViewErrorsNextStep;
    }
  }
  switch (verdict.kind) {
    case VerdictKind::kModelError:
      SuggestModel(result.camera.model, grows_with_closeness,
                   evidence.residuals.max_angle_deg, options, &verdict);
      break;
    case VerdictKind::kInconsistentViews:
      verdict.next_step = kInconsistentViewsNextStep;
      break;
    case VerdictKind::kViewErrors:
      verdict.next_step = kViewErrorsNextStep;
      break;
    case VerdictKind::kBadDetections:
      verdict.next_step = num_bad_views > 0
                              ? "look at the worst views in the report and "
                                "remove or retake them"
                              : "look at the outliers in the report (blur, "
                                "glare, a bent board) and retake those views";
      break;
    case VerdictKind::kInsufficientData:
      verdict.next_step =
          "add views: the board near the image borders and corners, tilted "
          "by 30 degrees or more, at several distances";
      break;
    case VerdictKind::kGood:
      verdict.reason = GoodReason(result, cv, halves_scale, min_count);
      verdict.next_step = "none: the camera file is ready to use";
      break;
  }
  return verdict;
}

}  // namespace puzzlecal
