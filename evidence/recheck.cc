#include "evidence/recheck.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "util/enum_names.h"
#include "util/failure.h"
#include "util/string_format.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

constexpr EnumName<RecheckVerdict> kRecheckVerdictNames[] = {
    {RecheckVerdict::kStillValid, "still-valid"},
    {RecheckVerdict::kDrifted, "drifted"},
    {RecheckVerdict::kNotEnoughData, "not-enough-data"},
};

// The new views posed with every intrinsic of `stored` held: only the
// poses are fitted (outliers rejected as usual), and nothing is refused for
// too few, too parallel or too concentrated views or a high RMS, which
// are the question here.
void FitHeld(const std::vector<CalibrationView>& views,
             const StoredCalibration& stored,
             const CalibrationOptions& calibration,
             const RecheckOptions& options, Recheck* out) {
  const Camera& camera = stored.camera;
  const CalibrationOptions held = PoseFitOptions(calibration, camera.params);
  CalibrationResult result;
  out->held_ok = Calibrate(views, camera.model, camera.width, camera.height,
                           held, &result, &out->held_error);
  out->held_rms_px = result.rms_px;
  out->views_used = result.num_views_used;
  const bool stored_rms_known = stored.rms_px > 0;
  if (stored_rms_known) out->worse_views = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    RecheckView view;
    view.name = views[v].name;
    view.used =
        out->held_ok && v < result.view_used.size() && result.view_used[v];
    if (v < result.view_reason.size()) view.reason = result.view_reason[v];
    if (view.used) {
      view.rms_px = result.view_rms_px[v];
      view.corners = static_cast<int>(
          std::count(result.inlier[v].begin(), result.inlier[v].end(), true));
      view.worse = stored_rms_known &&
                   view.rms_px > options.worse_view_factor * stored.rms_px;
      if (view.worse) ++out->worse_views;
    }
    out->views.push_back(view);
  }
  if (stored_rms_known && out->views_used > 0) {
    out->worse_fraction =
        static_cast<double>(out->worse_views) / out->views_used;
  }
}

// The same model calibrated on the new views from the stored intrinsics,
// holding what the stored calibration held (a standard deviation of 0).
void FitFresh(const std::vector<CalibrationView>& views,
              const StoredCalibration& stored,
              const CalibrationOptions& calibration, Recheck* out) {
  const Camera& camera = stored.camera;
  CalibrationOptions fresh = calibration;
  fresh.initial_params = camera.params;
  fresh.initial_cam_from_board.clear();
  fresh.compute_covariance = true;
  const std::vector<std::string> names = CameraModelParamNames(camera.model);
  if (stored.param_stddev.size() == names.size()) {
    for (size_t k = 0; k < names.size(); ++k) {
      if (stored.param_stddev[k] == 0 &&
          std::find(fresh.fixed_params.begin(), fresh.fixed_params.end(),
                    names[k]) == fresh.fixed_params.end()) {
        fresh.fixed_params.push_back(names[k]);
      }
    }
  }
  out->fresh_ok = Calibrate(views, camera.model, camera.width, camera.height,
                            fresh, &out->fresh, &out->fresh_error);
}

