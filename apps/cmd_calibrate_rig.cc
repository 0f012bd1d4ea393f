// `puzzlecal calibrate-rig`: one image folder per camera in, a rig file (and
// a report) out.

#include <glog/logging.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "apps/common_flags.h"
#include "apps/fixed_params.h"
#include "apps/options_io.h"
#include "apps/report_folder.h"
#include "apps/subcommand.h"
#include "calib/rig_calibration.h"
#include "formats/board_file.h"
#include "formats/camera_yaml.h"
#include "formats/image_io.h"
#include "formats/rig_yaml.h"
#include "pipeline/pipeline.h"
#include "pipeline/rig_run.h"
#include "pipeline/rig_video.h"
#include "pipeline/video_frames.h"
#include "report/rig_report.h"
#include "util/atomic_file.h"
#include "util/string_format.h"
#include "util/timer.h"

DEFINE_bool(match_by_order, false,
            "calibrate-rig: pair the n-th image (sorted by name) of every "
            "camera folder as one frame, instead of matching frames by file "
            "name. Every folder must then hold the same number of images.");

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

constexpr char kUsage[] =
    "puzzlecal calibrate-rig --images DIR --board BOARD.yaml "
    "--model M[,M1,...] --out rig.yaml\n"
    "                        [--format puzzlecal|opencv|ros|kalibr] "
    "[--report DIR] [--threads N]\n"
    "                        [--options FILE] [--match_by_order] "
    "[--fix NAMES] [--initial NAME=FILE,...]\n"
    "                        [--same-focal] [--knot-spacing-deg D]\n\n"
    "Calibrates a rig of cameras. DIR holds one subfolder per camera; sorted "
    "by name, the first\nis the reference camera (the rig frame). The same "
    "file name in different subfolders is the\nsame instant; a camera "
    "without that file did not see the board then (--match_by_order\n"
    "pairs the n-th image of every folder instead, for folders named "
    "left01.jpg, right01.jpg, ...).\nA camera folder may instead hold "
    "exactly one video (mp4, avi, mkv, mov, ...), then every camera's\n"
    "must: each video's sharp frames showing the board are paired with the "
    "first camera's frame\nnearest in time stamp, within "
    "rig_video.max_time_difference_ms (default a quarter of its\nframe "
    "period). The time stamps are taken to count from a common start: start "
    "the cameras\ntogether (or cut the videos to a common start). Near "
    "duplicate frames are dropped and at most\nvideo.max_frames kept, spread "
    "over the poses; a line per video and one for the rig say\nwhat became "
    "of the frames (the report folder gets video_frames_CAMERA.csv per "
    "camera), and\nframes are named cam0.mp4#frame0123. A folder with "
    "several videos, or photos and videos\nmixed, is refused.\nOne --model "
    "for all "
    "cameras, or one per camera in folder order; auto chooses a camera's\n"
    "model by held-out error, as calibrate --model auto does. Writes the rig "
    "file "
    "atomically (ros: one\ncamera_info file per camera, OUT_STEM_NAME.yaml); "
    "a run that cannot produce a trustworthy\nresult exits non-zero and "
    "writes nothing.";

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream stream(text);
  std::string part;
  while (std::getline(stream, part, ',')) parts.push_back(part);
  return parts;
}

constexpr const char* kName = "puzzlecal calibrate-rig";

// ---- interruption and outputs ----

// Set once the rig file is in place; read by the SIGINT handler.
volatile std::sig_atomic_t g_rig_written = 0;

// Ctrl-C: says so and what is left, then ends the process (exit 130). The
// rig file is written by rename and the report built aside, so none is
// half-written; a rig file written before the interruption stays.
void OnInterrupt(int) {
  const char* message =
      g_rig_written ? "\npuzzlecal calibrate-rig: interrupted; the rig file "
                      "was written, the report was not\n"
                    : "\npuzzlecal calibrate-rig: interrupted; nothing "
                      "written\n";
  const ssize_t ignored = ::write(STDERR_FILENO, message, std::strlen(message));
  (void)ignored;
  std::_Exit(130);
}

