#ifndef PUZZLECAL_PIPELINE_RECHECK_RUN_H_
#define PUZZLECAL_PIPELINE_RECHECK_RUN_H_

// An existing calibration re-checked on new photos (`puzzlecal check`) in
// library calls: the stored camera file (any format the program reads, with
// what the puzzlecal format adds: RMS, standard deviations, covariance), the
// photos through detection, grid and decode into views, and the re-check
// itself (evidence/recheck.h).

#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/recheck.h"
#include "pipeline/pipeline.h"
#include "target/board.h"

namespace puzzlecal {

struct RecheckRunOptions {
  PipelineOptions pipeline;        // detection, grid and decode
  CalibrationOptions calibration;  // both fits of the re-check
  RecheckOptions recheck;          // the comparison and the verdict
  // Every group's Check(); `why` names the group first.
  bool Check(std::string* why = nullptr) const;
};

struct RecheckRun {
  std::vector<ImageResult> images;  // one record per photo, in file order
  std::vector<CalibrationView> views;
  Recheck recheck;
  // Views from photos the stored calibration was made from (the same
  // files as its file lists): they cannot show a drift. When every view is
  // one, the verdict is not-enough-data and says so.
  int own_views = 0;
};

// The calibration a camera file holds, with its RMS, standard deviations
// and covariance where the file carries them. False with a message naming
// the file and the reason.
bool ReadStoredCalibration(const std::string& path, StoredCalibration* stored,
                           std::string* error);

// Detection, grid and decode of `files` on `num_threads` workers, the views
// of the photos of the stored camera's image size, and their re-check.
// False with a message naming the photos when none can be read or they are
// not of the stored camera's size (then nothing is judged); a re-check
// without enough usable views is a verdict (not-enough-data), not a
// failure. `on_done` as ProcessImageFiles'.
bool RecheckOnPhotos(
    const StoredCalibration& stored, const std::vector<std::string>& files,
    const Board& board, const RecheckRunOptions& options, int num_threads,
    RecheckRun* run, std::string* error,
    const std::function<void(size_t, const ImageResult&)>& on_done = {});

}  // namespace puzzlecal

#endif  // PUZZLECAL_PIPELINE_RECHECK_RUN_H_
