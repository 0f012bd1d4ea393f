// kannala-brandt-noncentral: the model against its own definition (the ray
// with its origin on the axis), against kannala-brandt and
// cv::fisheye::projectPoints in the far field, its Jet derivatives, and
// calibrations on the truth of non-central renders (sim/).

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <random>
#include <vector>

#include "calib/calibrate.h"
#include "camera/camera_models.h"
#include "sim/render.h"
#include "sim/scenes.h"
#include "tests/support/draws.h"

namespace puzzlecal {
namespace {

using Model = KannalaBrandtNoncentralModel;
constexpr double kDegree = M_PI / 180.0;

// A deltille-like 1600 x 1200 fisheye with the pupil shift measured on it.
const std::vector<double> kParams = {296.5,  296.1,  801.7,   598.4,   0.021,
                                     -0.006, 0.0012, -0.0002, 0.95e-3, 0.31e-3};

// Points at field angles up to max_angle and distances in [near, far]
// (metres, from the camera origin), log-uniform.
std::vector<Eigen::Vector3d> RandomPoints(double max_angle, double near,
                                          double far, int count,
                                          unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const double theta = max_angle * std::sqrt(uniform(rng));
    const double phi = 2 * M_PI * uniform(rng);
    const double depth = near * std::pow(far / near, uniform(rng));
    points.emplace_back(depth * std::sin(theta) * std::cos(phi),
                        depth * std::sin(theta) * std::sin(phi),
                        depth * std::cos(theta));
  }
  return points;
}

// The ray angle through a point by bisection on h(theta) = theta -
// atan2(r, z - z0(theta)) (increasing where a ray reaches the point): an
// independent reference for the fixed Newton count.
double BisectTheta(const double* params, double r, double z) {
  double lo = 0, hi = M_PI;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    const double h =
        mid - std::atan2(r, z - Model::PupilZ(params + kPupilBegin, mid));
    (h > 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(NoncentralTest, FixedNewtonCountConvergesCloseUpTo110Degrees) {
  // Twice the measured pupil shift, so the count has margin.
  std::vector<double> params = kParams;
  params[8] *= 2;
  params[9] *= 2;
  double worst = 0;
  for (double distance : {0.03, 0.04, 0.05, 0.1, 0.3, 1.0, 100.0}) {
    for (double deg = 1; deg <= 110; deg += 1) {
      const double r = distance * std::sin(deg * kDegree);
      const double z = distance * std::cos(deg * kDegree);
      double residual, slope;
      const double theta = Model::SolveTheta(params.data() + kPupilBegin, r, z,
                                             &residual, &slope);
      ASSERT_GT(slope, 0) << distance << " m, " << deg << " deg";
      EXPECT_LT(residual, 1e-13) << distance << " m, " << deg << " deg";
      worst =
          std::max(worst, std::abs(theta - BisectTheta(params.data(), r, z)));
    }
  }
  EXPECT_LT(worst, 1e-13);
  // The measured shift from 2 cm (the deltille photos' closest corners are
  // 2.4 cm away).
  for (double deg = 1; deg <= 110; deg += 1) {
    const double r = 0.02 * std::sin(deg * kDegree);
    const double z = 0.02 * std::cos(deg * kDegree);
    double residual, slope;
    const double theta = Model::SolveTheta(kParams.data() + kPupilBegin, r, z,
                                           &residual, &slope);
    ASSERT_GT(slope, 0) << deg << " deg";
    EXPECT_LT(residual, 1e-13) << deg << " deg";
    EXPECT_LT(std::abs(theta - BisectTheta(kParams.data(), r, z)), 1e-13);
  }
}

// Project then UnprojectRay: the point lies on the returned ray (its
// origin on the axis at z0(theta)); UnprojectRay then Project returns the
// pixel for any point along the ray.
TEST(NoncentralTest, ProjectAndUnprojectRayRoundTrip) {
  for (const Eigen::Vector3d& point :
       RandomPoints(110 * kDegree, 0.03, 20.0, 2000, 3)) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ProjectPoint(Model::kId, kParams.data(), point, &pixel));
    ViewingRay ray;
    ASSERT_TRUE(
        UnprojectPixelToRay(Model::kId, kParams.data(), pixel, &ray).converged);
    EXPECT_EQ(ray.origin.x(), 0.0);
    EXPECT_EQ(ray.origin.y(), 0.0);
    const Eigen::Vector3d along = point - ray.origin;
    EXPECT_GT(along.dot(ray.direction), 0);
    EXPECT_LT(along.cross(ray.direction).norm(), 1e-9 * along.norm());
    for (double s : {0.05, 0.5, 50.0}) {
      Eigen::Vector2d back;
      ASSERT_TRUE(ProjectPoint(Model::kId, kParams.data(),
                               ray.origin + s * ray.direction, &back));
      EXPECT_LT((back - pixel).norm(), 1e-7) << s;
    }
  }
  // The direction-only Unproject returns the same (far-field) direction.
  const Eigen::Vector2d pixel(1203.4, 277.9);
  ViewingRay ray;
  Eigen::Vector3d direction;
  UnprojectPixelToRay(Model::kId, kParams.data(), pixel, &ray);
  UnprojectPixel(Model::kId, kParams.data(), pixel, &direction);
  EXPECT_EQ(direction, ray.direction);
  EXPECT_GT(ray.origin.z(), 0.5e-3);  // about 1 mm at this field angle
}

TEST(NoncentralTest, EqualsKannalaBrandtWithoutPupilShiftAndInTheFarField) {
  std::vector<double> central(kParams.begin(), kParams.begin() + 8);
  std::vector<double> zero_shift = kParams;
  zero_shift[8] = zero_shift[9] = 0;
  for (const Eigen::Vector3d& point :
       RandomPoints(120 * kDegree, 0.03, 10.0, 500, 5)) {
    Eigen::Vector2d a, b;
    ASSERT_TRUE(ProjectPoint(Model::kId, zero_shift.data(), point, &a));
    ASSERT_TRUE(
        ProjectPoint(CameraModelId::kKannalaBrandt, central.data(), point, &b));
    EXPECT_LT((a - b).norm(), 1e-9);
  }
  // With the shift the difference falls as 1 / distance.
  Camera camera;
  camera.model = Model::kId;
  camera.params = kParams;
  const Camera far = FarFieldCamera(camera);
  ASSERT_EQ(far.model, CameraModelId::kKannalaBrandt);
  ASSERT_EQ(far.params, central);
  const Eigen::Vector3d direction =
      Eigen::Vector3d(std::sin(100 * kDegree), 0, std::cos(100 * kDegree));
  // To first order the pixels differ by fx * theta_d'(theta) * z0(theta) *
  // sin(theta) / distance.
  const double theta = 100 * kDegree, h = 1e-6;
  const double slope =
      (KannalaBrandtModel::DistortTheta(kParams.data(), theta + h) -
       KannalaBrandtModel::DistortTheta(kParams.data(), theta - h)) /
      (2 * h);
  const double first_order =
      kParams[0] * slope * Model::PupilZ(kParams.data() + kPupilBegin, theta) *
      std::sin(theta);
  double previous = 0;
  for (double distance : {1e5, 1e3, 10.0, 0.3}) {
    Eigen::Vector2d a, b;
    ASSERT_TRUE(camera.Project(distance * direction, &a));
    ASSERT_TRUE(far.Project(distance * direction, &b));
    const double difference = (a - b).norm();
    EXPECT_NEAR(difference * distance, first_order,
                (distance > 1 ? 1e-3 : 0.05) * first_order)
        << distance;
    EXPECT_GT(difference, previous);
    previous = difference;
  }
}

TEST(NoncentralTest, FarFieldMatchesCvFisheyeProjectPoints) {
  std::vector<cv::Point3d> cv_points;
  std::vector<Eigen::Vector2d> ours;
  for (const Eigen::Vector3d& point :
       RandomPoints(89 * kDegree, 1e6, 1e7, 500, 7)) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ProjectPoint(Model::kId, kParams.data(), point, &pixel));
    ours.push_back(pixel);
    cv_points.emplace_back(point.x(), point.y(), point.z());
  }
  const cv::Mat k = (cv::Mat_<double>(3, 3) << kParams[0], 0, kParams[2], 0,
                     kParams[1], kParams[3], 0, 0, 1);
  const cv::Mat d = (cv::Mat_<double>(1, 4) << kParams[4], kParams[5],
                     kParams[6], kParams[7]);
  std::vector<cv::Point2d> theirs;
  cv::fisheye::projectPoints(cv_points, theirs, cv::Vec3d(0, 0, 0),
                             cv::Vec3d(0, 0, 0), k, d);
  ASSERT_EQ(theirs.size(), ours.size());
  for (size_t i = 0; i < ours.size(); ++i) {
    // fx * z0 / distance < 3e-6 px here; OpenCV's own rounding near 89
    // degrees (it divides by z) dominates.
    EXPECT_LT((ours[i] - Eigen::Vector2d(theirs[i].x, theirs[i].y)).norm(),
              1e-5)
        << i;
  }
}

