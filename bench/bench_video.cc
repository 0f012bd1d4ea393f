// Calibration from a video. Prints JSON with two parts:
//  - "edge_width": the sharpness measure (pipeline/video_frames.h
//    BoardEdgeWidth) on renders of the sample lens, sharp and with motion
//    streaks of 4, 8 and 16 px in several directions, at three distances:
//    what max_edge_width_px separates;
//  - "clip": a rendered clip (sim/video_clip.h SampleClip: the board moving
//    along a path, a tenth of the frames blurred by 8-16 px streaks; 30 s at
//    30 fps unless `bench_video SECONDS FPS`), rendered by a child process,
//    then decoded and chosen from (ReadVideoFrames) and calibrated: f against
//    the truth, frames kept, blurred frames kept, decoding time and the
//    process's peak resident memory (getrusage), next to what the frames
//    would take held at once.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "pipeline/pipeline.h"
#include "pipeline/video_frames.h"
#include "sim/render.h"
#include "sim/scenes.h"
#include "sim/video_clip.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux: kilobytes
}

// Edge widths of one pose under streaks of each length and direction.
void PrintEdgeWidths() {
  const ClipSpec clip = SampleClip(2, 1);
  std::printf("  \"edge_width\": [\n");
  const double lengths[] = {0, 4, 8, 16};
  const double distances[] = {0.4, 0.6, 0.8};
  bool first = true;
  for (double distance : distances) {
    ViewPose view;
    view.target = Eigen::Vector2d(clip.board.origin.x() + 11,
                                  clip.board.origin.y() + 7.5);
    view.distance_m = distance;
    view.view_angle_deg = 60;
    view.tilt_direction_deg = 30;
    view.roll_deg = 15;
    const Eigen::Isometry3d pose = PoseFromView(clip.board, view);
    for (double length : lengths) {
      std::string widths;
      for (double angle = 0; angle < 180; angle += 22.5) {
        RenderOptions options = clip.render;
        options.motion_blur.length_px = length;
        options.motion_blur.angle_deg = angle;
        const cv::Mat image =
            RenderBoard(clip.board, clip.camera, pose, options);
        ImageResult result;
        ProcessGreyImage(image, clip.board, PipelineOptions(), &result);
        const double width =
            result.outcome == ImageOutcome::kUsable
                ? BoardEdgeWidth(image, result.decode.observation, 60)
                : -1;
        widths += (widths.empty() ? "" : ", ") + std::to_string(width);
        if (length == 0) break;  // no direction
      }
      std::printf("%s    {\"distance_m\": %.1f, \"streak_px\": %.0f, "
                  "\"widths_px_by_direction\": [%s]}",
                  first ? "" : ",\n", distance, length, widths.c_str());
      first = false;
    }
  }
  std::printf("\n  ],\n");
}

