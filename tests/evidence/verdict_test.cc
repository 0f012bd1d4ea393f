#include "evidence/verdict.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "sim/synthetic_views.h"
#include "tests/evidence/judge.h"
#include "tests/support/draws.h"

namespace puzzlecal {
namespace {

using sim::MakeSyntheticData;
using sim::SyntheticData;
using sim::SyntheticScene;
using testing_judge::Judge;
using testing_judge::Judged;
using testing_judge::TiltedScene;

TEST(VerdictOptions, CheckRejectsBadValues) {
  VerdictOptions options;
  EXPECT_TRUE(options.Check());
  options.halves_factor = 0;
  EXPECT_FALSE(options.Check());
  options = VerdictOptions();
  options.max_outlier_fraction = 2;
  EXPECT_FALSE(options.Check());
  options = VerdictOptions();
  options.pinhole_max_field_deg = 95;
  EXPECT_FALSE(options.Check());
  options = VerdictOptions();
  options.max_view_outlier_fraction = -0.1;
  EXPECT_FALSE(options.Check());
  options = VerdictOptions();
  options.min_views = 0;
  EXPECT_FALSE(options.Check());
}

TEST(Verdict, LineHasKindReasonAndNextStep) {
  Verdict verdict;
  verdict.kind = VerdictKind::kModelError;
  verdict.reason = "why";
  verdict.next_step = "what";
  EXPECT_EQ(verdict.Line(), "verdict: model-error \u2014 why \u2014 what");
}

TEST(NextModel, NamesTheModelToTry) {
  const VerdictOptions options;
  EXPECT_EQ(NextModel(CameraModelId::kKannalaBrandt, true, 80, options),
            "kannala-brandt-noncentral");
  EXPECT_EQ(NextModel(CameraModelId::kPinholeRadtan, false, 85, options),
            "kannala-brandt");
  EXPECT_EQ(NextModel(CameraModelId::kPinholeRational, false, 85, options),
            "kannala-brandt");
  EXPECT_EQ(NextModel(CameraModelId::kPinholeRadtan, false, 45, options),
            "pinhole-rational");
  // Within 55 degrees a lens is never called a fisheye.
  EXPECT_EQ(NextModel(CameraModelId::kPinholeRational, false, 45, options), "");
  EXPECT_EQ(NextModel(CameraModelId::kKannalaBrandt, false, 30, options),
            "pinhole-rational");
  // The non-central form, then the spline on top; structured residuals
  // that do not grow with closeness: the spline.
  EXPECT_EQ(
      NextModel(CameraModelId::kKannalaBrandtNoncentral, true, 80, options),
      "kannala-brandt-splined-noncentral");
  EXPECT_EQ(NextModel(CameraModelId::kKannalaBrandt, false, 80, options),
            "kannala-brandt-splined");
  EXPECT_EQ(NextModel(CameraModelId::kKannalaBrandtSplined, true, 80, options),
            "kannala-brandt-splined-noncentral");
  EXPECT_EQ(NextModel(CameraModelId::kKannalaBrandtSplined, false, 80, options),
            "");
  EXPECT_EQ(NextModel(CameraModelId::kKannalaBrandtSplinedNoncentral, true, 80,
                      options),
            "");
}

// The right model on clean data of several lenses: good.
TEST(Verdict, CleanScenesAreGood) {
  for (const Camera& truth :
       {sim::TruthRadtan(), sim::TruthRational(), sim::TruthFisheye190()}) {
    const SyntheticData data =
        MakeSyntheticData(TiltedScene(truth, 24, 0.2, 3));
    const Judged judged =
        Judge(data.views, truth.model, truth.width, truth.height);
    ASSERT_TRUE(judged.calibrated) << judged.error;
    EXPECT_EQ(judged.verdict.kind, VerdictKind::kGood)
        << CameraModelName(truth.model) << ": " << judged.verdict.Line() << "\n"
        << EvidenceText(judged.evidence);
  }
}

// A pinhole model on a strong fisheye (corners up to 80 degrees off the
// axis): model-error, and the next step is kannala-brandt.
TEST(Verdict, PinholeOnFisheyeIsModelErrorNamingKannalaBrandt) {
  const Camera truth = sim::TruthFisheye190();
  SyntheticScene scene = TiltedScene(truth, 24, 0.2, 5);
  scene.max_corner_angle_deg = 80;
  scene.max_direction_deg = 60;
  scene.min_visible_fraction = 0.4;
  const SyntheticData data = MakeSyntheticData(scene);
  // The RMS limit is raised so the (poor) fit is judged at all.
  CalibrationOptions options;
  options.max_rms_px = 1000;
  const Judged judged = Judge(data.views, CameraModelId::kPinholeRadtan,
                              truth.width, truth.height, options);
  ASSERT_TRUE(judged.calibrated) << judged.error;
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kModelError)
      << judged.verdict.Line();
  EXPECT_EQ(judged.verdict.suggested_model, "kannala-brandt");
  EXPECT_NE(judged.verdict.next_step.find("--model kannala-brandt"),
            std::string::npos);
}

// Kannala-Brandt projection through an entrance pupil that moves along the
// axis with the field angle, z0(theta) = e1 theta^2 (a non-central lens):
// theta is the angle of the ray from (0, 0, z0(theta)) to the point.
bool ProjectNoncentral(const Camera& camera, double e1,
                       const Eigen::Vector3d& point, Eigen::Vector2d* pixel) {
  const double r = point.head<2>().norm();
  double theta = std::atan2(r, point.z());
  for (int it = 0; it < 50; ++it) {
    theta = std::atan2(r, point.z() - e1 * theta * theta);
  }
  // The central model's projection of a point along the corrected ray.
  const Eigen::Vector3d ray(std::sin(theta) * point.x() / r,
                            std::sin(theta) * point.y() / r, std::cos(theta));
  return camera.Project(ray, pixel);
}

// The central model on a non-central lens seen from close up: model-error,
// and the next step is kannala-brandt-noncentral.
TEST(Verdict, CentralModelOnNoncentralLensNamesNoncentral) {
  const Camera truth = sim::TruthFisheye190();
  SyntheticScene scene = TiltedScene(truth, 40, 0.2, 19);
  scene.noise_px = 0.1;
  scene.max_corner_angle_deg = 85;
  scene.max_direction_deg = 60;
  scene.min_distance = 0.4;
  scene.max_distance = 2.0;
  scene.min_visible_fraction = 0.4;
  SyntheticData data = MakeSyntheticData(scene);
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, scene.noise_px);
  constexpr double kE1 = 0.004;  // metres per rad^2: 9 mm at 90 degrees
  for (size_t v = 0; v < data.views.size(); ++v) {
    CalibrationView& view = data.views[v];
    for (size_t i = 0; i < view.board_points.size(); ++i) {
      Eigen::Vector2d pixel;
      ASSERT_TRUE(ProjectNoncentral(
          truth, kE1, data.cam_from_board[v] * view.board_points[i], &pixel));
      view.image_points[i] =
          pixel + testing_draws::DrawVector2d([&] { return normal(rng); });
    }
  }
  const Judged judged = Judge(data.views, CameraModelId::kKannalaBrandt,
                              truth.width, truth.height);
  ASSERT_TRUE(judged.calibrated) << judged.error;
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kModelError)
      << judged.verdict.Line() << "\n"
      << EvidenceText(judged.evidence);
  EXPECT_EQ(judged.verdict.suggested_model, "kannala-brandt-noncentral");
  EXPECT_NE(judged.verdict.reason.find("closer"), std::string::npos)
      << judged.verdict.reason << "\n"
      << EvidenceText(judged.evidence);

  // The non-central model on the same corners: the pupil shift recovered,
  // no systematic residuals and no disagreement of the halves. (On these
  // 20 + 20 views their e2 differ by 2.3 of their sigmas, which at 80-85
  // degrees, where that one direction dominates, is 2.7 times the predicted
  // band median: every pixel of a band shares the one parameter draw. The
  // intrinsics as a whole differ as noise does, so it is no model error.)
  const Judged noncentral =
      Judge(data.views, CameraModelId::kKannalaBrandtNoncentral, truth.width,
            truth.height);
  ASSERT_TRUE(noncentral.calibrated) << noncentral.error;
  const std::vector<double>& fitted = noncentral.result.camera.params;
  ASSERT_TRUE(noncentral.result.covariance_ok);
  const double e1_sigma = noncentral.result.param_stddev[kPupilBegin];
  EXPECT_NEAR(fitted[kPupilBegin], kE1, std::max(3 * e1_sigma, 0.05 * kE1));
  EXPECT_NEAR(fitted[0], truth.params[0], 1e-3 * truth.params[0]);
  EXPECT_NEAR(noncentral.result.rms_px, scene.noise_px, 0.1 * scene.noise_px);
  // The halves' far-field difference leaves the pupil shift out: within 60
  // degrees at most 0.033 px (band median) was measured; unit rays projected
  // as points 1 m away would add the shift (0.21 px at 20-30 deg, 0.96 px at
  // 40-50 deg on this scene).
  const CrossValidation& cv = noncentral.evidence.cross_validation;
  ASSERT_TRUE(cv.ok) << cv.error;
  for (const AngleBand& band : cv.difference_bands) {
    if (band.hi_deg <= 60) {
      EXPECT_LT(band.median, 0.1) << band.lo_deg << "-" << band.hi_deg;
    }
  }
  for (const std::string& finding : noncentral.verdict.findings) {
    EXPECT_EQ(finding.find("systematic"), std::string::npos) << finding;
    EXPECT_EQ(finding.find("closer"), std::string::npos) << finding;
    EXPECT_EQ(finding.find("halves"), std::string::npos)
        << finding << "\n"
        << EvidenceText(noncentral.evidence);
  }
  EXPECT_NE(noncentral.verdict.kind, VerdictKind::kModelError)
      << noncentral.verdict.Line();

  // The same poses through the central lens: good.
  SyntheticScene central = scene;
  const SyntheticData clean = MakeSyntheticData(central);
  const Judged good = Judge(clean.views, CameraModelId::kKannalaBrandt,
                            truth.width, truth.height);
  ASSERT_TRUE(good.calibrated) << good.error;
  EXPECT_EQ(good.verdict.kind, VerdictKind::kGood) << good.verdict.Line();
}