// Jet derivatives against central differences, close up and far, up to 110
// degrees, for all ten parameters and the point.
TEST(NoncentralTest, JetDerivativesMatchFiniteDifferencesCloseUp) {
  constexpr int kN = Model::kNumParams + 3;
  using Jet = ceres::Jet<double, kN>;
  for (const Eigen::Vector3d& point :
       RandomPoints(110 * kDegree, 0.03, 3.0, 100, 9)) {
    Jet jet_params[Model::kNumParams], jet_point[3], jet_pixel[2];
    for (int k = 0; k < Model::kNumParams; ++k) {
      jet_params[k] = Jet(kParams[k], k);
    }
    for (int k = 0; k < 3; ++k)
      jet_point[k] = Jet(point[k], Model::kNumParams + k);
    ASSERT_TRUE(Model::Project(jet_params, jet_point, jet_pixel));
    double value[2];
    ASSERT_TRUE(Model::Project(kParams.data(), point.data(), value));
    // (Jet division multiplies by the inverse: last-bit differences.)
    EXPECT_NEAR(jet_pixel[0].a, value[0], 1e-10);
    EXPECT_NEAR(jet_pixel[1].a, value[1], 1e-10);
    for (int k = 0; k < kN; ++k) {
      std::vector<double> p_plus = kParams, p_minus = kParams;
      Eigen::Vector3d x_plus = point, x_minus = point;
      double step;
      if (k < Model::kNumParams) {
        // e1, e2 are about a millimetre: a step of 0.1 um.
        step = k >= kPupilBegin ? 1e-7
                                : 1e-6 * std::max(1.0, std::abs(kParams[k]));
        p_plus[k] += step;
        p_minus[k] -= step;
      } else {
        step = 1e-6 * point.norm();
        x_plus[k - Model::kNumParams] += step;
        x_minus[k - Model::kNumParams] -= step;
      }
      double plus[2], minus[2];
      ASSERT_TRUE(Model::Project(p_plus.data(), x_plus.data(), plus));
      ASSERT_TRUE(Model::Project(p_minus.data(), x_minus.data(), minus));
      for (int c = 0; c < 2; ++c) {
        const double numeric = (plus[c] - minus[c]) / (2 * step);
        EXPECT_NEAR(jet_pixel[c].v[k], numeric,
                    1e-5 * std::max(1.0, std::abs(numeric)))
            << "derivative " << k << " coordinate " << c << " at "
            << point.transpose();
      }
    }
  }
}

