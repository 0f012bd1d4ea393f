#ifndef PUZZLECAL_REPORT_REPORT_H_
#define PUZZLECAL_REPORT_REPORT_H_

// The calibration report (`puzzlecal calibrate --report DIR`): a markdown
// summary and PNG plots a user can judge the calibration by.

#include <string>
#include <vector>

#include "advice/advice.h"
#include "calib/calibrate.h"
#include "camera/calibration_view.h"
#include "evidence/evidence.h"
#include "evidence/verdict.h"
#include "formats/image_io.h"
#include "pipeline/pipeline.h"
#include "target/board.h"

namespace puzzlecal {

// What the calibration made of an image's view.
enum class ViewUse {
  kNoView,   // the image gave no view (ReportImage::outcome says why)
  kDropped,  // a view the calibration did not use (the reason says why)
  kUsed,     // a view of the calibration
};

// One input image of the run, in input order.
struct ReportImage {
  std::string file;                                  // path as given
  ImageOutcome outcome = ImageOutcome::kUnreadable;  // of the pipeline
  ViewUse use = ViewUse::kNoView;
  std::string reason;  // details (may be empty)
  int corners_detected = 0;
  int corners_used = 0;  // inlier corners in the calibration
  int view_index = -1;   // index into the CalibrationView list, -1 if none

  // "used", "not used by the calibration", or the pipeline's outcome
  // ("unreadable", "no corners", ...).
  std::string OutcomeText() const;
};

// The report's line of each image record of the pipeline, with what the
// calibration (`result`, null when it failed) made of its view.
std::vector<ReportImage> MakeReportImages(
    const std::vector<ImageResult>& images, const CalibrationResult* result);

struct ReportOptions {
  // Views drawn as overlays (the image with detected and reprojected
  // corners): half of them the worst views by RMS, the rest the best.
  // Default 4; 0 draws none.
  int num_overlays = 4;
  // Views listed as the worst ones in summary.md. Default 5.
  int num_worst_views = 5;
  // Residual arrows are drawn this many times longer than the residual.
  // 0 (the default) picks a 1-2-5 factor that makes the 95th percentile
  // residual about 3 % of the image width; the factor is written on the plot.
  double residual_arrow_scale = 0;
  // Bins of the residual histogram. Default 40.
  int histogram_bins = 40;
  // Cells of the coverage heatmap across the image width (square cells).
  // Default 24.
  int coverage_cells_across = 24;
  // Spacing in image pixels of the grid on which the distortion map is
  // computed before bilinear upsampling. Default 8.
  int distortion_grid_step_px = 8;
  // Width in pixels of the image-shaped plots (residuals, coverage,
  // distortion; the height follows the image's aspect ratio). Default 1200.
  int image_plot_width = 1200;
  // Size in pixels of the charts (histogram, per-view RMS). Default
  // 1200 x 600.
  int chart_width = 1200;
  int chart_height = 600;
  // Width in pixels of the overlays: view images are scaled (up or down) to
  // it, so markers and text keep a readable size. Default 1400.
  int overlay_width = 1400;
  // Limits for re-loading view images for the overlays.
  ImageLoadOptions load;