// The bands judged and the verdict drawn from them.
void JudgeBands(const RecheckOptions& options, Recheck* out) {
  const ProjectionDiff& diff = out->difference;
  const size_t count = diff.difference_bands.size();
  out->band_resolved.assign(count, false);
  out->band_drifted.assign(count, false);
  double best_resolution = std::numeric_limits<double>::infinity();
  int largest = -1;  // the resolved band with the largest median
  std::string drifted_list;
  for (size_t b = 0; b < count; ++b) {
    const AngleBand& d = diff.difference_bands[b];
    const AngleBand& e = diff.expected_bands[b];
    if (d.count < options.evidence.min_bin_count || !std::isfinite(d.median) ||
        !std::isfinite(e.median)) {
      continue;
    }
    const double bound = options.drift_sigmas * e.median;
    best_resolution = std::min(best_resolution, bound);
    out->band_resolved[b] = bound <= options.max_detectable_px;
    out->band_drifted[b] = d.median > std::max(bound, options.min_drift_px);
    if (out->band_drifted[b]) {
      drifted_list +=
          StringPrintf("%s%s %.2f px", drifted_list.empty() ? "" : ", ",
                       BandLabel(d).c_str(), d.median);
      if (out->worst_band < 0 ||
          d.median > diff.difference_bands[out->worst_band].median) {
        out->worst_band = static_cast<int>(b);
      }
    }
    if (out->band_resolved[b] &&
        (largest < 0 || d.median >= diff.difference_bands[largest].median)) {
      largest = static_cast<int>(b);
    }
  }
  if (out->worst_band >= 0) {
    const AngleBand& d = diff.difference_bands[out->worst_band];
    const AngleBand& e = diff.expected_bands[out->worst_band];
    out->verdict = RecheckVerdict::kDrifted;
    out->reason = StringPrintf(
        "the projection moved by up to %.2f px (median of the %s band; 95th "
        "percentile %.2f px, largest %.2f px), where the uncertainties give "
        "%.3f px; bands drifted: %s",
        d.median, BandLabel(d).c_str(), d.p95, d.max, e.median,
        drifted_list.c_str());
    return;
  }
  if (largest >= 0) {
    const AngleBand& d = diff.difference_bands[largest];
    out->verdict = RecheckVerdict::kStillValid;
    out->reason = StringPrintf(
        "the projection agrees with the new views' calibration up to %.0f "
        "deg off the axis: the largest band median is %.3f px (%s), where "
        "%.0f sigma is %.3f px (drifts below %.2f px are not counted)",
        out->observed_angle_deg, d.median, BandLabel(d).c_str(),
        options.drift_sigmas,
        options.drift_sigmas * diff.expected_bands[largest].median,
        options.min_drift_px);
    // Bands too uncertain to tell a drift are named: their medians (in
    // the table above the verdict) may be larger than the one quoted.
    std::string unresolved;
    for (size_t b = 0; b < count; ++b) {
      const AngleBand& band = diff.difference_bands[b];
      if (out->band_resolved[b] ||
          band.count < options.evidence.min_bin_count ||
          !std::isfinite(band.median)) {
        continue;
      }
      unresolved += StringPrintf("%s%s %.3f px", unresolved.empty() ? "" : ", ",
                                 BandLabel(band).c_str(), band.median);
    }
    if (!unresolved.empty()) {
      out->reason += StringPrintf(
          "; the bands whose %.0f sigma exceeds %.2f px cannot tell a drift "
          "and are not judged: %s",
          options.drift_sigmas, options.max_detectable_px, unresolved.c_str());
    }
    return;
  }
  out->verdict = RecheckVerdict::kNotEnoughData;
  out->reason =
      std::isfinite(best_resolution)
          ? StringPrintf(
                "the new views determine the projection only to %.3f px "
                "(%.0f sigma) in their best field-angle band, %.3g px is "
                "needed: add views, with the board near the image borders "
                "and tilted",
                best_resolution, options.drift_sigmas,
                options.max_detectable_px)
          : "no field-angle band holds enough compared pixels";
}

}  // namespace

bool RecheckOptions::Check(std::string* why) const {
  if (!(worse_view_factor > 0)) {
    return Fail("worse_view_factor must be > 0", why);
  }
  if (!(drift_sigmas > 0)) return Fail("drift_sigmas must be > 0", why);
  if (!(min_drift_px >= 0)) return Fail("min_drift_px must be >= 0", why);
  if (!(max_detectable_px > 0)) {
    return Fail("max_detectable_px must be > 0", why);
  }
  return evidence.Check(why);
}

const char* RecheckVerdictName(RecheckVerdict verdict) {
  return NameOf(kRecheckVerdictNames, verdict);
}

