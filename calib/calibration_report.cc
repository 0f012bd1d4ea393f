// The readable summary of a CalibrationResult (calib/calibrate.h), made
// from its facts on demand.

#include <sstream>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

// One line per parameter: value, and "(fixed)" or its standard deviation.
void ReportParameters(const CalibrationResult& result, std::ostream* out) {
  const std::vector<std::string> names =
      CameraModelParamNames(result.camera.model);
  const std::vector<double>& params = result.camera.params;
  if (params.size() != names.size()) return;  // stopped before a solve
  for (size_t k = 0; k < names.size(); ++k) {
    *out << "  " << names[k] << " = " << StringPrintf("%.10g", params[k]);
    if (k < result.param_fixed.size() && result.param_fixed[k]) {
      *out << " (fixed)";
    } else if (result.covariance_ok && k < result.param_stddev.size()) {
      *out << " +- " << StringPrintf("%.3g", result.param_stddev[k]);
    }
    *out << "\n";
  }
  if (result.covariance_requested && !result.covariance_ok) {
    *out << "covariance: not available (the problem is rank deficient; "
            "some parameters are not determined by these views)\n";
  }
}

// The views that lost corners to outlier rejection, with the fraction.
void ReportRejectedPerView(const CalibrationResult& result, std::ostream* out) {
  for (size_t v = 0; v < result.view_rejected_fraction.size(); ++v) {
    if (!(result.view_rejected_fraction[v] > 0)) continue;
    const std::string name =
        v < result.view_name.size() ? result.view_name[v] : "";
    *out << "  view " << v << " (" << name << "): "
         << StringPrintf("%.1f", 100 * result.view_rejected_fraction[v])
         << " % of its corners rejected\n";
  }
}

}  // namespace

std::string CalibrationReport(const CalibrationResult& result) {
  std::ostringstream report;
  const Camera& camera = result.camera;
  report << "model: " << CameraModelName(camera.model) << ", image "
         << camera.width << "x" << camera.height << "\n";
  report << "initialisation: " << result.initialization_method << "\n";
  ReportParameters(result, &report);
  report << "rms: " << StringPrintf("%.4f", result.rms_px)
         << " px per coordinate (" << StringPrintf("%.4f", result.rms_point_px)
         << " px per corner)\n";
  report << "views used: " << result.num_views_used << " of "
         << result.view_used.size()
         << ", corners used: " << result.num_corners_used
         << ", outliers rejected: " << result.num_outliers << " ("
         << StringPrintf("%.2f", 100 * result.rejected_fraction) << " %, "
         << result.outlier_rounds << " rejection rounds, threshold "
         << StringPrintf("%.3f", result.outlier_threshold_px)
         << " px, noise sigma " << StringPrintf("%.3f", result.noise_sigma_px)
         << " px)\n";
  ReportRejectedPerView(result, &report);
  report << "coverage: " << StringPrintf("%.0f", 100 * result.coverage)
         << " % of the image, board orientation spread "
         << StringPrintf("%.1f", result.orientation_spread_deg) << " degrees\n";
  report << "solver: " << result.iterations << " iterations, "
         << StringPrintf("%.3f", result.solve_seconds) << " s, "
         << result.termination << "\n";
  for (size_t v = 0; v < result.view_reason.size(); ++v) {
    if (result.view_reason[v].empty()) continue;
    const std::string name =
        v < result.view_name.size() ? result.view_name[v] : "";
    report << "view " << v << " (" << name
           << ") not used: " << result.view_reason[v] << "\n";
  }
  return report.str();
}

std::string CalibrationResult::FullReport() const {
  return CalibrationReport(*this);
}

}  // namespace puzzlecal