TEST(NoncentralTest, PointsNoSingleRayReachesDoNotProject) {
  // A point on the axis behind the pupil, and one at the lens' caustic
  // (twice the pupil shift seen from 2 cm at 66 degrees: h' < 0 there).
  std::vector<double> params = kParams;
  Eigen::Vector2d pixel;
  EXPECT_FALSE(ProjectPoint(Model::kId, params.data(),
                            Eigen::Vector3d(0, 0, -1), &pixel));
  params[8] *= 2;
  params[9] *= 2;
  const double angle = 66 * kDegree;
  EXPECT_FALSE(ProjectPoint(
      Model::kId, params.data(),
      0.02 * Eigen::Vector3d(std::sin(angle), 0, std::cos(angle)), &pixel));
  EXPECT_TRUE(ProjectPoint(
      Model::kId, params.data(),
      0.05 * Eigen::Vector3d(std::sin(angle), 0, std::cos(angle)), &pixel));
}

// Noisy truth corners of the non-central scene's views (more of them than
// the scene renders by default), as calibration views.
struct Observed {
  std::vector<CalibrationView> views;
  std::vector<std::vector<double>> distance_m, angle_deg;  // per corner
};

Observed ObserveScene(const SceneSpec& scene, double noise_px, unsigned seed) {
  Observed observed;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_px);
  for (const SceneViewSpec& spec : SceneViewSpecs(scene)) {
    CalibrationView view;
    view.name = spec.name;
    std::vector<double> distance, angle;
    for (const TruthCorner& corner : ProjectBoardCorners(
             scene.board, scene.camera, spec.cam_from_board, scene.render)) {
      if (!corner.visible) continue;
      const Eigen::Vector3d board_point = scene.board.Point(corner.id);
      const Eigen::Vector3d p = spec.cam_from_board * board_point;
      view.board_points.push_back(board_point);
      view.image_points.push_back(
          corner.xy + testing_draws::DrawVector2d([&] { return noise(rng); }));
      distance.push_back(p.norm());
      angle.push_back(std::atan2(p.head<2>().norm(), p.z()) / kDegree);
    }
    if (view.board_points.size() < 10) continue;
    observed.views.push_back(view);
    observed.distance_m.push_back(distance);
    observed.angle_deg.push_back(angle);
  }
  return observed;
}

