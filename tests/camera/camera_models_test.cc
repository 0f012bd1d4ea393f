#include "camera/camera_models.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <random>
#include <string>
#include <vector>

namespace puzzlecal {
namespace {

const std::vector<double> kRadtan = {820.0, 818.5, 642.3, 477.1, -0.28,
                                     0.09,  6e-4,  -4e-4, -0.012};
const std::vector<double> kRational = {760.0,  761.2, 637.8, 482.6,
                                       0.3,    0.02,  4e-4,  7e-4,
                                       0.0005, 0.52,  0.06,  0.001};
const std::vector<double> kFisheye = {495.0, 494.2,  801.7, 598.4,
                                      0.02,  -0.005, 0.001, -0.0002};
// kFisheye with a moving entrance pupil (e1, e2 in metres).
const std::vector<double> kNoncentral = {
    495.0, 494.2, 801.7, 598.4, 0.02, -0.005, 0.001, -0.0002, 0.95e-3, 0.31e-3};

// kFisheye with a spline correction of a few pixels (a smooth pattern over
// the knots) on a grid over 1.7 rad, and with the pupil of kNoncentral.
std::vector<double> SplinedParams(bool pupil) {
  std::vector<double> params = kFisheye;
  params.push_back(1.7);  // grid_radius
  for (int row = 0; row < kSplineKnots; ++row) {
    for (int col = 0; col < kSplineKnots; ++col) {
      for (int c = 0; c < 2; ++c) {
        params.push_back(0.004 * std::sin(0.9 * row + 1.3 * col + c));
      }
    }
  }
  if (pupil) params.insert(params.end(), {0.95e-3, 0.31e-3});
  return params;
}
const std::vector<double> kSplined = SplinedParams(false);
const std::vector<double> kSplinedNoncentral = SplinedParams(true);

const std::vector<double>& ParamsFor(CameraModelId id) {
  switch (id) {
    case CameraModelId::kKannalaBrandtSplined:
      return kSplined;
    case CameraModelId::kKannalaBrandtSplinedNoncentral:
      return kSplinedNoncentral;
    case CameraModelId::kPinholeRadtan:
      return kRadtan;
    case CameraModelId::kPinholeRational:
      return kRational;
    case CameraModelId::kKannalaBrandtNoncentral:
      return kNoncentral;
    default:
      return kFisheye;
  }
}

// Rays spread over a cone of half angle `max_angle`, at varying depths.
std::vector<Eigen::Vector3d> RandomPoints(double max_angle, int count,
                                          unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const double theta = max_angle * std::sqrt(uniform(rng));
    const double phi = 2 * M_PI * uniform(rng);
    const double depth = 0.2 + 5 * uniform(rng);
    points.emplace_back(depth * std::sin(theta) * std::cos(phi),
                        depth * std::sin(theta) * std::sin(phi),
                        depth * std::cos(theta));
  }
  return points;
}

cv::Mat CameraMatrix(const std::vector<double>& p) {
  return (cv::Mat_<double>(3, 3) << p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
}

TEST(CameraModelsTest, RadtanMatchesCvProjectPoints) {
  const auto points = RandomPoints(40 * M_PI / 180, 500, 1);
  std::vector<cv::Point3d> cv_points;
  for (const auto& p : points) cv_points.emplace_back(p.x(), p.y(), p.z());
  const cv::Mat dist = (cv::Mat_<double>(1, 5) << kRadtan[4], kRadtan[5],
                        kRadtan[6], kRadtan[7], kRadtan[8]);
  std::vector<cv::Point2d> cv_pixels;
  cv::projectPoints(cv_points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                    CameraMatrix(kRadtan), dist, cv_pixels);
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ProjectPoint(CameraModelId::kPinholeRadtan, kRadtan.data(),
                             points[i], &pixel));
    EXPECT_NEAR(pixel.x(), cv_pixels[i].x, 1e-9);
    EXPECT_NEAR(pixel.y(), cv_pixels[i].y, 1e-9);
  }
}

TEST(CameraModelsTest, RationalMatchesCvProjectPoints) {
  const auto points = RandomPoints(40 * M_PI / 180, 500, 2);
  std::vector<cv::Point3d> cv_points;
  for (const auto& p : points) cv_points.emplace_back(p.x(), p.y(), p.z());
  // OpenCV's order: k1 k2 p1 p2 k3 k4 k5 k6, the same as ours.
  cv::Mat dist(1, 8, CV_64F);
  for (int k = 0; k < 8; ++k) dist.at<double>(k) = kRational[4 + k];
  std::vector<cv::Point2d> cv_pixels;
  cv::projectPoints(cv_points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                    CameraMatrix(kRational), dist, cv_pixels);
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ProjectPoint(CameraModelId::kPinholeRational, kRational.data(),
                             points[i], &pixel));
    EXPECT_NEAR(pixel.x(), cv_pixels[i].x, 1e-9);
    EXPECT_NEAR(pixel.y(), cv_pixels[i].y, 1e-9);
  }
}

