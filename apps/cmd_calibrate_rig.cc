// `puzzlecal calibrate-rig`: one image folder per camera in, a rig file (and
// a report) out.

#include <glog/logging.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "apps/common_flags.h"
#include "apps/config_io.h"
#include "apps/image_io.h"
#include "apps/pipeline.h"
#include "apps/rig_report.h"
#include "apps/subcommand.h"
#include "calib/camera_yaml.h"
#include "calib/evidence.h"
#include "calib/rig_calibration.h"
#include "calib/rig_yaml.h"
#include "calib/verdict.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

constexpr char kUsage[] =
    "puzzlecal calibrate-rig --images DIR --board BOARD.yaml "
    "--model M[,M1,...] --out rig.yaml\n"
    "                        [--format puzzlecal|opencv|ros|kalibr] "
    "[--report DIR] [--threads N]\n\n"
    "Calibrates a rig of cameras. DIR holds one subfolder per camera; sorted "
    "by name, the first\nis the reference camera (the rig frame). The same "
    "file name in different subfolders is the\nsame instant; a camera "
    "without that file did not see the board then. One --model for all\n"
    "cameras, or one per camera in folder order. Writes the rig file "
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

// The camera subfolders of `root`, sorted by name.
bool ListCameraFolders(const std::string& root, std::vector<fs::path>* folders,
                       std::string* error) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) {
    *error = root + ": not a folder (expected one subfolder per camera)";
    return false;
  }
  for (fs::directory_iterator it(root, ec), end; !ec && it != end;
       it.increment(ec)) {
    if (it->is_directory(ec)) folders->push_back(it->path());
  }
  if (ec) {
    *error = root + ": cannot read the folder (" + ec.message() + ")";
    return false;
  }
  std::sort(folders->begin(), folders->end());
  if (folders->size() < 2) {
    *error = root + ": " + std::to_string(folders->size()) +
             " camera subfolder" + (folders->size() == 1 ? "" : "s") +
             " (a rig needs one per camera, at least two)";
    return false;
  }
  return true;
}

