#ifndef PUZZLECAL_PIPELINE_RIG_RUN_H_
#define PUZZLECAL_PIPELINE_RIG_RUN_H_

// A rig calibration run as `puzzlecal calibrate-rig` makes it, in library
// calls that the program, other programs and the Python package share:
// the frames of the camera folders (matched by file name or by order),
// each camera's views of the frames, `auto` models, the calibration
// (calib/rig_calibration.h) and its judgement: each camera's own evidence
// and verdict (evidence/evidence.h, evidence/verdict.h), the rig's
// per-frame consistency and verdict (evidence/rig_evidence.h), and what the
// puzzlecal rig file carries of them (formats/rig_yaml.h).

#include <map>
#include <string>
#include <vector>

#include "calib/rig_calibration.h"
#include "evidence/evidence.h"
#include "evidence/model_selection.h"
#include "evidence/rig_evidence.h"
#include "evidence/verdict.h"
#include "formats/image_io.h"
#include "formats/rig_yaml.h"
#include "pipeline/pipeline.h"
#include "target/board.h"

namespace puzzlecal {

// The camera subfolders of `root` (one per camera; hidden ones, whose name
// starts with a dot, are left out), sorted by name: the
// first is the reference camera. False with a message naming `root` when
// it is not a folder or holds fewer than two subfolders.
bool ListRigCameraFolders(const std::string& root,
                          std::vector<std::string>* folders,
                          std::string* error);

// Which frame each camera's image files show.
struct RigFrames {
  int num_frames = 0;
  // Per camera: image file (as listed) -> frame index.
  std::vector<std::map<std::string, int>> frame_of_file;
};

// The frames of the cameras' image listings (one per camera, named
// `camera_names`). By name (`by_order` false): the frames are the file
// names of all listings in sorted order (the same name in different
// listings is the same instant), and a camera whose names no other camera
// has is refused with the rule and the ways out. By order: the n-th image
// of every listing, which must then hold as many images. Either way two
// cameras whose files of one frame hold the same bytes (a folder copied
// for another camera's; no two cameras take byte-identical photos) are
// refused, naming both and how many of the frames they share are copies.
// False with a message naming the camera.
bool MatchRigFrames(const std::vector<std::string>& camera_names,
                    const std::vector<ImageListing>& listings, bool by_order,
                    RigFrames* frames, std::string* error);

// Detection, grid and decode of one camera's `files` (their frames in
// `frame_of_file`) into its rig input: one view per frame (empty where the
// camera did not see the board), the image size; `frame_files` receives
// the image file of each frame ("" where the camera has none) and
// `images` (optional) each image's outcome. Sets input->frames, width and
// height only. Returns the number of usable images.
int MakeRigCameraViews(const Board& board,
                       const std::vector<std::string>& files,
                       const std::map<std::string, int>& frame_of_file,
                       int num_frames, const PipelineOptions& options,
                       int num_threads, RigCameraInput* input,
                       std::vector<std::string>* frame_files,
                       std::vector<ImageResult>* images = nullptr);

// `auto` for one camera: the model with the lowest held-out error on the
// camera's views (evidence/model_selection.h). False with the reason when
// none could be chosen.
bool ChooseRigCameraModel(const RigCameraInput& input,
                          const CalibrationOptions& calibration,
                          const ModelSelectionOptions& options,
                          ModelSelection* selection, std::string* error);

// A plain checkerboard's corner grid is the same after half a turn about
// its centre (which camera labels it which way is settled from the rig's
// poses); a PuzzleBoard's ids are absolute.
RigBoardSymmetry RigSymmetryOf(const Board& board);

// The frames' names: the first camera's file name (without folder) that
// exists, per frame.
std::vector<std::string> RigFrameNames(
    const std::vector<std::vector<std::string>>& frame_files);

struct RigRunOptions {
  // The calibration (its `camera` options: each camera's own calibration
  // and the joint solve's loss, outliers and limits).
  RigCalibrationOptions rig;
  EvidenceOptions evidence;         // each camera's own evidence
  VerdictOptions verdict;           // each camera's verdict
  RigEvidenceOptions rig_evidence;  // the frames' consistency, the verdict
  // Every group's Check(); `why` names the group first.
  bool Check(std::string* why = nullptr) const;
};

// A rig calibration and its judgement.
struct JudgedRig {
  RigCalibrationResult result;
  // Per camera: its own calibration's evidence and verdict (as `calibrate`
  // judges one camera).
  std::vector<Evidence> evidence;
  std::vector<Verdict> verdicts;
  // The rig's: per-frame consistency and its verdict.
  RigEvidence rig;
  RigVerdict rig_verdict;
  // What the puzzlecal rig file carries of it (frames by file).
  RigFileJudgement file;
};

// Calibrates the rig of `inputs` (labels as found; a plain checkerboard's
// half-turn ambiguity settled from the rig's poses) and judges it.
// `frame_files`: per camera, the image file of each frame ("" where none;
// for the frames' names and the rig file). False with the calibration's
// reason (naming the camera) when it failed; `out->result` then holds what
// is known so far, with the frames' notes, and the judgement is empty.
bool CalibrateAndJudgeRig(
    const Board& board, const std::vector<RigCameraInput>& inputs,
    const std::vector<std::vector<std::string>>& frame_files,
    const RigRunOptions& options, JudgedRig* out, std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_PIPELINE_RIG_RUN_H_
