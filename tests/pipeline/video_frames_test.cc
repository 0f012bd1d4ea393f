// Calibration frames from a video, against a rendered clip's truth
// (sim/video_clip.h): the sample lens, the board moving along a path, a
// tenth of the frames blurred by 8-16 px streaks. The blurred frames are
// all refused and no sharp frame is called blurred, near duplicates are
// skipped, and the kept frames calibrate f within 0.05 % of the truth; a
// damaged or false video is named with the reason.

#include "pipeline/video_frames.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "sim/render.h"
#include "sim/scenes.h"
#include "sim/video_clip.h"
#include "tests/support/files.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

fs::path VideoScratch() {
  const fs::path dir = fs::temp_directory_path() /
                       ("puzzlecal_video_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

const auto* const kVideoScratchCleanup = ::testing::AddGlobalTestEnvironment(
    new testing_program::RemoveAtEnd(VideoScratch()));

// The 6 s clip at 10 fps (60 frames, six of them blurred), rendered once.
struct RenderedClip {
  ClipSpec spec = SampleClip(6, 10);
  std::vector<ClipFrameTruth> truth;
  fs::path file = VideoScratch() / "clip.avi";
  std::string error;
  bool rendered = RenderClip(spec, file.string(), 2, &truth, &error);
};

const RenderedClip& TheClip() {
  static const RenderedClip* clip = new RenderedClip();
  return *clip;
}

TEST(VideoFrames, BlurredFramesAreRefusedAndTheKeptOnesCalibrateWithinTruth) {
  const RenderedClip& clip = TheClip();
  ASSERT_TRUE(clip.rendered) << clip.error;
  VideoFrames frames;
  std::string error;
  ASSERT_TRUE(ReadVideoFrames(clip.file.string(), clip.spec.board,
                              PipelineOptions(), VideoFrameOptions(), &frames,
                              &error))
      << error;
  ASSERT_EQ(frames.frames_decoded, 60);
  ASSERT_EQ(frames.frames.size(), 60u);
  int blurred = 0, blurred_named_blurred = 0;
  for (const VideoFrameRecord& record : frames.frames) {
    const bool truly_blurred =
        clip.truth[record.index].motion_blur.length_px > 0;
    blurred += truly_blurred;
    if (truly_blurred) {
      // Never kept; counted as blurred where its edges can be measured,
      // else the pipeline found no board in it.
      EXPECT_TRUE(record.outcome == VideoFrameOutcome::kBlurred ||
                  record.outcome == VideoFrameOutcome::kNoBoard)
          << "frame " << record.index << ": "
          << VideoFrameOutcomeName(record.outcome);
      blurred_named_blurred += record.outcome == VideoFrameOutcome::kBlurred;
    } else {
      EXPECT_NE(record.outcome, VideoFrameOutcome::kBlurred)
          << "sharp frame " << record.index << " measured "
          << record.edge_width_px << " px";
    }
  }
  EXPECT_EQ(blurred, 6);
  EXPECT_GE(blurred_named_blurred, 1);
  // The kept frames: named by video and frame, none blurred.
  ASSERT_GE(frames.kept.size(), 15u);
  for (const ImageResult& kept : frames.kept) {
    EXPECT_NE(kept.file.find("clip.avi#frame00"), std::string::npos);
    EXPECT_TRUE(kept.corners.empty());  // only the corners with ids stay
  }
  std::vector<ImageResult> images = frames.kept;
  int width = 0, height = 0;
  const std::vector<CalibrationView> views =
      MakeCalibrationViews(clip.spec.board, &images, &width, &height);
  CalibrationResult result;
  ASSERT_TRUE(Calibrate(views, clip.spec.camera.model, width, height,
                        CalibrationOptions(), &result, &error))
      << error;
  for (int p = 0; p < 2; ++p) {
    const double truth = clip.spec.camera.params[p];
    EXPECT_LT(std::abs(result.camera.params[p] - truth) / truth, 0.0005)
        << (p == 0 ? "fx " : "fy ") << result.camera.params[p] << " truth "
        << truth;
  }
  ::testing::Test::RecordProperty("summary", frames.Summary());
}

TEST(VideoFrames, NearDuplicatesAreSkippedAndTheCapSpreadsTheChoice) {
  const RenderedClip& clip = TheClip();
  ASSERT_TRUE(clip.rendered) << clip.error;
  VideoFrameOptions options;
  options.max_frames = 8;
  VideoFrames frames;
  std::string error;
  ASSERT_TRUE(ReadVideoFrames(clip.file.string(), clip.spec.board,
                              PipelineOptions(), options, &frames, &error))
      << error;
  EXPECT_EQ(frames.kept.size(), 8u);
  EXPECT_EQ(frames.Count(VideoFrameOutcome::kKept), 8);
  EXPECT_GT(frames.Count(VideoFrameOutcome::kNearDuplicate), 0);
  EXPECT_GT(frames.Count(VideoFrameOutcome::kNotNeeded), 0);
  const double limit = options.min_pose_change * std::hypot(640, 480);
  int first_kept = 60, last_kept = -1;
  for (const VideoFrameRecord& record : frames.frames) {
    if (record.outcome == VideoFrameOutcome::kNearDuplicate) {
      EXPECT_LT(record.pose_change_px, limit);
      EXPECT_LT(record.similar_frame, record.index);
    }
    if (record.outcome == VideoFrameOutcome::kNotNeeded) {
      EXPECT_GE(record.similar_frame, 0);
    }
    if (record.outcome == VideoFrameOutcome::kKept) {
      first_kept = std::min(first_kept, record.index);
      last_kept = std::max(last_kept, record.index);
    }
  }
  // Spread over the clip's poses, not its first eight.
  EXPECT_GT(last_kept - first_kept, 30);
  // The table names every frame once.
  const std::string csv = frames.Csv();
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 61);
  EXPECT_NE(csv.find(",near duplicate,"), std::string::npos);
}

TEST(VideoFrames, TheEdgeWidthSeparatesEightPixelStreaksFromSharpFrames) {
  const ClipSpec clip = SampleClip(1, 1);
  ViewPose view;
  view.target = clip.board.origin.cast<double>() + Eigen::Vector2d(11, 7.5);
  view.distance_m = 0.6;
  view.view_angle_deg = 60;
  view.tilt_direction_deg = 30;
  view.roll_deg = 15;
  const Eigen::Isometry3d pose = PoseFromView(clip.board, view);
  const double limit = VideoFrameOptions().max_edge_width_px;
  for (const double length : {0.0, 4.0, 8.0}) {
    for (const double angle : {0.0, 45.0, 90.0, 135.0}) {
      RenderOptions options = clip.render;
      options.motion_blur.length_px = length;
      options.motion_blur.angle_deg = angle;
      const cv::Mat image = RenderBoard(clip.board, clip.camera, pose, options);
      ImageResult result;
      ProcessGreyImage(image, clip.board, PipelineOptions(), &result);
      ASSERT_EQ(result.outcome, ImageOutcome::kUsable) << result.reason;
      const double width =
          BoardEdgeWidth(image, result.decode.observation, 60);
      ASSERT_GT(width, 0);
      if (length == 0) {
        EXPECT_LT(width, 3.2);
      }
      if (length == 4) {
        EXPECT_LT(width, limit) << "angle " << angle;
      }
      if (length == 8) {
        EXPECT_GT(width, limit) << "angle " << angle;
      }
    }
  }
}

TEST(VideoFrames, ADamagedOrFalseVideoIsNamedWithTheReason) {
  const fs::path dir = VideoScratch();
  const fs::path fake = dir / "notes.mp4";
  testing_files::WriteFile(fake, "this is not a video\n");
  VideoFrames frames;
  std::string error;
  EXPECT_FALSE(ReadVideoFrames(fake.string(), SampleClip(1, 1).board,
                               PipelineOptions(), VideoFrameOptions(), &frames,
                               &error));
  EXPECT_NE(error.find("notes.mp4"), std::string::npos) << error;
  EXPECT_NE(error.find("not a readable video"), std::string::npos) << error;
  EXPECT_FALSE(ReadVideoFrames((dir / "missing.avi").string(),
                               SampleClip(1, 1).board, PipelineOptions(),
                               VideoFrameOptions(), &frames, &error));
  EXPECT_NE(error.find("missing.avi: no such file"), std::string::npos)
      << error;
  // The clip cut in half: the frames before the cut are read, and the
  // shortfall is said.
  const RenderedClip& clip = TheClip();
  ASSERT_TRUE(clip.rendered) << clip.error;
  const std::string bytes = testing_files::ReadFile(clip.file);
  const fs::path cut = dir / "cut.avi";
  testing_files::WriteFile(cut, bytes.substr(0, bytes.size() / 2));
  ASSERT_TRUE(ReadVideoFrames(cut.string(), clip.spec.board, PipelineOptions(),
                              VideoFrameOptions(), &frames, &error))
      << error;
  EXPECT_GT(frames.frames_decoded, 10);
  EXPECT_LT(frames.frames_decoded, 50);
  EXPECT_NE(frames.note.find("decoding stopped"), std::string::npos)
      << frames.Summary();
}

TEST(VideoFrames, OptionsAreChecked) {
  EXPECT_TRUE(VideoFrameOptions().Check());
  VideoFrameOptions options;
  options.max_frames = 0;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("max_frames"), std::string::npos);
  options = VideoFrameOptions();
  options.max_edge_width_px = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("max_edge_width_px"), std::string::npos);
}

}  // namespace
}  // namespace puzzlecal