// What the command line asks for, checked before any image is read.
struct RigRequest {
  CameraFileFormat format = CameraFileFormat::kPuzzlecal;
  std::vector<fs::path> folders;      // one per camera, sorted
  std::vector<CameraModelId> models;  // one per camera
  std::vector<bool> auto_model;       // per camera: --model auto
  // Per camera, the parameters the format holds fixed (Kalibr's radtan has
  // no k3).
  std::vector<std::vector<std::string>> format_fixed;
  // The parameters the user holds (options file and --fix), added per
  // camera once its model is known.
  std::vector<std::string> user_fixed;
  // --initial NAME=FILE: per camera folder name, the camera to start from.
  std::map<std::string, Camera> initial;
  Board board;
  int threads = 1;
  RunOptions options;  // --options FILE, or the defaults
};

// The models of --model (one for all cameras or one per camera; "auto"
// chooses after detection).
int ParseModelNames(std::vector<CameraModelId>* models,
                    std::vector<bool>* auto_model) {
  for (const std::string& name : SplitCommas(FLAGS_model)) {
    CameraModelId id = CameraModelId::kPinholeRadtan;
    const bool is_auto = name == "auto";
    if (!is_auto && !CameraModelIdFromName(name, &id)) {
      std::cerr << kName << ": unknown model '" << name << "'; choose one of "
                << CameraModelNames() << " or auto.\n";
      return kExitUsage;
    }
    models->push_back(id);
    auto_model->push_back(is_auto);
  }
  return kExitOk;
}

// One model for all cameras becomes one per camera, in folder order.
int MatchModelsToFolders(const std::vector<fs::path>& folders,
                         std::vector<CameraModelId>* models,
                         std::vector<bool>* auto_model) {
  if (models->size() != 1 && models->size() != folders.size()) {
    std::cerr << kName << ": " << models->size() << " models for "
              << folders.size()
              << " cameras; give one model for all or one per camera ("
              << FLAGS_images << " holds";
    for (const fs::path& folder : folders) {
      std::cerr << " " << folder.filename().string();
    }
    std::cerr << ").\n";
    return kExitUsage;
  }
  models->resize(folders.size(), (*models)[0]);
  auto_model->resize(folders.size(), (*auto_model)[0]);
  return kExitOk;
}