// Cross-validation facts made by hand: bands of 100 samples at 10-degree
// steps whose difference is `ratio[b]` times the prediction of 0.05 px, and
// intrinsics whose chi-square is `chi2` for `dof` free parameters (dof 0:
// not judged).
Judged HandMadeHalves(const std::vector<double>& ratio, double chi2 = 0,
                      int dof = 0) {
  const Camera truth = sim::TruthFisheye190();
  const SyntheticData data = MakeSyntheticData(TiltedScene(truth, 24, 0.2, 3));
  Judged judged = Judge(data.views, truth.model, truth.width, truth.height);
  CrossValidation& cv = judged.evidence.cross_validation;
  cv.ok = true;
  cv.difference_bands.clear();
  cv.expected_bands.clear();
  cv.intrinsics_chi2 = chi2;
  cv.intrinsics_dof = dof;
  for (size_t b = 0; b < ratio.size(); ++b) {
    AngleBand e;
    e.lo_deg = 10.0 * b;
    e.hi_deg = e.lo_deg + 10;
    e.count = 100;
    e.median = 0.05;
    AngleBand d = e;
    d.median = ratio[b] * e.median;
    cv.expected_bands.push_back(e);
    cv.difference_bands.push_back(d);
  }
  judged.verdict = MakeVerdict(judged.result, judged.evidence,
                               EvidenceOptions(), VerdictOptions());
  return judged;
}

