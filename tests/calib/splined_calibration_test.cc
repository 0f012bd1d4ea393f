// The splined models in the solver: the grid covers the observed field and
// is not estimated, the start is the kannala-brandt fit, the prior keeps
// the unseen part of the grid bounded, and bad options are refused.
// (tests/evidence/splined_evidence_test.cc: the lens kannala-brandt cannot
// follow, recovered and chosen.)

#include <ceres/crs_matrix.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "calib/spline_prior.h"
#include "calib/splined_reprojection.h"
#include "sim/synthetic_views.h"
#include "tests/calib/scenes.h"
#include "tests/support/draws.h"
#include "util/angles.h"

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

// The grid covers the corners' field, is held fixed by the solve (and has
// no standard deviation), and the start is the kannala-brandt fit.
TEST(SplinedCalibration, GridCoversTheObservedFieldAndIsNotEstimated) {
  const sim::SyntheticData data = BumpyData(12, 16);
  const Camera truth = sim::TruthBumpyFisheye();
  const CalibrationResult result =
      CalibrateOrDie(data, CameraModelId::kKannalaBrandtSplined, truth);
  const int grid = KannalaBrandtSplinedModel::kGridRadiusIndex;
  double widest = 0;
  for (const auto& view : data.exact) {
    for (const Eigen::Vector2d& pixel : view) {
      Eigen::Vector3d ray;
      ASSERT_TRUE(truth.Unproject(pixel, &ray).converged);
      const double r = ray.head<2>().norm();
      const double theta = std::atan2(r, ray.z());
      widest =
          std::max(widest, theta * ray.head<2>().cwiseAbs().maxCoeff() / r);
    }
  }
  // 1.05 times the widest corner, up to the kannala-brandt start's error.
  EXPECT_NEAR(result.camera.params[grid], 1.05 * widest, 0.02 * widest);
  EXPECT_TRUE(result.param_fixed[grid]);
  EXPECT_EQ(result.param_stddev[grid], 0.0);
  EXPECT_NE(result.initialization_method.find("kannala-brandt calibration"),
            std::string::npos)
      << result.initialization_method;
  EXPECT_NE(result.initialization_method.find("grid over"), std::string::npos);
}

// An asked knot spacing sets the grid's reach (3.5 spacings for 10 knots)
// when the grid then covers every corner, and is refused, with the spacing
// that would, when it does not.
TEST(SplinedCalibration, AskedKnotSpacingSetsTheGridOrIsRefusedWithWhy) {
  const sim::SyntheticData data = BumpyData(12, 12);
  const Camera truth = sim::TruthBumpyFisheye();
  CalibrationOptions options;
  options.spline_knot_spacing_deg = 40;
  CalibrationResult result;
  std::string error;
  ASSERT_TRUE(Calibrate(data.views, CameraModelId::kKannalaBrandtSplined,
                        truth.width, truth.height, options, &result, &error))
      << error;
  const int grid = KannalaBrandtSplinedModel::kGridRadiusIndex;
  EXPECT_DOUBLE_EQ(result.camera.params[grid], 3.5 * 40 * kDegree);
  EXPECT_NE(result.initialization_method.find("40.0 deg apart, as asked"),
            std::string::npos)
      << result.initialization_method;
  // The corners reach about 90 degrees (a 180-degree lens): 10-degree knots
  // reach 35.
  options.spline_knot_spacing_deg = 10;
  EXPECT_FALSE(Calibrate(data.views, CameraModelId::kKannalaBrandtSplined,
                         truth.width, truth.height, options, &result, &error));
  EXPECT_NE(error.find("knot spacing of 10.0 deg"), std::string::npos) << error;
  EXPECT_NE(error.find("covers them"), std::string::npos) << error;
}

