// `puzzlecal calibrate`: a folder of photos in, a camera file (and a report)
// out.

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "apps/common_flags.h"
#include "apps/config_io.h"
#include "apps/image_io.h"
#include "apps/pipeline.h"
#include "apps/report.h"
#include "apps/subcommand.h"
#include "calib/calibrate.h"
#include "calib/camera_yaml.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

constexpr char kUsage[] =
    "puzzlecal calibrate --images DIR --board BOARD.yaml --model MODEL "
    "--out camera.yaml\n"
    "                    [--format puzzlecal|opencv|ros|kalibr] "
    "[--report DIR] [--threads N]\n\n"
    "Calibrates a camera from every image in DIR (png, jpg, tif, bmp; 8 or 16 "
    "bit; grey or colour)\nshowing the board of BOARD.yaml. Writes the camera "
    "file atomically; a run that cannot\nproduce a trustworthy result exits "
    "non-zero and writes nothing.";

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

// A one-line progress bar on a terminal, a plain line per image otherwise.
class Progress {
 public:
  explicit Progress(size_t total)
      : total_(total), terminal_(::isatty(::fileno(stderr)) != 0) {}

  void Done(const ImageResult& result) {
    ++done_;
    const std::string name = fs::path(result.file).filename().string();
    if (!terminal_) {
      std::cerr << "[" << done_ << "/" << total_ << "] " << name << ": "
                << ImageOutcomeName(result.outcome) << " (" << result.reason
                << ")\n";
      return;
    }
    constexpr int kWidth = 30;
    const int filled =
        static_cast<int>(kWidth * done_ / std::max<size_t>(1, total_));
    std::cerr << "\r[" << std::string(filled, '#')
              << std::string(kWidth - filled, ' ') << "] " << done_ << "/"
              << total_ << " " << name << std::string(20, ' ');
    if (done_ == total_) std::cerr << "\n";
  }

 private:
  size_t total_;
  size_t done_ = 0;
  bool terminal_;
};

// One line per input image for the log and the report.
std::vector<ReportImage> ReportLines(const std::vector<ImageResult>& images,
                                     const std::vector<int>& view_of_image,
                                     const CalibrationResult* result) {
  std::vector<ReportImage> lines;
  for (size_t i = 0; i < images.size(); ++i) {
    const ImageResult& image = images[i];
    ReportImage line;
    line.file = image.file;
    line.outcome = ImageOutcomeName(image.outcome);
    line.reason = image.reason;
    line.corners_detected = static_cast<int>(image.corners.size());
    line.view_index = view_of_image[i];
    const int v = line.view_index;
    if (v >= 0 && result != nullptr) {
      if (!result->view_used[v]) {
        line.outcome = "not used by the calibration";
        line.reason = result->view_reason[v];
      } else {
        for (bool inlier : result->inlier[v]) line.corners_used += inlier;
        line.outcome = "used";
      }
    }
    lines.push_back(line);
  }
  return lines;
}