// Halves that differ by three times their prediction in every band (corner
// errors shared within views: the covariance is optimistic, the model is
// not wrong) are no model error; halves that agree near the axis and differ
// by four times at the rim are.
TEST(Verdict, HalvesJudgedAgainstTheirBestAgreeingBand) {
  ASSERT_TRUE(HandMadeHalves({1, 1, 1}).calibrated);
  EXPECT_EQ(HandMadeHalves({3, 3, 3, 3, 3}).verdict.kind, VerdictKind::kGood)
      << HandMadeHalves({3, 3, 3, 3, 3}).verdict.Line();
  const Judged rim = HandMadeHalves({1, 1, 1, 2, 4});
  EXPECT_EQ(rim.verdict.kind, VerdictKind::kModelError) << rim.verdict.Line();
  EXPECT_NE(rim.verdict.reason.find("40-50 deg"), std::string::npos)
      << rim.verdict.reason;
  // The same excess over a uniform factor of 3: 12 times at the rim.
  EXPECT_EQ(HandMadeHalves({3, 3, 3, 6, 12}).verdict.kind,
            VerdictKind::kModelError);
  // Too few bands to tell a uniform excess from a model error: unscaled.
  EXPECT_EQ(HandMadeHalves({3, 3}).verdict.kind, VerdictKind::kModelError);
  VerdictOptions options;
  options.halves_min_bands = -1;
  EXPECT_FALSE(options.Check());
}

