#ifndef PUZZLECAL_PIPELINE_VIDEO_FRAMES_H_
#define PUZZLECAL_PIPELINE_VIDEO_FRAMES_H_

// Calibration frames from a video: the video is decoded one frame at a time
// (formats/video_io.h), each frame goes through the photos' pipeline
// (detection -> grid -> decode), and a frame is kept when it shows enough of
// the board, is sharp where the corners are, and shows a pose that no kept
// frame already shows; at most max_frames, spread over the poses. Of each
// kept frame only its corners with board ids are kept, never its pixels, so
// memory does not grow with the video's length. Every frame's outcome is
// recorded with its figures, so the run can say which frames were taken and
// why the others were not.

#include <Eigen/Core>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "decode/decoder.h"
#include "pipeline/pipeline.h"
#include "target/board.h"

namespace puzzlecal {

struct VideoFrameOptions {
  // Examine every frame_step-th frame only (1: every frame); the others are
  // decoded (a video cannot skip frames cheaply) but not detected. >= 1.
  int frame_step = 1;
  // A frame must show at least this many corners with board ids: a few
  // corners at the image border add little and pose the board poorly.
  // Default 20; >= 6.
  int min_corners = 20;
  // Sharpness: the width of the board's tile edges next to the corners
  // (contrast between the tiles beside an edge over the steepest slope
  // across it, pixels: a Gaussian edge's 10 %-90 % rise; the median over up
  // to max_edges edges of each lattice direction, the wider of the two). A
  // frame whose edges are wider is blurred. Measured on renders of the
  // sample lens at 0.4-0.8 m (bench_video): sharp 2.5-2.7 px (0.8 px
  // optical blur; at most 3.2 px over a rendered clip), a 4 px motion streak
  // 3.6-4.3 px, an 8 px streak 4.6-6.8 px by its direction. Default 4.5:
  // streaks of about 8 px and more are refused, 4 px ones (corners still
  // accurate to a few hundredths of a pixel) kept. > 0.
  double max_edge_width_px = 4.5;
  // Edges measured per frame (spread over the decoded corners): the
  // median's noise falls with their number. Default 60; >= 4.
  int max_edges = 60;
  // Near duplicates: the board's outline (its four outermost corners, mapped
  // by the frame's board-to-image homography) moves on average less than
  // this fraction of the image diagonal from where a kept frame has it.
  // Default 0.04 (32 px at 640 x 480); >= 0.
  double min_pose_change = 0.04;
  // At most this many frames of one video: beyond it the calibration's
  // parameters change by less than their uncertainty (bench_video), while
  // the solve grows with every frame. When more frames differ, the most
  // different are kept (each next one farthest from those chosen).
  // Default 40; >= 1.
  int max_frames = 40;

  bool Check(std::string* why = nullptr) const;
};

// What became of one examined frame.
enum class VideoFrameOutcome {
  kKept,           // a calibration view
  kNoBoard,        // the pipeline gave no view (the reason says why)
  kFewCorners,     // fewer corners with ids than min_corners
  kBlurred,        // edges wider than max_edge_width_px
  kNearDuplicate,  // a kept frame shows nearly the same pose
  kNotNeeded,      // beyond max_frames: kept frames show more different poses
  // calibrate-rig: no frame of the reference camera's video within the
  // time tolerance (or a nearer frame of this video took it)
  kNoPartner,
};

// "kept", "no board", "few corners", "blurred", "near duplicate",
// "not needed", "no partner".
const char* VideoFrameOutcomeName(VideoFrameOutcome outcome);

struct VideoFrameRecord {
  int index = 0;         // frame number in the video, from 0
  double time_ms = 0;    // presentation time stamp
  VideoFrameOutcome outcome = VideoFrameOutcome::kNoBoard;
  int num_corners = 0;   // corners with board ids
  double edge_width_px = -1;  // sharpness; -1: not measured
  // Mean outline motion to the closest kept frame (pixels); -1: not
  // compared.
  double pose_change_px = -1;
  int similar_frame = -1;  // that kept frame's index
  std::string reason;      // kNoBoard: the pipeline's reason
  // calibrate-rig (pipeline/rig_video.h): the reference camera's frame this
  // frame was paired with by time stamp (-1: none), and this frame's time
  // minus that frame's (ms).
  int reference_frame = -1;
  double time_difference_ms = 0;
};

// The board-to-image homography's image of the board's outline: a frame's
// pose, comparable between frames of one camera without calibration.
using BoardOutline = Eigen::Matrix<double, 2, 4>;

// A frame that passed the board and sharpness tests, with what is kept of
// it: its corners with ids (ImageResult::decode.observation; the image's
// other detections are dropped) and its outline.
struct VideoFrameCandidate {
  int index = 0;
  double time_ms = 0;
  ImageResult result;  // file "clip.mp4#frame0123", outcome kUsable
  BoardOutline outline = BoardOutline::Zero();
};

// One video's frames.
struct VideoFrames {
  std::string file;
  int width = 0, height = 0;
  double fps = 0;             // as the container says
  int frames_decoded = 0;     // frames read from the file
  long long frames_stated = 0;  // as the container says (0: unknown)
  // Set when decoding stopped before the stated end (a damaged file).
  std::string note;
  std::vector<VideoFrameRecord> frames;  // every examined frame, in order
  // The kept frames, in video order: file "clip.mp4#frame0123", outcome
  // kUsable, their corners with board ids.
  std::vector<ImageResult> kept;

