// The splined model on a lens kannala-brandt cannot follow
// (sim::TruthBumpyFisheye): recovered to its stated, noise-limited
// uncertainty, and chosen by held-out views over kannala-brandt; on a lens
// kannala-brandt can follow it is not chosen
// (model_selection_test.cc's ChoosesKannalaBrandtForAFisheye runs every
// candidate, the splined ones included).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/model_selection.h"
#include "sim/synthetic_views.h"
#include "tests/calib/scenes.h"

namespace puzzlecal {
namespace {

sim::SyntheticData BumpyData(unsigned seed, int num_views = 30) {
  return sim::MakeSyntheticData(
      testing_scenes::BumpyFisheyeScene(seed, num_views));
}

CalibrationResult CalibrateOrDie(const sim::SyntheticData& data,
                                 CameraModelId model, const Camera& truth) {
  CalibrationResult result;
  std::string error;
  EXPECT_TRUE(Calibrate(data.views, model, truth.width, truth.height,
                        CalibrationOptions(), &result, &error))
      << CameraModelName(model) << ": " << error;
  return result;
}

// The widest field angle of a corner, degrees (the observed field).
double ObservedFieldDeg(const sim::SyntheticData& data, const Camera& truth) {
  double widest = 0;
  for (const auto& view : data.exact) {
    for (const Eigen::Vector2d& pixel : view) {
      Eigen::Vector3d ray;
      if (!truth.Unproject(pixel, &ray).converged) continue;
      widest = std::max(widest, std::acos(std::min(1.0, ray.z())));
    }
  }
  return widest * 180 / M_PI;
}

// On the bumpy lens the splined model's far-field projection is within 2x
// its own stated uncertainty of the truth in every band of the observed
// field (band medians, after the best-fitting rotation), while
// kannala-brandt's error is many times its uncertainty, and its RMS stays
// above the noise.
TEST(SplinedCalibration, RecoversALensKannalaBrandtCannotFollow) {
  const sim::SyntheticData data = BumpyData(11);
  const Camera truth = sim::TruthBumpyFisheye();
  const double field_deg = ObservedFieldDeg(data, truth);
  const CalibrationResult splined =
      CalibrateOrDie(data, CameraModelId::kKannalaBrandtSplined, truth);
  const CalibrationResult kb =
      CalibrateOrDie(data, CameraModelId::kKannalaBrandt, truth);
  ASSERT_TRUE(splined.covariance_ok);
  ASSERT_TRUE(kb.covariance_ok);
  // The noise is 0.1 px per coordinate.
  EXPECT_LT(splined.rms_px, 0.105);
  EXPECT_GT(kb.rms_px, 0.13);
  EvidenceOptions options;
  const ProjectionDiff splined_diff = ProjectionDifference(
      truth, splined.camera, field_deg, options, nullptr, &splined.covariance);
  const ProjectionDiff kb_diff = ProjectionDifference(
      truth, kb.camera, field_deg, options, nullptr, &kb.covariance);
  ASSERT_TRUE(splined_diff.ok && splined_diff.expected_ok)
      << splined_diff.error;
  ASSERT_TRUE(kb_diff.ok && kb_diff.expected_ok) << kb_diff.error;
  ASSERT_EQ(splined_diff.difference_bands.size(),
            splined_diff.expected_bands.size());
  double kb_worst_ratio = 0;
  for (size_t b = 0; b < splined_diff.difference_bands.size(); ++b) {
    const AngleBand& error = splined_diff.difference_bands[b];
    const AngleBand& expected = splined_diff.expected_bands[b];
    if (error.count < 20) continue;
    SCOPED_TRACE(std::to_string(error.lo_deg) + "-" +
                 std::to_string(error.hi_deg) + " deg");
    EXPECT_LT(error.median, 2 * expected.median);
    kb_worst_ratio =
        std::max(kb_worst_ratio, kb_diff.difference_bands[b].median /
                                     kb_diff.expected_bands[b].median);
  }
  EXPECT_GT(kb_worst_ratio, 5.0);
}

// --model auto between kannala-brandt and the splined model on the bumpy
// lens: the held-out views prefer the spline.
TEST(SplinedModelSelection, HeldOutViewsChooseTheSplineForTheBumpyLens) {
  const sim::SyntheticData data = BumpyData(15, 24);
  const Camera truth = sim::TruthBumpyFisheye();
  ModelSelectionOptions options;
  options.candidates = {"kannala-brandt", "kannala-brandt-splined"};
  ModelSelection selection;
  std::string error;
  ASSERT_TRUE(SelectModel(data.views, truth.width, truth.height,
                          CalibrationOptions(), options, &selection, &error))
      << error;
  ASSERT_GE(selection.chosen, 0);
  EXPECT_EQ(selection.candidates[selection.chosen].model,
            CameraModelId::kKannalaBrandtSplined)
      << selection.Table();
}

// On a pinhole lens (radtan leads) the splined candidates are not fitted:
// the table lists them as skipped and names the leader.
TEST(SplinedModelSelection, SkippedWhenTheModelTheyRefineDoesNotLead) {
  sim::SyntheticScene scene;
  scene.camera = sim::TruthRadtan();
  scene.num_views = 16;
  scene.noise_px = 0.2;
  scene.max_direction_deg = 40;
  scene.min_visible_fraction = 0.5;
  scene.seed = 16;
  const sim::SyntheticData data = sim::MakeSyntheticData(scene);
  ModelSelection selection;
  std::string error;
  ASSERT_TRUE(SelectModel(data.views, scene.camera.width, scene.camera.height,
                          CalibrationOptions(), ModelSelectionOptions(),
                          &selection, &error))
      << error;
  ASSERT_GE(selection.chosen, 0);
  EXPECT_EQ(selection.candidates[selection.chosen].model,
            CameraModelId::kPinholeRadtan);
  int skipped = 0;
  for (const ModelCandidate& c : selection.candidates) {
    if (!CameraModelIsSplined(c.model)) continue;
    EXPECT_FALSE(c.ok);
    EXPECT_EQ(c.seconds, 0.0);
    EXPECT_NE(c.error.find("pinhole-radtan does"), std::string::npos)
        << c.error;
    ++skipped;
  }
  EXPECT_EQ(skipped, 2);
  EXPECT_NE(selection.Table().find("skipped"), std::string::npos);
  // Candidates never fitted take no part in the comparison of the others.
  EXPECT_EQ(selection.reason.find("splined"), std::string::npos)
      << selection.reason;
}

}  // namespace
}  // namespace puzzlecal