// A band excess is a model error only when the intrinsics as a whole differ
// more than their covariances allow.
TEST(Verdict, HalvesBandExcessNeedsSignificantIntrinsics) {
  // Chi-square quantiles: the median of 10 degrees of freedom (9.34) is
  // about z = 0, the 0.999 quantile (29.59) z = 3.09.
  EXPECT_NEAR(ChiSquareZ(9.34, 10), 0.0, 0.05);
  EXPECT_NEAR(ChiSquareZ(29.59, 10), 3.09, 0.05);
  EXPECT_NEAR(ChiSquareZ(6.63, 1), 2.33, 0.1);
  EXPECT_EQ(ChiSquareZ(5, 0), 0);
  const Judged noise = HandMadeHalves({1, 1, 1, 2, 4}, 9.0, 10);
  for (const std::string& finding : noise.verdict.findings) {
    EXPECT_EQ(finding.find("halves"), std::string::npos) << finding;
  }
  const Judged real = HandMadeHalves({1, 1, 1, 2, 4}, 200.0, 10);
  EXPECT_EQ(real.verdict.kind, VerdictKind::kModelError) << real.verdict.Line();
  EXPECT_NE(real.verdict.reason.find("chi-square 200.0 for 10 parameters"),
            std::string::npos)
      << real.verdict.reason;
  VerdictOptions off;
  off.halves_min_z = 0;
  const Judged gate_off = HandMadeHalves({1, 1, 1, 2, 4}, 9.0, 10);
  EXPECT_EQ(
      MakeVerdict(gate_off.result, gate_off.evidence, EvidenceOptions(), off)
          .kind,
      VerdictKind::kModelError);
}

// Four views: the halves cannot be calibrated alone and the views are few.
TEST(Verdict, TooFewViewsIsInsufficientData) {
  const Camera truth = sim::TruthRadtan();
  const SyntheticData data = MakeSyntheticData(TiltedScene(truth, 4, 0.2, 7));
  const Judged judged =
      Judge(data.views, truth.model, truth.width, truth.height);
  ASSERT_TRUE(judged.calibrated) << judged.error;
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kInsufficientData)
      << judged.verdict.Line();
  EXPECT_FALSE(judged.evidence.cross_validation.ok);
}

