#include "evidence/evidence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "sim/synthetic_views.h"
#include "tests/support/draws.h"

namespace puzzlecal {
namespace {

using sim::MakeSyntheticData;
using sim::SyntheticData;
using sim::SyntheticScene;

SyntheticScene Scene(const Camera& camera, int num_views, double noise_px,
                     unsigned seed) {
  SyntheticScene scene;
  scene.camera = camera;
  scene.num_views = num_views;
  scene.noise_px = noise_px;
  scene.seed = seed;
  scene.max_direction_deg = 35;
  return scene;
}

CalibrationResult CalibrateOrDie(const std::vector<CalibrationView>& views,
                                 const Camera& truth) {
  CalibrationResult result;
  std::string error;
  EXPECT_TRUE(Calibrate(views, truth.model, truth.width, truth.height,
                        CalibrationOptions(), &result, &error))
      << error;
  return result;
}

// The views of `data` with fresh Gaussian noise on the exact corners.
std::vector<CalibrationView> Redraw(const SyntheticData& data, double noise_px,
                                    unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, noise_px);
  std::vector<CalibrationView> views = data.views;
  for (size_t v = 0; v < views.size(); ++v) {
    for (size_t i = 0; i < views[v].image_points.size(); ++i) {
      views[v].image_points[i] =
          data.exact[v][i] +
          testing_draws::DrawVector2d([&] { return normal(rng); });
    }
  }
  return views;
}

TEST(EvidenceOptions, CheckRejectsBadValues) {
  EvidenceOptions options;
  EXPECT_TRUE(options.Check());
  options.grid_step_px = 0;
  EXPECT_FALSE(options.Check());
  options = EvidenceOptions();
  options.band_width_deg = 0;
  EXPECT_FALSE(options.Check());
  options = EvidenceOptions();
  options.report_angles_deg = {200};
  EXPECT_FALSE(options.Check());
  for (int splits : {0, 17}) {
    options = EvidenceOptions();
    options.cross_validation_splits = splits;
    std::string why;
    EXPECT_FALSE(options.Check(&why)) << splits;
    EXPECT_NE(why.find("cross_validation_splits"), std::string::npos) << why;
  }
}

// The map's samples and their field angles follow the camera.
TEST(ProjectionUncertainty, MapCoversTheImage) {
  const Camera truth = sim::TruthRadtan();
  const SyntheticData data = MakeSyntheticData(Scene(truth, 20, 0.2, 3));
  const CalibrationResult result = CalibrateOrDie(data.views, truth);
  ASSERT_TRUE(result.covariance_ok);
  EvidenceOptions options;
  const ProjectionUncertainty u =
      ComputeProjectionUncertainty(result, 60.0, options);
  ASSERT_TRUE(u.ok);
  // 1280 x 960 with at least 10000 samples: an 11 px grid.
  const int step = GridStep(result.camera, options);
  EXPECT_EQ(step, 11);
  EXPECT_EQ(u.sigma_px.step_px, step);
  EXPECT_EQ(u.sigma_px.cols, (truth.width - 1 + step - 1) / step + 1);
  EXPECT_EQ(u.sigma_px.rows, (truth.height - 1 + step - 1) / step + 1);
  EXPECT_GE(u.sigma_px.cols * u.sigma_px.rows, options.grid_min_samples);
  // Without the minimum, the 40 px grid.
  options.grid_min_samples = 0;
  EXPECT_EQ(GridStep(result.camera, options), 40);
  ASSERT_FALSE(u.points.empty());
  EXPECT_EQ(u.points[0].label, "centre");
  EXPECT_TRUE(u.points[0].in_image);
  EXPECT_GT(u.points[0].sigma_px, 0);
  // The image corners of this lens see about 50 degrees: 90 is not in it.
  EXPECT_FALSE(u.points[3].in_image) << u.points[3].label;
}

// Four times the views: about half the uncertainty everywhere.
TEST(ProjectionUncertainty, ShrinksWithMoreViews) {
  const Camera truth = sim::TruthFisheye190();
  const SyntheticData few = MakeSyntheticData(Scene(truth, 10, 0.2, 5));
  const SyntheticData many = MakeSyntheticData(Scene(truth, 40, 0.2, 5));
  const CalibrationResult few_result = CalibrateOrDie(few.views, truth);
  const CalibrationResult many_result = CalibrateOrDie(many.views, truth);
  EvidenceOptions options;
  const ProjectionUncertainty u_few =
      ComputeProjectionUncertainty(few_result, 60.0, options);
  const ProjectionUncertainty u_many =
      ComputeProjectionUncertainty(many_result, 60.0, options);
  ASSERT_TRUE(u_few.ok && u_many.ok);
  ASSERT_EQ(u_few.sigma_px.values.size(), u_many.sigma_px.values.size());
  int compared = 0, smaller = 0;
  for (size_t k = 0; k < u_few.sigma_px.values.size(); ++k) {
    const double a = u_few.sigma_px.values[k], b = u_many.sigma_px.values[k];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    ++compared;
    smaller += b < 0.8 * a;
  }
  ASSERT_GT(compared, 100);
  EXPECT_GT(smaller, 0.95 * compared);
  EXPECT_LT(u_many.points[0].sigma_px, 0.75 * u_few.points[0].sigma_px);
}

// The predicted 1-sigma of fx and of the projection at a few pixels match
// the spread over noise re-draws of the same poses within a factor 1.6.
TEST(ProjectionUncertainty, MatchesEmpiricalSpread) {
  const Camera truth = sim::TruthRadtan();
  constexpr double kNoise = 0.3;
  const SyntheticData data = MakeSyntheticData(Scene(truth, 15, 0.0, 11));
  const std::vector<Eigen::Vector2d> pixels = {
      {640, 480}, {1000, 480}, {1200, 900}, {100, 100}};
  std::vector<Eigen::Vector3d> rays(pixels.size());
  for (size_t p = 0; p < pixels.size(); ++p) {
    ASSERT_TRUE(truth.Unproject(pixels[p], &rays[p]).converged);
  }
  constexpr int kDraws = 30;
  std::vector<double> fx;
  std::vector<std::vector<Eigen::Vector2d>> projected(pixels.size());
  double predicted_fx = 0;
  std::vector<double> predicted(pixels.size(), 0.0);
  for (int draw = 0; draw < kDraws; ++draw) {
    const CalibrationResult result =
        CalibrateOrDie(Redraw(data, kNoise, 100 + draw), truth);
    ASSERT_TRUE(result.covariance_ok);
    fx.push_back(result.camera.params[0]);
    predicted_fx += result.param_stddev[0] / kDraws;
    for (size_t p = 0; p < pixels.size(); ++p) {
      Eigen::Vector2d pixel;
      ASSERT_TRUE(result.camera.Project(rays[p], &pixel));
      projected[p].push_back(pixel);
      Eigen::Matrix2d cov;
      ASSERT_TRUE(ProjectionCovariance(result.camera, result.covariance,
                                       pixels[p], &cov));
      predicted[p] += std::sqrt(0.5 * cov.trace()) / kDraws;
    }
  }
  auto stddev = [](const std::vector<double>& x) {
    double mean = 0;
    for (double v : x) mean += v / x.size();
    double ss = 0;
    for (double v : x) ss += (v - mean) * (v - mean);
    return std::sqrt(ss / (x.size() - 1));
  };
  const double empirical_fx = stddev(fx);
  EXPECT_GT(predicted_fx, empirical_fx / 1.6);
  EXPECT_LT(predicted_fx, empirical_fx * 1.6);
  for (size_t p = 0; p < pixels.size(); ++p) {
    std::vector<double> xs, ys;
    for (const Eigen::Vector2d& q : projected[p]) {
      xs.push_back(q.x());
      ys.push_back(q.y());
    }
    const double sx = stddev(xs), sy = stddev(ys);
    const double empirical = std::sqrt(0.5 * (sx * sx + sy * sy));
    EXPECT_GT(predicted[p], empirical / 1.6) << "pixel " << p;
    EXPECT_LT(predicted[p], empirical * 1.6) << "pixel " << p;
  }
}

// The same with the rotation gauge removed: the spread of the projections
// over re-draws, after taking out the best-fit common rotation of each
// draw (linearised: the component along d pixel / d rotation over the
// observed field), matches the predicted map within a factor 1.6.
TEST(ProjectionUncertainty, RotationRemovedMatchesEmpiricalSpread) {
  const Camera truth = sim::TruthFisheye190();
  constexpr double kNoise = 0.3;
  SyntheticScene scene = Scene(truth, 15, 0.0, 13);
  const SyntheticData data = MakeSyntheticData(scene);
  constexpr double kMaxAngle = 50;
  constexpr int kStep = 100;
  // Grid pixels within the field and their true rays.
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> rays;
  for (int y = 0; y < truth.height; y += kStep) {
    for (int x = 0; x < truth.width; x += kStep) {
      Eigen::Vector3d ray;
      if (!truth.Unproject(Eigen::Vector2d(x, y), &ray).converged) continue;
      if (std::atan2(ray.head<2>().norm(), ray.z()) * 180 / M_PI > kMaxAngle) {
        continue;
      }
      pixels.emplace_back(x, y);
      rays.push_back(ray);
    }
  }
  const int n = static_cast<int>(pixels.size());
  ASSERT_GT(n, 30);
  // d pixel / d rotation at each pixel (numeric, through the truth).
  Eigen::MatrixXd g(2 * n, 3);
  for (int k = 0; k < n; ++k) {
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d omega = Eigen::Vector3d::Zero();
      omega[a] = 1e-6;
      Eigen::Vector2d plus, minus;
      ASSERT_TRUE(truth.Project(rays[k] + omega.cross(rays[k]), &plus));
      ASSERT_TRUE(truth.Project(rays[k] - omega.cross(rays[k]), &minus));
      g.block<2, 1>(2 * k, a) = (plus - minus) / 2e-6;
    }
  }
  const Eigen::MatrixXd remove =
      Eigen::MatrixXd::Identity(2 * n, 2 * n) -
      g * (g.transpose() * g).inverse() * g.transpose();
  constexpr int kDraws = 30;
  Eigen::MatrixXd projected(2 * n, kDraws);
  Eigen::VectorXd predicted = Eigen::VectorXd::Zero(n);
  for (int draw = 0; draw < kDraws; ++draw) {
    const CalibrationResult result =
        CalibrateOrDie(Redraw(data, kNoise, 300 + draw), truth);
    ASSERT_TRUE(result.covariance_ok);
    const Eigen::MatrixXd gauge =
        RotationGauge(result.camera, kStep, kMaxAngle);
    ASSERT_EQ(gauge.rows(), 3);
    for (int k = 0; k < n; ++k) {
      Eigen::Vector2d pixel;
      ASSERT_TRUE(result.camera.Project(rays[k], &pixel));
      projected.block<2, 1>(2 * k, draw) = pixel;
      Eigen::Matrix2d cov;
      ASSERT_TRUE(ProjectionCovariance(result.camera, result.covariance,
                                       pixels[k], &cov, &gauge));
      predicted[k] += std::sqrt(0.5 * cov.trace()) / kDraws;
    }
  }
  const Eigen::VectorXd mean = projected.rowwise().mean();
  const Eigen::MatrixXd deviations = remove * (projected.colwise() - mean);
  int checked = 0;
  for (int k = 0; k < n; ++k) {
    const double var = (deviations.row(2 * k).squaredNorm() +
                        deviations.row(2 * k + 1).squaredNorm()) /
                       (2.0 * (kDraws - 1));
    const double empirical = std::sqrt(var);
    EXPECT_GT(predicted[k], empirical / 1.6)
        << "pixel " << pixels[k].transpose();
    EXPECT_LT(predicted[k], empirical * 1.6)
        << "pixel " << pixels[k].transpose();
    ++checked;
  }
  EXPECT_EQ(checked, n);
}

