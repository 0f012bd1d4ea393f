// The fisheye models side by side on one photo set: kannala-brandt,
// kannala-brandt-noncentral, kannala-brandt-splined and
// kannala-brandt-splined-noncentral. Per model:
//  - the calibration on all views: wall time (its starts included: the
//    non-central model starts from kannala-brandt, the splined ones from
//    kannala-brandt or kannala-brandt-noncentral), RMS, corners kept,
//    whether the covariance exists;
//  - the held-out RMS of --model auto (every view held out once, 4 folds,
//    the intrinsics fixed and only the held-out views' poses fitted);
//  - the halves' agreement (evidence/evidence.h CrossValidate): the largest
//    10-degree band median of the far-field difference between the two
//    halves' calibrations, and what their uncertainty predicts there.
// Then the model --model auto chooses among them, and why (a splined
// model is fitted only when the model it refines leads; its held-out RMS is
// null otherwise). Prints JSON. Each calibration runs 3 times; "seconds" is
// the median (this machine's timings vary by tens of percent).
//
// Usage: bench_lens_models IMAGES BOARD.yaml [threads [MODEL]]
//   MODEL: time that model's calibration alone (no auto, no halves; for a
//   profiler).
//   e.g. bench_lens_models ../shared/deltille/fisheye
//        configs/boards/deltille_checkerboard_11x8_20mm.yaml

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/model_selection.h"
#include "formats/board_file.h"
#include "formats/image_io.h"
#include "pipeline/pipeline.h"
#include "util/string_format.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

struct HalvesFigures {
  bool ok = false;
  double worst_median_px = 0;  // the largest band median of the difference
  double expected_px = 0;      // the expected median in that band
  double band_lo_deg = 0;
  double band_hi_deg = 0;
};

HalvesFigures Halves(const std::vector<CalibrationView>& views,
                     const CalibrationResult& result,
                     const CalibrationOptions& options) {
  HalvesFigures figures;
  double field_deg = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    if (!result.view_used[v]) continue;
    for (const Eigen::Vector3d& point : views[v].board_points) {
      const Eigen::Vector3d p = result.cam_from_board[v] * point;
      field_deg = std::max(field_deg,
                           std::atan2(p.head<2>().norm(), p.z()) * 180 / M_PI);
    }
  }
  const CrossValidation halves =
      CrossValidate(views, result, options, field_deg, EvidenceOptions());
  if (!halves.ok) return figures;
  figures.ok = true;
  for (size_t b = 0; b < halves.difference_bands.size(); ++b) {
    const AngleBand& band = halves.difference_bands[b];
    if (band.count == 0 || band.median < figures.worst_median_px) continue;
    figures.worst_median_px = band.median;
    figures.band_lo_deg = band.lo_deg;
    figures.band_hi_deg = band.hi_deg;
    figures.expected_px = b < halves.expected_bands.size()
                              ? halves.expected_bands[b].median
                              : 0.0;
  }
  return figures;
}

constexpr int kRepeats = 3;

// Calibrates kRepeats times; `seconds` gets the median wall time.
bool TimedCalibrate(const std::vector<CalibrationView>& views,
                    CameraModelId model, int width, int height,
                    const CalibrationOptions& options,
                    CalibrationResult* result, std::string* why,
                    double* seconds) {
  std::vector<double> times;
  bool ok = true;
  for (int r = 0; r < kRepeats && ok; ++r) {
    const Timer timer;
    ok = Calibrate(views, model, width, height, options, result, why);
    times.push_back(timer.Seconds());
  }
  std::sort(times.begin(), times.end());
  *seconds = times[times.size() / 2];
  return ok;
}

// One model's calibration time alone, as JSON.
int TimeOneModel(const std::vector<CalibrationView>& views, CameraModelId model,
                 int width, int height, const CalibrationOptions& options) {
  CalibrationResult result;
  std::string why;
  double seconds = 0;
  const bool ok = TimedCalibrate(views, model, width, height, options, &result,
                                 &why, &seconds);
  std::printf(
      "{\"model\": \"%s\", \"ok\": %s, \"seconds\": %.3f, "
      "\"covariance_seconds\": %.3f, \"iterations\": %d, "
      "\"rms_px\": %.4f}\n",
      CameraModelName(model), ok ? "true" : "false", seconds,
      result.covariance_seconds, result.iterations, result.rms_px);
  return ok ? 0 : 1;
}