TEST(CameraModelsTest, KannalaBrandtMatchesCvFisheyeProjectPoints) {
  // OpenCV's fisheye model divides by z: valid below 90 degrees.
  const auto points = RandomPoints(85 * M_PI / 180, 500, 3);
  std::vector<cv::Point3d> cv_points;
  for (const auto& p : points) cv_points.emplace_back(p.x(), p.y(), p.z());
  const cv::Vec4d dist(kFisheye[4], kFisheye[5], kFisheye[6], kFisheye[7]);
  std::vector<cv::Point2d> cv_pixels;
  cv::fisheye::projectPoints(cv_points, cv_pixels, cv::Vec3d(0, 0, 0),
                             cv::Vec3d(0, 0, 0), CameraMatrix(kFisheye), dist);
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ProjectPoint(CameraModelId::kKannalaBrandt, kFisheye.data(),
                             points[i], &pixel));
    EXPECT_NEAR(pixel.x(), cv_pixels[i].x, 1e-9);
    EXPECT_NEAR(pixel.y(), cv_pixels[i].y, 1e-9);
  }
}

TEST(CameraModelsTest, KannalaBrandtProjectsBeyondNinetyDegrees) {
  // theta = atan2(r, z): a ray 100 degrees off the axis lands at
  // f * theta_d(100 deg) from the principal point.
  const double theta = 100 * M_PI / 180;
  const Eigen::Vector3d point(std::sin(theta), 0, std::cos(theta));
  Eigen::Vector2d pixel;
  ASSERT_TRUE(ProjectPoint(CameraModelId::kKannalaBrandt, kFisheye.data(),
                           point, &pixel));
  const double t2 = theta * theta;
  const double theta_d =
      theta * (1 + kFisheye[4] * t2 + kFisheye[5] * t2 * t2 +
               kFisheye[6] * t2 * t2 * t2 + kFisheye[7] * t2 * t2 * t2 * t2);
  EXPECT_NEAR(pixel.x(), kFisheye[2] + kFisheye[0] * theta_d, 1e-9);
  EXPECT_NEAR(pixel.y(), kFisheye[3], 1e-9);
  // The pinhole models refuse points behind the camera.
  EXPECT_FALSE(ProjectPoint(CameraModelId::kPinholeRadtan, kRadtan.data(),
                            point, &pixel));
}

// Unproject(pixel) then Project(ray) returns the pixel everywhere in the
// image, and Project then Unproject returns the ray.
TEST(CameraModelsTest, UnprojectRoundTripsOverTheWholeImage) {
  struct Case {
    CameraModelId id;
    int width, height;
  };
  for (const Case& c :
       {Case{CameraModelId::kPinholeRadtan, 1280, 960},
        Case{CameraModelId::kPinholeRational, 1280, 960},
        Case{CameraModelId::kKannalaBrandt, 1600, 1200},
        Case{CameraModelId::kKannalaBrandtSplined, 1600, 1200}}) {
    SCOPED_TRACE(CameraModelName(c.id));
    const std::vector<double>& params = ParamsFor(c.id);
    double max_error = 0;
    for (int y = 0; y < c.height; y += 8) {
      for (int x = 0; x < c.width; x += 8) {
        const Eigen::Vector2d pixel(x, y);
        Eigen::Vector3d ray;
        const UnprojectStatus status =
            UnprojectPixel(c.id, params.data(), pixel, &ray);
        ASSERT_TRUE(status.converged) << x << "," << y;
        EXPECT_NEAR(ray.norm(), 1.0, 1e-12);
        Eigen::Vector2d back;
        ASSERT_TRUE(ProjectPoint(c.id, params.data(), ray * 3.0, &back));
        max_error = std::max(max_error, (back - pixel).norm());
      }
    }
    EXPECT_LT(max_error, 1e-6);
  }
  // Rays up to 114 degrees through the fisheye and back.
  for (const auto& point : RandomPoints(114 * M_PI / 180, 300, 4)) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ProjectPoint(CameraModelId::kKannalaBrandt, kFisheye.data(),
                             point, &pixel));
    Eigen::Vector3d ray;
    ASSERT_TRUE(UnprojectPixel(CameraModelId::kKannalaBrandt, kFisheye.data(),
                               pixel, &ray)
                    .converged);
    EXPECT_LT((ray - point.normalized()).norm(), 1e-9);
  }
}