// Gross outliers on 10 % of the corners: bad-detections.
TEST(Verdict, ManyOutliersAreBadDetections) {
  const Camera truth = sim::TruthRadtan();
  SyntheticScene scene = TiltedScene(truth, 24, 0.2, 13);
  scene.outlier_fraction = 0.1;
  const SyntheticData data = MakeSyntheticData(scene);
  const Judged judged =
      Judge(data.views, truth.model, truth.width, truth.height);
  ASSERT_TRUE(judged.calibrated) << judged.error;
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kBadDetections)
      << judged.verdict.Line();
}

// One view whose corners are off by about 1 px each (a blurred or badly
// detected view): a few views far worse than the rest.
TEST(Verdict, OneBadViewIsBadDetections) {
  const Camera truth = sim::TruthRadtan();
  SyntheticData data = MakeSyntheticData(TiltedScene(truth, 24, 0.2, 17));
  for (size_t i = 0; i < data.views[5].image_points.size(); ++i) {
    // Alternating 1 px shifts: no pose absorbs them.
    const double sign = i % 2 == 0 ? 1.0 : -1.0;
    data.views[5].image_points[i] += sign * Eigen::Vector2d(0.8, 0.6);
  }
  const Judged judged =
      Judge(data.views, truth.model, truth.width, truth.height);
  ASSERT_TRUE(judged.calibrated) << judged.error;
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kBadDetections)
      << judged.verdict.Line();
  // Named by its file (here the view's name), as the tables name it.
  EXPECT_NE(judged.verdict.reason.find(data.views[5].name + " ("),
            std::string::npos)
      << judged.verdict.reason << " used " << judged.result.view_used[5] << " "
      << judged.result.view_reason[5] << " rms " << judged.result.view_rms_px[5]
      << " outliers " << judged.result.num_outliers;
}

// One false corner in a view (12 px off, as a printed mark or a reflection
// gives): the outlier rejection takes it out and the view's other corners
// fit, so the verdict stays good and names the view in a note. An RMS over
// all of the view's corners would have called it a bad view.
TEST(Verdict, OneFalseCornerIsANoteNotABadView) {
  const Camera truth = sim::TruthRadtan();
  SyntheticData data = MakeSyntheticData(TiltedScene(truth, 24, 0.1, 23));
  CalibrationView& view = data.views[3];
  view.image_points[view.image_points.size() / 2] += Eigen::Vector2d(9, -8);
  const Judged judged =
      Judge(data.views, truth.model, truth.width, truth.height);
  ASSERT_TRUE(judged.calibrated) << judged.error;
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kGood) << judged.verdict.Line();
  for (const std::string& finding : judged.verdict.findings) {
    EXPECT_EQ(finding.find(view.name), std::string::npos) << finding;
  }
  ASSERT_EQ(judged.verdict.notes.size(), 1u);
  const std::string& note = judged.verdict.notes[0];
  EXPECT_NE(
      note.find(view.name + " (1 of " +
                std::to_string(view.image_points.size()) + " corners rejected"),
      std::string::npos)
      << note;
  // The old rule's figure: the view's RMS over all corners, the false one
  // included, stands out against the median view.
  const std::vector<Eigen::Vector2d>& residuals = judged.result.residuals[3];
  double sum2 = 0;
  for (const Eigen::Vector2d& r : residuals) sum2 += r.squaredNorm();
  EXPECT_GT(std::sqrt(sum2 / (2.0 * residuals.size())),
            VerdictOptions().view_rms_factor * 0.1);
  // The per-view judgement the report's table and chart use says the same:
  // this view handled, every other view fits.
  ASSERT_EQ(judged.verdict.views.size(), data.views.size());
  for (size_t v = 0; v < data.views.size(); ++v) {
    EXPECT_EQ(judged.verdict.views[v].standing,
              v == 3 ? ViewStanding::kHandled : ViewStanding::kFits)
        << "view " << v;
  }
  EXPECT_EQ(judged.verdict.views[3].rejected, 1);
  EXPECT_GT(judged.verdict.views[3].worst_rejected_px, 8.0);
  EXPECT_NEAR(judged.verdict.view_rms_limit_px,
              std::max(VerdictOptions().view_rms_factor *
                           judged.verdict.median_view_rms_px,
                       VerdictOptions().view_rms_floor_px),
              1e-12);
}

