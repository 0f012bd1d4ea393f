// The verdict's false-alarm rate: clean random scenes (the right model,
// Gaussian corner noise, no fault) must not be blamed on a fault that is not
// there (model-error, inconsistent-views, bad-detections) in more than 2 %
// of them. insufficient-data is no false alarm: random poses of a few views
// often leave the image corners without data (it is counted apart). Prints
// the figures as JSON.

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/verdict.h"
#include "sim/synthetic_views.h"

namespace puzzlecal {
namespace {

TEST(Verdict, FalseAlarmRateOnCleanRandomScenesIsAtMostTwoPercent) {
  constexpr int kScenes = 60;
  const Camera cameras[] = {sim::TruthRadtan(), sim::TruthRational(),
                            sim::TruthFisheye190()};
  int alarms = 0, judged = 0;
  std::map<std::string, int> kinds;
  std::string lines;
  for (int s = 0; s < kScenes; ++s) {
    sim::SyntheticScene scene;
    scene.camera = cameras[s % 3];
    scene.num_views = 12 + (s * 7) % 19;
    scene.noise_px = 0.1 + 0.05 * (s % 7);
    scene.max_direction_deg = 30 + (s * 5) % 16;
    scene.min_visible_fraction = 0.6;
    scene.seed = 1000 + s;
    const sim::SyntheticData data = sim::MakeSyntheticData(scene);
    CalibrationResult result;
    std::string error;
    ASSERT_TRUE(Calibrate(data.views, scene.camera.model, scene.camera.width,
                          scene.camera.height, CalibrationOptions(), &result,
                          &error))
        << "scene " << s << ": " << error;
    const EvidenceOptions evidence_options;
    const Evidence evidence = ComputeEvidence(
        data.views, result, CalibrationOptions(), evidence_options);
    const Verdict verdict =
        MakeVerdict(result, evidence, evidence_options, VerdictOptions());
    ++judged;
    ++kinds[VerdictKindName(verdict.kind)];
    if (verdict.kind != VerdictKind::kGood &&
        verdict.kind != VerdictKind::kInsufficientData) {
      ++alarms;
      lines += "scene " + std::to_string(s) + " (" +
               CameraModelName(scene.camera.model) + ", " +
               std::to_string(scene.num_views) + " views): " + verdict.Line() +
               "\n";
    }
  }
  std::printf("{\"clean_scenes\": %d, \"false_alarms\": %d, \"rate\": %.4f",
              judged, alarms, static_cast<double>(alarms) / judged);
  for (const auto& [kind, count] : kinds) {
    std::printf(", \"%s\": %d", kind.c_str(), count);
  }
  std::printf("}\n");
  EXPECT_LE(alarms, 0.02 * judged) << lines;
}

}  // namespace
}  // namespace puzzlecal