TEST(CameraModelsTest, UnprojectReportsPixelsOutsideTheValidRegion) {
  // Radial distortion 1 + k1 r^2 with k1 < 0 folds back at r^2 = 1/(3|k1|):
  // pixels beyond the fold's image radius have no ray.
  const std::vector<double> params = {500, 500, 320, 240, -0.5, 0, 0, 0, 0};
  const double r_max = std::sqrt(1.0 / 1.5);
  const double rd_max = r_max * (1 - 0.5 * r_max * r_max);
  Eigen::Vector3d ray;
  const UnprojectStatus inside =
      UnprojectPixel(CameraModelId::kPinholeRadtan, params.data(),
                     Eigen::Vector2d(320 + 500 * 0.9 * rd_max, 240), &ray);
  EXPECT_TRUE(inside.converged);
  const UnprojectStatus outside =
      UnprojectPixel(CameraModelId::kPinholeRadtan, params.data(),
                     Eigen::Vector2d(320 + 500 * 1.2 * rd_max, 240), &ray);
  // (The iteration may find the mirrored solution beyond the fold; it must
  // not be reported as the pixel's ray.)
  EXPECT_FALSE(outside.converged);
  // Kannala-Brandt: theta_d saturates when the polynomial turns over.
  const std::vector<double> kb = {300, 300, 320, 240, -0.2, 0, 0, 0};
  const UnprojectStatus beyond =
      UnprojectPixel(CameraModelId::kKannalaBrandt, kb.data(),
                     Eigen::Vector2d(320 + 300 * 2.0, 240), &ray);
  EXPECT_FALSE(beyond.converged);
  // NaN input never claims convergence.
  EXPECT_FALSE(UnprojectPixel(CameraModelId::kKannalaBrandt, kFisheye.data(),
                              Eigen::Vector2d(std::nan(""), 3), &ray)
                   .converged);
}

// Jet derivatives of Project against central differences, for the
// parameters and the point.
TEST(CameraModelsTest, JetDerivativesMatchFiniteDifferences) {
  for (CameraModelId id : kAllCameraModels) {
    SCOPED_TRACE(CameraModelName(id));
    DispatchCameraModel(id, [&](auto model) {
      using Model = decltype(model);
      constexpr int kN = Model::kNumParams + 3;
      using Jet = ceres::Jet<double, kN>;
      const std::vector<double>& params = ParamsFor(id);
      const double max_angle =
          CameraModelIsFisheye(id) ? 110 * M_PI / 180 : 0.6;
      for (const Eigen::Vector3d& point : RandomPoints(max_angle, 50, 5)) {
        Jet jet_params[Model::kNumParams], jet_point[3], jet_pixel[2];
        for (int k = 0; k < Model::kNumParams; ++k) {
          jet_params[k] = Jet(params[k], k);
        }
        for (int k = 0; k < 3; ++k) {
          jet_point[k] = Jet(point[k], Model::kNumParams + k);
        }
        ASSERT_TRUE(Model::Project(jet_params, jet_point, jet_pixel));
        for (int k = 0; k < kN; ++k) {
          std::vector<double> p_plus = params, p_minus = params;
          Eigen::Vector3d x_plus = point, x_minus = point;
          double step;
          if (k < Model::kNumParams) {
            step = 1e-6 * std::max(1.0, std::abs(params[k]));
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
                        1e-6 * std::max(1.0, std::abs(numeric)))
                << "derivative " << k << " coordinate " << c;
          }
        }
      }
    });
  }
}

TEST(CameraModelsTest, KannalaBrandtJetOnTheOpticalAxisIsFinite) {
  using Jet = ceres::Jet<double, 3>;
  const Jet point[3] = {Jet(0.0, 0), Jet(0.0, 1), Jet(2.0, 2)};
  Jet params[8];
  for (int k = 0; k < 8; ++k) params[k] = Jet(kFisheye[k]);
  Jet pixel[2];
  ASSERT_TRUE(KannalaBrandtModel::Project(params, point, pixel));
  EXPECT_NEAR(pixel[0].a, kFisheye[2], 1e-12);
  // d u / d x = fx / z on the axis.
  EXPECT_NEAR(pixel[0].v[0], kFisheye[0] / 2.0, 1e-9);
  EXPECT_TRUE(std::isfinite(pixel[1].v[2]));
}