Recheck RecheckCalibration(const std::vector<CalibrationView>& views,
                           const StoredCalibration& stored,
                           const CalibrationOptions& calibration,
                           const RecheckOptions& options) {
  const Timer timer;
  Recheck out;
  std::string why;
  if (!options.Check(&why)) {
    out.reason = "check options: " + why;
    return out;
  }
  if (!calibration.Check(&why)) {
    out.reason = "calibration options: " + why;
    return out;
  }
  FitHeld(views, stored, calibration, options, &out);
  FitFresh(views, stored, calibration, &out);
  if (!out.fresh_ok || !out.fresh.covariance_ok) {
    out.reason = out.fresh_ok ? "the new views do not determine the camera (no "
                                "covariance of its parameters)"
                              : "the new views do not calibrate the camera: " +
                                    out.fresh_error;
    out.seconds = timer.Seconds();
    return out;
  }
  out.observed_angle_deg =
      ComputeSystematicResiduals(views, out.fresh, options.evidence)
          .max_angle_deg;
  const Eigen::Index n = CameraModelNumParams(stored.camera.model);
  out.stored_covariance_used =
      stored.covariance.rows() == n && stored.covariance.cols() == n;
  out.difference = ProjectionDifference(
      stored.camera, out.fresh.camera, out.observed_angle_deg, options.evidence,
      out.stored_covariance_used ? &stored.covariance : nullptr,
      &out.fresh.covariance);
  if (!out.difference.ok) {
    out.reason = "comparing the cameras: " + out.difference.error;
  } else {
    JudgeBands(options, &out);
  }
  out.seconds = timer.Seconds();
  return out;
}

std::string RecheckText(const Recheck& recheck,
                        const StoredCalibration& stored) {
  std::ostringstream text;
  const Camera& camera = stored.camera;
  text << "stored camera: " << CameraModelName(camera.model) << " "
       << camera.width << " x " << camera.height << ", "
       << (stored.rms_px > 0 ? StringPrintf("RMS %.3f px", stored.rms_px)
                             : std::string("RMS not in the file"))
       << ", "
       << (recheck.stored_covariance_used ? "covariance in the file"
           : stored.param_stddev.empty()
               ? "no uncertainty in the file"
               : "parameter sigmas but no covariance in the file "
                 "(the expected difference is the new fit's alone)")
       << "\n";
  if (recheck.held_ok) {
    text << StringPrintf(
        "with the stored intrinsics (poses fitted): %d of %d views, RMS %.3f "
        "px",
        recheck.views_used, static_cast<int>(recheck.views.size()),
        recheck.held_rms_px);
    if (recheck.worse_views >= 0) {
      text << StringPrintf(
          "; %d of %d views (%.0f %%) worse than the stored noise",
          recheck.worse_views, recheck.views_used,
          100 * recheck.worse_fraction);
    } else {
      text << "; views against the stored noise: not judged (the file has no "
              "RMS)";
    }
    text << "\n";
    for (const RecheckView& view : recheck.views) {
      if (view.worse) {
        text << StringPrintf("  %s: RMS %.3f px, %d corners\n",
                             view.name.c_str(), view.rms_px, view.corners);
      }
    }
  } else {
    text << "with the stored intrinsics: " << recheck.held_error << "\n";
  }
  if (recheck.fresh_ok) {
    const std::vector<double>& p = recheck.fresh.camera.params;
    text << StringPrintf(
        "calibrated on the new views (from the stored camera): %d views, RMS "
        "%.3f px, fx %.2f (stored %.2f, %+.3f %%), fy %.2f (stored %.2f, "
        "%+.3f %%)\n",
        recheck.fresh.num_views_used, recheck.fresh.rms_px, p[0],
        camera.params[0], 100 * (p[0] / camera.params[0] - 1), p[1],
        camera.params[1], 100 * (p[1] / camera.params[1] - 1));
  }
  if (recheck.difference.ok) {
    text << "projection difference, stored against new, after the "
            "best-fitting rotation:\n"
         << ProjectionDifferenceText(recheck.difference, "  ");
  }
  text << "verdict: " << RecheckVerdictName(recheck.verdict) << " — "
       << recheck.reason << "\n";
  return text.str();
}

}  // namespace puzzlecal