int Run(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(
        stderr,
        "usage: bench_lens_models IMAGES BOARD.yaml [threads [MODEL]]\n");
    return 2;
  }
  const int threads = argc > 3 ? std::atoi(argv[3]) : 2;
  std::string error;
  Board board;
  ImageListing listing;
  if (!LoadBoardFile(argv[2], &board, &error) ||
      !ListImages(argv[1], &listing, &error)) {
    std::fprintf(stderr, "bench_lens_models: %s\n", error.c_str());
    return 1;
  }
  std::vector<ImageResult> images =
      ProcessImageFiles(listing.images, board, PipelineOptions(), threads);
  int width = 0, height = 0;
  const std::vector<CalibrationView> views =
      MakeCalibrationViews(board, &images, &width, &height);
  CalibrationOptions options;
  options.num_threads = threads;
  const std::vector<CameraModelId> models = {
      CameraModelId::kKannalaBrandt, CameraModelId::kKannalaBrandtNoncentral,
      CameraModelId::kKannalaBrandtSplined,
      CameraModelId::kKannalaBrandtSplinedNoncentral};
  if (argc > 4) {
    CameraModelId only;
    if (!CameraModelIdFromName(argv[4], &only)) {
      std::fprintf(stderr, "bench_lens_models: unknown model '%s'\n", argv[4]);
      return 2;
    }
    return TimeOneModel(views, only, width, height, options);
  }
  ModelSelectionOptions selection_options;
  for (CameraModelId model : models) {
    selection_options.candidates.push_back(CameraModelName(model));
  }
  ModelSelection selection;
  const Timer selection_timer;
  const bool selected = SelectModel(views, width, height, options,
                                    selection_options, &selection, &error);
  const double selection_seconds = selection_timer.Seconds();
  std::printf("{\n  \"images\": \"%s\",\n  \"views\": %zu,\n  \"models\": [\n",
              argv[1], views.size());
  for (size_t m = 0; m < models.size(); ++m) {
    CalibrationResult result;
    std::string why;
    double seconds = 0;
    const bool ok = TimedCalibrate(views, models[m], width, height, options,
                                   &result, &why, &seconds);
    const HalvesFigures halves =
        ok ? Halves(views, result, options) : HalvesFigures();
    const ModelCandidate* candidate = nullptr;
    for (const ModelCandidate& c : selection.candidates) {
      if (c.model == models[m] && c.ok) candidate = &c;
    }
    std::printf(
        "    {\"model\": \"%s\", \"ok\": %s, \"seconds\": %.3f, "
        "\"covariance_seconds\": %.3f, \"iterations\": %d, "
        "\"outlier_rounds\": %d, \"rms_px\": %.4f, "
        "\"corners\": %d, "
        "\"covariance\": %s, \"holdout_rms_px\": %s, "
        "\"halves_worst_band_median_px\": %.3f, "
        "\"halves_expected_px\": %.3f, \"halves_band_deg\": [%.0f, "
        "%.0f]%s}%s\n",
        CameraModelName(models[m]), ok ? "true" : "false", seconds,
        result.covariance_seconds, result.iterations, result.outlier_rounds,
        result.rms_px, result.num_corners_used,
        result.covariance_ok ? "true" : "false",
        candidate != nullptr
            ? StringPrintf("%.4f", candidate->holdout_rms_px).c_str()
            : "null",
        halves.worst_median_px, halves.expected_px, halves.band_lo_deg,
        halves.band_hi_deg, ok ? "" : (", \"error\": \"" + why + "\"").c_str(),
        m + 1 < models.size() ? "," : "");
  }
  std::printf("  ],\n  \"auto_reason\": \"%s\",\n", selection.reason.c_str());
  std::printf(
      "  \"auto_chooses\": \"%s\",\n  \"auto_seconds\": %.2f\n}\n",
      selected && selection.chosen >= 0
          ? CameraModelName(selection.candidates[selection.chosen].model)
          : "none",
      selection_seconds);
  return 0;
}

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) { return puzzlecal::Run(argc, argv); }
