// `puzzlecal check`: an existing calibration re-checked on new photos.

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <vector>

#include "apps/common_flags.h"
#include "apps/options_io.h"
#include "apps/subcommand.h"
#include "formats/board_file.h"
#include "formats/camera_yaml.h"
#include "formats/image_io.h"
#include "pipeline/recheck_run.h"
#include "report/image_chart.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

constexpr char kChartFile[] = "projection_difference.png";
constexpr char kNewCameraFile[] = "new_camera.yaml";

// The exit code of a verdict: 0 still valid, 1 drifted, 4 not enough data.
int ExitCodeOf(RecheckVerdict verdict) {
  switch (verdict) {
    case RecheckVerdict::kStillValid:
      return kExitOk;
    case RecheckVerdict::kDrifted:
      return kExitDrifted;
    case RecheckVerdict::kNotEnoughData:
      break;
  }
  return kExitNoResult;
}

// Each photo that gave no view, once.
void PrintPhotoProblems(const std::vector<ImageResult>& images) {
  for (const ImageResult& image : images) {
    if (image.outcome == ImageOutcome::kUsable) continue;
    std::string reason = image.reason;
    if (reason.rfind(image.file + ": ", 0) == 0) {
      reason.erase(0, image.file.size() + 2);
    }
    std::cerr << fs::path(image.file).filename().string() << ": "
              << ImageOutcomeName(image.outcome)
              << (reason.empty() ? "" : " (" + reason + ")") << "\n";
  }
}

// The map and the camera fitted on the new photos into FLAGS_out.
int WriteOutputs(const Recheck& recheck, const Camera& camera) {
  std::string error;
  if (recheck.difference.ok) {
    const std::string path = (fs::path(FLAGS_out) / kChartFile).string();
    if (!WriteProjectionDifferenceChart(
            path, recheck.difference, camera.width, camera.height,
            "Projection difference: the new photos' calibration against " +
                fs::path(FLAGS_camera).filename().string(),
            &error)) {
      std::cerr << "puzzlecal check: " << error << "\n";
      return kExitOutputError;
    }
    std::cout << "wrote " << path << "\n";
  }
  if (recheck.fresh_ok) {
    const std::string path = (fs::path(FLAGS_out) / kNewCameraFile).string();
    CalibrationRange range;
    range.max_field_angle_deg = recheck.observed_angle_deg;
    if (!WriteCameraFile(path, CameraFileFormat::kPuzzlecal, recheck.fresh,
                         &error, range)) {
      std::cerr << "puzzlecal check: " << error << "\n";
      return kExitOutputError;
    }
    std::cout << "wrote " << path << "\n";
  }
  return kExitOk;
}

int RunCheck() {
  if (FLAGS_camera.empty() || FLAGS_images.empty() || FLAGS_board.empty()) {
    std::cerr << "puzzlecal check: --camera, --images and --board are "
                 "required. Run `puzzlecal check --help`.\n";
    return kExitUsage;
  }
  if (FLAGS_threads < 0) {
    std::cerr << "puzzlecal check: --threads must be >= 0.\n";
    return kExitUsage;
  }
  const int threads =
      FLAGS_threads > 0
          ? FLAGS_threads
          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::string error;
  RunOptions options;
  if (!FLAGS_options.empty() &&
      !LoadOptionsFile(FLAGS_options, &options, &error)) {
    std::cerr << "puzzlecal check: " << error << "\n";
    return kExitBadInput;
  }
  std::error_code ec;
  if (!FLAGS_out.empty() &&
      (fs::create_directories(FLAGS_out, ec), !fs::is_directory(FLAGS_out))) {
    std::cerr << "puzzlecal check: cannot create the folder " << FLAGS_out
              << (ec ? ": " + ec.message() : "") << "\n";
    return kExitOutputError;
  }
  StoredCalibration stored;
  Board board;
  ImageListing listing;
  if (!ReadStoredCalibration(FLAGS_camera, &stored, &error) ||
      !LoadBoardFile(FLAGS_board, &board, &error) ||
      !ListImages(FLAGS_images, &listing, &error)) {
    std::cerr << "puzzlecal check: " << error << "\n";
    return kExitBadInput;
  }
  if (!listing.note.empty() && ConsoleVerbosity() != Verbosity::kQuiet) {
    std::cerr << "note: " << listing.note << "\n";
  }
  if (stored.covariance.size() == 0 &&
      ConsoleVerbosity() != Verbosity::kQuiet) {
    // A hand-written or trimmed file, or a format without the field: the
    // check runs, but the stored camera's own uncertainty cannot widen
    // what counts as a drift.
    std::cerr
        << "note: " << FLAGS_camera
        << " has no parameter_covariance: the check cannot judge drift "
           "against its uncertainty, only against the new photos' "
           "(a difference within the stored calibration's own "
           "uncertainty can count as drift); `puzzlecal calibrate` writes "
           "it in its own format (--format puzzlecal)\n";
  }
  RecheckRunOptions run_options;
  run_options.pipeline = options.pipeline;
  run_options.calibration = options.calibration;
  run_options.calibration.num_threads = threads;
  run_options.recheck = options.check;
  run_options.recheck.evidence = options.evidence;
  cv::setNumThreads(1);  // the workers are the photos
  RecheckRun run;
  if (!RecheckOnPhotos(stored, listing.images, board, run_options, threads,
                       &run, &error)) {
    std::cerr << "puzzlecal check: " << FLAGS_images << ": " << error << "\n";
    return kExitBadInput;
  }
  const Verbosity verbosity = ConsoleVerbosity();
  if (verbosity != Verbosity::kQuiet) {
    PrintPhotoProblems(run.images);
    std::cout << RecheckText(run.recheck, stored);
  } else {
    std::cout << "verdict: " << RecheckVerdictName(run.recheck.verdict) << " — "
              << run.recheck.reason << "\n";
  }
  if (verbosity == Verbosity::kVerbose) {
    std::cout << "check: " << run.recheck.seconds << " s\n";
  }
  if (!FLAGS_out.empty()) {
    const int written = WriteOutputs(run.recheck, stored.camera);
    if (written != kExitOk) return written;
  }
  return ExitCodeOf(run.recheck.verdict);
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    check, "check", "re-check an existing calibration on new photos",
    "puzzlecal check --camera camera.yaml --images DIR --board BOARD.yaml\n"
    "                [--out DIR] [--threads N] [--options FILE]\n\n"
    "Checks whether a calibration (a camera file in any format puzzlecal "
    "reads) still holds,\nfrom new photos of the board: their reprojection "
    "error with the stored intrinsics held\n(only the poses fitted) and the "
    "views worse than the stored calibration's noise (its\nRMS, in puzzlecal "
    "camera files); the same model calibrated on the new photos, started\n"
    "from the stored camera; the projection difference between the two after "
    "the\nbest-fitting rotation, per field-angle band, against the new fit's "
    "uncertainty (and the\nstored one's, when its file has a covariance). "
    "Verdict: still-valid, drifted (by how\nmuch, in which bands) or "
    "not-enough-data. --out writes DIR/projection_difference.png\nand the "
    "camera calibrated on the new photos, DIR/new_camera.yaml.\n\n"
    "Exit codes: 0 still valid, 1 drifted, 2 bad command line, 3 bad input, "
    "4 not enough\ndata, 5 an output cannot be written.",
    {"camera", "images", "board", "out", "threads", "options"}, &RunCheck);

}  // namespace
}  // namespace puzzlecal
