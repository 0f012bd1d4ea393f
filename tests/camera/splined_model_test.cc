#include "camera/splined_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "tests/support/draws.h"

namespace puzzlecal {
namespace {

using Splined = KannalaBrandtSplinedModel;

// kannala-brandt parameters, grid_radius and the correction values
// `value(component, row, col)`.
template <typename Fn>
std::vector<double> SplinedParams(double radius, Fn value) {
  std::vector<double> params = {495.0,  494.2, 801.7,   598.4, 0.02,
                                -0.005, 0.001, -0.0002, radius};
  for (int row = 0; row < kSplineKnots; ++row) {
    for (int col = 0; col < kSplineKnots; ++col) {
      for (int c = 0; c < 2; ++c) params.push_back(value(c, row, col));
    }
  }
  return params;
}

// The position of control point i along one axis of a grid over [-R, R].
double KnotPosition(int i, double radius) {
  return -radius + (i - 1) * 2 * radius / (kSplineKnots - 3);
}

// A uniform cubic B-spline reproduces linear functions of its control
// point positions exactly: control values a + b x + c y give the
// correction a + b ex + c ey everywhere on the grid. (This is also why the
// calibration needs a prior: such a correction is what fx, fy, cx, cy do.)
TEST(SplinedModel, ReproducesLinearFunctionsExactly) {
  constexpr double kRadius = 1.6;
  const std::vector<double> params =
      SplinedParams(kRadius, [&](int c, int row, int col) {
        const double x = KnotPosition(col, kRadius);
        const double y = KnotPosition(row, kRadius);
        return c == 0 ? 0.01 + 0.02 * x - 0.03 * y : -0.02 + 0.05 * y;
      });
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-kRadius, kRadius);
  for (int i = 0; i < 200; ++i) {
    const double ex = uniform(rng), ey = uniform(rng);
    double du, dv;
    Splined::Correction(params.data(), ex, ey, &du, &dv);
    EXPECT_NEAR(du, 0.01 + 0.02 * ex - 0.03 * ey, 1e-14);
    EXPECT_NEAR(dv, -0.02 + 0.05 * ey, 1e-14);
  }
}

// One control value moves the surface only within two cells of its knot,
// and the surface has no step at cell borders; beyond the grid it keeps
// its value at the edge.
TEST(SplinedModel, ControlValuesActLocallyAndSmoothly) {
  constexpr double kRadius = 1.5;
  constexpr int kRow = 4, kCol = 5;
  const std::vector<double> params =
      SplinedParams(kRadius, [&](int c, int row, int col) {
        return c == 0 && row == kRow && col == kCol ? 1.0 : 0.0;
      });
  const double spacing = 2 * kRadius / (kSplineKnots - 3);
  const double knot_x = KnotPosition(kCol, kRadius);
  const double knot_y = KnotPosition(kRow, kRadius);
  double du, dv;
  // At the knot: the cubic B-spline's peak 2/3 * 2/3.
  Splined::Correction(params.data(), knot_x, knot_y, &du, &dv);
  EXPECT_NEAR(du, 4.0 / 9.0, 1e-12);
  EXPECT_EQ(dv, 0.0);
  // Two cells away and beyond: nothing.
  Splined::Correction(params.data(), knot_x + 2.01 * spacing, knot_y, &du, &dv);
  EXPECT_EQ(du, 0.0);
  // Across a cell border the value is continuous.
  const double border = -kRadius + 4 * spacing;
  double left, right;
  Splined::Correction(params.data(), border - 1e-9, knot_y, &left, &dv);
  Splined::Correction(params.data(), border + 1e-9, knot_y, &right, &dv);
  EXPECT_NEAR(left, right, 1e-8);
  // Beyond the grid: the edge value.
  const std::vector<double> edge =
      SplinedParams(kRadius, [&](int c, int row, int col) {
        return c == 0 ? 0.1 * col + 0.01 * row : 0.0;
      });
  double at_edge, beyond;
  Splined::Correction(edge.data(), kRadius, 0.2, &at_edge, &dv);
  Splined::Correction(edge.data(), kRadius + 0.5, 0.2, &beyond, &dv);
  EXPECT_NEAR(beyond, at_edge, 1e-12);
}

// With every correction value at zero the model is kannala-brandt.
TEST(SplinedModel, ZeroCorrectionIsKannalaBrandt) {
  const std::vector<double> params =
      SplinedParams(1.6, [](int, int, int) { return 0.0; });
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d point =
        testing_draws::DrawVector3d([&] { return uniform(rng); }) +
        Eigen::Vector3d(0, 0, 0.3);
    Eigen::Vector2d splined, kb;
    ASSERT_TRUE(ProjectPoint(CameraModelId::kKannalaBrandtSplined,
                             params.data(), point, &splined));
    ASSERT_TRUE(
        ProjectPoint(CameraModelId::kKannalaBrandt, params.data(), point, &kb));
    EXPECT_LT((splined - kb).norm(), 1e-12);
  }
}