TEST(CameraModelsTest, NameDispatch) {
  EXPECT_STREQ(CameraModelName(CameraModelId::kPinholeRadtan),
               "pinhole-radtan");
  EXPECT_STREQ(CameraModelName(CameraModelId::kPinholeRational),
               "pinhole-rational");
  EXPECT_STREQ(CameraModelName(CameraModelId::kKannalaBrandt),
               "kannala-brandt");
  for (CameraModelId id : kAllCameraModels) {
    CameraModelId parsed;
    ASSERT_TRUE(CameraModelIdFromName(CameraModelName(id), &parsed));
    EXPECT_EQ(parsed, id);
    const std::vector<std::string> names = CameraModelParamNames(id);
    ASSERT_EQ(static_cast<int>(names.size()), CameraModelNumParams(id));
    EXPECT_EQ(names[0], "fx");
    EXPECT_EQ(names[3], "cy");
  }
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kPinholeRadtan), 9);
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kPinholeRational), 12);
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kKannalaBrandt), 8);
  EXPECT_TRUE(CameraModelIsPinhole(CameraModelId::kPinholeRational));
  EXPECT_FALSE(CameraModelIsPinhole(CameraModelId::kKannalaBrandt));
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kKannalaBrandtNoncentral), 10);
  EXPECT_STREQ(CameraModelName(CameraModelId::kKannalaBrandtNoncentral),
               "kannala-brandt-noncentral");
  EXPECT_EQ(CameraModelParamNames(CameraModelId::kKannalaBrandtNoncentral)[8],
            "e1");
  EXPECT_FALSE(CameraModelIsPinhole(CameraModelId::kKannalaBrandtNoncentral));
  EXPECT_TRUE(CameraModelIsFisheye(CameraModelId::kKannalaBrandtNoncentral));
  EXPECT_FALSE(CameraModelIsFisheye(CameraModelId::kPinholeRadtan));
  EXPECT_FALSE(CameraModelIsCentral(CameraModelId::kKannalaBrandtNoncentral));
  for (CameraModelId id :
       {CameraModelId::kPinholeRadtan, CameraModelId::kPinholeRational,
        CameraModelId::kKannalaBrandt}) {
    EXPECT_TRUE(CameraModelIsCentral(id));
  }
  CameraModelId parsed;
  EXPECT_FALSE(CameraModelIdFromName("pinhole", &parsed));
  EXPECT_FALSE(CameraModelIdFromName("", &parsed));
  EXPECT_NE(CameraModelNames().find("kannala-brandt"), std::string::npos);
}

// The family says how the field angle reaches the image: a fisheye model
// projects a point 100 degrees off the axis, a pinhole model refuses it.
TEST(CameraModelFacts, FamilyMatchesWhatProjectAccepts) {
  const double angle = 100 * M_PI / 180;
  const Eigen::Vector3d behind(std::sin(angle), 0.0, std::cos(angle));
  for (CameraModelId id : kAllCameraModels) {
    Eigen::Vector2d pixel;
    const bool projected =
        ProjectPoint(id, ParamsFor(id).data(), behind, &pixel);
    EXPECT_EQ(projected, CameraModelIsFisheye(id)) << CameraModelName(id);
    EXPECT_NE(CameraModelIsFisheye(id), CameraModelIsPinhole(id));
  }
}

// FieldRadius is tan(angle) for pinhole models and the angle for fisheyes.
TEST(CameraModelFacts, FieldRadiusOfARay) {
  const double angle = 40 * M_PI / 180;
  const Eigen::Vector3d ray(0.6 * std::sin(angle), 0.8 * std::sin(angle),
                            std::cos(angle));
  for (CameraModelId id : kAllCameraModels) {
    Camera camera;
    camera.model = id;
    camera.params = ParamsFor(id);
    const double expected = CameraModelIsFisheye(id) ? angle : std::tan(angle);
    EXPECT_NEAR(FieldRadius(camera, ray), expected, 1e-12)
        << CameraModelName(id);
  }
  Camera pinhole;
  pinhole.params = kRadtan;
  EXPECT_TRUE(std::isinf(FieldRadius(pinhole, Eigen::Vector3d(0.1, 0, -1))));
}

