#include "evidence/judgement.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "sim/synthetic_views.h"

namespace puzzlecal {
namespace {

sim::SyntheticData Views(const Camera& camera, unsigned seed) {
  sim::SyntheticScene scene;
  scene.camera = camera;
  scene.num_views = 14;
  scene.noise_px = 0.2;
  scene.seed = seed;
  scene.max_direction_deg = 35;
  scene.min_visible_fraction = 0.6;
  return sim::MakeSyntheticData(scene);
}

// CalibrateAndJudge takes the same steps as calling the pieces: the same
// parameters and the same verdict as Calibrate + JudgeCalibration.
TEST(CalibrateAndJudge, EqualsThePiecesOnANamedModel) {
  const Camera truth = sim::TruthRadtan();
  const sim::SyntheticData data = Views(truth, 3);
  JudgedCalibration judged;
  std::string error;
  ASSERT_TRUE(CalibrateAndJudge(data.views, truth.width, truth.height,
                                "pinhole-radtan", CalibrationOptions(),
                                JudgementOptions(), &judged, &error))
      << error;
  EXPECT_FALSE(judged.auto_model);
  CalibrationResult direct;
  ASSERT_TRUE(Calibrate(data.views, CameraModelId::kPinholeRadtan, truth.width,
                        truth.height, CalibrationOptions(), &direct, &error));
  EXPECT_EQ(judged.result.camera.params, direct.camera.params);
  const Judgement pieces = JudgeCalibration(
      data.views, direct, CalibrationOptions(), JudgementOptions());
  EXPECT_EQ(judged.judgement.verdict.Line(), pieces.verdict.Line());
  // Against the truth: the focal length within 0.5 %.
  EXPECT_NEAR(judged.result.camera.params[0], truth.params[0],
              0.005 * truth.params[0]);
}

// `auto` chooses among the models on held-out views; a pinhole lens within
// 35 degrees gets a pinhole model.
TEST(CalibrateAndJudge, AutoChoosesAPinholeModelForAPinholeLens) {
  const Camera truth = sim::TruthRadtan();
  const sim::SyntheticData data = Views(truth, 5);
  JudgedCalibration judged;
  std::string error;
  ASSERT_TRUE(CalibrateAndJudge(data.views, truth.width, truth.height, "auto",
                                CalibrationOptions(), JudgementOptions(),
                                &judged, &error))
      << error;
  EXPECT_TRUE(judged.auto_model);
  ASSERT_FALSE(judged.selection.candidates.empty());
  EXPECT_EQ(judged.result.camera.model,
            judged.selection.candidates[judged.selection.chosen].model);
  EXPECT_TRUE(CameraModelIsPinhole(judged.result.camera.model))
      << CameraModelName(judged.result.camera.model);
}

TEST(CalibrateAndJudge, RefusesUnknownModelsEmptyViewsAndBadOptions) {
  const Camera truth = sim::TruthRadtan();
  const sim::SyntheticData data = Views(truth, 7);
  JudgedCalibration judged;
  std::string error;
  EXPECT_FALSE(CalibrateAndJudge(data.views, truth.width, truth.height,
                                 "pinhole", CalibrationOptions(),
                                 JudgementOptions(), &judged, &error));
  EXPECT_NE(error.find("unknown model 'pinhole'"), std::string::npos) << error;
  EXPECT_FALSE(CalibrateAndJudge({}, truth.width, truth.height,
                                 "pinhole-radtan", CalibrationOptions(),
                                 JudgementOptions(), &judged, &error));
  EXPECT_NE(error.find("no views"), std::string::npos) << error;
  JudgementOptions bad;
  bad.evidence.grid_step_px = 0;
  EXPECT_FALSE(CalibrateAndJudge(data.views, truth.width, truth.height,
                                 "pinhole-radtan", CalibrationOptions(), bad,
                                 &judged, &error));
  EXPECT_NE(error.find("evidence: "), std::string::npos) << error;
}

}  // namespace
}  // namespace puzzlecal
