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

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_VIDEO_CLIP_H_