// Flags, the board file, the output and the camera folders. Returns
// kExitOk or the exit code, having said why.
int ParseRigRequest(RigRequest* request) {
  if (FLAGS_images.empty() || FLAGS_board.empty() || FLAGS_out.empty()) {
    std::cerr << kName << ": --images, --board and --out are required. Run "
              << "`puzzlecal calibrate-rig --help`.\n";
    return kExitUsage;
  }
  if (!CameraFileFormatFromName(FLAGS_format, &request->format)) {
    std::cerr << kName << ": unknown format '" << FLAGS_format
              << "'; choose one of puzzlecal, opencv, ros, kalibr.\n";
    return kExitUsage;
  }
  if (FLAGS_threads < 0) {
    std::cerr << kName << ": --threads must be >= 0.\n";
    return kExitUsage;
  }
  if (const int code = ParseModelNames(&request->models, &request->auto_model);
      code != kExitOk) {
    return code;
  }
  std::string error;
  if (!FLAGS_options.empty() &&
      !LoadOptionsFile(FLAGS_options, &request->options, &error)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitBadInput;
  }
  if (FLAGS_same_focal) {
    request->options.calibration.same_focal_length = true;
    request->options.rig.camera.same_focal_length = true;
  }
  if (FLAGS_knot_spacing_deg != 0) {
    request->options.calibration.spline_knot_spacing_deg =
        FLAGS_knot_spacing_deg;
    request->options.rig.camera.spline_knot_spacing_deg =
        FLAGS_knot_spacing_deg;
    if (!request->options.calibration.Check(&error)) {
      std::cerr << kName << ": --knot-spacing-deg: " << error << ".\n";
      return kExitUsage;
    }
  }
  request->user_fixed = request->options.calibration.fixed_params;
  request->options.calibration.fixed_params.clear();
  request->options.rig.camera.fixed_params.clear();
  for (const std::string& item : SplitCommas(FLAGS_initial)) {
    const size_t equals = item.find('=');
    Camera camera;
    if (equals == std::string::npos || equals == 0) {
      std::cerr << kName << ": --initial takes NAME=FILE per camera folder "
                << "(got '" << item << "').\n";
      return kExitUsage;
    }
    if (!ReadCameraFile(item.substr(equals + 1), &camera, &error)) {
      std::cerr << kName << ": --initial: " << error << "\n";
      return kExitBadInput;
    }
    request->initial[item.substr(0, equals)] = camera;
  }
  if (!LoadBoardFile(FLAGS_board, &request->board, &error)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitBadInput;
  }
  // Every output is checked before the work starts.
  if (!CheckOutputPath(FLAGS_out, &error) ||
      (!FLAGS_report.empty() && !CheckReportFolder(FLAGS_report, &error))) {
    std::cerr << kName << ": " << error << "\n";
    return kExitOutputError;
  }
  std::vector<std::string> folders;
  if (!ListRigCameraFolders(FLAGS_images, &folders, &error)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitBadInput;
  }
  request->folders.assign(folders.begin(), folders.end());
  if (const int code = MatchModelsToFolders(request->folders, &request->models,
                                            &request->auto_model);
      code != kExitOk) {
    return code;
  }
  for (const auto& named_camera : request->initial) {
    // (A structured binding cannot be captured by a lambda in C++17.)
    const std::string& name = named_camera.first;
    const Camera& camera = named_camera.second;
    const auto folder = std::find_if(
        request->folders.begin(), request->folders.end(),
        [&](const fs::path& f) { return f.filename().string() == name; });
    if (folder == request->folders.end()) {
      std::cerr << kName << ": --initial names camera '" << name
                << "', which is not a camera folder of " << FLAGS_images
                << ".\n";
      return kExitUsage;
    }
    const size_t c = folder - request->folders.begin();
    if (!request->auto_model[c] && request->models[c] != camera.model &&
        !gflags::GetCommandLineFlagInfoOrDie("model").is_default) {
      std::cerr << kName << ": --initial for camera '" << name << "' holds a "
                << CameraModelName(camera.model) << " camera, --model says "
                << CameraModelName(request->models[c]) << ".\n";
      return kExitUsage;
    }
    request->models[c] = camera.model;  // the known camera's model
    request->auto_model[c] = false;
  }
  request->format_fixed.resize(request->folders.size());
  for (size_t c = 0; c < request->folders.size(); ++c) {
    if (request->auto_model[c]) continue;  // after the model is chosen
    if (!CameraFormatFixedParams(request->format, request->models[c],
                                 &request->format_fixed[c], &error)) {
      std::cerr << kName << ": --format " << FLAGS_format << ", camera '"
                << request->folders[c].filename().string() << "': " << error
                << ".\n";
      return kExitUsage;
    }
  }
  request->threads =
      FLAGS_threads > 0
          ? FLAGS_threads
          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return kExitOk;
}

// The names of a listing's files, for messages ("a.mp4, b.mp4").
std::string FileNames(const std::vector<std::string>& files) {
  std::string names;
  for (size_t i = 0; i < files.size() && i < 4; ++i) {
    names += (i > 0 ? ", " : "") + fs::path(files[i]).filename().string();
  }
  return names + (files.size() > 4 ? ", ..." : "");
}

// Photos in every camera folder, or exactly one video in every one
// (`videos` receives them then, one per camera; empty for photos).
// Returns kExitOk or kExitBadInput, having named the folder and said why.
int CheckCameraInputs(const RigRequest& request,
                      const std::vector<ImageListing>& listings,
                      std::vector<std::string>* videos) {
  constexpr char kRule[] =
      "a camera folder holds photos or exactly one video, and a rig is "
      "calibrated from photos in every camera folder or from one video in "
      "every camera folder";
  int first_video = -1, first_photos = -1;
  for (size_t c = 0; c < listings.size(); ++c) {
    const std::string camera = "camera '" +
                               request.folders[c].filename().string() + "' (" +
                               request.folders[c].string() + ")";
    const ImageListing& listing = listings[c];
    if (listing.videos.size() > 1) {
      std::cerr << kName << ": " << camera << " holds " << listing.videos.size()
                << " videos (" << FileNames(listing.videos) << "); " << kRule
                << ".\n";
      return kExitBadInput;
    }
    if (!listing.videos.empty() && !listing.images.empty()) {
      std::cerr << kName << ": " << camera << " holds both photos ("
                << FileNames(listing.images) << ") and a video ("
                << FileNames(listing.videos) << "); " << kRule << ".\n";
      return kExitBadInput;
    }
    int& first = listing.videos.empty() ? first_photos : first_video;
    if (first < 0) first = static_cast<int>(c);
  }
  if (first_video >= 0 && first_photos >= 0) {
    const size_t v = first_video, p = first_photos;
    std::cerr << kName << ": camera '" << request.folders[v].filename().string()
              << "' (" << request.folders[v].string() << ") holds a video ("
              << FileNames(listings[v].videos) << "), camera '"
              << request.folders[p].filename().string() << "' ("
              << request.folders[p].string() << ") photos; " << kRule << ".\n";
    return kExitBadInput;
  }
  videos->clear();
  if (first_video < 0) return kExitOk;
  if (FLAGS_match_by_order) {
    std::cerr << kName << ": --match_by_order pairs photos; the frames of "
              << "the camera videos in " << FLAGS_images
              << " are paired by time stamp.\n";
    return kExitUsage;
  }
  for (const ImageListing& listing : listings) {
    videos->push_back(listing.videos[0]);
  }
  return kExitOk;
}

