#ifndef PUZZLECAL_PIPELINE_RIG_VIDEO_H_
#define PUZZLECAL_PIPELINE_RIG_VIDEO_H_

// A rig's frames from one video per camera (`puzzlecal calibrate-rig` when
// every camera folder holds one video): each video is examined frame by
// frame as `calibrate` examines one (pipeline/video_frames.h ExamineVideo:
// the board, enough corners, sharpness; only the corners of the frames
// that pass are kept, never their pixels), then the frames are paired by
// presentation time stamp with the reference camera's (the first camera's)
// frames. The time stamps are taken to count from a common start: frame
// times of every video are compared as they are, so the videos must have
// been started together (or cut to a common start) and the cameras
// synchronised; a camera whose clock runs apart pairs frames of different
// instants, which the rig's verdict then names (evidence/rig_evidence.h).
//
// A rig frame is one reference frame with the frames of the other cameras
// paired with it. Near duplicates are dropped in time order (a rig frame
// repeats a kept one when every camera that sees the board in it saw it in
// that kept frame too, its outline within min_pose_change of the image
// diagonal), then at most max_frames are chosen by farthest-point over the
// joint outlines, frames seen by more cameras first. Deterministic and
// independent of the thread count.

#include <string>
#include <vector>

#include "calib/rig_calibration.h"
#include "pipeline/pipeline.h"
#include "pipeline/video_frames.h"
#include "target/board.h"

namespace puzzlecal {

struct RigVideoOptions {
  // The largest difference between the time stamp of a camera's frame and
  // that of the reference camera's frame it is paired with, in
  // milliseconds. 0 (the default): a quarter of the reference video's
  // frame period (1000 / (4 fps), its rate as the container states; from
  // its time stamps when the container states none), so that a frame pairs
  // only with the reference frame of its own instant and cameras running
  // half a frame apart pair none. >= 0.
  double max_time_difference_ms = 0;

  bool Check(std::string* why = nullptr) const;
};

// How one frame of a camera pairs with the reference camera's frames.
struct TimePairing {
  int reference = -1;  // position in the reference times; -1: unpaired
  int nearest = -1;    // the nearest reference time's position (-1: none)
  double difference_ms = 0;  // this time minus the nearest reference time
  // Unpaired although the nearest is within the tolerance: another frame of
  // this camera is nearer to it (a camera of a higher rate).
  bool taken = false;
};

// Pairs the frames of one camera (`times_ms`, ascending) with the reference
// camera's (`reference_ms`, ascending): each with the nearest reference
// time (ties: the earlier) when |difference| <= tolerance_ms; where several
// frames are nearest to one reference frame, only the nearest of them is
// paired (ties: the earlier).
std::vector<TimePairing> PairFramesByTime(
    const std::vector<double>& reference_ms,
    const std::vector<double>& times_ms, double tolerance_ms);

// The outlines of one rig frame, for the choice of frames.
struct RigFrameOutlines {
  std::vector<bool> seen;              // per camera: the board passed
  std::vector<BoardOutline> outlines;  // per camera (where seen)
  int corners = 0;                     // over the cameras
};

// What became of the rig frames offered to ChooseRigFrames.
struct RigFrameChoice {
  std::vector<int> kept;  // positions, ascending
  // Per position: the kept frame (position) it nearly repeats, -1 if none.
  std::vector<int> duplicate_of;
  // Per position: beyond max_frames (the closest chosen frame's position
  // in `closest`).
  std::vector<bool> not_needed;
  std::vector<int> closest;
};

// The choice of rig frames (see the header's comment): `frames` in time
// order; `diagonals` per camera (pixels), `min_pose_change` and
// `max_frames` as VideoFrameOptions. Joint distance between two frames: the
// mean over the cameras seeing the board in either of the outline distance
// over the diagonal (1 where only one of the two sees it).
RigFrameChoice ChooseRigFrames(const std::vector<RigFrameOutlines>& frames,
                               const std::vector<double>& diagonals,
                               double min_pose_change, int max_frames);

// The rig's frames from its videos.
struct RigVideoFrames {
  // Per camera: its video's frames, every examined frame's record with the
  // outcome the rig's choice left it (kNoPartner: no reference frame
  // within the tolerance), the reference frame it was paired with and the
  // time difference. `kept` is empty: the chosen frames are below.
  std::vector<VideoFrames> videos;
  double tolerance_ms = 0;  // the tolerance used
  // Reference frames paired with a frame of every other camera.
  int matched_frames = 0;
  // Frames of the other cameras paired with no reference frame.
  int unpaired_frames = 0;
  // Rig frames in which some camera's frame passed (board, corners,
  // sharpness), and what became of them.
  int candidate_frames = 0;
  int near_duplicates = 0;
  int not_needed = 0;
  // The chosen rig frames in time order: per camera, per frame, the view
  // (file "cam1.mp4#frame0012", outcome kUsable; file empty where the
  // camera's frame did not pass or it has none) and the name of the
  // camera's frame paired with it ("" where it has none).
  std::vector<std::vector<ImageResult>> views;
  std::vector<std::vector<std::string>> frame_files;

  // "rig: 60 frames of cam0.mp4 paired with every camera (|dt| <= 25.0
  // ms), 0 frames without a partner; 52 frames show the board, 12 near
  // duplicates, 0 not needed, 40 kept (38 seen by 2 cameras)".
  std::string Summary() const;
};

// Examines `videos` (one per camera, the first the reference; on up to
// `num_threads` threads, one video each) and chooses the rig's frames.
// False with a message naming the video when one cannot be read, or when
// its frames are of another size than the camera's first.
bool ReadRigVideos(const std::vector<std::string>& videos, const Board& board,
                   const PipelineOptions& pipeline,
                   const VideoFrameOptions& video_options,
                   const RigVideoOptions& options, int num_threads,
                   RigVideoFrames* frames, std::string* error);

// Camera c's rig input from the chosen frames (as MakeRigCameraViews for
// photos): one view per rig frame (empty where the camera did not see the
// board), the image size; `frame_files` the names of its frames. Moves the
// camera's views out of `frames`. Returns the number of views.
int MakeRigVideoCameraViews(const Board& board, size_t c,
                            RigVideoFrames* frames, RigCameraInput* input,
                            std::vector<std::string>* frame_files);

}  // namespace puzzlecal

#endif  // PUZZLECAL_PIPELINE_RIG_VIDEO_H_