// Threads evaluate the splined corners' costs ahead of the solve
// (calib/parallel_costs.h): every output bit is that of one thread,
// through the cell re-checks and the covariance.
TEST(SplinedCalibration, ResultIsBitIdenticalForOneAndTwoThreads) {
  const sim::SyntheticData data = BumpyData(14, 12);
  const Camera truth = sim::TruthBumpyFisheye();
  std::vector<CalibrationResult> results(2);
  for (int threads : {1, 2}) {
    CalibrationOptions options;
    options.num_threads = threads;
    std::string error;
    ASSERT_TRUE(Calibrate(
        data.views, CameraModelId::kKannalaBrandtSplinedNoncentral, truth.width,
        truth.height, options, &results[threads - 1], &error))
        << error;
  }
  ASSERT_TRUE(results[0].covariance_ok);
  EXPECT_EQ(results[0].camera.params, results[1].camera.params);
  EXPECT_EQ(results[0].param_stddev, results[1].param_stddev);
  EXPECT_EQ(results[0].inlier, results[1].inlier);
  EXPECT_EQ(results[0].iterations, results[1].iterations);
  EXPECT_EQ(results[0].residuals, results[1].residuals);
}

// Where no corner was seen (the grid is square, the observed field round)
// the prior decides: every control value stays finite and small, and the
// covariance of all 209 parameters exists.
TEST(SplinedCalibration, UnseenCellsStayBoundedAndTheCovarianceExists) {
  // A narrow field: board directions within 25 degrees, so that the outer
  // ring of the grid (which covers 1.05x the widest corner) sees little.
  sim::SyntheticScene scene;
  scene.camera = sim::TruthBumpyFisheye();
  scene.num_views = 20;
  scene.noise_px = 0.1;
  scene.max_direction_deg = 25;
  scene.seed = 13;
  const sim::SyntheticData data = sim::MakeSyntheticData(scene);
  const CalibrationResult result =
      CalibrateOrDie(data, CameraModelId::kKannalaBrandtSplined, scene.camera);
  // Every value finite and the correction below a few pixels everywhere.
  const double fx = result.camera.params[0];
  for (int k = KannalaBrandtSplinedModel::kSplineBegin;
       k < KannalaBrandtSplinedModel::kNumParams; ++k) {
    ASSERT_TRUE(std::isfinite(result.camera.params[k]));
    EXPECT_LT(std::abs(result.camera.params[k]) * fx, 10.0) << k;
  }
  ASSERT_TRUE(result.covariance_ok);
}

TEST(SplinedCalibration, OptionsAreChecked) {
  CalibrationOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.spline_prior.smoothness_weight = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("smoothness"), std::string::npos);
  options = CalibrationOptions();
  options.spline_grid_margin = 0.9;
  EXPECT_FALSE(options.Check(&why));
  for (double spacing : {-1.0, 0.5, 52.0}) {
    options = CalibrationOptions();
    options.spline_knot_spacing_deg = spacing;
    EXPECT_FALSE(options.Check(&why)) << spacing;
    EXPECT_NE(why.find("spline_knot_spacing_deg"), std::string::npos) << why;
  }
  // A given start without a grid radius is refused, by name.
  const sim::SyntheticData data = BumpyData(14, 8);
  const Camera truth = sim::TruthBumpyFisheye();
  options = CalibrationOptions();
  options.initial_params = truth.params;
  options.initial_params[KannalaBrandtSplinedModel::kGridRadiusIndex] = 0;
  CalibrationResult result;
  EXPECT_FALSE(Calibrate(data.views, CameraModelId::kKannalaBrandtSplined,
                         truth.width, truth.height, options, &result, &why));
  EXPECT_NE(why.find("grid_radius"), std::string::npos) << why;
}

