// `puzzlecal calibrate-rig` from one video per camera, run as a user runs
// it, on rendered stereo clips with known truth (sim/video_clip.h
// StereoClip): a synchronised pair recovers the rig and the lenses, a pair
// whose second camera runs several frames late is not called good, and
// folders that break the rule (two videos, videos and photos mixed) are
// refused naming the folder. Pairing by time stamp itself is tested in
// tests/pipeline/rig_video_test.cc.

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "apps/subcommand.h"
#include "calib/rig_calibration.h"
#include "formats/rig_yaml.h"
#include "sim/video_clip.h"
#include "tests/support/files.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using testing_program::ProgramRun;
using testing_program::Quote;

constexpr char kBoard[] = "configs/boards/puzzleboard_23x16_30mm.yaml";

fs::path Scratch() {
  return fs::temp_directory_path() /
         ("puzzlecal_rig_video_test_" + std::to_string(::getpid()));
}

const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(
    new testing_program::RemoveAtEnd(Scratch()));

// The clips of `spec` in ROOT/<camera>/<camera>.avi.
fs::path RenderRig(const RigClipSpec& spec, const std::string& name) {
  const fs::path root = Scratch() / name;
  std::vector<std::string> paths;
  for (const RigSceneCamera& camera : spec.cameras) {
    fs::create_directories(root / camera.name);
    paths.push_back((root / camera.name / (camera.name + ".avi")).string());
  }
  std::string error;
  EXPECT_TRUE(RenderRigClip(spec, paths, 2, nullptr, &error)) << error;
  return root;
}

ProgramRun CalibrateRig(const fs::path& root, const std::string& extra = "") {
  return testing_program::RunProgram(
      "calibrate-rig --images " + Quote(root.string()) + " --board " + kBoard +
          " --model pinhole-radtan --out " +
          Quote((root / "rig.yaml").string()) + " --threads 2 " + extra,
      Scratch());
}

// The line of `output` that starts with `prefix` ("" if none).
std::string Line(const std::string& output, const std::string& prefix) {
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(prefix, 0) == 0) return line;
  }
  return "";
}

struct RigErrors {
  double rotation_deg = 0;
  double baseline_relative = 0;  // |t - t_true| / |t_true|
  double fx_relative[2] = {0, 0};
};

RigErrors Compare(const RigClipSpec& spec,
                  const std::vector<RigFileCamera>& cameras) {
  RigErrors errors;
  const Eigen::Isometry3d& truth = spec.cameras[1].cam_from_rig;
  errors.rotation_deg =
      RotationDifferenceDeg(cameras[1].cam_from_rig.linear(), truth.linear());
  errors.baseline_relative =
      (cameras[1].cam_from_rig.translation() - truth.translation()).norm() /
      truth.translation().norm();
  for (int c = 0; c < 2; ++c) {
    const double fx = spec.cameras[c].camera.params[0];
    errors.fx_relative[c] = std::abs(cameras[c].camera.params[0] - fx) / fx;
  }
  std::cout << "rotation error " << errors.rotation_deg
            << " deg, translation error " << 100 * errors.baseline_relative
            << " % of the baseline, fx errors " << 100 * errors.fx_relative[0]
            << " %, " << 100 * errors.fx_relative[1] << " %\n";
  return errors;
}

TEST(CalibrateRigVideo, ASynchronisedStereoClipPairRecoversTheRig) {
  // 4 s at 10 fps, 640 x 480: 40 frames per camera, 4 of them blurred.
  const RigClipSpec spec = StereoClip(4.0, 10.0, 640, 480);
  const fs::path root = RenderRig(spec, "synchronised");
  const fs::path report = root / "report";
  const auto start = std::chrono::steady_clock::now();
  const ProgramRun run = CalibrateRig(root, "--report " + Quote(report.string()));
  const double seconds = std::chrono::duration<double>(
                             std::chrono::steady_clock::now() - start)
                             .count();
  std::cout << run.all() << "calibrate-rig took " << seconds << " s\n";
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  // A line per video and one for the rig: every frame of cam0 paired.
  EXPECT_NE(Line(run.out, "camera 'cam0': cam0.avi: 40 frames"), "");
  EXPECT_NE(Line(run.out, "camera 'cam1': cam1.avi: 40 frames"), "");
  const std::string rig_line = Line(run.out, "rig: 40 frames of cam0.avi");
  EXPECT_NE(rig_line.find("0 frames of the other cameras without a partner"),
            std::string::npos)
      << run.out;

  std::vector<RigFileCamera> cameras;
  std::string error;
  ASSERT_TRUE(ReadRigFile((root / "rig.yaml").string(), &cameras, &error))
      << error;
  ASSERT_EQ(cameras.size(), 2u);
  const RigErrors errors = Compare(spec, cameras);
  EXPECT_LT(errors.rotation_deg, 0.05);
  EXPECT_LT(errors.baseline_relative, 0.005);
  EXPECT_LT(errors.fx_relative[0], 0.002);
  EXPECT_LT(errors.fx_relative[1], 0.002);
  // The frames are of one instant: the rig's consistency names no frame
  // and no camera (its verdict is good or a camera's own; cam1's detector
  // finds two sharp frames of a steep view at 0.2-0.3 px, which its own
  // verdict names as bad detections).
  const std::string verdict = Line(run.out, "rig: verdict: ");
  ASSERT_NE(verdict, "") << run.out;
  EXPECT_EQ(verdict.find("moved-frames"), std::string::npos) << verdict;
  EXPECT_EQ(verdict.find("inconsistent"), std::string::npos) << verdict;
  EXPECT_NE(Line(run.out, "cam0: verdict: good"), "") << run.out;

  // The rig file names the frames by video and frame; the kept frames are
  // at most video.max_frames (40) and spread over the clip.
  const YAML::Node rig = YAML::LoadFile((root / "rig.yaml").string());
  const YAML::Node frames = rig["frames"];
  ASSERT_TRUE(frames.IsSequence());
  EXPECT_GT(frames.size(), 10u);
  EXPECT_LE(frames.size(), 40u);
  std::cout << frames.size() << " rig frames kept\n";
  int both = 0;
  for (const YAML::Node& frame : frames) {
    const std::string file0 = frame["cameras"][0]["file"].as<std::string>();
    const std::string file1 = frame["cameras"][1]["file"].as<std::string>();
    EXPECT_NE(file0.find("cam0.avi#frame00"), std::string::npos) << file0;
    // Synchronised: cam1's frame of the same instant has the same number.
    EXPECT_EQ(file1.substr(file1.find('#')), file0.substr(file0.find('#')));
    both += frame["cameras"][0]["use"].as<std::string>().rfind("used", 0) ==
                0 &&
            frame["cameras"][1]["use"].as<std::string>().rfind("used", 0) == 0;
  }
  EXPECT_GT(both, 10);
  // The report's per-video tables: every frame, each paired with the
  // reference frame of its own number; no blurred frame kept.
  const std::vector<ClipFrameTruth> truth = ClipTruth(spec.clip);
  for (const char* camera : {"cam0", "cam1"}) {
    const std::string table = testing_files::ReadFile(
        report / (std::string("video_frames_") + camera + ".csv"));
    std::istringstream lines(table);
    std::string line;
    std::getline(lines, line);
    EXPECT_NE(line.find("reference_frame,time_difference_ms"),
              std::string::npos);
    int rows = 0;
    while (std::getline(lines, line)) {
      const int frame = std::stoi(line);
      ++rows;
      if (truth[frame].motion_blur.length_px > 0) {
        EXPECT_EQ(line.find(",kept,"), std::string::npos) << line;
      }
      EXPECT_NE(line.find("\"," + std::to_string(frame) + ",0.000"),
                std::string::npos)
          << line;
    }
    EXPECT_EQ(rows, 40) << table;
  }
  EXPECT_TRUE(fs::exists(report / "rectified_pair.png"));
}

