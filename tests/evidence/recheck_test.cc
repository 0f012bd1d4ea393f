// The projection difference between two cameras (ProjectionDifference) and
// a stored calibration re-checked on new views (evidence/recheck.h), on
// synthetic views with known truth.

#include "evidence/recheck.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "sim/synthetic_views.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

using sim::MakeSyntheticData;
using sim::SyntheticData;
using sim::SyntheticScene;

SyntheticScene Scene(const Camera& camera, int num_views, unsigned seed) {
  SyntheticScene scene;
  scene.camera = camera;
  scene.num_views = num_views;
  scene.noise_px = 0.1;
  scene.seed = seed;
  scene.max_direction_deg = 35;
  scene.min_visible_fraction = 0.6;
  return scene;
}

CalibrationResult CalibrateOrFail(const std::vector<CalibrationView>& views,
                                  CameraModelId model, const Camera& truth) {
  CalibrationResult result;
  std::string error;
  EXPECT_TRUE(Calibrate(views, model, truth.width, truth.height,
                        CalibrationOptions(), &result, &error))
      << error;
  EXPECT_TRUE(result.covariance_ok);
  return result;
}

// `camera` with both focal lengths scaled by `scale`.
Camera ScaledFocal(Camera camera, double scale) {
  camera.params[0] *= scale;
  camera.params[1] *= scale;
  return camera;
}

// The widest field angle of the inlier corners of a calibration.
double ObservedAngle(const std::vector<CalibrationView>& views,
                     const CalibrationResult& result) {
  return ComputeSystematicResiduals(views, result, EvidenceOptions())
      .max_angle_deg;
}

TEST(ProjectionDifference, ACameraAgainstItselfIsExactlyZero) {
  for (const Camera& camera :
       {sim::TruthRadtan(), sim::TruthRational(), sim::TruthFisheye190()}) {
    const ProjectionDiff diff =
        ProjectionDifference(camera, camera, 0, EvidenceOptions());
    ASSERT_TRUE(diff.ok) << diff.error;
    EXPECT_EQ(diff.rotation_deg, 0.0);
    EXPECT_TRUE(diff.b_from_a.isIdentity(0.0));
    EXPECT_FALSE(diff.expected_ok);
    int compared = 0;
    for (double value : diff.difference_px.values) {
      if (!std::isfinite(value)) continue;
      EXPECT_EQ(value, 0.0);
      ++compared;
    }
    EXPECT_GT(compared, 1000) << CameraModelName(camera.model);
    for (const AngleBand& band : diff.difference_bands) {
      if (band.count > 0) {
        EXPECT_EQ(band.max, 0.0);
      }
    }
  }
}

TEST(ProjectionDifference, ARotatedCameraDiffersByItsRotationOnly) {
  // A principal point moved by 2 px is, near the axis, a rotation of the
  // camera by 2 / f rad: the rotation is taken out and what remains is the
  // small part a rotation does not undo (an eighth of the shift at most,
  // up to 30 degrees off the axis).
  const Camera a = sim::TruthFisheye190();
  Camera b = a;
  b.params[2] += 2.0;
  const ProjectionDiff diff = ProjectionDifference(a, b, 30, EvidenceOptions());
  ASSERT_TRUE(diff.ok) << diff.error;
  EXPECT_NEAR(diff.rotation_deg, 2.0 / a.params[0] * 180 / M_PI, 0.01);
  for (const AngleBand& band : diff.difference_bands) {
    EXPECT_LT(band.p95, 0.25) << band.lo_deg;
  }
}

TEST(ProjectionDifference, ScaledFocalLengthGrowsWithTheImageRadius) {
  const Camera a = sim::TruthRadtan();
  const Camera b = ScaledFocal(a, 1.005);
  const ProjectionDiff diff = ProjectionDifference(a, b, 40, EvidenceOptions());
  ASSERT_TRUE(diff.ok) << diff.error;
  // Every pixel moves by 0.5 % of its distance from the principal point,
  // which no rotation undoes: the outer bands differ most, the band median
  // by up to 0.005 x the radius of the widest compared pixel.
  double rim_radius = 0;
  const PixelMap& map = diff.difference_px;
  for (int j = 0; j < map.rows; ++j) {
    for (int i = 0; i < map.cols; ++i) {
      if (!std::isfinite(map.At(i, j))) continue;
      rim_radius = std::max(
          rim_radius,
          std::hypot(std::min(i * map.step_px, a.width - 1) - a.params[2],
                     std::min(j * map.step_px, a.height - 1) - a.params[3]));
    }
  }
  double previous = 0;
  for (const AngleBand& band : diff.difference_bands) {
    EXPECT_GT(band.median, previous) << band.lo_deg;
    previous = band.median;
  }
  EXPECT_GT(diff.difference_bands.back().max, 0.6 * 0.005 * rim_radius);
  // (The rotation fitted over the whole field shifts the rim a little.)
  EXPECT_LT(diff.difference_bands.back().max, 1.05 * 0.005 * rim_radius);
}