  bool Check(std::string* why = nullptr) const;
};

struct ReportInput {
  Board board;
  // The calibration and the views it was given (same order as
  // result->view_used). Both must be set.
  const CalibrationResult* result = nullptr;
  const std::vector<CalibrationView>* views = nullptr;
  // False when Calibrate failed; the report then says why
  // (calibration_error) and draws what the result holds.
  bool calibration_ok = true;
  std::string calibration_error;
  // Every input image, in input order.
  std::vector<ReportImage> images;
  // Time of the run in seconds (negative = not measured): reading and
  // decoding image files and detection (corners, grid, board ids), both
  // summed over the images (so with several threads they can exceed the
  // run's wall-clock time); calibration and the whole run, wall-clock. And
  // the worker threads used.
  double seconds_load = -1;
  double seconds_detect = -1;
  double seconds_calibrate = -1;
  double seconds_total = -1;
  int threads = 0;
  // Evidence on the calibration and its verdict (evidence/evidence.h,
  // evidence/verdict.h); null when not computed. The verdict heads
  // summary.md; the evidence adds a section (EvidenceMarkdown) and its
  // charts (WriteEvidenceCharts).
  const Evidence* evidence = nullptr;
  const Verdict* verdict = nullptr;
  // The comparison table of `--model auto` ("" when not run).
  std::string model_selection;
  // Capture advice (advice/advice.h; calibrate gives it when the verdict
  // is not good): a section after the evidence, the pictures
  // next_1.png, ... and advice.yaml. Null: none.
  const Advice* advice = nullptr;
};

// What WriteReport did.
struct ReportSummary {
  std::vector<std::string> files;     // written, in order (file names)
  std::vector<std::string> warnings;  // e.g. an overlay image not readable
};

// Writes into `dir` (created if needed): summary.md, residuals.png,
// residual_histogram.png, view_rms.png, coverage.png, distortion.png,
// the evidence plots (when input.evidence is set) and
// overlay_<image name>.png for options.num_overlays views. Files are
// written atomically (temporary name, then rename). Returns false with a
// message naming the path on failure; `summary` (optional) lists the files.
bool WriteReport(const std::string& dir, const ReportInput& input,
                 const ReportOptions& options, std::string* error,
                 ReportSummary* summary = nullptr);

// The markdown summary alone (what summary.md holds); `png_files` are the
// PNG files written next to it, listed with how to read each.
std::string ReportMarkdown(const ReportInput& input,
                           const ReportOptions& options,
                           const std::vector<std::string>& png_files);

// The evidence part of a report (evidence/evidence.h), shared by the
// single-camera report and the rig report (one per camera).

// File names of the evidence charts (the rig report puts the camera's name
// in front).
inline constexpr char kCrossValidationChart[] = "cross_validation.png";
inline constexpr char kUncertaintyChart[] = "uncertainty.png";
inline constexpr char kResidualBinsChart[] = "residual_bins.png";

// The evidence section of a summary: the verdict (null: none) with all its
// findings, then the cross-validation, projection uncertainty and
// systematic residual tables. Its heading has `heading_level` '#' (1-5),
// its subsections one more.
std::string EvidenceMarkdown(const Evidence& evidence, const Verdict* verdict,
                             int heading_level);

// How to read an evidence chart (`chart`: one of the names above, without
// a prefix), one sentence; "" for any other file.
std::string EvidenceChartDescription(const std::string& chart);

// Writes the evidence charts the evidence holds (the cross-validation and
// uncertainty maps when computed, the residual bins always) into `dir`,
// named `prefix` + the chart's name, for images of width x height, and
// appends the file names to `files` (optional). False with a message on an
// invalid size, when charts cannot be drawn, or when a file cannot be
// written.
bool WriteEvidenceCharts(const std::string& dir, const std::string& prefix,
                         int width, int height, const Evidence& evidence,
                         const ReportOptions& options,
                         std::vector<std::string>* files, std::string* error);

// How far the model's distortion moves `pixel`: the distance in pixels
// between `pixel` and where its ray (camera.Unproject) lands in the same
// camera without distortion (distortion parameters 0: the pinhole for the
// pinhole models, the equidistant fisheye r = f * theta for kannala-brandt),
// and the ray's angle from the optical axis in degrees. False when the model
// has no ray for the pixel (the undistortion does not converge).
bool DistortionShift(const Camera& camera, const Eigen::Vector2d& pixel,
                     double* shift_px, double* ray_angle_deg);

// A parameter value and its standard deviation as the summary prints them:
// both rounded to three significant digits of sigma (sigma > 0), or the value
// to 8 significant digits when sigma is unknown (<= 0 or not finite).
std::string FormatWithSigma(double value, double sigma,
                            std::string* sigma_text);

}  // namespace puzzlecal

#endif  // PUZZLECAL_REPORT_REPORT_H_
