// The rig's per-frame consistency and verdict on sim rigs with exact
// truth: a second camera out of sync (the board moved between the two
// exposures by a known amount in known frames) is named frame by frame,
// and clean rigs have no frame named.

#include "evidence/rig_evidence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "calib/rig_calibration.h"
#include "sim/rig_scenes.h"

namespace puzzlecal {
namespace {

// Corner noise of the detector on renders is about 0.03 px; real photos of
// a printed board reach 0.05-0.1 px.
constexpr double kNoisePx = 0.06;

struct JudgedRig {
  RigCalibrationResult result;
  RigEvidence evidence;
  RigVerdict verdict;
};

JudgedRig JudgeRig(const RigSceneSpec& scene, uint64_t noise_seed) {
  JudgedRig judged;
  const std::vector<RigCameraInput> inputs =
      RigCorrespondences(scene, kNoisePx, noise_seed);
  std::string error;
  EXPECT_TRUE(
      CalibrateRig(inputs, RigCalibrationOptions(), &judged.result, &error))
      << error;
  const RigEvidenceOptions options;
  judged.evidence = ComputeRigEvidence(inputs, judged.result, options);
  judged.verdict =
      MakeRigVerdict(judged.result, judged.evidence, {}, {}, options);
  return judged;
}

RigSceneSpec Scene(int kind, uint64_t seed) {
  RigSceneSpec scene = kind == 0 ? StereoPinholeRig() : StereoFisheyeRig();
  scene.random_frames.seed = seed;
  scene.random_frames.count = 16;
  return scene;
}

TEST(RigEvidenceTest, NoCleanFrameIsNamedInTwentyCleanScenes) {
  int named = 0, frames = 0;
  double worst_ratio = 0;
  for (int s = 0; s < 20; ++s) {
    const JudgedRig judged = JudgeRig(Scene(s % 2, 100 + s), 7 + s);
    named += static_cast<int>(judged.evidence.moved_frames.size());
    for (const RigFrameEvidence& frame : judged.evidence.frames) {
      if (!frame.compared) continue;
      ++frames;
      worst_ratio = std::max(
          worst_ratio, frame.transfer_px / judged.evidence.moved_limit_px);
    }
    EXPECT_EQ(judged.verdict.kind, "good") << judged.verdict.Line();
  }
  std::cout << frames << " clean frames in 20 scenes: " << named
            << " named; largest transfer error " << worst_ratio
            << " of the limit\n";
  EXPECT_EQ(named, 0);
}

TEST(RigEvidenceTest, FramesMovedByMoreThanTwoMillimetresAreNamed) {
  int moved = 0, found = 0, false_named = 0;
  for (int s = 0; s < 12; ++s) {
    RigSceneSpec scene = Scene(s % 2, 200 + s);
    scene.moved_frames = {1, 5, 9, 13};
    scene.moved_by_m = 0.001 * (2.2 + 0.5 * (s % 6));  // 2.2 .. 4.7 mm
    scene.moved_seed = 300 + s;
    const JudgedRig judged = JudgeRig(scene, 11 + s);
    EXPECT_EQ(judged.verdict.kind, "moved-frames") << judged.verdict.Line();
    for (size_t f = 0; f < judged.evidence.frames.size(); ++f) {
      const RigFrameEvidence& frame = judged.evidence.frames[f];
      if (!frame.compared) continue;
      const bool is_moved =
          std::count(scene.moved_frames.begin(), scene.moved_frames.end(),
                     static_cast<int>(f)) > 0;
      moved += is_moved;
      found += is_moved && frame.moved;
      false_named += !is_moved && frame.moved;
      if (is_moved && !frame.moved) {
        std::cout << "missed: scene " << s << " frame " << f << " moved "
                  << scene.moved_by_m * 1000 << " mm: transfer "
                  << frame.transfer_px << " px, limit "
                  << judged.evidence.moved_limit_px << " px\n";
      }
    }
  }
  std::cout << found << " of " << moved << " moved frames named, "
            << false_named << " clean frames named\n";
  ASSERT_GT(moved, 30);
  EXPECT_GE(found, 0.9 * moved);
  EXPECT_EQ(false_named, 0);
}

// A clean rig whose cameras' own verdicts are not all good: the rig's
// verdict takes the first one's kind, reason and next step, and names every
// other camera that is not good with its kind.
TEST(RigEvidenceTest, EveryCameraThatIsNotGoodIsNamed) {
  const JudgedRig judged = JudgeRig(Scene(0, 7), 7);
  ASSERT_EQ(judged.verdict.kind, "good") << judged.verdict.Line();
  ASSERT_EQ(judged.result.cameras.size(), 2u);
  const std::string name0 = judged.result.cameras[0].name;
  const std::string name1 = judged.result.cameras[1].name;
  auto verdict = [](VerdictKind kind, const std::string& reason) {
    Verdict v;
    v.kind = kind;
    v.reason = reason;
    v.next_step = reason + " next";
    return v;
  };
  const RigVerdict both =
      MakeRigVerdict(judged.result, judged.evidence,
                     {verdict(VerdictKind::kInsufficientData, "few views"),
                      verdict(VerdictKind::kModelError, "halves differ")},
                     {}, RigEvidenceOptions());
  EXPECT_EQ(both.kind, "insufficient-data");
  EXPECT_EQ(both.reason.find("camera '" + name0 + "': few views"), 0u)
      << both.reason;
  EXPECT_NE(both.reason.find("camera '" + name1 + "' is model-error"),
            std::string::npos)
      << both.reason;
  EXPECT_EQ(both.next_step, "few views next");

  const RigVerdict second =
      MakeRigVerdict(judged.result, judged.evidence,
                     {verdict(VerdictKind::kGood, "fine"),
                      verdict(VerdictKind::kModelError, "halves differ")},
                     {}, RigEvidenceOptions());
  EXPECT_EQ(second.kind, "model-error");
  EXPECT_EQ(second.reason, "camera '" + name1 + "': halves differ");
}

TEST(RigEvidenceTest, OptionsCheckNamesTheField) {
  RigEvidenceOptions options;
  options.moved_factor = 1;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("moved_factor"), std::string::npos);
}

}  // namespace
}  // namespace puzzlecal
