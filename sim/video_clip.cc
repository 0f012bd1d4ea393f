#include "sim/video_clip.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "formats/video_io.h"
#include "util/failure.h"
#include "util/parallel_for.h"

namespace puzzlecal {
namespace {

// `angle` moved by whole turns to within half a turn of `reference`, so the
// path turns the short way between two poses.
double Unwrapped(double angle, double reference) {
  return angle - 360.0 * std::round((angle - reference) / 360.0);
}

// The keyframe poses of the path, their angles unwrapped in order.
std::vector<ViewPose> PathPoses(const ClipSpec& spec) {
  std::mt19937_64 rng(spec.path.seed);
  std::vector<ViewPose> poses;
  for (int i = 0; i < spec.path.count; ++i) {
    ViewPose pose = DrawViewPose(spec.board, spec.path, &rng);
    if (!poses.empty()) {
      const ViewPose& previous = poses.back();
      pose.tilt_direction_deg =
          Unwrapped(pose.tilt_direction_deg, previous.tilt_direction_deg);
      pose.off_axis_direction_deg = Unwrapped(pose.off_axis_direction_deg,
                                              previous.off_axis_direction_deg);
    }
    poses.push_back(pose);
  }
  return poses;
}

// Catmull-Rom through p0..p3 at t in [0, 1] between p1 and p2.
double CatmullRom(double p0, double p1, double p2, double p3, double t) {
  return 0.5 * (2 * p1 + (p2 - p0) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t * t +
                (3 * p1 - p0 - 3 * p2 + p3) * t * t * t);
}

// The path's pose at `s` in [0, 1] (0: the first keyframe, 1: the last).
ViewPose PoseAlongPath(const std::vector<ViewPose>& poses, double s) {
  const int last = static_cast<int>(poses.size()) - 1;
  const double x = std::clamp(s, 0.0, 1.0) * last;
  const int i = std::min(static_cast<int>(x), last - 1);
  const double t = x - i;
  const ViewPose& p0 = poses[std::max(0, i - 1)];
  const ViewPose& p1 = poses[i];
  const ViewPose& p2 = poses[i + 1];
  const ViewPose& p3 = poses[std::min(last, i + 2)];
  const auto at = [&](auto field) {
    return CatmullRom(p0.*field, p1.*field, p2.*field, p3.*field, t);
  };
  ViewPose pose;
  pose.target = Eigen::Vector2d(
      CatmullRom(p0.target.x(), p1.target.x(), p2.target.x(), p3.target.x(), t),
      CatmullRom(p0.target.y(), p1.target.y(), p2.target.y(), p3.target.y(),
                 t));
  pose.distance_m = at(&ViewPose::distance_m);
  pose.view_angle_deg = std::min(90.0, at(&ViewPose::view_angle_deg));
  pose.tilt_direction_deg = at(&ViewPose::tilt_direction_deg);
  pose.roll_deg = at(&ViewPose::roll_deg);
  pose.off_axis_deg = std::max(0.0, at(&ViewPose::off_axis_deg));
  pose.off_axis_direction_deg = at(&ViewPose::off_axis_direction_deg);
  return pose;
}

// The blur of every frame: runs of blurred frames until the share is
// reached.
std::vector<MotionBlur> BlurOfFrames(const ClipSpec& spec, int num_frames) {
  std::vector<MotionBlur> blur(num_frames);
  std::mt19937_64 rng(spec.blur_seed);
  const int wanted =
      static_cast<int>(std::lround(spec.blurred_fraction * num_frames));
  int blurred = 0;
  for (int attempt = 0; blurred < wanted && attempt < 100 * num_frames;
       ++attempt) {
    const int start = static_cast<int>(UniformDraw(&rng, 0, num_frames - 1));
    MotionBlur streak;
    streak.length_px = UniformDraw(&rng, spec.min_blur_px, spec.max_blur_px);
    streak.angle_deg = UniformDraw(&rng, 0.0, 180.0);
    for (int i = start;
         i < std::min(num_frames, start + spec.blur_run_frames) &&
         blurred < wanted;
         ++i) {
      if (blur[i].length_px > 0) continue;
      blur[i] = streak;
      ++blurred;
    }
  }
  return blur;
}

// The truth of every frame of a clip of `spec`'s motion seen by a camera at
// `cam_from_rig` (the path's poses are the rig frame's), its frame i
// showing the instant i / fps + offset_ms (clamped to the path; the blur of
// the frame nearest that instant).
std::vector<ClipFrameTruth> FrameTruths(const ClipSpec& spec, double offset_ms,
                                        const Eigen::Isometry3d& cam_from_rig) {
  const int n = ClipFrameCount(spec);
  const std::vector<ViewPose> poses = PathPoses(spec);
  const std::vector<MotionBlur> blur = BlurOfFrames(spec, n);
  const double offset_frames = offset_ms * spec.fps / 1000.0;
  std::vector<ClipFrameTruth> truth(n);
  for (int i = 0; i < n; ++i) {
    const double at = i + offset_frames;  // in frames of the path
    truth[i].index = i;
    truth[i].time_ms = 1000.0 * i / spec.fps;
    truth[i].cam_from_board =
        cam_from_rig *
        PoseFromView(spec.board, PoseAlongPath(poses, n > 1 ? at / (n - 1.0)
                                                            : 0.0));
    const long nearest = std::clamp<long>(std::lround(at), 0, n - 1);
    truth[i].motion_blur = blur[nearest];
  }
  return truth;
}

// Renders the frames of `truth` (their poses and blur; fills their visible
// corner counts) through `camera` into the video `path`, frame i with seed
// seed + i; a few frames per thread at a time, rendered in parallel and
// written in order, so only a batch is in memory.
bool WriteClipFrames(const Board& board, const Camera& camera,
                     const RenderOptions& render, uint64_t seed, double fps,
                     const std::string& path, int num_threads,
                     std::vector<ClipFrameTruth>* truth, std::string* error) {
  VideoWriteOptions write_options;
  write_options.fps = fps;
  VideoWriter writer;
  if (!writer.Open(path, cv::Size(camera.width, camera.height), write_options,
                   error)) {
    return false;
  }
  const int threads = std::max(1, num_threads);
  const int batch = 4 * threads;
  const int n = static_cast<int>(truth->size());
  std::vector<cv::Mat> images(batch);
  std::vector<RenderSummary> summaries(batch);
  for (int first = 0; first < n; first += batch) {
    const int count = std::min(batch, n - first);
    ParallelFor(count, threads, [&](int k) {
      ClipFrameTruth& frame = (*truth)[first + k];
      RenderOptions options = render;
      options.seed = seed + frame.index;
      options.motion_blur = frame.motion_blur;
      images[k] = RenderBoard(board, camera, frame.cam_from_board, options,
                              nullptr, &summaries[k]);
      frame.num_visible_corners = summaries[k].num_visible_corners;
    });
    for (int k = 0; k < count; ++k) {
      if (images[k].empty()) {
        return Fail("clip frame " + std::to_string(first + k) + ": " +
                        summaries[k].reason,
                    error);
      }
      if (!writer.Write(images[k], error)) return false;
    }
  }
  writer.Close();
  return true;
}

}  // namespace

bool ClipSpec::Check(std::string* why) const {
  std::string inner;
  if (!render.Check(&inner)) return Fail("render: " + inner, why);
  if (!(fps > 0)) return Fail("fps must be > 0", why);
  if (!(seconds > 0)) return Fail("seconds must be > 0", why);
  if (path.count < 2) return Fail("path.count must be >= 2", why);
  if (!(blurred_fraction >= 0 && blurred_fraction < 1)) {
    return Fail("blurred_fraction must be in [0, 1)", why);
  }
  if (blur_run_frames < 1) return Fail("blur_run_frames must be >= 1", why);
  if (!(min_blur_px > 0 && max_blur_px >= min_blur_px)) {
    return Fail("blur lengths must satisfy 0 < min_blur_px <= max_blur_px",
                why);
  }
  if (ClipFrameCount(*this) < 1) return Fail("the clip has no frame", why);
  return true;
}

int ClipFrameCount(const ClipSpec& spec) {
  return static_cast<int>(std::lround(spec.fps * spec.seconds));
}

std::vector<ClipFrameTruth> ClipTruth(const ClipSpec& spec) {
  return FrameTruths(spec, 0.0, Eigen::Isometry3d::Identity());
}

bool RenderClip(const ClipSpec& spec, const std::string& path, int num_threads,
                std::vector<ClipFrameTruth>* truth_out, std::string* error) {
  std::string why;
  if (!spec.Check(&why)) return Fail("clip: " + why, error);
  std::vector<ClipFrameTruth> truth = ClipTruth(spec);
  if (!WriteClipFrames(spec.board, spec.camera, spec.render, spec.render.seed,
                       spec.fps, path, num_threads, &truth, error)) {
    return false;
  }
  if (truth_out != nullptr) *truth_out = std::move(truth);
  return true;
}

bool RigClipSpec::Check(std::string* why) const {
  std::string inner;
  if (!clip.Check(&inner)) return Fail("clip: " + inner, why);
  if (cameras.empty()) return Fail("cameras: none (a rig needs >= 1)", why);
  if (!cameras[0].cam_from_rig.isApprox(Eigen::Isometry3d::Identity())) {
    return Fail("cameras[0].cam_from_rig must be the identity (the rig frame)",
                why);
  }
  for (size_t c = 0; c < cameras.size(); ++c) {
    const Camera& camera = cameras[c].camera;
    if (static_cast<int>(camera.params.size()) !=
            CameraModelNumParams(camera.model) ||
        camera.width <= 0 || camera.height <= 0) {
      return Fail("cameras[" + std::to_string(c) + "] ('" + cameras[c].name +
                      "'): wrong number of parameters or no image size",
                  why);
    }
  }
  if (!time_offset_ms.empty() && time_offset_ms.size() != cameras.size()) {
    return Fail("time_offset_ms: " + std::to_string(time_offset_ms.size()) +
                    " offsets for " + std::to_string(cameras.size()) +
                    " cameras (give one per camera or none)",
                why);
  }
  for (const double offset : time_offset_ms) {
    if (!std::isfinite(offset)) return Fail("time_offset_ms: not finite", why);
  }
  return true;
}

std::vector<std::vector<ClipFrameTruth>> RigClipTruth(const RigClipSpec& spec) {
  std::vector<std::vector<ClipFrameTruth>> truth;
  for (size_t c = 0; c < spec.cameras.size(); ++c) {
    truth.push_back(FrameTruths(
        spec.clip, spec.time_offset_ms.empty() ? 0.0 : spec.time_offset_ms[c],
        spec.cameras[c].cam_from_rig));
  }
  return truth;
}

bool RenderRigClip(const RigClipSpec& spec,
                   const std::vector<std::string>& paths, int num_threads,
                   std::vector<std::vector<ClipFrameTruth>>* truth_out,
                   std::string* error) {
  std::string why;
  if (!spec.Check(&why)) return Fail("rig clip: " + why, error);
  if (paths.size() != spec.cameras.size()) {
    return Fail("rig clip: " + std::to_string(paths.size()) + " files for " +
                    std::to_string(spec.cameras.size()) + " cameras",
                error);
  }
  std::vector<std::vector<ClipFrameTruth>> truth = RigClipTruth(spec);
  for (size_t c = 0; c < spec.cameras.size(); ++c) {
    RenderOptions render = spec.clip.render;
    render.field_of_view_deg = spec.cameras[c].field_of_view_deg;
    std::string reason;
    if (!WriteClipFrames(spec.clip.board, spec.cameras[c].camera, render,
                         spec.clip.render.seed + 100000 * c, spec.clip.fps,
                         paths[c], num_threads, &truth[c], &reason)) {
      return Fail("camera '" + spec.cameras[c].name + "': " + reason, error);
    }
  }
  if (truth_out != nullptr) *truth_out = std::move(truth);
  return true;
}

ClipSpec SampleClip(double seconds, double fps, int width, int height) {
  const SceneSpec sample = SampleScene(width, height);
  ClipSpec clip;
  clip.camera = sample.camera;
  clip.board = sample.board;
  clip.render = sample.render;
  clip.render.lighting_gradient = 0.1;
  clip.fps = fps;
  clip.seconds = seconds;
  clip.path = sample.random_views;
  clip.path.count = std::max(2, static_cast<int>(std::lround(seconds)) + 1);
  clip.path.seed = 21;
  clip.path.occluders_per_view = 0;
  clip.path.target_margin_tiles = 1;
  return clip;
}

RigClipSpec StereoClip(double seconds, double fps, int width, int height,
                       double cam1_offset_ms) {
  constexpr double kDegree = M_PI / 180.0;
  RigClipSpec rig;
  rig.clip = SampleClip(seconds, fps, width, height);
  RigSceneCamera left, right;
  left.name = "cam0";
  left.camera = rig.clip.camera;
  right.name = "cam1";
  right.camera = WidePinholeCamera(width, height, 84.0, -0.12);
  right.camera.params[2] -= 0.02 * width;
  // Centred at (0.12, 0.004, -0.002) in the rig frame, its axis turned 4
  // degrees towards -x (about y) and 0.7 degrees down (about x).
  const Eigen::Vector3d centre(0.12, 0.004, -0.002);
  const Eigen::Matrix3d rig_from_cam =
      (Eigen::AngleAxisd(-4.0 * kDegree, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.7 * kDegree, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  right.cam_from_rig.linear() = rig_from_cam.transpose();
  right.cam_from_rig.translation() = -(rig_from_cam.transpose() * centre);
  rig.cameras = {left, right};
  rig.time_offset_ms = {0.0, cam1_offset_ms};
  return rig;
}

}  // namespace puzzlecal