int RunCalibrateRig() {
  const Timer run_timer;
  const char* kName = "puzzlecal calibrate-rig";
  if (FLAGS_images.empty() || FLAGS_board.empty() || FLAGS_out.empty()) {
    std::cerr << kName << ": --images, --board and --out are required. Run "
              << "`puzzlecal calibrate-rig --help`.\n";
    return kExitUsage;
  }
  CameraFileFormat format;
  if (!CameraFileFormatFromName(FLAGS_format, &format)) {
    std::cerr << kName << ": unknown format '" << FLAGS_format
              << "'; choose one of puzzlecal, opencv, ros, kalibr.\n";
    return kExitUsage;
  }
  if (FLAGS_threads < 0) {
    std::cerr << kName << ": --threads must be >= 0.\n";
    return kExitUsage;
  }
  std::vector<CameraModelId> models;
  for (const std::string& name : SplitCommas(FLAGS_model)) {
    CameraModelId id;
    if (!CameraModelIdFromName(name, &id)) {
      std::cerr << kName << ": unknown model '" << name << "'; choose one of "
                << CameraModelNames() << ".\n";
      return kExitUsage;
    }
    models.push_back(id);
  }
  std::string error;
  Board board;
  if (!LoadBoardFile(FLAGS_board, &board, &error)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitBadInput;
  }
  if (!CheckOutputPath(FLAGS_out, &error)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitOutputError;
  }
  std::vector<fs::path> folders;
  if (!ListCameraFolders(FLAGS_images, &folders, &error)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitBadInput;
  }
  if (models.size() != 1 && models.size() != folders.size()) {
    std::cerr << kName << ": " << models.size() << " models for "
              << folders.size()
              << " cameras; give one model for all or one per camera ("
              << FLAGS_images << " holds";
    for (const fs::path& folder : folders) {
      std::cerr << " " << folder.filename().string();
    }
    std::cerr << ").\n";
    return kExitUsage;
  }
  models.resize(folders.size(), models[0]);
  // The format decides each camera's free parameters (Kalibr's radtan has
  // no k3), so it is settled before any image is read.
  std::vector<std::vector<std::string>> format_fixed(folders.size());
  for (size_t c = 0; c < folders.size(); ++c) {
    if (!CameraFormatFixedParams(format, models[c], &format_fixed[c], &error)) {
      std::cerr << kName << ": --format " << FLAGS_format << ", camera '"
                << folders[c].filename().string() << "': " << error << ".\n";
      return kExitUsage;
    }
  }

  // Every camera's images; the frames are the file names of all folders.
  std::vector<ImageListing> listings(folders.size());
  std::map<std::string, int> frame_of_name;
  for (size_t c = 0; c < folders.size(); ++c) {
    if (!ListImages(folders[c].string(), &listings[c], &error)) {
      std::cerr << kName << ": camera '" << folders[c].filename().string()
                << "': " << error << "\n";
      return kExitBadInput;
    }
    for (const std::string& skipped : listings[c].skipped) {
      LOG(INFO) << "skipped " << skipped;
    }
    for (const std::string& file : listings[c].images) {
      frame_of_name.emplace(fs::path(file).filename().string(), 0);
    }
  }
  int num_frames = 0;
  for (auto& [name, index] : frame_of_name) index = num_frames++;

  const int threads =
      FLAGS_threads > 0
          ? FLAGS_threads
          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  cv::setNumThreads(1);
  const Timer images_timer;
  std::vector<RigCameraInput> inputs(folders.size());
  std::vector<std::vector<std::string>> frame_files(
      folders.size(), std::vector<std::string>(num_frames));
  PipelineOptions pipeline_options;
  for (size_t c = 0; c < folders.size(); ++c) {
    RigCameraInput& input = inputs[c];
    input.name = folders[c].filename().string();
    input.model = models[c];
    input.fixed_params = format_fixed[c];
    input.frames.resize(num_frames);
    std::vector<ImageResult> images =
        ProcessImageFiles(listings[c].images, board, pipeline_options, threads);
    std::vector<CalibrationView> views =
        MakeCalibrationViews(board, &images, &input.width, &input.height);
    int usable = 0;
    for (size_t i = 0; i < images.size(); ++i) {
      const std::string name = fs::path(images[i].file).filename().string();
      const int frame = frame_of_name[name];
      frame_files[c][frame] = images[i].file;
      if (images[i].view_index < 0) {
        LOG(WARNING) << images[i].file << ": "
                     << ImageOutcomeName(images[i].outcome)
                     << (images[i].reason.empty()
                             ? ""
                             : " (" + images[i].reason + ")");
        continue;
      }
      input.frames[frame] = std::move(views[images[i].view_index]);
      ++usable;
    }
    std::cerr << "camera '" << input.name << "': " << usable << " of "
              << images.size() << " images usable\n";
    if (usable == 0) {
      std::cerr << kName << ": camera '" << input.name << "' ("
                << folders[c].string()
                << "): no image shows the board; no calibration written.\n";
      return kExitBadInput;
    }
  }
  const double seconds_images = images_timer.Seconds();

  RigCalibrationOptions options;
  options.camera.num_threads = threads;
  RigCalibrationResult result;
  std::string calibration_error;
  const bool calibrated =
      CalibrateRig(inputs, options, &result, &calibration_error);

  if (!FLAGS_report.empty()) {
    RigReportInput report;
    report.result = &result;
    report.calibration_ok = calibrated;
    report.calibration_error = calibration_error;
    report.files = frame_files;
    report.seconds_images = seconds_images;
    report.seconds_total = run_timer.Seconds();
    report.threads = threads;
    if (!WriteRigReport(FLAGS_report, report, RigReportOptions(), &error)) {
      std::cerr << kName << ": report not written: " << error << "\n";
      if (calibrated) return kExitOutputError;
    }
  }
  if (!calibrated) {
    std::cerr << kName << ": no calibration written. " << calibration_error
              << "\n";
    return kExitNoResult;
  }
  std::vector<std::string> written;
  if (!WriteRigFiles(FLAGS_out, format, result, &written, &error)) {
    std::cerr << kName << ": " << error << "\n";
    return kExitOutputError;
  }
  std::cout << RigCalibrationReport(result);
  // Each camera's own calibration judged as `calibrate` judges one camera
  // (halves, uncertainty, binned residuals; calib/verdict.h).
  for (size_t c = 0; c < result.cameras.size(); ++c) {
    const RigCameraResult& cam = result.cameras[c];
    const EvidenceOptions evidence_options;
    const Evidence evidence = ComputeEvidence(inputs[c].frames, cam.single,
                                              options.camera, evidence_options);
    const Verdict verdict =
        MakeVerdict(cam.single, evidence, evidence_options, VerdictOptions());
    std::cout << cam.name << ": " << verdict.Line() << "\n";
  }
  std::cout << "time: " << run_timer.Seconds() << " s wall clock on " << threads
            << " threads (images " << seconds_images << " s, calibration "
            << result.seconds_single + result.seconds_joint << " s)\n";
  for (const std::string& path : written) std::cout << "wrote " << path << "\n";
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    calibrate_rig, "calibrate-rig",
    "calibrate a multi-camera rig from one photo folder per camera", kUsage,
    {"images", "board", "model", "out", "format", "report", "threads"},
    &RunCalibrateRig);

}  // namespace
}  // namespace puzzlecal