TEST(ProjectionDifference, RefusesDifferentImageSizesAndBadCovariances) {
  const Camera a = sim::TruthRadtan();
  Camera b = a;
  b.width = 640;
  EXPECT_FALSE(ProjectionDifference(a, b, 0, EvidenceOptions()).ok);
  const Eigen::MatrixXd wrong = Eigen::MatrixXd::Identity(4, 4);
  const ProjectionDiff diff =
      ProjectionDifference(a, a, 0, EvidenceOptions(), &wrong);
  EXPECT_FALSE(diff.ok);
  EXPECT_NE(diff.error.find("covariance of camera A"), std::string::npos)
      << diff.error;
}

// Two calibrations of two lenses differ as their truths do, within the
// uncertainty their covariances give.
TEST(ProjectionDifference, TwoCalibrationsDifferAsTheirTruthsWithinSigma) {
  const Camera truth_a = sim::TruthRadtan();
  const Camera truth_b = ScaledFocal(truth_a, 1.005);
  const SyntheticData data_a = MakeSyntheticData(Scene(truth_a, 25, 3));
  const SyntheticData data_b = MakeSyntheticData(Scene(truth_b, 25, 4));
  const CalibrationResult a =
      CalibrateOrFail(data_a.views, truth_a.model, truth_a);
  const CalibrationResult b =
      CalibrateOrFail(data_b.views, truth_b.model, truth_b);
  const double field =
      std::min(ObservedAngle(data_a.views, a), ObservedAngle(data_b.views, b));
  const ProjectionDiff truth =
      ProjectionDifference(truth_a, truth_b, field, EvidenceOptions());
  const ProjectionDiff found =
      ProjectionDifference(a.camera, b.camera, field, EvidenceOptions(),
                           &a.covariance, &b.covariance);
  ASSERT_TRUE(truth.ok && found.ok) << truth.error << found.error;
  ASSERT_TRUE(found.expected_ok);
  ASSERT_EQ(truth.difference_bands.size(), found.difference_bands.size());
  int judged = 0;
  for (size_t k = 0; k < found.difference_bands.size(); ++k) {
    const AngleBand& t = truth.difference_bands[k];
    const AngleBand& f = found.difference_bands[k];
    const AngleBand& e = found.expected_bands[k];
    if (f.count < EvidenceOptions().min_bin_count) continue;
    ++judged;
    EXPECT_NEAR(f.median, t.median, 3 * e.median)
        << f.lo_deg << " deg: truth " << t.median << ", found " << f.median
        << ", expected " << e.median;
  }
  EXPECT_GE(judged, 3);
}

TEST(ProjectionDifference, RunsAcrossModels) {
  // kannala-brandt fitted to views of the radtan lens: the two describe the
  // same lens, differently.
  const Camera truth = sim::TruthRadtan();
  const SyntheticData data = MakeSyntheticData(Scene(truth, 20, 5));
  const CalibrationResult radtan =
      CalibrateOrFail(data.views, CameraModelId::kPinholeRadtan, truth);
  const CalibrationResult fisheye =
      CalibrateOrFail(data.views, CameraModelId::kKannalaBrandt, truth);
  const ProjectionDiff diff = ProjectionDifference(
      radtan.camera, fisheye.camera, ObservedAngle(data.views, radtan),
      EvidenceOptions(), &radtan.covariance, &fisheye.covariance);
  ASSERT_TRUE(diff.ok) << diff.error;
  ASSERT_FALSE(diff.difference_bands.empty());
  std::cout << ProjectionDifferenceText(diff);
  EXPECT_LT(diff.rotation_deg, 0.5);
  // The centre agrees; the model error of the 4-coefficient fisheye grows
  // outwards but stays within a few pixels where the views were.
  EXPECT_LT(diff.difference_bands.front().median, 1.0);
  EXPECT_LT(diff.difference_bands.back().median, 5.0);
}

StoredCalibration StoredOf(const CalibrationResult& result) {
  StoredCalibration stored;
  stored.camera = result.camera;
  stored.rms_px = result.rms_px;
  stored.param_stddev = result.param_stddev;
  stored.covariance = result.covariance;
  return stored;
}

// The stored calibration of `num_views` synthetic views of `truth`.
StoredCalibration StoredCalibrationOf(const Camera& truth, int num_views,
                                      unsigned seed) {
  const SyntheticData original =
      MakeSyntheticData(Scene(truth, num_views, seed));
  return StoredOf(CalibrateOrFail(original.views, truth.model, truth));
}

