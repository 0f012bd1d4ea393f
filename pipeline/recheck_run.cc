#include "pipeline/recheck_run.h"

#include <algorithm>

#include "formats/camera_yaml.h"
#include "util/failure.h"

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
  *stored = read;
  return true;
}

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
  return true;
}

}  // namespace puzzlecal
