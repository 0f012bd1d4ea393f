#ifndef PUZZLECAL_APPS_OPTIONS_IO_H_
#define PUZZLECAL_APPS_OPTIONS_IO_H_

// Every algorithmic option of a run, in one place, and the YAML options file
// that sets them (`puzzlecal options` writes one with the defaults;
// `--options FILE` reads one). The file's top-level sections are the
// groups below and its keys the C++ field names, a nested group being a
// nested map:
//
//   grid:
//     merge:
//       neighbor_weight_ratio: 2.9
//   calibration:
//     outlier_k: 4
//     initialization:
//       focal_search_steps: 40
//
// A field the file leaves out keeps its default. The meaning and range of
// each field is documented at its options struct (named below).

#include <string>

#include "advice/advice.h"
#include "calib/calibrate.h"
#include "calib/rig_calibration.h"
#include "evidence/evidence.h"
#include "evidence/model_selection.h"
#include "evidence/recheck.h"
#include "evidence/rig_evidence.h"
#include "evidence/verdict.h"
#include "pipeline/pipeline.h"
#include "pipeline/rig_video.h"
#include "pipeline/video_frames.h"

namespace puzzlecal {

struct RunOptions {
  // Sections detector (DetectorOptions), grid (GridOptions), decode
  // (DecodeOptions), load (ImageLoadOptions) and pipeline (min_corners).
  // run_decode is not in the file: `detect` sets it from --board.
  PipelineOptions pipeline;
  // Section calibration (CalibrationOptions, with initialization). Not in
  // the file: fixed_params (set from --format) and num_threads (from
  // --threads).
  CalibrationOptions calibration;
  EvidenceOptions evidence;               // section evidence
  VerdictOptions verdict;                 // section verdict
  ModelSelectionOptions model_selection;  // section model_selection
  // Section rig: min_shared_frames, max_start_rotation_deviation_deg. Its
  // `camera` options are the calibration section (LoadOptionsFile copies
  // them).
  RigCalibrationOptions rig;
  RigEvidenceOptions rig_evidence;  // section rig_evidence
  // Section check (`puzzlecal check`): RecheckOptions but its `evidence`,
  // which is the evidence section.
  RecheckOptions check;
  // Section video: choosing calibration frames from videos
  // (VideoFrameOptions).
  VideoFrameOptions video;
  // Section rig_video (calibrate-rig from one video per camera): pairing
  // the cameras' frames by time stamp (RigVideoOptions).
  RigVideoOptions rig_video;
  // Section advice (`puzzlecal advise`, and calibrate's report when the
  // verdict is not good): AdviceOptions but count, field_deg, num_threads
  // (flags) and the target (the verdict section's max_uncertainty_px and
  // min_views).
  AdviceOptions advice;
};

// Reads the options file at `path` over `options` (fields it leaves out
// keep their values), then runs every group's Check(). False with a message
// naming the file and the field ("FILE: field 'grid.merge.kruskal_passes':
// must be an integer, got 'two'"; unknown fields list the allowed names) or
// the section whose Check() failed ("FILE: section 'detector': ...").
bool LoadOptionsFile(const std::string& path, RunOptions* options,
                     std::string* error);
// The same for options text (YAML, or JSON, which YAML reads); `source`
// names it in messages.
bool ParseOptionsText(const std::string& text, const std::string& source,
                      RunOptions* options, std::string* error);

// Every field of `options` with its value, as an options file (what
// LoadOptionsFile reads back to the same options).
std::string OptionsYaml(const RunOptions& options);

}  // namespace puzzlecal

#endif  // PUZZLECAL_APPS_OPTIONS_IO_H_
