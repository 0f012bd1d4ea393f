#include "evidence/model_selection.h"

#include <gtest/gtest.h>

#include <iostream>
#include <string>
#include <vector>

#include "sim/synthetic_views.h"

namespace puzzlecal {
namespace {

using sim::MakeSyntheticData;
using sim::SyntheticData;
using sim::SyntheticScene;

SyntheticData Data(const Camera& camera, unsigned seed,
                   double max_corner_angle_deg = 180) {
  SyntheticScene scene;
  scene.camera = camera;
  scene.num_views = 24;
  scene.noise_px = 0.2;
  scene.seed = seed;
  scene.max_direction_deg = 45;
  scene.min_visible_fraction = 0.5;
  scene.max_corner_angle_deg = max_corner_angle_deg;
  return MakeSyntheticData(scene);
}

ModelSelection Select(const SyntheticData& data, const Camera& truth) {
  ModelSelection selection;
  std::string error;
  EXPECT_TRUE(SelectModel(data.views, truth.width, truth.height,
                          CalibrationOptions(), ModelSelectionOptions(),
                          &selection, &error))
      << error;
  return selection;
}

TEST(ModelSelectionOptions, CheckRejectsBadValues) {
  ModelSelectionOptions options;
  EXPECT_TRUE(options.Check());
  options.holdout_every = 1;
  EXPECT_FALSE(options.Check());
  options = ModelSelectionOptions();
  options.holdout_offset = 4;
  EXPECT_FALSE(options.Check());
  options = ModelSelectionOptions();
  options.candidates = {"no-such-model"};
  EXPECT_FALSE(options.Check());
  options = ModelSelectionOptions();
  options.gross_error_k = 0;
  EXPECT_FALSE(options.Check());
  options = ModelSelectionOptions();
  options.gross_error_floor_px = -1;
  EXPECT_FALSE(options.Check());
}

// The true camera on noise-free corners: zero held-out error.
TEST(HoldoutError, ZeroForTheTrueCameraOnExactCorners) {
  const Camera truth = sim::TruthFisheye190();
  SyntheticScene scene;
  scene.camera = truth;
  scene.num_views = 5;
  scene.noise_px = 0;
  const SyntheticData data = MakeSyntheticData(scene);
  double rms = -1;
  int corners = 0;
  std::string error;
  ASSERT_TRUE(HoldoutError(data.views, truth, CalibrationOptions(), &rms,
                           &corners, &error))
      << error;
  EXPECT_EQ(corners, data.num_corners);
  EXPECT_LT(rms, 1e-6);
}

// Every 4th view is held out, in 4 folds: each view once; the table lists
// every candidate.
TEST(SelectModel, SplitsViewsAndListsCandidates) {
  const Camera truth = sim::TruthRadtan();
  const ModelSelection selection = Select(Data(truth, 2), truth);
  EXPECT_EQ(selection.folds, 4);
  EXPECT_EQ(selection.fit_views, 18);
  EXPECT_EQ(selection.holdout_views, 24);
  EXPECT_EQ(selection.candidates.size(), kAllCameraModels.size());
  const std::string table = selection.Table();
  for (CameraModelId id : kAllCameraModels) {
    EXPECT_NE(table.find(CameraModelName(id)), std::string::npos);
  }
}

// Fewer views than a comparison can fit on and hold out: one message in
// the calibration's words, not a failure per candidate and fold.
TEST(SelectModel, TooFewViewsAreSaidOnce) {
  const Camera truth = sim::TruthRadtan();
  SyntheticData data = Data(truth, 2);
  for (size_t count : {1u, 3u}) {
    std::vector<CalibrationView> views(data.views.begin(),
                                       data.views.begin() + count);
    ModelSelection selection;
    std::string error;
    EXPECT_FALSE(SelectModel(views, truth.width, truth.height,
                             CalibrationOptions(), ModelSelectionOptions(),
                             &selection, &error));
    EXPECT_EQ(error.rfind("only " + std::to_string(count) + " usable view", 0),
              0u)
        << error;
    EXPECT_NE(error.find("need at least 4 to compare models"),
              std::string::npos)
        << error;
    EXPECT_TRUE(selection.candidates.empty());
  }
  // Four: a comparison runs.
  std::vector<CalibrationView> four(data.views.begin(), data.views.begin() + 4);
  ModelSelection selection;
  std::string error;
  SelectModel(four, truth.width, truth.height, CalibrationOptions(),
              ModelSelectionOptions(), &selection, &error);
  EXPECT_FALSE(selection.candidates.empty()) << error;
}

// Five views of a radtan lens, three of them of the board facing the camera
// (one orientation): the first fold fits on those three alone, where no
// pinhole model can find the focal length. Model selection cannot compare
// pinhole-radtan with the others, so it chooses it without a comparison,
// saying why, instead of the best of the models that happened to fit that
// fold; it calibrates on all five views to the truth.
TEST(SelectModel, PreferredModelFailingOnAFoldIsChosenWithoutAComparison) {
  const Camera truth = sim::TruthRadtan();
  SyntheticScene scene;
  scene.camera = truth;
  scene.noise_px = 0.1;
  scene.max_direction_deg = 30;
  scene.num_views = 2;
  scene.min_tilt_deg = 35;
  scene.seed = 3;
  const SyntheticData tilted = MakeSyntheticData(scene);
  scene.num_views = 3;
  scene.fronto_parallel = true;
  scene.seed = 4;
  const SyntheticData facing = MakeSyntheticData(scene);
  ASSERT_EQ(tilted.views.size(), 2u);
  ASSERT_EQ(facing.views.size(), 3u);
  // Fold 1 holds out the first and the fifth view.
  const std::vector<CalibrationView> views = {tilted.views[0], facing.views[0],
                                              facing.views[1], facing.views[2],
                                              tilted.views[1]};
  ModelSelection selection;
  std::string error;
  ASSERT_TRUE(SelectModel(views, truth.width, truth.height,
                          CalibrationOptions(), ModelSelectionOptions(),
                          &selection, &error))
      << error;
  std::cout << selection.Table();
  ASSERT_GE(selection.chosen, 0);
  const ModelCandidate& chosen = selection.candidates[selection.chosen];
  EXPECT_EQ(chosen.model, CameraModelId::kPinholeRadtan);
  EXPECT_FALSE(selection.compared);
  EXPECT_FALSE(chosen.ok);
  EXPECT_EQ(chosen.error.rfind("fold 1 (3 views fitted): calibration failed: "
                               "all views show the board at nearly the same "
                               "orientation",
                               0),
            0u)
      << chosen.error;
  EXPECT_EQ(selection.reason.rfind(
                "model selection could not compare the models: "
                "pinhole-radtan, the model for corners within 55 deg of the "
                "axis, failed on fold 1 (3 views fitted)",
                0),
            0u)
      << selection.reason;
  EXPECT_NE(selection.reason.find("it calibrates on all 5 views and is used "
                                  "without a comparison"),
            std::string::npos)
      << selection.reason;
  EXPECT_NE(selection.Table().find("chosen: pinhole-radtan (model selection "
                                   "could not compare"),
            std::string::npos);
  // The chosen model on all the views: the truth.
  CalibrationResult result;
  ASSERT_TRUE(Calibrate(views, chosen.model, truth.width, truth.height,
                        CalibrationOptions(), &result, &error))
      << error;
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(result.camera.params[k], truth.params[k],
                4 * result.param_stddev[k] + 1e-3 * truth.params[k])
        << k;
  }
}

// Radtan lens: radtan (the rational model fits as well, with more
// parameters, and does not win).
TEST(SelectModel, ChoosesRadtanForARadtanLens) {
  const Camera truth = sim::TruthRadtan();
  const ModelSelection selection = Select(Data(truth, 4), truth);
  ASSERT_GE(selection.chosen, 0);
  EXPECT_EQ(selection.candidates[selection.chosen].model,
            CameraModelId::kPinholeRadtan)
      << selection.Table();
}

// A wide rational lens (about 60 degrees off the axis in the image
// corners), where radtan's polynomial cannot follow.
TEST(SelectModel, ChoosesRationalForARationalLens) {
  Camera truth = sim::TruthRational();
  truth.params[0] = truth.params[1] = 480;
  const ModelSelection selection = Select(Data(truth, 6), truth);
  ASSERT_GE(selection.chosen, 0);
  EXPECT_EQ(selection.candidates[selection.chosen].model,
            CameraModelId::kPinholeRational)
      << selection.Table();
}

// A 190-degree fisheye with corners beyond 90 degrees: only
// kannala-brandt fits.
TEST(SelectModel, ChoosesKannalaBrandtForAFisheye) {
  const Camera truth = sim::TruthFisheye190();
  const ModelSelection selection = Select(Data(truth, 8), truth);
  ASSERT_GE(selection.chosen, 0);
  EXPECT_EQ(selection.candidates[selection.chosen].model,
            CameraModelId::kKannalaBrandt)
      << selection.Table();
}

// Boards far off the axis, corners beyond 90 degrees: the pinhole
// candidates are not even tried.
TEST(SelectModel, SkipsPinholeModelsBeyondTheirField) {
  const Camera truth = sim::TruthFisheye190();
  SyntheticScene scene;
  scene.camera = truth;
  scene.num_views = 24;
  scene.noise_px = 0.2;
  scene.seed = 10;
  scene.max_direction_deg = 85;
  scene.min_visible_fraction = 0.4;
  const ModelSelection selection = Select(MakeSyntheticData(scene), truth);
  ASSERT_GE(selection.chosen, 0);
  EXPECT_EQ(selection.candidates[selection.chosen].model,
            CameraModelId::kKannalaBrandt)
      << selection.Table();
  for (const ModelCandidate& c : selection.candidates) {
    if (!CameraModelIsPinhole(c.model)) continue;
    EXPECT_FALSE(c.ok);
    EXPECT_EQ(c.error.rfind("skipped", 0), 0u) << c.error;
  }
}

// A false corner 20 px off in a held-out view is off for every model: it is
// left out of every held-out RMS (so the figures are those of the clean
// corners), and a corner only some models miss would stay.
TEST(SelectModel, FalseCornerInAHeldOutViewIsLeftOutForEveryModel) {
  const Camera truth = sim::TruthRadtan();
  const SyntheticData clean = Data(truth, 2);
  SyntheticData dirty = clean;
  // Views 3, 7, 11, ... are held out (every 4th from offset 3).
  dirty.views[3].image_points[5] += Eigen::Vector2d(20, 0);
  ModelSelectionOptions options;
  options.candidates = {"pinhole-radtan", "pinhole-rational"};
  ModelSelection with_clean, with_dirty;
  std::string error;
  ASSERT_TRUE(SelectModel(clean.views, truth.width, truth.height,
                          CalibrationOptions(), options, &with_clean, &error))
      << error;
  ASSERT_TRUE(SelectModel(dirty.views, truth.width, truth.height,
                          CalibrationOptions(), options, &with_dirty, &error))
      << error;
  EXPECT_EQ(with_clean.holdout_detection_errors, 0);
  EXPECT_EQ(with_dirty.holdout_detection_errors, 1);
  ASSERT_EQ(with_dirty.candidates.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    const ModelCandidate& c = with_dirty.candidates[k];
    ASSERT_TRUE(c.ok) << c.error;
    EXPECT_EQ(c.holdout_corners, with_clean.candidates[k].holdout_corners - 1);
    // The clean corners' RMS: the pose fit of view 3 moves a little.
    EXPECT_NEAR(c.holdout_rms_px, with_clean.candidates[k].holdout_rms_px,
                0.02 * with_clean.candidates[k].holdout_rms_px);
  }
  EXPECT_EQ(with_dirty.chosen, with_clean.chosen);
  EXPECT_NE(with_dirty.Table().find("1 held-out corner(s) off for every model"),
            std::string::npos)
      << with_dirty.Table();
  // Without the rule the one corner dominates: 20 px among ~2000 corners.
  options.gross_error_floor_px = 1e9;
  ModelSelection kept;
  ASSERT_TRUE(SelectModel(dirty.views, truth.width, truth.height,
                          CalibrationOptions(), options, &kept, &error));
  EXPECT_EQ(kept.holdout_detection_errors, 0);
  EXPECT_GT(kept.candidates[0].holdout_rms_px,
            1.2 * with_clean.candidates[0].holdout_rms_px);
}

}  // namespace
}  // namespace puzzlecal