// Mean residual length of the corners nearer than `near_m` and wider than
// `wide_deg`, and of those farther than `far_m` and within `narrow_deg`.
std::pair<double, double> NearWideAndFarNarrowResiduals(
    const Observed& observed, const CalibrationResult& result, double near_m,
    double wide_deg, double far_m, double narrow_deg) {
  double near_sum = 0, far_sum = 0;
  int near_count = 0, far_count = 0;
  for (size_t v = 0; v < observed.views.size(); ++v) {
    if (!result.view_used[v]) continue;
    for (size_t i = 0; i < result.residuals[v].size(); ++i) {
      const double e = result.residuals[v][i].norm();
      if (!std::isfinite(e)) continue;
      if (observed.distance_m[v][i] < near_m &&
          observed.angle_deg[v][i] > wide_deg) {
        near_sum += e;
        ++near_count;
      } else if (observed.distance_m[v][i] > far_m &&
                 observed.angle_deg[v][i] < narrow_deg) {
        far_sum += e;
        ++far_count;
      }
    }
  }
  EXPECT_GT(near_count, 50);
  EXPECT_GT(far_count, 50);
  return {near_sum / std::max(near_count, 1), far_sum / std::max(far_count, 1)};
}

TEST(NoncentralTest, CalibrationOnNoncentralRendersRecoversThePupil) {
  SceneSpec scene = NoncentralFisheyeScene(1600, 1200);
  scene.random_views.count = 40;
  const Observed observed = ObserveScene(scene, 0.1, 21);
  ASSERT_GE(observed.views.size(), 30u);
  const std::vector<double>& truth = scene.camera.params;

  CalibrationOptions options;
  CalibrationResult noncentral;
  std::string error;
  ASSERT_TRUE(Calibrate(observed.views, Model::kId, 1600, 1200, options,
                        &noncentral, &error))
      << error;
  ASSERT_TRUE(noncentral.covariance_ok);
  EXPECT_NEAR(noncentral.camera.params[0], truth[0], 5e-4 * truth[0]);
  EXPECT_NEAR(noncentral.camera.params[1], truth[1], 5e-4 * truth[1]);
  for (int k : {kPupilBegin, kPupilBegin + 1}) {
    EXPECT_GT(noncentral.param_stddev[k], 0);
    EXPECT_NEAR(noncentral.camera.params[k], truth[k],
                3 * noncentral.param_stddev[k])
        << CameraModelParamNames(Model::kId)[k];
  }
  // The noise, and no structure left: near and wide corners fit as well as
  // far and central ones.
  EXPECT_NEAR(noncentral.rms_px, 0.1, 0.01);
  const auto [near_nc, far_nc] =
      NearWideAndFarNarrowResiduals(observed, noncentral, 0.12, 60, 0.18, 40);
  EXPECT_LT(near_nc, 1.3 * far_nc);

  // The central model on the same corners: a biased focal length and
  // residuals that grow at close range and large field angles.
  CalibrationOptions no_rejection;
  no_rejection.outlier_k = 0;
  CalibrationResult central;
  ASSERT_TRUE(Calibrate(observed.views, CameraModelId::kKannalaBrandt, 1600,
                        1200, no_rejection, &central, &error))
      << error;
  EXPECT_GT(central.rms_px, 2 * noncentral.rms_px);
  EXPECT_GT(std::abs(central.camera.params[0] - truth[0]), 2e-3 * truth[0]);
  const auto [near_c, far_c] =
      NearWideAndFarNarrowResiduals(observed, central, 0.12, 60, 0.18, 40);
  EXPECT_GT(near_c, 3 * far_c);
}

}  // namespace
}  // namespace puzzlecal