// Every camera's images and the frame of each (pipeline/rig_run.h: by file
// name, or by order with --match_by_order), or every camera's video
// (`videos`, frames paired later by time).
int ListFrames(const RigRequest& request, std::vector<ImageListing>* listings,
               RigFrames* frames, std::vector<std::string>* videos) {
  const size_t num_cameras = request.folders.size();
  listings->resize(num_cameras);
  std::vector<std::string> names;
  for (size_t c = 0; c < num_cameras; ++c) {
    names.push_back(request.folders[c].filename().string());
    std::string error;
    if (!ListImagesAndVideos(request.folders[c].string(), &(*listings)[c],
                             &error)) {
      std::cerr << kName << ": camera '" << names.back() << "': " << error
                << "\n";
      return kExitBadInput;
    }
    for (const std::string& skipped : (*listings)[c].skipped) {
      LOG(INFO) << "skipped " << skipped;
    }
  }
  if (const int code = CheckCameraInputs(request, *listings, videos);
      code != kExitOk || !videos->empty()) {
    return code;
  }
  std::string error;
  if (!MatchRigFrames(names, *listings, FLAGS_match_by_order, frames, &error)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitBadInput;
  }
  return kExitOk;
}

// --model auto for camera c: the model with the lowest held-out error on
// its own views (evidence/model_selection.h), then the format's fixed
// parameters for it.
int ChooseModel(const RigRequest& request, RigCameraInput* input) {
  ModelSelection selection;
  std::string error;
  if (!ChooseRigCameraModel(*input, request.options.calibration,
                            request.options.model_selection, &selection,
                            &error)) {
    std::cerr << kName << ": camera '" << input->name
              << "': --model auto: " << error << "\n";
    return kExitNoResult;
  }
  input->model = selection.candidates[selection.chosen].model;
  if (!FLAGS_quiet)
    std::cerr << "camera '" << input->name << "': --model auto chose "
              << CameraModelName(input->model) << " (" << selection.reason
              << ")\n";
  if (!CameraFormatFixedParams(request.format, input->model,
                               &input->fixed_params, &error)) {
    std::cerr << kName << ": --format " << FLAGS_format << ", camera '"
              << input->name << "' (--model auto chose "
              << CameraModelName(input->model) << "): " << error << ".\n";
    return kExitUsage;
  }
  return kExitOk;
}

// The user's fixed parameters (options file, --fix) for camera `input`'s
// model, and its --initial camera. Returns kExitOk or the exit code, having
// said why.
int AddKnownCamera(const RigRequest& request, RigCameraInput* input) {
  std::vector<std::string> names;
  std::string error;
  std::vector<std::string> lists = request.user_fixed;
  lists.push_back(FLAGS_fix);
  for (const std::string& list : lists) {
    std::vector<std::string> one;
    if (!ExpandFixedParams(list, input->model, &one, &error)) {
      std::cerr << kName << ": camera '" << input->name << "': fixed "
                << "parameters: " << error << ".\n";
      return kExitUsage;
    }
    AddFixedParams(one, &names);
  }
  AddFixedParams(names, &input->fixed_params);
  const auto known = request.initial.find(input->name);
  if (known == request.initial.end()) return kExitOk;
  if (known->second.width != input->width ||
      known->second.height != input->height) {
    std::cerr << kName << ": --initial for camera '" << input->name
              << "' is a camera of " << known->second.width << " x "
              << known->second.height << " pixels, its photos are "
              << input->width << " x " << input->height << ".\n";
    return kExitBadInput;
  }
  input->initial_params = known->second.params;
  return kExitOk;
}

