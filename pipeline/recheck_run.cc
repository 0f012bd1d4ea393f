#include "pipeline/recheck_run.h"

#include <algorithm>
#include <filesystem>
#include <set>

#include "formats/camera_yaml.h"
#include "util/failure.h"
#include "util/string_format.h"

namespace puzzlecal {

bool RecheckRunOptions::Check(std::string* why) const {
  std::string reason;
  if (!pipeline.Check(&reason)) return Fail("pipeline: " + reason, why);
  if (!calibration.Check(&reason)) return Fail("calibration: " + reason, why);
  if (!recheck.Check(&reason)) return Fail("check: " + reason, why);
  return true;
}

bool ReadStoredCalibration(const std::string& path, StoredCalibration* stored,
                           std::string* error) {
  CameraFileStats stats;
  StoredCalibration read;
  if (!ReadCameraFile(path, &read.camera, error, &stats)) return false;
  read.rms_px = stats.rms_px;
  read.param_stddev = stats.param_stddev;
  read.covariance = stats.covariance;
  // Only puzzlecal camera files list their photos; the others have none.
  std::vector<CameraFileView> views;
  std::string ignored;
  if (ReadCameraFileViews(path, &views, &ignored)) {
    for (const CameraFileView& view : views) {
      read.view_files.push_back(view.file);
    }
  }
  *stored = read;
  return true;
}

namespace {

// The same file, whatever the spelling of its path.
std::string CanonicalPath(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path canonical =
      std::filesystem::weakly_canonical(path, ec);
  return ec ? path : canonical.string();
}

// Counts the views made from the stored calibration's own photos; when
// they are all of them, the verdict cannot be still-valid or drifted.
void JudgeOwnPhotos(const StoredCalibration& stored, RecheckRun* run) {
  if (stored.view_files.empty() || run->views.empty()) return;
  std::set<std::string> own;
  for (const std::string& file : stored.view_files) {
    own.insert(CanonicalPath(file));
  }
  for (const ImageResult& image : run->images) {
    if (image.view_index >= 0 && own.count(CanonicalPath(image.file)) > 0) {
      ++run->own_views;
    }
  }
  if (run->own_views == 0) return;
  const int views = static_cast<int>(run->views.size());
  if (run->own_views == views) {
    run->recheck.verdict = RecheckVerdict::kNotEnoughData;
    run->recheck.reason =
        "every photo is one the camera file was calibrated from (its views "
        "list them): they fit it by construction and cannot show a drift; "
        "take new photos of the board";
    return;
  }
  run->recheck.reason += StringPrintf(
      " (%d of the %d views are photos the camera file was calibrated from, "
      "which cannot show a drift)",
      run->own_views, views);
}

}  // namespace

bool RecheckOnPhotos(
    const StoredCalibration& stored, const std::vector<std::string>& files,
    const Board& board, const RecheckRunOptions& options, int num_threads,
    RecheckRun* run, std::string* error,
    const std::function<void(size_t, const ImageResult&)>& on_done) {
  *run = RecheckRun();
  std::string why;
  if (!options.Check(&why)) return Fail("options: " + why, error);
  run->images =
      ProcessImageFiles(files, board, options.pipeline, num_threads, on_done);
  if (std::all_of(run->images.begin(), run->images.end(),
                  [](const ImageResult& image) {
                    return image.outcome == ImageOutcome::kUnreadable;
                  })) {
    std::string reasons;
    for (const ImageResult& image : run->images) {
      reasons += "\n  " + image.reason;
    }
    return Fail("none of the " + std::to_string(files.size()) +
                    " photos could be read:" + reasons,
                error);
  }
  int width = 0, height = 0;
  run->views = MakeCalibrationViews(board, &run->images, &width, &height);
  const Camera& camera = stored.camera;
  if (!run->views.empty() &&
      (width != camera.width || height != camera.height)) {
    return Fail("the photos are " + std::to_string(width) + " x " +
                    std::to_string(height) + " pixels, the camera is for " +
                    std::to_string(camera.width) + " x " +
                    std::to_string(camera.height),
                error);
  }
  run->recheck = RecheckCalibration(run->views, stored, options.calibration,
                                    options.recheck);
  JudgeOwnPhotos(stored, run);
  return true;
}

}  // namespace puzzlecal