// The split cost (kannala-brandt's part, pose, 16 knots, pupil) gives the
// residual and Jacobians of the whole-block automatic differentiation of
// the model's own Project, column for column, for corners in their cell.
template <typename Model>
void ExpectSplitCostMatchesAutoDiff(const std::vector<double>& intrinsics) {
  constexpr int kN = Model::kNumParams;
  ASSERT_EQ(static_cast<int>(intrinsics.size()), kN);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<double> params = intrinsics;
  for (int trial = 0; trial < 30; ++trial) {
    PoseBlock pose = {0.3 * uniform(rng), 0.3 * uniform(rng),
                      0.3 * uniform(rng), 0.2 * uniform(rng),
                      0.2 * uniform(rng), 0.3 + 0.1 * uniform(rng)};
    const Eigen::Vector2d on_board =
        0.2 * testing_draws::DrawVector2d([&] { return uniform(rng); });
    const Eigen::Vector3d board(on_board.x(), on_board.y(), 0);
    const Eigen::Vector2d observed =
        Eigen::Vector2d(700, 600) +
        50 * testing_draws::DrawVector2d([&] { return uniform(rng); });
    const std::array<int, 2> cell = SplineCellOf<Model>(
        params.data(), IsometryFromPoseBlock(pose.data()) * board);
    SplinedReprojectionCost<Model> split(board, observed, cell);
    std::unique_ptr<ceres::CostFunction> whole(
        ReprojectionError<Model>::CreateAutoDiff(board, observed));
    double whole_residual[2];
    std::vector<double> whole_intrinsics(2 * kN), whole_pose(12);
    const double* whole_parameters[2] = {params.data(), pose.data()};
    double* whole_jacobians[2] = {whole_intrinsics.data(), whole_pose.data()};
    ASSERT_TRUE(
        whole->Evaluate(whole_parameters, whole_residual, whole_jacobians));
    const std::vector<double*> blocks =
        split.Blocks(params.data(), pose.data());
    const auto& sizes = split.parameter_block_sizes();
    std::vector<std::vector<double>> jacobian_storage(blocks.size());
    std::vector<double*> jacobians(blocks.size());
    for (size_t b = 0; b < blocks.size(); ++b) {
      jacobian_storage[b].assign(2 * sizes[b], 0.0);
      jacobians[b] = jacobian_storage[b].data();
    }
    double residual[2];
    ASSERT_TRUE(split.Evaluate(blocks.data(), residual, jacobians.data()));
    for (int r = 0; r < 2; ++r) {
      EXPECT_NEAR(residual[r], whole_residual[r], 1e-9);
      for (int c = 0; c < 6; ++c) {
        EXPECT_NEAR(jacobian_storage[1][r * 6 + c], whole_pose[r * 6 + c],
                    1e-7 * std::max(1.0, std::abs(whole_pose[r * 6 + c])));
      }
      // Every intrinsic column: the split cost's block that holds it, or 0.
      for (int k = 0; k < kN; ++k) {
        double split_value = 0;
        for (size_t b = 0; b < blocks.size(); ++b) {
          if (b == 1) continue;
          const int offset = static_cast<int>(blocks[b] - params.data());
          if (k >= offset && k < offset + sizes[b]) {
            split_value = jacobian_storage[b][r * sizes[b] + k - offset];
          }
        }
        EXPECT_NEAR(
            split_value, whole_intrinsics[r * kN + k],
            1e-7 * std::max(1.0, std::abs(whole_intrinsics[r * kN + k])))
            << "parameter " << k << " row " << r;
      }
    }
  }
}

TEST(SplinedReprojectionCost, MatchesTheWholeBlockAutoDiff) {
  std::vector<double> params = sim::TruthBumpyFisheye().params;
  ExpectSplitCostMatchesAutoDiff<KannalaBrandtSplinedModel>(params);
  params.insert(params.end(), {1.5e-3, 0.4e-3});
  ExpectSplitCostMatchesAutoDiff<KannalaBrandtSplinedNoncentralModel>(params);
}