int FinishCamera(const RigRequest& request, size_t c, int usable,
                 const std::string& what, RigCameraInput* input);

// Detection, grid and decode of one camera's images into its rig input:
// one (possibly empty) view per frame; `frame_files` receives the image
// file of each frame ("" where the camera has none).
int DetectCamera(const RigRequest& request, size_t c,
                 const ImageListing& listing,
                 const std::map<std::string, int>& frame_of_file,
                 int num_frames, RigCameraInput* input,
                 std::vector<std::string>* frame_files) {
  input->name = request.folders[c].filename().string();
  input->model = request.models[c];
  input->fixed_params = request.format_fixed[c];
  std::vector<ImageResult> images;
  const int usable = MakeRigCameraViews(
      request.board, listing.images, frame_of_file, num_frames,
      request.options.pipeline, request.threads, input, frame_files, &images);
  if (!FLAGS_quiet) {
    std::cerr << "camera '" << input->name << "': " << usable << " of "
              << images.size() << " images usable\n";
    for (const ImageResult& image : images) {
      if (image.view_index >= 0) continue;
      std::cerr << "  " << image.file << ": not used \u2014 "
                << ImageOutcomeName(image.outcome)
                << (image.reason.empty() ? "" : " (" + image.reason + ")")
                << "\n";
    }
  }
  return FinishCamera(request, c, usable, "image", input);
}

// Camera c's model (--model auto) and known parameters once its views are
// made; `usable` views, none: bad input naming the folder.
int FinishCamera(const RigRequest& request, size_t c, int usable,
                 const std::string& what, RigCameraInput* input) {
  if (usable > 0) {
    if (request.auto_model[c]) {
      if (const int code = ChooseModel(request, input); code != kExitOk) {
        return code;
      }
    }
    return AddKnownCamera(request, input);
  }
  std::cerr << kName << ": camera '" << input->name << "' ("
            << request.folders[c].string() << "): no " << what
            << " shows the board; no calibration written.\n";
  return kExitBadInput;
}

// Every camera's video (pipeline/rig_video.h): frames examined, paired by
// time stamp with the first camera's and chosen; a line per video and one
// for the rig say what became of them. `videos_out` keeps each video's
// frame records for the report.
int DetectVideoCameras(const RigRequest& request,
                       const std::vector<std::string>& videos,
                       std::vector<RigCameraInput>* inputs,
                       std::vector<std::vector<std::string>>* frame_files,
                       std::vector<VideoFrames>* videos_out) {
  RigVideoFrames frames;
  std::string error;
  if (!ReadRigVideos(videos, request.board, request.options.pipeline,
                     request.options.video, request.options.rig_video,
                     request.threads, &frames, &error)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitBadInput;
  }
  if (!FLAGS_quiet) {
    for (size_t c = 0; c < videos.size(); ++c) {
      std::cout << "camera '" << request.folders[c].filename().string()
                << "': " << frames.videos[c].Summary() << "\n";
    }
    std::cout << frames.Summary() << "\n";
  }
  for (size_t c = 0; c < videos.size(); ++c) {
    RigCameraInput& input = (*inputs)[c];
    input.name = request.folders[c].filename().string();
    input.model = request.models[c];
    input.fixed_params = request.format_fixed[c];
    const int usable = MakeRigVideoCameraViews(request.board, c, &frames,
                                               &input, &(*frame_files)[c]);
    if (usable == 0 &&
        frames.videos[c].Count(VideoFrameOutcome::kNoPartner) > 0) {
      std::cerr << kName << ": camera '" << input.name << "' ("
                << request.folders[c].string()
                << "): none of its frames showing the board has a frame of "
                << fs::path(videos[0]).filename().string() << " within "
                << StringPrintf("%.1f", frames.tolerance_ms) << " ms ("
                << frames.Summary()
                << "). The time stamps are taken to count from a common "
                   "start: start the cameras together (or cut the videos to "
                   "a common start), or widen "
                   "rig_video.max_time_difference_ms; no calibration "
                   "written.\n";
      return kExitBadInput;
    }
    if (const int code =
            FinishCamera(request, c, usable, "chosen video frame", &input);
        code != kExitOk) {
      return code;
    }
  }
  *videos_out = std::move(frames.videos);
  return kExitOk;
}