// MaxMonotonicRadius is where the projected radius stops growing: checked
// through Project on both sides, against the closed form of a pure k1 lens.
TEST(CameraModelFacts, MaxMonotonicRadiusIsWhereTheImageFoldsOver) {
  struct Case {
    CameraModelId id;
    std::vector<double> params;
    double fold;  // where d(r_d)/dr = 0
  };
  const std::vector<Case> cases = {
      // r (1 - 0.5 r^2): 1 - 1.5 r^2 = 0.
      {CameraModelId::kPinholeRadtan,
       {500, 500, 320, 240, -0.5, 0, 0, 0, 0},
       std::sqrt(1 / 1.5)},
      // theta (1 - 0.1 theta^2): 1 - 0.3 theta^2 = 0.
      {CameraModelId::kKannalaBrandt,
       {500, 500, 320, 240, -0.1, 0, 0, 0},
       std::sqrt(1 / 0.3)},
  };
  for (const Case& c : cases) {
    Camera camera;
    camera.model = c.id;
    camera.params = c.params;
    const double fold = MaxMonotonicRadius(camera);
    EXPECT_NEAR(fold, c.fold, 2e-3) << CameraModelName(c.id);
    // The image radius along x of a ray at field radius r.
    auto image_radius = [&](double r) {
      const Eigen::Vector3d ray =
          CameraModelIsFisheye(c.id)
              ? Eigen::Vector3d(std::sin(r), 0, std::cos(r))
              : Eigen::Vector3d(r, 0, 1);
      Eigen::Vector2d pixel;
      EXPECT_TRUE(camera.Project(ray, &pixel));
      return pixel.x() - c.params[2];
    };
    EXPECT_LT(image_radius(fold - 0.02), image_radius(fold - 0.01));
    EXPECT_GT(image_radius(fold + 0.01), image_radius(fold + 0.02));
  }
  // A lens without distortion never folds within the scanned range.
  Camera plain;
  plain.params = {500, 500, 320, 240, 0, 0, 0, 0, 0};
  EXPECT_NEAR(MaxMonotonicRadius(plain), 572.0, 1e-9);
}

// BorderFractionWithoutRay against the closed form of a pure k1 lens: r (1 +
// k1 r^2) peaks at r = 1 / sqrt(-3 k1) with the distorted radius 2/3 of it,
// so the border pixels farther than f times that from the principal point
// have no ray. A mild lens keeps every border pixel.
TEST(CameraModelFacts, BorderPixelsBeyondTheFoldHaveNoRay) {
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.width = 640;
  camera.height = 480;
  const double f = 400;
  for (double k1 : {-0.05, -0.3, -0.6}) {
    camera.params = {f, f, 320, 240, k1, 0, 0, 0, 0};
    const double fold_px = f * (2.0 / 3.0) / std::sqrt(-3 * k1);
    const int n = 64;
    int beyond = 0, samples = 0;
    for (int k = 0; k < n; ++k) {
      const double s = (k + 0.5) / n;
      for (const Eigen::Vector2d& p :
           {Eigen::Vector2d(-0.5, -0.5 + s * 480),
            Eigen::Vector2d(639.5, -0.5 + s * 480),
            Eigen::Vector2d(-0.5 + s * 640, -0.5),
            Eigen::Vector2d(-0.5 + s * 640, 479.5)}) {
        ++samples;
        beyond += (p - Eigen::Vector2d(320, 240)).norm() > fold_px ? 1 : 0;
      }
    }
    const double expected = static_cast<double>(beyond) / samples;
    EXPECT_NEAR(BorderFractionWithoutRay(camera, n), expected, 1.0 / samples)
        << "k1 " << k1 << ", fold at " << fold_px << " px";
    if (k1 == -0.05) {
      EXPECT_EQ(expected, 0.0);
    }
    if (k1 == -0.6) {
      EXPECT_GT(expected, 0.3);
    }
  }
}

// The far-field camera of the non-central model is kannala-brandt with its
// first eight parameters; central models are their own far field.
TEST(CameraModelFacts, FarFieldCamera) {
  for (CameraModelId id : kAllCameraModels) {
    Camera camera;
    camera.model = id;
    camera.params = ParamsFor(id);
    const Camera far = FarFieldCamera(camera);
    EXPECT_TRUE(CameraModelIsCentral(far.model));
    EXPECT_EQ(static_cast<int>(far.params.size()),
              CameraModelNumParams(far.model));
    // Far points project the same through both.
    const Eigen::Vector3d point(3.0, -2.0, 1000.0);
    Eigen::Vector2d a, b;
    ASSERT_TRUE(camera.Project(point, &a));
    ASSERT_TRUE(far.Project(point, &b));
    EXPECT_LT((a - b).norm(), 1e-3) << CameraModelName(id);
    if (CameraModelIsCentral(id)) {
      EXPECT_EQ(far.model, id);
    }
  }
}

}  // namespace
}  // namespace puzzlecal