// Two halves of clean data agree within what their uncertainty predicts.
TEST(CrossValidation, HalvesAgreeOnCleanData) {
  for (const Camera& truth : {sim::TruthRadtan(), sim::TruthFisheye190()}) {
    const SyntheticData data = MakeSyntheticData(Scene(truth, 30, 0.2, 21));
    const CalibrationResult result = CalibrateOrDie(data.views, truth);
    const EvidenceOptions options;
    const SystematicResiduals residuals =
        ComputeSystematicResiduals(data.views, result, options);
    const CrossValidation cv =
        CrossValidate(data.views, result, CalibrationOptions(),
                      residuals.max_angle_deg, options);
    ASSERT_TRUE(cv.ok) << cv.error;
    EXPECT_EQ(cv.views_a, 15);
    EXPECT_EQ(cv.views_b, 15);
    int judged = 0;
    for (size_t b = 0; b < cv.difference_bands.size(); ++b) {
      if (cv.difference_bands[b].count < options.min_bin_count) continue;
      ++judged;
      // Two-sided: the predicted difference (rotation gauge removed) is
      // neither far too small nor far too large.
      EXPECT_GT(cv.difference_bands[b].median,
                0.3 * cv.expected_bands[b].median)
          << CameraModelName(truth.model) << " band "
          << cv.difference_bands[b].lo_deg;
      EXPECT_LT(cv.difference_bands[b].median,
                2.0 * cv.expected_bands[b].median)
          << CameraModelName(truth.model) << " band "
          << cv.difference_bands[b].lo_deg;
    }
    EXPECT_GE(judged, 2);
  }
}

