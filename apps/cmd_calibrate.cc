// `puzzlecal calibrate`: a folder of photos in, a camera file (and a report)
// out.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "advice/advice.h"
#include "apps/common_flags.h"
#include "apps/fixed_params.h"
#include "apps/options_io.h"
#include "apps/report_folder.h"
#include "apps/subcommand.h"
#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/judgement.h"
#include "evidence/model_selection.h"
#include "evidence/verdict.h"
#include "formats/board_file.h"
#include "formats/camera_yaml.h"
#include "formats/image_io.h"
#include "formats/png_writer.h"
#include "pipeline/folder_watch.h"
#include "pipeline/pipeline.h"
#include "pipeline/video_frames.h"
#include "report/advice_report.h"
#include "report/report.h"
#include "util/atomic_file.h"
#include "util/statistics.h"
#include "util/string_format.h"
#include "util/timer.h"

DEFINE_string(watch, "",
              "calibrate: a folder to watch instead of --images: after each "
              "photo that arrives, one line (used or why not, views, "
              "uncertainty, verdict, the next advised photo); ends when the "
              "verdict is good, on Ctrl-C or after --watch-idle seconds "
              "without a photo, and writes what calibrate writes.");
DEFINE_double(watch_idle, 0,
              "calibrate --watch: stop after this many seconds without a new "
              "photo (0: wait for Ctrl-C or a good verdict).");

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// How often --watch looks into its folder.
constexpr int kWatchPollMs = 200;
// A photo whose board corners sit, in the median, within this fraction of
// the image diagonal of an earlier photo's same corners repeats its pose.
constexpr double kDuplicateFraction = 0.01;

constexpr char kUsage[] =
    "puzzlecal calibrate --images DIR --board BOARD.yaml --out camera.yaml\n"
    "                    [--model MODEL|auto]  (MODEL: see --model below)\n"
    "                    [--format puzzlecal|opencv|ros|kalibr] "
    "[--report DIR] [--threads N]\n"
    "                    [--rostopic TOPIC] [--camera-name NAME] "
    "[--quiet | --verbose]\n"
    "                    [--options FILE]  (`puzzlecal options` writes one)\n"
    "                    [--fix NAMES] [--initial camera.yaml] [--same-focal]\n"
    "                    [--knot-spacing-deg D]  (splined models)\n"
    "puzzlecal calibrate --watch DIR --board BOARD.yaml --out camera.yaml "
    "[--watch-idle S] [...]\n\n"
    "Calibrates a camera from every image in DIR (png, jpg, tif, bmp; 8 or 16 "
    "bit; grey or colour)\nshowing the board of BOARD.yaml, and from the "
    "videos in it (mp4, avi, mkv, mov, ...;\nDIR may be one video): sharp "
    "frames with new poses are chosen, at most video.max_frames\nper video; "
    "a line per video says how many were kept and why the others were not "
    "(the\nreport folder gets a table per video, video_frames_NAME.csv). --out "
    "is the "
    "camera file to write (a file path in an\nexisting folder; --format "
    "chooses what it holds). The camera file is written first and\n"
    "atomically; the report folder is replaced as a whole. A run that cannot "
    "produce a\nresult (too few usable views, no convergence) exits non-zero "
    "and writes no camera\nfile; a result whose verdict is not good is "
    "written with its verdict (exit 0):\nread the verdict line before using "
    "it.\n\n--fix holds parameters at their start (k3,p1,p2 as OpenCV's "
    "CALIB_FIX_K3 and\nCALIB_ZERO_TANGENT_DIST; focal, principal-point, "
    "distortion, all); --initial starts\nfrom a camera file (its model), so "
    "--initial cam.yaml --fix all fits only the poses.\n\n--watch DIR waits "
    "for "
    "photos to arrive in DIR (a phone or a capture script writing\ninto it) "
    "and after each prints one line: used or why not (no board, too few "
    "corners,\na pose nearly repeating an earlier photo), views so far, "
    "coverage, the projection\nuncertainty, the verdict and the next advised "
    "photo (its picture refreshed beside\n--out as next_1.png). It ends when "
    "the verdict is good, on Ctrl-C or after\n--watch-idle seconds without a "
    "photo, and writes the camera file and report then.\n\nExit codes: 0 done, "
    "2 bad command line, 3 bad input, 4 no "
    "trustworthy result,\n5 an output cannot be written (checked before the "
    "work starts), 130 interrupted.";

// A one-line progress bar on a terminal, a plain line per image otherwise.
class Progress {
 public:
  Progress(size_t total, Verbosity verbosity)
      : total_(total),
        terminal_(::isatty(::fileno(stderr)) != 0),
        verbosity_(verbosity) {}