// A third of a view's corners off by 6-8 px (a mislabelled stretch of the
// board): the view stands out by its rejected fraction although its
// inliers fit and the rejected corners are under 2 % of all.
TEST(Verdict, AViewWithManyRejectedCornersStandsOut) {
  const Camera truth = sim::TruthRadtan();
  SyntheticData data = MakeSyntheticData(TiltedScene(truth, 24, 0.1, 29));
  CalibrationView& view = data.views[7];
  for (size_t i = 0; i < view.image_points.size(); i += 3) {
    const double sign = i % 2 == 0 ? 1.0 : -1.0;
    view.image_points[i] += sign * Eigen::Vector2d(6, 4);
  }
  const Judged judged =
      Judge(data.views, truth.model, truth.width, truth.height);
  ASSERT_TRUE(judged.calibrated) << judged.error;
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kBadDetections)
      << judged.verdict.Line();
  EXPECT_NE(judged.verdict.reason.find(view.name + " ("), std::string::npos)
      << judged.verdict.reason;
  EXPECT_NE(judged.verdict.reason.find("corners rejected"), std::string::npos)
      << judged.verdict.reason;
  // Exactly the view the reason names stands out in the per-view judgement.
  ASSERT_EQ(judged.verdict.views.size(), data.views.size());
  for (size_t v = 0; v < data.views.size(); ++v) {
    const ViewStanding standing = judged.verdict.views[v].standing;
    EXPECT_EQ(standing == ViewStanding::kStandsOut, v == 7) << "view " << v;
  }
  EXPECT_NE(judged.verdict.reason.find(judged.verdict.views[7].why),
            std::string::npos)
      << judged.verdict.views[7].why;
}

// The rational model on a lens without the rational terms: its
// denominator coefficients are undetermined one by one while the projection
// is well determined; the verdict says so in a note and does not change.
// The radtan model on the same views needs no such note.
TEST(Verdict, UndeterminedCoefficientsAreSaidInANote) {
  const Camera truth = sim::TruthRadtan();
  const SyntheticData data = MakeSyntheticData(TiltedScene(truth, 24, 0.2, 31));
  const Judged rational = Judge(data.views, CameraModelId::kPinholeRational,
                                truth.width, truth.height);
  ASSERT_TRUE(rational.calibrated) << rational.error;
  std::string notes;
  for (const std::string& note : rational.verdict.notes) notes += note + "\n";
  EXPECT_NE(notes.find("coefficients undetermined one by one: "),
            std::string::npos)
      << notes << rational.verdict.Line();
  // Each coefficient named there is one whose sigma exceeds its value.
  const std::vector<std::string> names =
      CameraModelParamNames(CameraModelId::kPinholeRational);
  for (size_t k = kDistortionBegin; k < names.size(); ++k) {
    const bool named = notes.find(names[k] + " (") != std::string::npos;
    const bool undetermined =
        rational.result.param_stddev[k] >
            std::abs(rational.result.camera.params[k]) &&
        rational.result.param_stddev[k] >
            VerdictOptions().min_undetermined_distortion_stddev;
    EXPECT_EQ(named, undetermined) << names[k];
  }
  const Judged radtan =
      Judge(data.views, truth.model, truth.width, truth.height);
  ASSERT_TRUE(radtan.calibrated) << radtan.error;
  for (const std::string& note : radtan.verdict.notes) {
    EXPECT_EQ(note.find("undetermined"), std::string::npos) << note;
  }
}

}  // namespace
}  // namespace puzzlecal