// Names: unique, du and dv knot by knot, grid_radius structural, e1 e2 last for
// the non-central form, whose first parameters are the central one's.
TEST(SplinedModel, ParameterLayout) {
  const std::vector<std::string> names =
      CameraModelParamNames(CameraModelId::kKannalaBrandtSplined);
  ASSERT_EQ(names.size(), 9u + 2 * kSplineValues);
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(),
            names.size());
  EXPECT_EQ(names[8], "grid_radius");
  // Knot by knot: du, dv of knot (0, 0), then of (0, 1), ...
  EXPECT_EQ(names[9], "du_0_0");
  EXPECT_EQ(names[10], "dv_0_0");
  EXPECT_EQ(names[9 + 2 * (kSplineKnots + 2)], "du_1_2");
  EXPECT_EQ(names.back(), "dv_9_9");
  EXPECT_TRUE(
      CameraModelParamIsStructural(CameraModelId::kKannalaBrandtSplined, 8));
  EXPECT_FALSE(
      CameraModelParamIsStructural(CameraModelId::kKannalaBrandtSplined, 9));
  EXPECT_FALSE(CameraModelParamIsStructural(CameraModelId::kKannalaBrandt, 8));
  const std::vector<std::string> noncentral =
      CameraModelParamNames(CameraModelId::kKannalaBrandtSplinedNoncentral);
  ASSERT_EQ(noncentral.size(), names.size() + 2);
  EXPECT_TRUE(std::equal(names.begin(), names.end(), noncentral.begin()));
  EXPECT_EQ(noncentral[names.size()], "e1");
  EXPECT_EQ(noncentral[names.size() + 1], "e2");
  EXPECT_TRUE(CameraModelIsFisheye(CameraModelId::kKannalaBrandtSplined));
  EXPECT_TRUE(CameraModelIsCentral(CameraModelId::kKannalaBrandtSplined));
  EXPECT_FALSE(
      CameraModelIsCentral(CameraModelId::kKannalaBrandtSplinedNoncentral));
}

// Unproject inverts Project for rays up to 100 degrees (the correction a
// few pixels), and the non-central form's ray passes through the point.
TEST(SplinedModel, UnprojectInvertsProject) {
  std::vector<double> params = SplinedParams(1.75, [](int c, int row, int col) {
    return 0.006 * std::cos(0.7 * row - 1.1 * col + 2 * c);
  });
  std::vector<double> pupil = params;
  pupil.insert(pupil.end(), {2e-3, 0.5e-3});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  double worst_direction = 0, worst_miss = 0;
  for (int i = 0; i < 300; ++i) {
    const double theta = 100 * M_PI / 180 * std::sqrt(uniform(rng));
    const double phi = 2 * M_PI * uniform(rng);
    const Eigen::Vector3d direction(std::sin(theta) * std::cos(phi),
                                    std::sin(theta) * std::sin(phi),
                                    std::cos(theta));
    const Eigen::Vector3d point = (0.2 + 2 * uniform(rng)) * direction;
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ProjectPoint(CameraModelId::kKannalaBrandtSplined,
                             params.data(), point, &pixel));
    Eigen::Vector3d ray;
    ASSERT_TRUE(UnprojectPixel(CameraModelId::kKannalaBrandtSplined,
                               params.data(), pixel, &ray)
                    .converged);
    worst_direction = std::max(worst_direction, (ray - direction).norm());
    ASSERT_TRUE(ProjectPoint(CameraModelId::kKannalaBrandtSplinedNoncentral,
                             pupil.data(), point, &pixel));
    ViewingRay full;
    ASSERT_TRUE(
        UnprojectPixelToRay(CameraModelId::kKannalaBrandtSplinedNoncentral,
                            pupil.data(), pixel, &full)
            .converged);
    const Eigen::Vector3d to_point = point - full.origin;
    worst_miss = std::max(
        worst_miss,
        (to_point - to_point.dot(full.direction) * full.direction).norm());
  }
  EXPECT_LT(worst_direction, 1e-9);
  EXPECT_LT(worst_miss, 1e-9);
}

}  // namespace
}  // namespace puzzlecal
