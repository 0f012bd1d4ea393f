// `puzzlecal advise`: which photos to take next, from the photos taken.

#include <gflags/gflags.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <vector>

#include "advice/advice.h"
#include "apps/common_flags.h"
#include "apps/options_io.h"
#include "apps/subcommand.h"
#include "evidence/judgement.h"
#include "formats/board_file.h"
#include "formats/image_io.h"
#include "pipeline/pipeline.h"
#include "pipeline/recheck_run.h"
#include "report/advice_report.h"

DEFINE_int32(count, 4, "advise: board poses to advise (>= 1).");
DEFINE_double(field_deg, 0,
              "advise: judge the uncertainty over rays up to this many "
              "degrees off the axis (0: the image's width circle for a "
              "pinhole camera, the image's inscribed circle or the observed "
              "field for a fisheye).");

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// Picture width of the advice, pixels.
constexpr int kPictureWidth = 1200;

struct AdviseRequest {
  RunOptions options;
  Board board;
  std::vector<std::string> files;
  int threads = 1;
  StoredCalibration known;  // --camera (empty params: none)
};

int ParseAdviseRequest(AdviseRequest* request) {
  if (FLAGS_images.empty() || FLAGS_board.empty() || FLAGS_out.empty()) {
    std::cerr << "puzzlecal advise: --images, --board and --out are "
                 "required. Run `puzzlecal advise --help`.\n";
    return kExitUsage;
  }
  if (FLAGS_threads < 0) {
    std::cerr << "puzzlecal advise: --threads must be >= 0.\n";
    return kExitUsage;
  }
  request->threads =
      FLAGS_threads > 0
          ? FLAGS_threads
          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::string error;
  if (!FLAGS_options.empty() &&
      !LoadOptionsFile(FLAGS_options, &request->options, &error)) {
    std::cerr << "puzzlecal advise: " << error << "\n";
    return kExitBadInput;
  }
  AdviceOptions& advice = request->options.advice;
  advice.count = FLAGS_count;
  advice.field_deg = FLAGS_field_deg;
  advice.num_threads = request->threads;
  advice.target_uncertainty_px = request->options.verdict.max_uncertainty_px;
  advice.target_min_views = request->options.verdict.min_views;
  advice.spline_prior = request->options.calibration.spline_prior;
  if (!advice.Check(&error)) {
    std::cerr << "puzzlecal advise: " << error << "\n";
    return kExitUsage;
  }
  std::error_code ec;
  fs::create_directories(FLAGS_out, ec);
  if (!fs::is_directory(FLAGS_out)) {
    std::cerr << "puzzlecal advise: cannot create the folder " << FLAGS_out
              << (ec ? ": " + ec.message() : "") << "\n";
    return kExitOutputError;
  }
  ImageListing listing;
  if (!LoadBoardFile(FLAGS_board, &request->board, &error) ||
      !ListImages(FLAGS_images, &listing, &error) ||
      (!FLAGS_camera.empty() &&
       !ReadStoredCalibration(FLAGS_camera, &request->known, &error))) {
    std::cerr << "puzzlecal advise: " << error << "\n";
    return kExitBadInput;
  }
  if (!listing.note.empty() && ConsoleVerbosity() != Verbosity::kQuiet) {
    std::cerr << "note: " << listing.note << "\n";
  }
  request->files = listing.images;
  return kExitOk;
}

// The intrinsics and poses the advice starts from: with --camera, the
// photos posed with its intrinsics held (each intrinsic then counted as
// free for the information: the advice is about calibrating it); otherwise
// a calibration of --model. False with the reason.
bool StartingPoint(const AdviseRequest& request,
                   const std::vector<CalibrationView>& views, int width,
                   int height, CalibrationResult* result, std::string* why) {
  CalibrationOptions calibration = request.options.calibration;
  calibration.num_threads = request.threads;
  if (!request.known.camera.params.empty()) {
    const Camera& camera = request.known.camera;
    if (camera.width != width || camera.height != height) {
      *why = "--camera " + FLAGS_camera + " is a camera of " +
             std::to_string(camera.width) + " x " +
             std::to_string(camera.height) + " pixels, the photos are " +
             std::to_string(width) + " x " + std::to_string(height);
      return false;
    }
    if (!Calibrate(views, camera.model, width, height,
                   PoseFitOptions(calibration, camera.params), result, why)) {
      return false;
    }
    std::fill(result->param_fixed.begin(), result->param_fixed.end(), false);
    return true;
  }
  JudgementOptions judgement;
  judgement.evidence = request.options.evidence;
  judgement.evidence.cross_validation = false;  // not needed for advice
  judgement.verdict = request.options.verdict;
  judgement.model_selection = request.options.model_selection;
  JudgedCalibration judged;
  if (!CalibrateAndJudge(views, width, height, FLAGS_model, calibration,
                         judgement, &judged, why)) {
    return false;
  }
  if (ConsoleVerbosity() != Verbosity::kQuiet) {
    if (judged.auto_model) std::cout << judged.selection.Table();
    std::cout << judged.judgement.verdict.Line() << "\n";
  }
  *result = std::move(judged.result);
  return true;
}