TEST(Recheck, TheSameCameraIsStillValidAndAChangedFocalLengthHasDrifted) {
  const Camera truth = sim::TruthRadtan();
  const StoredCalibration stored = StoredCalibrationOf(truth, 25, 7);

  const SyntheticData same = MakeSyntheticData(Scene(truth, 15, 8));
  const Recheck valid = RecheckCalibration(
      same.views, stored, CalibrationOptions(), RecheckOptions());
  EXPECT_EQ(valid.verdict, RecheckVerdict::kStillValid) << valid.reason;
  EXPECT_TRUE(valid.held_ok) << valid.held_error;
  EXPECT_EQ(valid.views_used, 15);
  EXPECT_EQ(valid.worse_views, 0);
  EXPECT_TRUE(valid.stored_covariance_used);

  const Camera changed = ScaledFocal(truth, 1.005);
  const SyntheticData moved = MakeSyntheticData(Scene(changed, 15, 8));
  const Recheck drifted = RecheckCalibration(
      moved.views, stored, CalibrationOptions(), RecheckOptions());
  ASSERT_EQ(drifted.verdict, RecheckVerdict::kDrifted) << drifted.reason;
  ASSERT_GE(drifted.worst_band, 0);
  // The reported drift is the one the truth implies, band by band.
  const ProjectionDiff truth_diff = ProjectionDifference(
      truth, changed, drifted.observed_angle_deg, EvidenceOptions());
  ASSERT_TRUE(truth_diff.ok);
  const AngleBand& worst =
      drifted.difference.difference_bands[drifted.worst_band];
  const AngleBand& truth_worst =
      truth_diff.difference_bands[drifted.worst_band];
  EXPECT_NEAR(worst.median, truth_worst.median, 0.15 * truth_worst.median)
      << drifted.reason;
  EXPECT_NE(drifted.reason.find("bands drifted"), std::string::npos);
}

// A still-valid verdict quotes the largest median of the bands that can
// tell a drift; the bands too uncertain to (3 sigma above
// max_detectable_px) are named with their medians, which may be larger.
TEST(Recheck, StillValidNamesTheBandsItCannotJudge) {
  const Camera truth = sim::TruthRadtan();
  const StoredCalibration stored = StoredCalibrationOf(truth, 25, 7);
  const SyntheticData same = MakeSyntheticData(Scene(truth, 15, 8));
  const Recheck all = RecheckCalibration(
      same.views, stored, CalibrationOptions(), RecheckOptions());
  ASSERT_EQ(all.verdict, RecheckVerdict::kStillValid) << all.reason;
  EXPECT_EQ(all.reason.find("not judged"), std::string::npos) << all.reason;
  // The bound between the two most certain judged bands: only the most
  // certain stays judged.
  RecheckOptions options;
  std::vector<double> bounds;
  for (size_t b = 0; b < all.difference.expected_bands.size(); ++b) {
    if (all.difference.difference_bands[b].count <
        options.evidence.min_bin_count) {
      continue;
    }
    bounds.push_back(options.drift_sigmas *
                     all.difference.expected_bands[b].median);
  }
  ASSERT_GE(bounds.size(), 2u);
  std::sort(bounds.begin(), bounds.end());
  options.max_detectable_px = 0.5 * (bounds[0] + bounds[1]);
  const Recheck few =
      RecheckCalibration(same.views, stored, CalibrationOptions(), options);
  ASSERT_EQ(few.verdict, RecheckVerdict::kStillValid) << few.reason;
  EXPECT_NE(few.reason.find("cannot tell a drift and are not judged"),
            std::string::npos)
      << few.reason;
  for (size_t b = 0; b < few.band_resolved.size(); ++b) {
    const AngleBand& band = few.difference.difference_bands[b];
    if (few.band_resolved[b] || band.count < options.evidence.min_bin_count) {
      continue;
    }
    const std::string named = StringPrintf("%.0f-%.0f deg %.3f px", band.lo_deg,
                                           band.hi_deg, band.median);
    EXPECT_NE(few.reason.find(named), std::string::npos) << named << "\n"
                                                         << few.reason;
  }
}

TEST(Recheck, TooFewViewsIsNotEnoughData) {
  const Camera truth = sim::TruthRadtan();
  const StoredCalibration stored = StoredCalibrationOf(truth, 20, 9);
  SyntheticData few = MakeSyntheticData(Scene(truth, 2, 10));
  const Recheck recheck = RecheckCalibration(
      few.views, stored, CalibrationOptions(), RecheckOptions());
  EXPECT_EQ(recheck.verdict, RecheckVerdict::kNotEnoughData);
  EXPECT_NE(recheck.reason.find("do not calibrate"), std::string::npos)
      << recheck.reason;
  // The held fit still poses and judges the two views.
  EXPECT_TRUE(recheck.held_ok) << recheck.held_error;
  EXPECT_EQ(recheck.views_used, 2);
}

TEST(Recheck, OptionsAreChecked) {
  RecheckOptions options;
  EXPECT_TRUE(options.Check());
  options.drift_sigmas = 0;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("drift_sigmas"), std::string::npos);
  options = RecheckOptions();
  options.evidence.band_width_deg = 0;
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace puzzlecal