TEST(CalibrateRigVideo, ACameraSeveralFramesLateIsNotCalledGood) {
  // cam1's clip shows the motion 3 frame periods (300 ms) later than its
  // time stamps say: every frame pairs, with the board elsewhere.
  const RigClipSpec spec = StereoClip(4.0, 10.0, 640, 480, 300.0);
  const fs::path root = RenderRig(spec, "late");
  const ProgramRun run = CalibrateRig(root);
  std::cout << run.all();
  EXPECT_NE(Line(run.out, "rig: 40 frames of cam0.avi"), "") << run.all();
  if (run.exit_code == kExitOk) {
    const std::string verdict = Line(run.out, "rig: verdict: ");
    ASSERT_NE(verdict, "") << run.out;
    // The frames paired are 300 ms apart in the motion: the rig's
    // consistency says so (inconsistent or moved frames), and rightly: the
    // rig it found is far from the truth.
    EXPECT_TRUE(verdict.find("rig: verdict: inconsistent") == 0 ||
                verdict.find("rig: verdict: moved-frames") == 0)
        << verdict;
    std::vector<RigFileCamera> cameras;
    std::string error;
    ASSERT_TRUE(ReadRigFile((root / "rig.yaml").string(), &cameras, &error))
        << error;
    const RigErrors errors = Compare(spec, cameras);
    EXPECT_GT(errors.rotation_deg, 1.0);
    // The rig file carries the verdict too.
    const YAML::Node rig = YAML::LoadFile((root / "rig.yaml").string());
    EXPECT_NE(rig["verdict"]["kind"].as<std::string>(), "good");
  } else {
    EXPECT_EQ(run.exit_code, kExitNoResult) << run.all();
  }
}

TEST(CalibrateRigVideo, FoldersBreakingTheRuleAreRefusedByName) {
  const fs::path root = Scratch() / "bad";
  fs::create_directories(root / "cam0");
  fs::create_directories(root / "cam1");
  testing_files::WriteFile(root / "cam0" / "a.avi", "x");
  testing_files::WriteFile(root / "cam1" / "b.avi", "x");
  testing_files::WriteFile(root / "cam1" / "c.avi", "x");
  ProgramRun run = CalibrateRig(root);
  EXPECT_EQ(run.exit_code, kExitBadInput) << run.all();
  EXPECT_NE(run.err.find("camera 'cam1' (" + (root / "cam1").string() +
                         ") holds 2 videos (b.avi, c.avi)"),
            std::string::npos)
      << run.err;

  fs::remove(root / "cam1" / "c.avi");
  fs::remove(root / "cam1" / "b.avi");
  testing_files::WriteFile(root / "cam1" / "frame_000.png", "x");
  run = CalibrateRig(root);
  EXPECT_EQ(run.exit_code, kExitBadInput) << run.all();
  EXPECT_NE(run.err.find("camera 'cam0' (" + (root / "cam0").string() +
                         ") holds a video (a.avi), camera 'cam1' (" +
                         (root / "cam1").string() + ") photos"),
            std::string::npos)
      << run.err;

  testing_files::WriteFile(root / "cam0" / "frame_000.png", "x");
  run = CalibrateRig(root);
  EXPECT_EQ(run.exit_code, kExitBadInput) << run.all();
  EXPECT_NE(run.err.find("camera 'cam0' (" + (root / "cam0").string() +
                         ") holds both photos (frame_000.png) and a video "
                         "(a.avi)"),
            std::string::npos)
      << run.err;
}

}  // namespace
}  // namespace puzzlecal