// Several splits (EvidenceOptions::cross_validation_splits) order the views
// by their contents: the same views in another order give the same halves
// and figures, and on clean data the halves still agree within their
// predicted difference.
TEST(CrossValidation, SeveralSplitsDoNotDependOnTheViewOrder) {
  const Camera truth = sim::TruthRadtan();
  const SyntheticData data = MakeSyntheticData(Scene(truth, 24, 0.2, 33));
  std::vector<CalibrationView> shuffled = data.views;
  std::mt19937 rng(5);
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  ASSERT_NE(shuffled.front().name, data.views.front().name);
  EvidenceOptions options;
  options.cross_validation_splits = 5;
  CrossValidation cv[2];
  const std::vector<CalibrationView>* orders[2] = {&data.views, &shuffled};
  for (int k = 0; k < 2; ++k) {
    const CalibrationResult result = CalibrateOrDie(*orders[k], truth);
    const SystematicResiduals residuals =
        ComputeSystematicResiduals(*orders[k], result, options);
    cv[k] = CrossValidate(*orders[k], result, CalibrationOptions(),
                          residuals.max_angle_deg, options);
    ASSERT_TRUE(cv[k].ok) << cv[k].error;
    EXPECT_EQ(cv[k].splits, 5);
    EXPECT_EQ(cv[k].splits_tried, 5);
  }
  EXPECT_EQ(cv[0].views_a, cv[1].views_a);
  EXPECT_NEAR(cv[0].intrinsics_chi2, cv[1].intrinsics_chi2,
              1e-3 * (1 + cv[0].intrinsics_chi2));
  ASSERT_EQ(cv[0].difference_bands.size(), cv[1].difference_bands.size());
  int judged = 0;
  for (size_t b = 0; b < cv[0].difference_bands.size(); ++b) {
    const AngleBand& d = cv[0].difference_bands[b];
    const AngleBand& e = cv[0].expected_bands[b];
    // Another split would differ by about the figure itself.
    EXPECT_NEAR(d.median, cv[1].difference_bands[b].median, 0.01 * e.median)
        << d.lo_deg;
    EXPECT_NEAR(e.median, cv[1].expected_bands[b].median, 0.01 * e.median)
        << d.lo_deg;
    if (d.count < options.min_bin_count) continue;
    ++judged;
    EXPECT_GT(d.median, 0.3 * e.median) << d.lo_deg;
    EXPECT_LT(d.median, 2.0 * e.median) << d.lo_deg;
  }
  EXPECT_GE(judged, 2);
}