  // Each image's problems are listed once at the end; here a terminal gets
  // a bar, --verbose a line per image as it finishes.
  void Done(const ImageResult& result) {
    ++done_;
    const std::string name = fs::path(result.file).filename().string();
    if (verbosity_ == Verbosity::kVerbose) {
      std::cerr << "[" << done_ << "/" << total_ << "] " << name << ": "
                << ImageOutcomeName(result.outcome) << " (" << result.reason
                << ")\n";
      return;
    }
    if (!terminal_ || verbosity_ == Verbosity::kQuiet) return;
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
  Verbosity verbosity_;
};

// ---- interruption ----

// Set once the camera file is in place; read by the SIGINT handler.
volatile std::sig_atomic_t g_camera_written = 0;

// Ctrl-C: says so and what is left, then ends the process (exit 130). Files
// are written by rename, so none is half-written; a camera file written
// before the interruption stays.
void OnInterrupt(int) {
  const char* message =
      g_camera_written
          ? "\npuzzlecal calibrate: interrupted; the camera file was written, "
            "the report was not\n"
          : "\npuzzlecal calibrate: interrupted; nothing written\n";
  const ssize_t ignored = ::write(STDERR_FILENO, message, std::strlen(message));
  (void)ignored;
  std::_Exit(130);
}

// ---- outputs ----

// Writes the report aside, then puts it in place of `dir`
// (apps/report_folder.h).
bool WriteReportInPlace(const fs::path& dir, const ReportInput& input,
                        const std::vector<VideoFrames>& videos,
                        std::string* error) {
  return WriteFolderInPlace(
      dir,
      [&](const std::string& folder, std::string* why) {
        if (!WriteReport(folder, input, ReportOptions(), why)) return false;
        // Each video's frames: which were taken and why the others not.
        for (const VideoFrames& video : videos) {
          const std::string name = "video_frames_" +
                                   fs::path(video.file).filename().string() +
                                   ".csv";
          if (!WriteFileAtomically((fs::path(folder) / name).string(),
                                   video.Csv(), why)) {
            return false;
          }
        }
        return true;
      },
      error);
}

// ---- messages ----

// Why no image gave a view, when the photos look like a board but not like
// the board of the board file: most readable images have a lattice the code
// (or the size) of the board file does not fit anywhere.
std::string BoardMismatchMessage(const std::vector<ImageResult>& images,
                                 const Board& board,
                                 const std::string& board_file) {
  constexpr int kManyCorners = 20;
  int readable = 0, mismatched = 0;
  for (const ImageResult& image : images) {
    if (image.outcome == ImageOutcome::kUnreadable) continue;
    ++readable;
    const bool many = static_cast<int>(image.corners.size()) >= kManyCorners;
    mismatched += many && (image.outcome == ImageOutcome::kNotDecoded ||
                           (!board.Traits().absolute_ids &&
                            image.outcome == ImageOutcome::kTooFewCorners));
  }
  if (mismatched == 0 || 2 * mismatched < readable) return "";
  std::ostringstream out;
  out << mismatched << " of " << readable
      << " images show many corners but none matches ";
  if (board.Traits().absolute_ids) {
    out << "the code of " << board_file
        << " at any position: check cols, rows and origin (" << board.cols
        << " x " << board.rows << " from [" << board.origin.x() << ", "
        << board.origin.y()
        << "]), or whether the board is a plain "
           "checkerboard (type: checkerboard)";
  } else {
    out << "the " << board.cols << " x " << board.rows << " corners of "
        << board_file << ": check cols and rows";
  }
  return out.str();
}

// A plain checkerboard's board file that does not match the photos: most
// views show a complete lattice of one size (every corner of a W x H
// rectangle of ids, W x H in either orientation), none a larger one, and
// that size is not the file's. The views alone cannot tell a checkerboard's
// size otherwise (its corners carry no ids), so a 6 x 4 board calibrated as
// 10 x 10 would be accepted with every distance scaled. Returns the message
// ("" when the file fits or the photos cannot tell).
std::string CheckerboardSizeMismatch(const std::vector<CalibrationView>& views,
                                     const Board& board,
                                     const std::string& board_file) {
  constexpr double kMostViews = 0.8;  // share of views showing the size
  constexpr int kMinViews = 3;
  if (board.type != BoardType::kCheckerboard || views.empty()) return "";
  std::map<std::pair<int, int>, int> complete;  // {short, long} side -> views
  int largest_short = 0, largest_long = 0, counted = 0;
  for (const CalibrationView& view : views) {
    if (view.board_points.empty()) continue;
    ++counted;
    int min_x = INT_MAX, max_x = INT_MIN, min_y = INT_MAX, max_y = INT_MIN;
    for (const Eigen::Vector3d& p : view.board_points) {
      const int x = static_cast<int>(std::lround(p.x() / board.tile_size_m));
      const int y = static_cast<int>(std::lround(p.y() / board.tile_size_m));
      min_x = std::min(min_x, x);
      max_x = std::max(max_x, x);
      min_y = std::min(min_y, y);
      max_y = std::max(max_y, y);
    }
    const int w = max_x - min_x + 1, h = max_y - min_y + 1;
    const int short_side = std::min(w, h), long_side = std::max(w, h);
    largest_short = std::max(largest_short, short_side);
    largest_long = std::max(largest_long, long_side);
    if (static_cast<int>(view.board_points.size()) == w * h) {
      ++complete[{short_side, long_side}];
    }
  }
  if (counted < kMinViews) return "";
  for (const auto& [size, count] : complete) {
    if (count < kMinViews || count < kMostViews * counted) continue;
    const auto [short_side, long_side] = size;
    if (largest_short > short_side || largest_long > long_side) return "";
    const int file_short = std::min(board.cols, board.rows);
    const int file_long = std::max(board.cols, board.rows);
    if (short_side == file_short && long_side == file_long) return "";
    std::ostringstream out;
    out << board_file << " gives a checkerboard of " << board.cols << " x "
        << board.rows << " inner corners, but " << count << " of " << counted
        << " photos show a complete lattice of " << long_side << " x "
        << short_side
        << " inner corners and none a larger one: the file does not match "
           "the board photographed. Set cols and rows to the inner corners "
           "of the printed board (and tile_size_m to its square size)";
    return out.str();
  }
  return "";
}

// Each image that gave no view, once: "NAME: outcome (reason)".
void PrintImageProblems(const std::vector<ReportImage>& lines) {
  const Verbosity verbosity = ConsoleVerbosity();
  if (verbosity == Verbosity::kQuiet) return;
  for (const ReportImage& line : lines) {
    if (line.use == ViewUse::kUsed && verbosity != Verbosity::kVerbose) {
      continue;
    }
    // Loading messages start with the path; the line names the file already.
    std::string reason = line.reason;
    if (reason.rfind(line.file + ": ", 0) == 0) {
      reason.erase(0, line.file.size() + 2);
    }
    std::cerr << fs::path(line.file).filename().string() << ": "
              << line.OutcomeText()
              << (reason.empty() ? "" : " (" + reason + ")") << "\n";
  }
}

// ---- the command, in stages ----

// What the command line asks for, checked before any image is read.
struct CalibrateRequest {
  bool auto_model = false;
  CameraModelId model = CameraModelId::kPinholeRadtan;
  CameraFileFormat format = CameraFileFormat::kPuzzlecal;
  // The format decides the model's free parameters (Kalibr's radtan has no
  // k3), so they are settled here.
  CalibrationOptions calibration_options;
  // The parameters the user holds (options file and --fix), added to the
  // format's once the model is known.
  std::vector<std::string> user_fixed;
  // --initial: the camera to start from (empty params: none).
  Camera initial;
  RunOptions options;  // --options FILE, or the defaults
  int threads = 1;
  Board board;
  ImageListing listing;
  Verbosity verbosity = Verbosity::kNormal;
  // --watch: photos arrive one by one (the model table is not printed at
  // every step).
  bool watching = false;
};

// What the run produced, image by image and as a whole.
struct CalibrationRun {
  // One record per image, in file order, then per kept video frame (a video
  // that cannot be read: one unreadable record).
  std::vector<ImageResult> images;
  // Every video's frames and their outcomes (kept frames are in `images`).
  std::vector<VideoFrames> videos;
  std::vector<CalibrationView> views;
  int width = 0, height = 0;
  ModelSelection selection;  // --model auto only
  CalibrationResult result;
  bool calibrated = false;
  std::string calibration_error;
  Evidence evidence;
  Verdict verdict;
  // Which photos to take next, when the verdict is not good and a report
  // is written (advice.ok false otherwise).
  Advice advice;
  double seconds_load = 0, seconds_detect = 0, seconds_grid_decode = 0;
  double seconds_calibrate = 0;
};

// --initial FILE: the camera to start from. Its model is the run's unless
// --model names another (a usage error) or auto (which would not start
// from it).
int ParseInitialCamera(CalibrateRequest* request) {
  if (FLAGS_initial.empty()) return kExitOk;
  std::string error;
  if (!ReadCameraFile(FLAGS_initial, &request->initial, &error)) {
    std::cerr << "puzzlecal calibrate: --initial: " << error << "\n";
    return kExitBadInput;
  }
  const bool model_given =
      !gflags::GetCommandLineFlagInfoOrDie("model").is_default;
  if (model_given &&
      (request->auto_model || request->model != request->initial.model)) {
    std::cerr << "puzzlecal calibrate: --initial " << FLAGS_initial
              << " holds a " << CameraModelName(request->initial.model)
              << " camera, --model says " << FLAGS_model
              << "; leave --model out to calibrate the file's model.\n";
    return kExitUsage;
  }
  request->auto_model = false;
  request->model = request->initial.model;
  request->calibration_options.initial_params = request->initial.params;
  return kExitOk;
}

// The user's fixed parameters (options file, --fix) for the run's model,
// on top of the format's. Returns kExitOk or kExitUsage, having said why.
int AddUserFixed(CalibrateRequest* request) {
  std::vector<std::string> names;
  std::string error;
  if (!ExpandFixedParams(FLAGS_fix, request->model, &names, &error)) {
    std::cerr << "puzzlecal calibrate: --fix: " << error << ".\n";
    return kExitUsage;
  }
  for (const std::string& name : request->user_fixed) {
    std::vector<std::string> one;
    if (!ExpandFixedParams(name, request->model, &one, &error)) {
      std::cerr << "puzzlecal calibrate: calibration.fixed_params: " << error
                << ".\n";
      return kExitUsage;
    }
    AddFixedParams(one, &names);
  }
  AddFixedParams(names, &request->calibration_options.fixed_params);
  if (request->calibration_options.fixed_params.size() ==
      static_cast<size_t>(CameraModelNumParams(request->model))) {
    std::cerr << "puzzlecal calibrate: every parameter of "
              << CameraModelName(request->model)
              << " is held: nothing to calibrate (calibrate-rig --initial "
                 "NAME=FILE --fix all fits a rig's poses to known cameras).\n";
    return kExitUsage;
  }
  return kExitOk;
}

// Flags, formats, outputs, the board file and the image folder. Returns
// kExitOk or the exit code, having said why.
int ParseRequest(CalibrateRequest* request) {
  request->watching = !FLAGS_watch.empty();
  if ((FLAGS_images.empty() == FLAGS_watch.empty()) || FLAGS_board.empty() ||
      FLAGS_out.empty()) {
    std::cerr << "puzzlecal calibrate: --images (or --watch), --board and "
                 "--out are required, --images and --watch not both. Run "
                 "`puzzlecal calibrate --help`.\n";
    return kExitUsage;
  }
  if (!(FLAGS_watch_idle >= 0)) {
    std::cerr << "puzzlecal calibrate: --watch-idle must be >= 0.\n";
    return kExitUsage;
  }
  request->auto_model = FLAGS_model == "auto";
  if (!request->auto_model &&
      !CameraModelIdFromName(FLAGS_model, &request->model)) {
    std::cerr << "puzzlecal calibrate: unknown model '" << FLAGS_model
              << "'; choose one of " << CameraModelNames() << " or auto.\n";
    return kExitUsage;
  }
  std::string error;
  if (!FLAGS_options.empty() &&
      !LoadOptionsFile(FLAGS_options, &request->options, &error)) {
    std::cerr << "puzzlecal calibrate: " << error << "\n";
    return kExitBadInput;
  }
  request->calibration_options = request->options.calibration;
  if (FLAGS_same_focal) request->calibration_options.same_focal_length = true;
  if (FLAGS_knot_spacing_deg != 0) {
    request->calibration_options.spline_knot_spacing_deg =
        FLAGS_knot_spacing_deg;
    if (!request->calibration_options.Check(&error)) {
      std::cerr << "puzzlecal calibrate: --knot-spacing-deg: " << error
                << ".\n";
      return kExitUsage;
    }
  }
  request->user_fixed = request->calibration_options.fixed_params;
  request->calibration_options.fixed_params.clear();
  if (const int code = ParseInitialCamera(request); code != kExitOk) {
    return code;
  }
  if (!CameraFileFormatFromName(FLAGS_format, &request->format)) {
    std::cerr << "puzzlecal calibrate: unknown format '" << FLAGS_format
              << "'; choose one of puzzlecal, opencv, ros, kalibr.\n";
    return kExitUsage;
  }
  if (!request->auto_model &&
      !CameraFormatFixedParams(request->format, request->model,
                               &request->calibration_options.fixed_params,
                               &error)) {
    std::cerr << "puzzlecal calibrate: --format " << FLAGS_format << ": "
              << error << ".\n";
    return kExitUsage;
  }
  if (!request->auto_model) {
    if (const int code = AddUserFixed(request); code != kExitOk) return code;
  }
  if (FLAGS_threads < 0) {
    std::cerr << "puzzlecal calibrate: --threads must be >= 0.\n";
    return kExitUsage;
  }
  request->threads =
      FLAGS_threads > 0
          ? FLAGS_threads
          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  // Every output is checked before the work starts.
  if (!CheckOutputPath(FLAGS_out, &error) ||
      (!FLAGS_report.empty() && !CheckReportFolder(FLAGS_report, &error))) {
    std::cerr << "puzzlecal calibrate: " << error << "\n";
    return kExitOutputError;
  }
  if (!LoadBoardFile(FLAGS_board, &request->board, &error) ||
      (!request->watching &&
       !ListImagesAndVideos(FLAGS_images, &request->listing, &error))) {
    std::cerr << "puzzlecal calibrate: " << error << "\n";
    return kExitBadInput;
  }
  std::error_code ec;
  if (request->watching && (fs::create_directories(FLAGS_watch, ec),
                            !fs::is_directory(FLAGS_watch))) {
    std::cerr << "puzzlecal calibrate: --watch " << FLAGS_watch
              << ": not a folder and cannot be made one"
              << (ec ? ": " + ec.message() : "") << "\n";
    return kExitBadInput;
  }
  request->verbosity = ConsoleVerbosity();
  // Photos in formats that are not read, said even without --verbose.
  if (!request->listing.note.empty() &&
      request->verbosity != Verbosity::kQuiet) {
    std::cerr << "note: " << request->listing.note << "\n";
  }
  if (request->verbosity == Verbosity::kVerbose) {
    for (const std::string& skipped : request->listing.skipped) {
      std::cerr << "skipped " << skipped << "\n";
    }
  }
  return kExitOk;
}

// The frames chosen from each video (pipeline/video_frames.h), one video
// at a time: its kept frames join the images, a video that cannot be read
// is one unreadable record. A line per video says what became of its
// frames.
void ReadVideos(const CalibrateRequest& request, CalibrationRun* run) {
  for (const std::string& video : request.listing.videos) {
    VideoFrames frames;
    std::string error;
    if (!ReadVideoFrames(video, request.board, request.options.pipeline,
                         request.options.video, &frames, &error)) {
      ImageResult unreadable;
      unreadable.file = video;
      unreadable.outcome = ImageOutcome::kUnreadable;
      unreadable.reason = error;
      run->images.push_back(std::move(unreadable));
      continue;
    }
    if (request.verbosity != Verbosity::kQuiet) {
      std::cout << frames.Summary() << "\n";
    }
    for (ImageResult& kept : frames.kept)
      run->images.push_back(std::move(kept));
    frames.kept.clear();
    run->videos.push_back(std::move(frames));
  }
}

// Detection, grid and decode on all images, in parallel over images (each
// worker holds one image at a time; OpenCV's own threads stay off so the
// workers do not oversubscribe the cores), then the calibration views.
// Returns kExitOk or kExitBadInput when no image could be read.
int DetectAll(const CalibrateRequest& request, CalibrationRun* run) {
  cv::setNumThreads(1);
  Progress progress(request.listing.images.size(), request.verbosity);
  run->images = ProcessImageFiles(
      request.listing.images, request.board, request.options.pipeline,
      request.threads,
      [&](size_t, const ImageResult& result) { progress.Done(result); });
  ReadVideos(request, run);
  run->views = MakeCalibrationViews(request.board, &run->images, &run->width,
                                    &run->height);
  for (const ImageResult& image : run->images) {
    run->seconds_load += image.seconds_load;
    run->seconds_detect += image.seconds_detect;
    run->seconds_grid_decode += image.seconds_grid_decode;
  }
  const bool any_readable = std::any_of(
      run->images.begin(), run->images.end(), [](const ImageResult& r) {
        return r.outcome != ImageOutcome::kUnreadable;
      });
  if (any_readable) {
    const std::string mismatch =
        CheckerboardSizeMismatch(run->views, request.board, FLAGS_board);
    if (mismatch.empty()) return kExitOk;
    std::cerr << "puzzlecal calibrate: " << mismatch
              << "; no calibration written.\n";
    return kExitBadInput;
  }
  for (const ImageResult& image : run->images) {
    std::cerr << image.reason << "\n";
  }
  const size_t count = run->images.size();
  std::cerr << "puzzlecal calibrate: "
            << (count == 1 ? "the one image or video file in " + FLAGS_images +
                                 " could not be read"
                           : "none of the " + std::to_string(count) +
                                 " image and video files in " + FLAGS_images +
                                 " could be read")
            << "; no calibration written.\n";
  return kExitBadInput;
}

// --model auto: the candidate with the lowest held-out error
// (evidence/model_selection.h), which must fit the format. Returns kExitOk or
// the exit code.
int SelectModelOf(CalibrateRequest* request, CalibrationRun* run) {
  std::string error;
  if (!SelectModel(run->views, run->width, run->height,
                   request->calibration_options,
                   request->options.model_selection, &run->selection, &error)) {
    if (request->watching) {
      run->calibration_error = error;
      return kExitNoResult;
    }
    // The table, when any candidate was tried (it shows why each failed).
    if (!run->selection.candidates.empty()) std::cerr << run->selection.Table();
    std::cerr << "puzzlecal calibrate: " << error << "\n";
    return kExitNoResult;
  }
  if (!request->watching && request->verbosity != Verbosity::kQuiet) {
    std::cout << run->selection.Table();
  } else if (!request->watching && !run->selection.compared) {
    // The table's "chosen:" line says it otherwise.
    std::cerr << "note: --model auto: "
              << CameraModelName(
                     run->selection.candidates[run->selection.chosen].model)
              << ": " << run->selection.reason << "\n";
  }
  request->model = run->selection.candidates[run->selection.chosen].model;
  if (!CameraFormatFixedParams(request->format, request->model,
                               &request->calibration_options.fixed_params,
                               &error)) {
    std::cerr << "puzzlecal calibrate: --format " << FLAGS_format << ": "
              << error << "; choose --model explicitly.\n";
    return kExitUsage;
  }
  return AddUserFixed(request);
}

// The model (--model auto chooses it), the calibration, its evidence
// (halves, uncertainty, binned residuals) and the verdict made from it
// (evidence/evidence.h, evidence/verdict.h). A failed calibration is kept in
// run->calibration_error (the report shows it); returns kExitOk or the exit
// code of a failed model selection.
int CalibrateAndJudge(CalibrateRequest* request_in, CalibrationRun* run) {
  const Timer calib_timer;
  if (request_in->auto_model) {
    if (const int code = SelectModelOf(request_in, run); code != kExitOk) {
      return code;
    }
  }
  const CalibrateRequest& request = *request_in;
  const std::string mismatch =
      BoardMismatchMessage(run->images, request.board, FLAGS_board);
  if (run->views.empty()) {
    run->calibration_error = "no image gave a view";
  } else if (!request.initial.params.empty() &&
             (request.initial.width != run->width ||
              request.initial.height != run->height)) {
    run->calibration_error = StringPrintf(
        "--initial %s is a camera of %d x %d pixels, the photos are %d x %d",
        FLAGS_initial.c_str(), request.initial.width, request.initial.height,
        run->width, run->height);
  } else {
    run->calibrated = Calibrate(run->views, request.model, run->width,
                                run->height, request.calibration_options,
                                &run->result, &run->calibration_error);
  }
  if (!run->calibrated && !mismatch.empty()) run->calibration_error = mismatch;
  run->seconds_calibrate = calib_timer.Seconds();
  if (!run->calibrated) return kExitOk;
  // The evidence, the verdict and the model advice (evidence/judgement.h:
  // the steps every user of the library takes).
  JudgementOptions judgement_options;
  judgement_options.evidence = request.options.evidence;
  judgement_options.verdict = request.options.verdict;
  judgement_options.model_selection = request.options.model_selection;
  Judgement judgement = JudgeCalibration(
      run->views, run->result, request.calibration_options, judgement_options,
      request.auto_model ? &run->selection : nullptr);
  run->evidence = std::move(judgement.evidence);
  run->verdict = std::move(judgement.verdict);
  if (run->verdict.kind != VerdictKind::kGood &&
      (!FLAGS_report.empty() || request.watching)) {
    AdviceOptions advice = request.options.advice;
    advice.num_threads = request.threads;
    advice.target_uncertainty_px = request.options.verdict.max_uncertainty_px;
    advice.target_min_views = request.options.verdict.min_views;
    advice.spline_prior = request.calibration_options.spline_prior;
    run->advice = AdviseViews(run->views, run->result, request.board, advice);
  }
  return kExitOk;
}

// The camera file, written first so that a failing report or Ctrl-C does
// not lose it. Returns kExitOk or kExitOutputError.
int WriteCameraOf(const CalibrateRequest& request, const CalibrationRun& run,
                  std::string* format_note) {
  CameraFileNames names;
  names.camera_name = FLAGS_camera_name;
  names.rostopic = FLAGS_rostopic;
  const CameraFileStats stats = CalibrationFileStats(
      run.result, run.views, ViewFiles(run.images, run.views.size()),
      request.board.Point(request.board.origin), run.verdict.Line());
  std::string error;
  if (!WriteCameraFile(FLAGS_out, request.format, run.result.camera, stats,
                       &error, format_note, names)) {
    std::cerr << "puzzlecal calibrate: " << error << "\n";
    return kExitOutputError;
  }
  g_camera_written = 1;
  return kExitOk;
}

// The report, written also for a failed calibration (it shows why). False
// when it could not be written (said on stderr).
bool WriteReportOf(const CalibrateRequest& request, const CalibrationRun& run,
                   const std::vector<ReportImage>& report_images,
                   double seconds_total) {
  ReportInput input;
  input.board = request.board;
  input.result = &run.result;
  input.views = &run.views;
  input.calibration_ok = run.calibrated;
  input.calibration_error = run.calibration_error;
  input.images = report_images;
  input.seconds_load = run.seconds_load;
  input.seconds_detect = run.seconds_detect + run.seconds_grid_decode;
  input.seconds_calibrate = run.seconds_calibrate;
  input.seconds_total = seconds_total;
  input.threads = request.threads;
  if (run.calibrated) {
    input.evidence = &run.evidence;
    input.verdict = &run.verdict;
  }
  if (request.auto_model) input.model_selection = run.selection.Table();
  if (run.advice.ok) input.advice = &run.advice;
  std::string error;
  if (WriteReportInPlace(FLAGS_report, input, run.videos, &error)) return true;
  std::cerr << "puzzlecal calibrate: report not written: " << error
            << (run.calibrated
                    ? "\n(the camera file " + FLAGS_out + " was written)"
                    : "")
            << "\n";
  return false;
}

// The first advised photo's picture as the run writes it: in the report
// folder, or beside --out while watching without one (next_1.png in the
// working folder when --out names no folder).
fs::path NextPicturePath() {
  const std::string name = AdvicePictureName(0);
  return FLAGS_report.empty() ? fs::path(FLAGS_out).parent_path() / name
                              : fs::path(FLAGS_report) / name;
}

// The closing lines on stdout: the calibration, counts, timings (verbose),
// the verdict and what was written.
void PrintOutcome(const CalibrateRequest& request, const CalibrationRun& run,
                  double seconds_total) {
  const CalibrationResult& result = run.result;
  if (request.verbosity != Verbosity::kQuiet) {
    std::cout << CalibrationReport(result) << "\n";
    const auto repeated = std::count_if(
        run.images.begin(), run.images.end(), [](const ImageResult& image) {
          return image.outcome == ImageOutcome::kRepeatedPhoto;
        });
    std::cout << "views used: " << result.num_views_used << " of "
              << run.images.size() << " images"
              << (repeated == 0 ? ""
                                : StringPrintf(" (%d the same photo as an "
                                               "earlier one, not used)",
                                               static_cast<int>(repeated)))
              << "; corners: " << result.num_corners_used << "; RMS "
              << std::setprecision(4) << result.rms_px << " px\n";
  }
  if (request.verbosity == Verbosity::kVerbose) {
    std::cout << EvidenceText(run.evidence) << std::setprecision(3)
              << "evidence: " << run.evidence.seconds << " s (halves "
              << run.evidence.cross_validation.seconds << " s)\n";
    std::cout << std::setprecision(3) << "time: " << seconds_total
              << " s wall clock on " << request.threads
              << (request.threads == 1 ? " thread" : " threads")
              << "; summed over images: image decoding " << run.seconds_load
              << " s, detection " << run.seconds_detect
              << " s, grid and decode " << run.seconds_grid_decode
              << " s; calibration " << run.seconds_calibrate << " s\n";
  }
  std::cout << run.verdict.Line() << "\n";
  for (const std::string& note : run.verdict.notes) {
    std::cout << "note: " << note << "\n";
  }
  if (run.advice.ok && request.verbosity != Verbosity::kQuiet) {
    std::cout << "next photo (" << NextPicturePath().string()
              << "): " << run.advice.views[0].words << "\n";
  }
  std::cout << "wrote " << FLAGS_out
            << (FLAGS_report.empty() ? "" : " and the report " + FLAGS_report)
            << "\n";
}

// The outputs of a run whose views are calibrated and judged: the image
// problems, the camera file, the report and the closing lines. Returns the
// exit code.
int FinishRun(const CalibrateRequest& request, const CalibrationRun& run,
              const Timer& run_timer) {
  const std::vector<ReportImage> report_images =
      MakeReportImages(run.images, run.calibrated ? &run.result : nullptr);
  PrintImageProblems(report_images);
  std::string format_note;
  if (run.calibrated) {
    if (const int code = WriteCameraOf(request, run, &format_note);
        code != kExitOk) {
      return code;
    }
  }
  if (!FLAGS_report.empty() &&
      !WriteReportOf(request, run, report_images, run_timer.Seconds()) &&
      run.calibrated) {
    return kExitOutputError;  // a failed calibration stays what matters
  }
  if (!run.calibrated) {
    std::cerr << "puzzlecal calibrate: no calibration written. "
              << run.calibration_error << "\n";
    return kExitNoResult;
  }
  PrintOutcome(request, run, run_timer.Seconds());
  // What the file's format could not hold, after the verdict that judged
  // the calibration (its "ready to use" is about the calibration; this is
  // about the file), also with --quiet.
  if (!format_note.empty()) {
    std::cout << "note: " << FLAGS_out << ": " << format_note << "\n";
  }
  return kExitOk;
}

// ---- --watch ----

// Set by Ctrl-C while watching: the watch ends and writes what it has (a
// second Ctrl-C interrupts as usual).
volatile std::sig_atomic_t g_stop_watch = 0;

void OnWatchInterrupt(int) {
  g_stop_watch = 1;
  std::signal(SIGINT, OnInterrupt);
}

// The earlier photo whose board corners `image` nearly repeats (most of
// its ids seen at nearly the same pixels: a second photo of one pose adds
// little), or "".
std::string DuplicateOf(const std::vector<ImageResult>& earlier,
                        const ImageResult& image) {
  const BoardObservation& seen = image.decode.observation;
  const double limit =
      kDuplicateFraction * std::hypot(image.width, image.height);
  for (const ImageResult& other : earlier) {
    if (other.outcome != ImageOutcome::kUsable) continue;
    std::map<std::pair<int, int>, Eigen::Vector2d> at;
    for (size_t i = 0; i < other.decode.observation.id.size(); ++i) {
      const Eigen::Vector2i& id = other.decode.observation.id[i];
      at[{id.x(), id.y()}] = other.decode.observation.xy[i];
    }
    std::vector<double> moved;
    for (size_t i = 0; i < seen.id.size(); ++i) {
      const auto found = at.find({seen.id[i].x(), seen.id[i].y()});
      if (found != at.end())
        moved.push_back((found->second - seen.xy[i]).norm());
    }
    const size_t fewer = std::min(seen.id.size(), at.size());
    if (fewer > 0 && moved.size() >= 0.9 * fewer && Median(moved) < limit) {
      return fs::path(other.file).filename().string();
    }
  }
  return "";
}

// The verdict's uncertainty figure: the largest band median of the
// projection uncertainty within the observed field (0 when none).
double WorstBandMedian(const Evidence& evidence, int min_count) {
  double worst = 0;
  for (const AngleBand& band : evidence.uncertainty.bands) {
    if (band.count >= min_count) worst = std::max(worst, band.median);
  }
  return worst;
}

// Calibrates and judges the photos so far (once there are enough views) and
// says where the calibration stands, after the photo's own words.
std::string WatchStanding(CalibrateRequest* request, CalibrationRun* run) {
  run->views = MakeCalibrationViews(request->board, &run->images, &run->width,
                                    &run->height);
  const int needed = request->calibration_options.min_views;
  if (static_cast<int>(run->views.size()) < needed) {
    run->calibrated = false;
    return StringPrintf("%zu views, calibrating from %d", run->views.size(),
                        needed);
  }
  run->calibration_error.clear();
  run->advice = Advice();
  run->verdict = Verdict();
  if (CalibrateAndJudge(request, run) != kExitOk || !run->calibrated) {
    run->calibrated = false;
    return StringPrintf("%zu views, not calibrated yet: %s", run->views.size(),
                        run->calibration_error.c_str());
  }
  std::string line = StringPrintf(
      "%d of %zu views used, coverage %.0f %%, uncertainty %.3f px (limit "
      "%.2f), verdict %s",
      run->result.num_views_used, run->views.size(), 100 * run->result.coverage,
      WorstBandMedian(run->evidence, request->options.evidence.min_bin_count),
      request->options.verdict.max_uncertainty_px,
      VerdictKindName(run->verdict.kind));
  if (run->advice.ok) line += " — next: " + run->advice.views[0].words;
  return line;
}

// The line for one photo that arrived: whether it is used, then the
// standing. A photo that gives no view, or repeats an earlier pose, is
// left out (the standing is unchanged then).
std::string WatchStep(const std::string& file, CalibrateRequest* request,
                      CalibrationRun* run) {
  ImageResult image =
      ProcessImageFile(file, request->board, request->options.pipeline);
  const std::string name = fs::path(file).filename().string();
  if (image.outcome != ImageOutcome::kUsable) {
    std::string reason = image.reason;
    if (reason.rfind(image.file + ": ", 0) == 0) {
      reason.erase(0, image.file.size() + 2);
    }
    run->images.push_back(std::move(image));
    return name + ": not used — " +
           ImageOutcomeName(run->images.back().outcome) +
           (reason.empty() ? "" : " (" + reason + ")");
  }
  const std::string duplicate = DuplicateOf(run->images, image);
  if (!duplicate.empty()) {
    return name + ": not used — nearly the same pose as " + duplicate +
           " (move or tilt the board)";
  }
  const size_t corners = image.decode.observation.id.size();
  run->images.push_back(std::move(image));
  return name + StringPrintf(": used (%zu corners) — ", corners) +
         WatchStanding(request, run);
}

// The advised photo's picture beside --out (next_1.png), refreshed.
void RefreshNextPicture(const CalibrationRun& run) {
  if (!run.advice.ok) return;
  const fs::path path =
      fs::path(FLAGS_out).parent_path() / AdvicePictureName(0);
  std::string error;
  if (!WritePngFile(path.string(),
                    DrawAdvicePicture(run.advice, 0,
                                      SeenCorners(run.views, run.result), 1200),
                    &error)) {
    std::cerr << "puzzlecal calibrate: " << error << "\n";
  }
}

// Photos as they arrive in --watch, each processed and said in one line,
// until the verdict is good, Ctrl-C or --watch-idle; then the outputs.
int RunWatch(CalibrateRequest* request, const Timer& run_timer) {
  std::signal(SIGINT, OnWatchInterrupt);
  request->calibration_options.num_threads = request->threads;
  CalibrationRun run;
  FolderWatch watch(FLAGS_watch);
  std::cout << "watching " << FLAGS_watch
            << " for photos (Ctrl-C ends and writes the result)" << std::endl;
  Timer idle;
  int photos = 0;
  bool good = false;
  while (!g_stop_watch && !good &&
         !(FLAGS_watch_idle > 0 && idle.Seconds() > FLAGS_watch_idle)) {
    std::vector<std::string> files;
    std::string error;
    if (!watch.Poll(&files, &error)) {
      std::cerr << "puzzlecal calibrate: " << error << "\n";
      return kExitBadInput;
    }
    for (const std::string& file : files) {
      if (good || g_stop_watch) break;
      const std::string line = WatchStep(file, request, &run);
      RefreshNextPicture(run);  // before the line that names the advice
      std::cout << "[" << ++photos << "] " << line << std::endl;
      good = run.calibrated && run.verdict.kind == VerdictKind::kGood;
      idle.Restart();
    }
    if (files.empty()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(kWatchPollMs));
    }
  }
  std::signal(SIGINT, OnInterrupt);
  std::cout << (good           ? "the verdict is good: done"
                : g_stop_watch ? "stopped"
                               : "no new photo: done")
            << std::endl;
  return FinishRun(*request, run, run_timer);
}

int RunCalibrate() {
  std::signal(SIGINT, OnInterrupt);
  const Timer run_timer;
  CalibrateRequest request;
  CalibrationRun run;
  if (const int code = ParseRequest(&request); code != kExitOk) return code;
  if (request.watching) return RunWatch(&request, run_timer);
  if (const int code = DetectAll(request, &run); code != kExitOk) return code;
  request.calibration_options.num_threads = request.threads;  // same result
  if (const int code = CalibrateAndJudge(&request, &run); code != kExitOk) {
    return code;
  }
  return FinishRun(request, run, run_timer);
}

PUZZLECAL_REGISTER_SUBCOMMAND(calibrate, "calibrate",
                              "calibrate a camera from a folder of photos",
                              kUsage,
                              {"images", "board", "model", "out", "format",
                               "report", "threads", "rostopic", "camera_name",
                               "options", "fix", "initial", "same_focal",
                               "knot_spacing_deg", "watch", "watch_idle"},
                              &RunCalibrate);

}  // namespace
}  // namespace puzzlecal