// The frames' notes (relabelled views of a symmetric board, views left
// out and why), each named by its file.
void PrintFrameNotes(const RigCalibrationResult& result,
                     const std::vector<std::vector<std::string>>& frame_files) {
  bool relabelled = false;
  for (size_t c = 0; c < result.cameras.size(); ++c) {
    const RigCameraResult& cam = result.cameras[c];
    for (size_t f = 0; f < cam.frame_note.size(); ++f) {
      if (cam.frame_note[f].empty()) continue;
      const std::string& file = frame_files[c][f];
      std::cout << "frame " << f + 1 << " ("
                << (file.empty() ? std::string("no image")
                                 : fs::path(file).filename().string())
                << "), camera '" << cam.name << "': " << cam.frame_note[f]
                << "\n";
      relabelled |= cam.relabelled[f];
    }
  }
  if (relabelled) {
    std::cout << "(a plain checkerboard looks the same after half a turn, so "
                 "each camera may label it either way; the rig's poses "
                 "settle which. A PuzzleBoard has no such ambiguity.)\n";
  }
}

// The rig's figures, each camera's verdict line (the one in the report),
// the time and what was written.
void PrintRigOutcome(const RigCalibrationResult& result,
                     const std::vector<std::vector<std::string>>& frame_files,
                     CameraFileFormat format, const JudgedRig& judged,
                     int threads, double seconds_images, double seconds_total,
                     const std::vector<std::string>& written) {
  if (FLAGS_quiet) {
    for (const std::string& path : written) {
      std::cout << "wrote " << path << "\n";
    }
    return;
  }
  std::cout << RigCalibrationReport(result);
  PrintFrameNotes(result, frame_files);
  for (size_t c = 0; c < result.cameras.size(); ++c) {
    std::cout << RigVerdictLine(result.cameras[c].name, judged.verdicts[c])
              << "\n";
    for (const std::string& note : judged.verdicts[c].notes) {
      std::cout << result.cameras[c].name << ": note: " << note << "\n";
    }
  }
  std::cout << judged.rig_verdict.Line() << "\n";
  const bool rectified =
      format == CameraFileFormat::kOpenCv || format == CameraFileFormat::kRos;
  if (rectified && result.cameras.size() == 2) {
    StereoRectification rect;
    std::string why;
    if (StereoRectify(result.cameras[0].camera, result.cameras[1].camera,
                      result.cameras[1].cam_from_rig *
                          result.cameras[0].cam_from_rig.inverse(),
                      &rect, &why)) {
      std::cout << "rectification: " << rect.Summary() << "\n";
    }
  }
  std::cout << "time: " << seconds_total << " s wall clock on " << threads
            << (threads == 1 ? " thread" : " threads") << " (images "
            << seconds_images << " s, calibration "
            << result.seconds_single + result.seconds_joint << " s)\n";
  for (const std::string& path : written) std::cout << "wrote " << path << "\n";
}

// The report (--report DIR) with the judgements when the calibration
// succeeded.
bool WriteReport(const RigCalibrationResult& result, bool calibrated,
                 const std::string& calibration_error, const JudgedRig& judged,
                 const std::vector<std::vector<std::string>>& frame_files,
                 const std::vector<VideoFrames>& videos,
                 const std::vector<std::string>& camera_names,
                 double seconds_images, double seconds_total, int threads,
                 std::string* error) {
  RigReportInput report;
  report.result = &result;
  report.calibration_ok = calibrated;
  report.calibration_error = calibration_error;
  report.files = frame_files;
  report.seconds_images = seconds_images;
  report.seconds_total = seconds_total;
  report.threads = threads;
  for (size_t c = 0; c < judged.verdicts.size(); ++c) {
    report.evidence.push_back(&judged.evidence[c]);
    report.verdicts.push_back(&judged.verdicts[c]);
  }
  if (calibrated) {
    report.rig_evidence = &judged.rig;
    report.rig_verdict = &judged.rig_verdict;
  }
  // Built aside, then put in place of the folder (the old report goes).
  return WriteFolderInPlace(
      fs::path(FLAGS_report),
      [&](const std::string& folder, std::string* why) {
        if (!WriteRigReport(folder, report, RigReportOptions(), why)) {
          return false;
        }
        // Each camera video's frames: which were taken and why the others
        // not, and the reference frame each was paired with.
        for (size_t c = 0; c < videos.size(); ++c) {
          const std::string name = "video_frames_" + camera_names[c] + ".csv";
          if (!WriteFileAtomically((fs::path(folder) / name).string(),
                                   videos[c].Csv(true), why)) {
            return false;
          }
        }
        return true;
      },
      error);
}