// Field-angle bins cover 0 to the widest corner; a last sliver narrower than
// a quarter of the bin width (here the one corner at 50.5 deg) joins the bin
// before it instead of standing alone with no usable statistics.
TEST(SystematicResiduals, AngleBinsLeaveNoSliverAtTheWidestCorner) {
  CalibrationResult result;
  result.camera = sim::TruthRadtan();
  CalibrationView view;
  std::vector<Eigen::Vector2d> residuals;
  for (double angle_deg : {5.0, 15.0, 25.0, 35.0, 45.0, 47.0, 50.5}) {
    const double t = std::tan(angle_deg * M_PI / 180.0);
    view.board_points.emplace_back(t, 0.0, 1.0);
    view.image_points.emplace_back(result.camera.params[2] + 100 * t,
                                   result.camera.params[3] + 20 * t);
    residuals.emplace_back(0.1, 0.0);
  }
  result.view_used = {true};
  result.residuals = {residuals};
  result.inlier = {std::vector<bool>(residuals.size(), true)};
  result.cam_from_board = {Eigen::Isometry3d::Identity()};
  EvidenceOptions options;
  options.band_width_deg = 10;
  const SystematicResiduals bins =
      ComputeSystematicResiduals({view}, result, options);
  ASSERT_EQ(bins.by_angle.size(), 5u);
  int total = 0;
  for (size_t b = 0; b < bins.by_angle.size(); ++b) {
    EXPECT_DOUBLE_EQ(bins.by_angle[b].lo, 10.0 * b);
    total += bins.by_angle[b].count;
  }
  EXPECT_NEAR(bins.by_angle.back().hi, 50.5, 1e-9);
  EXPECT_EQ(bins.by_angle.back().count, 3);  // 45, 47 and 50.5 deg
  EXPECT_EQ(total, 7);
  // A wide last bin stays: up to 53 deg there are six bins.
  const double t = std::tan(53.0 * M_PI / 180.0);
  view.board_points.back() = Eigen::Vector3d(t, 0.0, 1.0);
  const SystematicResiduals six =
      ComputeSystematicResiduals({view}, result, options);
  ASSERT_EQ(six.by_angle.size(), 6u);
  EXPECT_EQ(six.by_angle.back().count, 1);
}