int RunCalibrate() {
  const auto run_start = std::chrono::steady_clock::now();
  if (FLAGS_images.empty() || FLAGS_board.empty() || FLAGS_out.empty()) {
    std::cerr << "puzzlecal calibrate: --images, --board and --out are "
                 "required. Run `puzzlecal calibrate --help`.\n";
    return kExitUsage;
  }
  CameraModelId model;
  if (!CameraModelIdFromName(FLAGS_model, &model)) {
    std::cerr << "puzzlecal calibrate: unknown model '" << FLAGS_model
              << "'; choose one of " << CameraModelNames() << ".\n";
    return kExitUsage;
  }
  CameraFileFormat format;
  if (!CameraFileFormatFromName(FLAGS_format, &format)) {
    std::cerr << "puzzlecal calibrate: unknown format '" << FLAGS_format
              << "'; choose one of puzzlecal, opencv, ros, kalibr.\n";
    return kExitUsage;
  }
  if (FLAGS_threads < 0) {
    std::cerr << "puzzlecal calibrate: --threads must be >= 0.\n";
    return kExitUsage;
  }
  std::string error;
  Board board;
  if (!LoadBoardFile(FLAGS_board, &board, &error)) {
    std::cerr << "puzzlecal calibrate: " << error << "\n";
    return kExitBadInput;
  }
  if (!CheckOutputPath(FLAGS_out, &error)) {
    std::cerr << "puzzlecal calibrate: " << error << "\n";
    return kExitOutputError;
  }
  ImageListing listing;
  if (!ListImages(FLAGS_images, &listing, &error)) {
    std::cerr << "puzzlecal calibrate: " << error << "\n";
    return kExitBadInput;
  }
  for (const std::string& skipped : listing.skipped) {
    LOG(INFO) << "skipped " << skipped;
  }

  // Detection, grid and decode on all images, in parallel over images; each
  // worker holds one image at a time. OpenCV's own threads stay off so the
  // workers do not oversubscribe the cores.
  PipelineOptions pipeline_options;
  const int threads =
      FLAGS_threads > 0
          ? FLAGS_threads
          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  cv::setNumThreads(1);
  Progress progress(listing.images.size());
  std::vector<ImageResult> images = ProcessImageFiles(
      listing.images, board, pipeline_options, threads,
      [&](size_t, const ImageResult& result) { progress.Done(result); });

  int width = 0, height = 0;
  std::vector<int> view_of_image;
  const std::vector<CalibrationView> views =
      MakeCalibrationViews(board, &images, &view_of_image, &width, &height);
  double seconds_load = 0, seconds_detect = 0, seconds_grid_decode = 0;
  for (const ImageResult& image : images) {
    seconds_load += image.seconds_load;
    seconds_detect += image.seconds_detect;
    seconds_grid_decode += image.seconds_grid_decode;
  }

  const bool any_readable =
      std::any_of(images.begin(), images.end(), [](const ImageResult& r) {
        return r.outcome != ImageOutcome::kUnreadable;
      });
  if (!any_readable) {
    for (const ImageResult& image : images) std::cerr << image.reason << "\n";
    std::cerr << "puzzlecal calibrate: none of the " << images.size()
              << " image files in " << FLAGS_images
              << " could be read; no calibration written.\n";
    return kExitBadInput;
  }

  const auto calib_start = std::chrono::steady_clock::now();
  CalibrationOptions calibration_options;
  calibration_options.num_threads = threads;  // same result for any count
  CalibrationResult result;
  std::string calibration_error;
  const bool calibrated =
      Calibrate(views, model, width, height, calibration_options, &result,
                &calibration_error);
  const double seconds_calibrate = SecondsSince(calib_start);

  const std::vector<ReportImage> report_images =
      ReportLines(images, view_of_image, calibrated ? &result : nullptr);
  for (const ReportImage& line : report_images) {
    if (line.outcome == "used") continue;
    LOG(WARNING) << line.file << ": " << line.outcome
                 << (line.reason.empty() ? "" : " (" + line.reason + ")");
  }

  // The report is written also for a failed calibration: it shows why.
  if (!FLAGS_report.empty()) {
    ReportInput input;
    input.board = board;
    input.result = &result;
    input.views = &views;
    input.calibration_ok = calibrated;
    input.calibration_error = calibration_error;
    input.images = report_images;
    input.seconds_load = seconds_load;
    input.seconds_detect = seconds_detect + seconds_grid_decode;
    input.seconds_calibrate = seconds_calibrate;
    input.seconds_total = SecondsSince(run_start);
    input.threads = threads;
    if (!WriteReport(FLAGS_report, input, ReportOptions(), &error)) {
      std::cerr << "puzzlecal calibrate: report not written: " << error << "\n";
      // A failed calibration stays the outcome that matters.
      if (calibrated) return kExitOutputError;
    }
  }
  if (!calibrated) {
    std::cerr << "puzzlecal calibrate: no calibration written. "
              << calibration_error << "\n";
    return kExitNoResult;
  }
  if (!WriteCameraFile(FLAGS_out, format, result, &error)) {
    std::cerr << "puzzlecal calibrate: " << error << "\n";
    return kExitOutputError;
  }

  const double seconds_total = SecondsSince(run_start);
  std::cout << CalibrationReport(result) << "\n";
  std::cout << "views used: " << result.num_views_used << " of "
            << images.size() << " images; corners: " << result.num_corners_used
            << "; RMS " << std::setprecision(4) << result.rms_px << " px\n";
  std::cout << std::setprecision(3) << "time: " << seconds_total
            << " s wall clock on " << threads
            << " threads; summed over images: image decoding " << seconds_load
            << " s, detection " << seconds_detect << " s, grid and decode "
            << seconds_grid_decode << " s; calibration " << seconds_calibrate
            << " s\n";
  std::cout << "wrote " << FLAGS_out << "\n";
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    calibrate, "calibrate", "calibrate a camera from a folder of photos",
    kUsage, {"images", "board", "model", "out", "format", "report", "threads"},
    &RunCalibrate);

}  // namespace
}  // namespace puzzlecal