  int Count(VideoFrameOutcome outcome) const;
  // "clip.mp4: 900 frames, 87 with the board, 23 blurred, 41 near
  // duplicates, 30 kept" (the frames without a partner in time when there
  // are any, and the note).
  std::string Summary() const;
  // One line per examined frame: frame,time_ms,outcome,corners,
  // edge_width_px,pose_change_px,similar_frame,reason; `with_partners`
  // (calibrate-rig) adds reference_frame,time_difference_ms.
  std::string Csv(bool with_partners = false) const;
};

// The name of frame `index` of `video`: "VIDEO#frame0123" (at least four
// digits), what messages, tables and camera files call it.
std::string VideoFrameName(const std::string& video, int index);

// The video and frame index of a VideoFrameName; false for other names.
bool ParseVideoFrameName(const std::string& name, std::string* video,
                         int* index);

// The 8-bit grey pixels of `file`: a photo (formats/image_io.h
// LoadGreyImage with default options) or a video frame named by
// VideoFrameName (the video decoded up to that frame). False with a message
// naming the file and the reason.
bool LoadFrameImage(const std::string& file, cv::Mat* grey,
                    std::string* error);

// Sharpness of a frame where its board is: the edge width (see
// VideoFrameOptions::max_edge_width_px) across the tile edges between
// neighbouring corners of `observation` (board ids or any lattice labels)
// in `grey`; -1 when neither lattice direction has 5 edges that can be
// measured (tiles under 8 px or nearly edge-on).
double BoardEdgeWidth(const cv::Mat& grey, const BoardObservation& observation,
                      int max_edges);

// The outline of `board` in the image of a frame whose corners are
// `observation` (board-to-image homography). False when the corners do not
// determine one.
bool BoardOutlineOf(const Board& board, const BoardObservation& observation,
                    int width, int height, BoardOutline* outline);

// Mean distance between the corners of two outlines (pixels).
double OutlineDistance(const BoardOutline& a, const BoardOutline& b);

// Decodes `path` frame by frame and examines every frame_step-th: the
// pipeline's detection (`pipeline`), then min_corners and sharpness.
// `on_candidate` receives each frame that passed (its index, time, corners
// with ids and outline); `record` (not null) each examined frame's outcome
// so far (kKept for candidates, which the caller may change). False with
// a message naming the file when it cannot be opened or no frame decodes.
bool ExamineVideo(const std::string& path, const Board& board,
                  const PipelineOptions& pipeline,
                  const VideoFrameOptions& options,
                  const std::function<void(VideoFrameCandidate&&)>&
                      on_candidate,
                  VideoFrames* frames, std::string* error);

// The frames of one video to calibrate from: ExamineVideo, then near
// duplicates dropped (in video order: a frame whose outline is within
// min_pose_change of a frame kept before it), then at most max_frames
// (farthest-point choice over the outlines, starting from the frame with
// the most corners). Deterministic. False as ExamineVideo.
bool ReadVideoFrames(const std::string& path, const Board& board,
                     const PipelineOptions& pipeline,
                     const VideoFrameOptions& options, VideoFrames* frames,
                     std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_PIPELINE_VIDEO_FRAMES_H_
