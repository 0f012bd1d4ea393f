#ifndef PUZZLECAL_SIM_VIDEO_CLIP_H_
#define PUZZLECAL_SIM_VIDEO_CLIP_H_

// A rendered video with its truth: a board moving along a smooth path in
// front of a camera, some frames motion-blurred (a shaken hand), written
// frame by frame to a video file (formats/video_io.h), so a video run can
// be checked against the camera and against which frames were blurred.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "sim/render.h"
#include "sim/rig_scenes.h"
#include "sim/scenes.h"
#include "target/board.h"

namespace puzzlecal {

struct ClipSpec {
  Camera camera;
  Board board;
  // Options of every frame; frame i uses seed render.seed + i and the
  // frame's own motion blur.
  RenderOptions render;
  double fps = 30.0;     // > 0
  double seconds = 30.0;  // > 0
  // The board's path: `path.count` poses drawn as RandomViews draws them
  // (its ranges and seed; no occluders), passed through at even times from
  // the first frame to the last and joined smoothly (Catmull-Rom through
  // the ViewPose parameters). >= 2 poses.
  RandomViews path;
  // Motion blur: runs of `blur_run_frames` consecutive frames (a shake),
  // starting at random frames until about `blurred_fraction` of the frames
  // are blurred; each run has one streak, its length uniform in
  // [min_blur_px, max_blur_px] and its direction uniform. Seeded by
  // `blur_seed`.
  double blurred_fraction = 0.1;  // in [0, 1)
  int blur_run_frames = 3;        // >= 1
  double min_blur_px = 8.0;       // > 0
  double max_blur_px = 16.0;      // >= min_blur_px
  uint64_t blur_seed = 7;

  bool Check(std::string* why = nullptr) const;
};

// What one frame of a clip shows.
struct ClipFrameTruth {
  int index = 0;
  double time_ms = 0;
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  MotionBlur motion_blur;  // length_px 0: sharp
  int num_visible_corners = 0;
};

// The number of frames of the clip: round(fps * seconds).
int ClipFrameCount(const ClipSpec& spec);

// The truth of every frame (pose, blur) without rendering.
std::vector<ClipFrameTruth> ClipTruth(const ClipSpec& spec);

// Renders the clip into the video file `path` (formats/video_io.h: motion
// JPEG at quality 100 for .avi / .mkv, MPEG-4 for .mp4), frames rendered on
// `num_threads` threads a few at a time and written in order (the file does
// not depend on the thread count). Fills `truth` (optional). False with a
// reason naming the field or the file.
bool RenderClip(const ClipSpec& spec, const std::string& path, int num_threads,
                std::vector<ClipFrameTruth>* truth, std::string* error);

// The sample set's lens (sim/scenes.h SampleScene: a 90-degree pinhole with
// barrel distortion) at `width` x `height` and the 23 x 16 PuzzleBoard
// moving at 0.35-0.8 m, one pose per second, a tenth of the frames blurred
// by 8-16 px streaks.
ClipSpec SampleClip(double seconds = 30.0, double fps = 30.0, int width = 640,
                    int height = 480);

// A rig's clips: the same board motion (a ClipSpec's path, blur, rate and
// length) seen by every camera of a rig, one video per camera, so a rig
// run from videos can be checked against the rig, the cameras and each
// frame's pose. A camera may be offset in time (an unsynchronised rig): its
// frame i shows the board where it is at i / fps + time_offset_ms, while
// its video's time stamps count i / fps from 0 as every camera's do.
struct RigClipSpec {
  // The board, its path (poses in the rig frame, the first camera's:
  // cam_from_board of camera 0), render options, fps, length and blur; its
  // `camera` is not used (each camera below has its own). Camera c's frame
  // i uses seed render.seed + 100000 * c + i; a shake blurs every camera's
  // frame of that instant with the same streak.
  ClipSpec clip;
  // The cameras, [0] the rig frame (its cam_from_rig the identity); >= 1.
  // field_of_view_deg is each camera's RenderOptions::field_of_view_deg.
  std::vector<RigSceneCamera> cameras;
  // Per camera, its clip's offset in time (ms; positive: the camera shows
  // later instants of the motion). Empty (the default): all 0. Poses
  // beyond the path's ends stay at its ends.
  std::vector<double> time_offset_ms;

  bool Check(std::string* why = nullptr) const;
};

// Per camera, the truth of every frame of its clip (camera c's
// cam_from_board).
std::vector<std::vector<ClipFrameTruth>> RigClipTruth(const RigClipSpec& spec);

// Renders camera c's clip into `paths[c]` (as RenderClip: frames rendered
// on `num_threads` threads, the files do not depend on the thread count).
// Fills `truth` (optional, per camera). False with a reason naming the
// field, the camera or the file.
bool RenderRigClip(const RigClipSpec& spec,
                   const std::vector<std::string>& paths, int num_threads,
                   std::vector<std::vector<ClipFrameTruth>>* truth,
                   std::string* error);

// A stereo rig filming SampleClip's motion (the board 0.35-0.8 m in front
// of the first camera): "cam0" the sample lens, "cam1" a 84-degree pinhole
// with less distortion and its principal point 2 % of the width off the
// centre, 12 cm to the right of cam0 (and 4 mm down, 2 mm back), turned 4
// degrees towards it and 0.7 degrees down. `cam1_offset_ms` offsets cam1's
// clip in time (0: synchronised).
RigClipSpec StereoClip(double seconds = 4.0, double fps = 10.0,
                       int width = 640, int height = 480,
                       double cam1_offset_ms = 0.0);

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_VIDEO_CLIP_H_