int RunAdvise() {
  AdviseRequest request;
  if (const int code = ParseAdviseRequest(&request); code != kExitOk) {
    return code;
  }
  cv::setNumThreads(1);  // the workers are the photos
  std::vector<ImageResult> images = ProcessImageFiles(
      request.files, request.board, request.options.pipeline, request.threads);
  int width = 0, height = 0;
  const std::vector<CalibrationView> views =
      MakeCalibrationViews(request.board, &images, &width, &height);
  if (views.empty()) {
    std::cerr << "puzzlecal advise: " << FLAGS_images
              << ": no photo shows the board; take a first photo with the "
                 "board filling the middle of the image\n";
    return kExitNoResult;
  }
  CalibrationResult result;
  std::string error;
  if (!StartingPoint(request, views, width, height, &result, &error)) {
    std::cerr << "puzzlecal advise: " << FLAGS_images << ": " << error << "\n";
    return kExitNoResult;
  }
  const Advice advice =
      AdviseViews(views, result, request.board, request.options.advice);
  if (!advice.ok) {
    std::cerr << "puzzlecal advise: " << advice.error << "\n";
    return kExitNoResult;
  }
  std::cout << advice.Text();
  std::vector<std::string> files;
  if (!WriteAdviceFiles(FLAGS_out, advice, SeenCorners(views, result),
                        kPictureWidth, &files, &error)) {
    std::cerr << "puzzlecal advise: " << error << "\n";
    return kExitOutputError;
  }
  for (const std::string& file : files) {
    std::cout << "wrote " << (fs::path(FLAGS_out) / file).string() << "\n";
  }
  if (ConsoleVerbosity() == Verbosity::kVerbose) {
    std::cout << "advice: " << advice.seconds << " s, "
              << advice.candidate_poses.size() << " candidate poses\n";
  }
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    advise, "advise", "which photos of the board to take next",
    "puzzlecal advise --images DIR --board BOARD.yaml --out DIR\n"
    "                 [--camera camera.yaml] [--model NAME|auto] [--count N]\n"
    "                 [--field-deg DEG] [--threads N] [--options FILE]\n\n"
    "From the photos taken so far, the board poses that would lower the "
    "projection\nuncertainty the most: each candidate pose (the board's "
    "centre at places over the\nimage, at 0.5 to 3 times the distances used, "
    "tilted up to 60 degrees) is added to\nthe calibration's information and "
    "the uncertainty over the image predicted; the\nbest N are chosen one by "
    "one, no two alike. For each: words (\"board about 0.6 m\naway, its "
    "centre in the top-left corner of the image, tilted about 40 degrees "
    "with\nits left edge towards the camera\"), a picture DIR/next_K.png of "
    "the image frame with\nthe board's outline where it should appear, and "
    "the expected uncertainty after it;\nDIR/advice.yaml holds the poses "
    "(cam_from_board R, t) and an estimate of how many\nphotos reach the "
    "verdict's limit. --camera: start from known intrinsics (the photos\nare "
    "posed with them) instead of calibrating --model.\n\n"
    "Exit codes: 0 advice written, 2 bad command line, 3 bad input, 4 no "
    "advice (no\nphoto shows the board, or the photos cannot be calibrated), "
    "5 an output cannot be\nwritten.",
    {"images", "board", "out", "camera", "model", "count", "field_deg",
     "threads", "options"},
    &RunAdvise);

}  // namespace
}  // namespace puzzlecal