int RunCalibrateRig() {
  std::signal(SIGINT, OnInterrupt);
  const Timer run_timer;
  RigRequest request;
  if (const int code = ParseRigRequest(&request); code != kExitOk) {
    return code;
  }
  std::vector<ImageListing> listings;
  RigFrames frames;
  std::vector<std::string> videos;
  if (const int code = ListFrames(request, &listings, &frames, &videos);
      code != kExitOk) {
    return code;
  }
  cv::setNumThreads(1);
  const Timer images_timer;
  const size_t num_cameras = request.folders.size();
  std::vector<RigCameraInput> inputs(num_cameras);
  std::vector<std::vector<std::string>> frame_files(num_cameras);
  std::vector<VideoFrames> video_frames;
  std::vector<std::string> camera_names;
  for (const fs::path& folder : request.folders) {
    camera_names.push_back(folder.filename().string());
  }
  if (!videos.empty()) {
    if (const int code = DetectVideoCameras(request, videos, &inputs,
                                            &frame_files, &video_frames);
        code != kExitOk) {
      return code;
    }
  }
  for (size_t c = 0; c < num_cameras && videos.empty(); ++c) {
    if (const int code =
            DetectCamera(request, c, listings[c], frames.frame_of_file[c],
                         frames.num_frames, &inputs[c], &frame_files[c]);
        code != kExitOk) {
      return code;
    }
  }
  const double seconds_images = images_timer.Seconds();

  RigRunOptions options;
  options.rig = request.options.rig;
  options.rig.camera.num_threads = request.threads;
  options.evidence = request.options.evidence;
  options.verdict = request.options.verdict;
  options.rig_evidence = request.options.rig_evidence;
  JudgedRig judged;
  std::string calibration_error, error;
  const bool calibrated = CalibrateAndJudgeRig(
      request.board, inputs, frame_files, options, &judged, &calibration_error);
  const RigCalibrationResult& result = judged.result;
  if (!calibrated) {
    if (!FLAGS_report.empty() &&
        !WriteReport(result, calibrated, calibration_error, judged, frame_files,
                     video_frames, camera_names, seconds_images,
                     run_timer.Seconds(), request.threads, &error)) {
      std::cerr << kName << ": report not written: " << error << "\n";
    }
    std::cerr << kName << ": no calibration written. " << calibration_error
              << "\n";
    return kExitNoResult;
  }
  // The rig file first (atomically), then the report.
  std::vector<std::string> written;
  if (!WriteRigFiles(FLAGS_out, request.format, result, &written, &error,
                     &judged.file)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitOutputError;
  }
  g_rig_written = 1;
  if (!FLAGS_report.empty()) {
    if (!WriteReport(result, calibrated, calibration_error, judged, frame_files,
                     video_frames, camera_names, seconds_images,
                     run_timer.Seconds(), request.threads, &error)) {
      for (const std::string& path : written) {
        std::cout << "wrote " << path << "\n";
      }
      std::cerr << kName << ": report not written: " << error << "\n";
      return kExitOutputError;
    }
    written.push_back(FLAGS_report + " (the report)");
  }
  PrintRigOutcome(result, frame_files, request.format, judged, request.threads,
                  seconds_images, run_timer.Seconds(), written);
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    calibrate_rig, "calibrate-rig",
    "calibrate a multi-camera rig from one photo folder per camera", kUsage,
    {"images", "board", "model", "out", "format", "report", "threads",
     "options", "match_by_order", "quiet", "fix", "initial", "same_focal",
     "knot_spacing_deg"},
    &RunCalibrateRig);

}  // namespace
}  // namespace puzzlecal