void PrintClip(double seconds, double fps) {
  const ClipSpec clip = SampleClip(seconds, fps);
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("bench_video_" + std::to_string(::getpid()) + ".avi"))
          .string();
  const Timer render_timer;
  const pid_t child = fork();
  if (child == 0) {
    std::string error;
    _exit(RenderClip(clip, path, 2, nullptr, &error) ? 0 : 1);
  }
  int status = 0;
  waitpid(child, &status, 0);
  const double render_s = render_timer.Seconds();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::printf("  \"error\": \"rendering the clip failed\"\n}\n");
    return;
  }
  const std::vector<ClipFrameTruth> truth = ClipTruth(clip);
  const double rss_before = PeakRssMb();
  const Timer decode_timer;
  VideoFrameOptions options;
  VideoFrames frames;
  std::string error;
  const bool read = ReadVideoFrames(path, clip.board, PipelineOptions(),
                                    options, &frames, &error);
  const double decode_s = decode_timer.Seconds();
  const double rss_after = PeakRssMb();
  const long long file_bytes = std::filesystem::file_size(path);
  std::filesystem::remove(path);
  if (!read) {
    std::printf("  \"error\": \"%s\"\n}\n", error.c_str());
    return;
  }
  int blurred_kept = 0, blurred = 0, blurred_rejected_as_blurred = 0,
      sharp_called_blurred = 0, sharp_measured = 0;
  for (const VideoFrameRecord& record : frames.frames) {
    const bool truly_blurred = truth[record.index].motion_blur.length_px > 0;
    blurred += truly_blurred;
    if (truly_blurred && record.outcome == VideoFrameOutcome::kKept) {
      ++blurred_kept;
    }
    if (truly_blurred && record.outcome == VideoFrameOutcome::kBlurred) {
      ++blurred_rejected_as_blurred;
    }
    if (!truly_blurred && record.edge_width_px >= 0) ++sharp_measured;
    if (!truly_blurred && record.outcome == VideoFrameOutcome::kBlurred) {
      ++sharp_called_blurred;
    }
  }
  const auto calibrate = [&](const std::vector<ImageResult>& kept,
                             double* fx_error_pct, double* fy_error_pct,
                             double* fx_sigma_pct, int* views) {
    std::vector<ImageResult> images = kept;
    int width = 0, height = 0;
    const std::vector<CalibrationView> views_made =
        MakeCalibrationViews(clip.board, &images, &width, &height);
    CalibrationResult result;
    std::string why;
    if (!Calibrate(views_made, clip.camera.model, width, height,
                   CalibrationOptions(), &result, &why)) {
      return false;
    }
    const double fx = clip.camera.params[0], fy = clip.camera.params[1];
    *fx_error_pct = 100 * (result.camera.params[0] - fx) / fx;
    *fy_error_pct = 100 * (result.camera.params[1] - fy) / fy;
    *fx_sigma_pct = 100 * result.param_stddev[0] / fx;
    *views = result.num_views_used;
    return true;
  };
  double fx_err = NAN, fy_err = NAN, fx_sigma = NAN;
  int views = 0;
  calibrate(frames.kept, &fx_err, &fy_err, &fx_sigma, &views);
  const double frame_mb = clip.camera.width * clip.camera.height * 3 / 1e6;
  std::printf(
      "  \"clip\": {\"seconds\": %.1f, \"fps\": %.1f, \"size\": \"%dx%d\", "
      "\"file_mb\": %.1f, \"render_s\": %.1f,\n"
      "    \"summary\": \"%s\",\n"
      "    \"frames_decoded\": %d, \"frames_truly_blurred\": %d, "
      "\"frames_kept\": %d, \"blurred_frames_kept\": %d, "
      "\"blurred_frames_rejected_as_blurred\": %d, "
      "\"sharp_frames_called_blurred\": %d, \"sharp_frames_measured\": %d,\n"
      "    \"fx_error_pct\": %.4f, \"fy_error_pct\": %.4f, "
      "\"fx_sigma_pct\": %.4f, \"views_used\": %d,\n"
      "    \"decode_and_choose_s\": %.2f, \"ms_per_frame\": %.2f, "
      "\"peak_rss_mb_before_decoding\": %.1f, \"peak_rss_mb\": %.1f, "
      "\"all_frames_decoded_would_take_mb\": %.0f}",
      seconds, fps, clip.camera.width, clip.camera.height, file_bytes / 1e6,
      render_s, frames.Summary().c_str(), frames.frames_decoded, blurred,
      static_cast<int>(frames.kept.size()), blurred_kept,
      blurred_rejected_as_blurred, sharp_called_blurred, sharp_measured,
      fx_err, fy_err, fx_sigma, views, decode_s,
      1000 * decode_s / std::max(1, frames.frames_decoded), rss_before,
      rss_after, frames.frames_decoded * frame_mb);
  std::printf("\n");
}

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 30.0;
  const double fps = argc > 2 ? std::atof(argv[2]) : 30.0;
  std::printf("{\n");
  puzzlecal::PrintEdgeWidths();
  puzzlecal::PrintClip(seconds, fps);
  std::printf("}\n");
  return 0;
}