// The prior split over the knot rows' blocks (the solver's layout) is the
// same prior: the same cost at any values, and the same information W'W on
// the control values as the whole-block form.
TEST(SplinePrior, OnKnotRowsItIsTheWholeBlocksPrior) {
  using Model = KannalaBrandtSplinedModel;
  const Camera truth = sim::TruthBumpyFisheye();
  std::vector<double> params = truth.params;
  SplinePriorOptions options;
  options.smoothness_weight = 0.3;
  options.zero_weight = 0.02;
  const Eigen::MatrixXd whole_information = SplinePriorInformation(
      CameraModelId::kKannalaBrandtSplined, params[0], params[1], options);

  ceres::Problem::Options problem_options;
  ceres::Problem problem(problem_options);
  AddSplinePriorOnKnots(CameraModelId::kKannalaBrandtSplined, params.data(),
                        options, &problem);
  std::vector<double*> blocks;
  for (int row = 0; row < kSplineKnots; ++row) {
    blocks.push_back(params.data() + Model::kSplineBegin +
                     2 * kSplineKnots * row);
  }
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  double cost = 0;
  ceres::CRSMatrix crs;
  ASSERT_TRUE(problem.Evaluate(evaluate, &cost, nullptr, nullptr, &crs));
  ASSERT_EQ(crs.num_rows, SplinePriorResidualCount());
  ASSERT_EQ(crs.num_cols, 2 * kSplineValues);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) {
      jacobian(r, crs.cols[k]) = crs.values[k];
    }
  }
  const Eigen::MatrixXd information = jacobian.transpose() * jacobian;
  const Eigen::MatrixXd expected =
      whole_information.block(Model::kSplineBegin, Model::kSplineBegin,
                              2 * kSplineValues, 2 * kSplineValues);
  EXPECT_LT((information - expected).norm(), 1e-9 * expected.norm());
  EXPECT_GT(expected.norm(), 0.0);

  // The cost of the truth's (bumpy) control values, against the whole form.
  std::unique_ptr<ceres::CostFunction> whole(CreateSplinePriorCost(
      CameraModelId::kKannalaBrandtSplined, params[0], params[1], options));
  std::vector<double> residuals(SplinePriorResidualCount());
  const double* parameters[1] = {params.data()};
  ASSERT_TRUE(whole->Evaluate(parameters, residuals.data(), nullptr));
  double whole_cost = 0;
  for (double r : residuals) whole_cost += 0.5 * r * r;
  EXPECT_GT(whole_cost, 0.0);
  EXPECT_NEAR(cost, whole_cost, 1e-12 * whole_cost);
}

// The prior's Jacobian is its residuals' linear map: residual = J x.
TEST(SplinePrior, ResidualsAreTheJacobianTimesTheValues) {
  const Camera truth = sim::TruthBumpyFisheye();
  SplinePriorOptions options;
  std::unique_ptr<ceres::CostFunction> cost(CreateSplinePriorCost(
      CameraModelId::kKannalaBrandtSplined, 400, 500, options));
  const int n = static_cast<int>(truth.params.size());
  const int m = SplinePriorResidualCount();
  ASSERT_EQ(cost->num_residuals(), m);
  std::vector<double> residuals(m), jacobian(static_cast<size_t>(m) * n);
  const double* parameters[1] = {truth.params.data()};
  double* jacobians[1] = {jacobian.data()};
  ASSERT_TRUE(cost->Evaluate(parameters, residuals.data(), jacobians));
  for (int r = 0; r < m; ++r) {
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += jacobian[r * n + k] * truth.params[k];
    EXPECT_NEAR(residuals[r], sum, 1e-12);
    // Only the correction values' columns.
    for (int k = 0; k < KannalaBrandtSplinedModel::kSplineBegin; ++k) {
      EXPECT_EQ(jacobian[r * n + k], 0.0);
    }
  }
  // A plane of control values has no second differences: only the pull
  // towards zero is left.
  std::vector<double> plane = truth.params;
  for (int c = 0; c < 2; ++c) {
    for (int i = 0; i < kSplineValues; ++i) {
      plane[KannalaBrandtSplinedModel::kSplineBegin + 2 * i + c] =
          0.001 * (i % kSplineKnots) - 0.002 * (i / kSplineKnots) + c;
    }
  }
  parameters[0] = plane.data();
  ASSERT_TRUE(cost->Evaluate(parameters, residuals.data(), nullptr));
  const int per_component = m / 2;
  const int second_differences = 2 * kSplineKnots * (kSplineKnots - 2);
  for (int c = 0; c < 2; ++c) {
    for (int r = 0; r < second_differences; ++r) {
      EXPECT_NEAR(residuals[c * per_component + r], 0.0, 1e-9);
    }
  }
}

}  // namespace
}  // namespace puzzlecal
