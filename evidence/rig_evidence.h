#ifndef PUZZLECAL_EVIDENCE_RIG_EVIDENCE_H_
#define PUZZLECAL_EVIDENCE_RIG_EVIDENCE_H_

// Judging a rig calibration: per frame, whether the cameras saw the board
// at the same instant, and the rig's verdict.
//
// A frame's consistency: each camera's own calibration poses the board of
// the frame by itself. Moved to the neighbouring camera (the camera its
// start was chained from) through the rig's relative pose — the robust
// centre of those per-frame relative poses — the board's corners should
// land where that camera saw them. The transfer error of a frame is the RMS
// of those pixel differences (both ways, the larger over the camera pairs);
// a board that moved between the two exposures (cameras not synchronised,
// a hand-held board) moves the corners by its motion, while a still board
// leaves only the noise of two single-view poses. A frame is named when its
// transfer error exceeds both moved_factor times the median over frames (a
// robust scale of the set's own noise: the frames that moved are a
// minority) and min_moved_px. Its figures: the transfer error, the
// difference of its relative pose from the rig's (mm, degrees), the rig's
// residual RMS per camera and the epipolar error (median distance of a
// corner's ray in the second camera from the epipolar plane of the first,
// in pixels of the second).
//
// The rig verdict: `moved-frames` when frames are named (and kept: they
// bend the rig) or a camera's view of a frame was left out before the
// joint solve because its board pose relative to the rig disagreed (the
// photos show two moments; the rig is made without them, but the folders
// hold photos that are not one instant), `inconsistent` when a camera's joint
// RMS exceeds max_joint_over_alone times its own calibration's, else the first
// camera verdict that is not good (with the camera's name), else `good`.

#include <string>
#include <vector>

#include "calib/rig_calibration.h"
#include "evidence/verdict.h"

namespace puzzlecal {

struct RigEvidenceOptions {
  // A frame's transfer error above this many times the median over the
  // frames names it (with min_moved_px). > 1; default 4: a still board's
  // transfer error is the noise of two single-view poses, which varies
  // from frame to frame by far less.
  double moved_factor = 4.0;
  // ... and above this many pixels. > 0; default 0.3 px.
  double min_moved_px = 0.3;
  // A camera's joint RMS above this many times its own calibration's makes
  // the rig `inconsistent`. > 1; default 1.5.
  double max_joint_over_alone = 1.5;

  bool Check(std::string* why = nullptr) const;
};

// One camera's view of one frame.
struct RigFrameCamera {
  bool has_view = false;  // the camera found the board
  bool used = false;      // took part in the joint solve
  int corners = 0;
  double rms_px = 0;  // the rig's residuals, every valid corner
  std::string note;   // from the calibration (relabelled, not used)
};

struct RigFrameEvidence {
  std::vector<RigFrameCamera> cameras;  // one per camera
  bool compared = false;                // two cameras posed the board alone
  double transfer_px = 0;
  double pose_difference_mm = 0;
  double pose_difference_deg = 0;
  double epipolar_px = 0;  // median, 0 without shared corners
  bool moved = false;      // named as unsynchronised or moved
  // A camera's view of the frame was left out before the joint solve: its
  // board pose relative to the rig disagreed by this many degrees (the
  // largest over cameras); 0 when none was.
  double left_out_deg = 0;
};

struct RigEvidence {
  std::vector<RigFrameEvidence> frames;
  double median_transfer_px = 0;
  double moved_limit_px = 0;
  std::vector<int> moved_frames;
  // Frames with a view left out for its disagreeing pose (left_out_deg).
  std::vector<int> left_out_frames;
  // Per camera: joint RMS / own calibration's RMS.
  std::vector<double> joint_over_alone;
};

// `inputs`: the views given to CalibrateRig (labels as found).
RigEvidence ComputeRigEvidence(const std::vector<RigCameraInput>& inputs,
                               const RigCalibrationResult& result,
                               const RigEvidenceOptions& options);

// The rig's verdict.
struct RigVerdict {
  // "good", "moved-frames", "inconsistent", or a camera verdict's kind
  // ("model-error", "insufficient-data", "bad-detections").
  std::string kind = "good";
  std::string reason;
  std::string next_step;
  // "rig: verdict: <kind> — <reason> — <next step>"
  std::string Line() const;
};

// `camera_verdicts`: one per camera (may be empty). `frame_names` (one per
// frame, may be empty) names the frames.
RigVerdict MakeRigVerdict(const RigCalibrationResult& result,
                          const RigEvidence& evidence,
                          const std::vector<Verdict>& camera_verdicts,
                          const std::vector<std::string>& frame_names,
                          const RigEvidenceOptions& options);

}  // namespace puzzlecal

#endif  // PUZZLECAL_EVIDENCE_RIG_EVIDENCE_H_