// Clean data leave residual means within a few standard errors of zero; a
// wrong model leaves them far from it.
TEST(SystematicResiduals, ZeroForTheRightModelNotForAWrongOne) {
  const Camera truth = sim::TruthFisheye190();
  SyntheticScene scene = Scene(truth, 30, 0.2, 31);
  scene.max_corner_angle_deg = 70;
  scene.min_visible_fraction = 0.5;
  scene.max_direction_deg = 55;
  const SyntheticData data = MakeSyntheticData(scene);
  const EvidenceOptions options;
  const CalibrationResult right = CalibrateOrDie(data.views, truth);
  const SystematicResiduals good =
      ComputeSystematicResiduals(data.views, right, options);
  ASSERT_FALSE(good.by_angle.empty());
  ASSERT_EQ(static_cast<int>(good.by_distance.size()), options.distance_bins);
  int total = 0;
  for (const ResidualBin& bin : good.by_angle) {
    total += bin.count;
    if (bin.count < options.min_bin_count) continue;
    EXPECT_LT(std::abs(bin.mean_radial_px), 5 * bin.se_radial_px + 0.01)
        << bin.lo;
    EXPECT_LT(std::abs(bin.mean_tangential_px), 5 * bin.se_tangential_px + 0.01)
        << bin.lo;
    // The standard error is noise / sqrt(n).
    EXPECT_NEAR(bin.se_radial_px, 0.2 / std::sqrt(bin.count),
                0.5 * 0.2 / std::sqrt(bin.count));
  }
  EXPECT_EQ(total, right.num_corners_used);

  CalibrationOptions options_wrong;
  options_wrong.max_rms_px = 100;
  CalibrationResult wrong;
  std::string error;
  ASSERT_TRUE(Calibrate(data.views, CameraModelId::kPinholeRadtan, truth.width,
                        truth.height, options_wrong, &wrong, &error))
      << error;
  const SystematicResiduals bad =
      ComputeSystematicResiduals(data.views, wrong, options);
  double worst = 0;
  for (const ResidualBin& bin : bad.by_angle) {
    if (bin.count >= options.min_bin_count) {
      worst = std::max(worst, std::abs(bin.mean_radial_px) / bin.se_radial_px);
    }
  }
  EXPECT_GT(worst, 10);
}

}  // namespace
}  // namespace puzzlecal

namespace puzzlecal {
namespace {

// A last band cut short by the widest angle seen is labelled to a tenth of
// a degree ("20-20.4 deg", not "20-20 deg").
TEST(BandLabel, ShortLastBandKeepsItsEnd) {
  AngleBand band;
  band.lo_deg = 10;
  band.hi_deg = 20;
  EXPECT_EQ(BandLabel(band), "10-20 deg");
  band.lo_deg = 20;
  band.hi_deg = 20.4;
  EXPECT_EQ(BandLabel(band), "20-20.4 deg");
  EXPECT_EQ(AngleRangeLabel(80, 92.7), "80-93 deg");
}

}  // namespace
}  // namespace puzzlecal
