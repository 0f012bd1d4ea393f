// ReprojectionCost (the chain rule through the camera-frame point) against
// ceres::AutoDiffCostFunction over the same functor: the same residuals bit
// for bit (with and without Jacobians; a splined model's, through its spline
// cell, to 1e-9 px), the same Jacobians to rounding, for every camera model,
// at poses that put the corners near the axis and far off it.

#include "calib/reprojection_error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "camera/camera_models.h"
#include "sim/synthetic_views.h"
#include "tests/support/draws.h"

namespace puzzlecal {
namespace {

std::vector<double> ParamsOf(CameraModelId id) {
  switch (id) {
    case CameraModelId::kPinholeRadtan:
      return sim::TruthRadtan().params;
    case CameraModelId::kPinholeRational:
      return sim::TruthRational().params;
    case CameraModelId::kKannalaBrandt:
      return sim::TruthFisheye190().params;
    case CameraModelId::kKannalaBrandtNoncentral: {
      std::vector<double> params = sim::TruthFisheye190().params;
      params.push_back(0.001);   // e1, metres
      params.push_back(0.0003);  // e2
      return params;
    }
    case CameraModelId::kKannalaBrandtSplined:
      return sim::TruthBumpyFisheye().params;
    case CameraModelId::kKannalaBrandtSplinedNoncentral: {
      std::vector<double> params = sim::TruthBumpyFisheye().params;
      params.push_back(0.001);   // e1, metres
      params.push_back(0.0003);  // e2
      return params;
    }
  }
  return {};
}

// Evaluates the residual (2) and, where the pointers are not null, the
// Jacobians d residual / d intrinsics (2 x n) and d residual / d pose (2 x 6),
// row-major; false when the point does not project.
using ReprojectionEvaluator = std::function<bool(
    const Eigen::Vector3d& board_point, const Eigen::Vector2d& observed,
    const double* intrinsics, const double* pose, double* residual,
    double* d_intrinsics, double* d_pose)>;

// `fast` against automatic differentiation of ReprojectionError over all
// N + 6 values. The residuals agree exactly when residual_tolerance is 0.
template <typename Model>
void ExpectSameAsAutoDiff(const std::vector<double>& intrinsics,
                          const ReprojectionEvaluator& fast,
                          double residual_tolerance) {
  constexpr int kN = Model::kNumParams;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // Board points up to 0.3 m from the board origin, the board 0.2-1 m
    // away, turned up to about 70 degrees and shifted sideways so that some
    // corners lie far off the axis.
    const Eigen::Vector2d on_board =
        0.3 * testing_draws::DrawVector2d([&] { return uniform(rng); });
    const Eigen::Vector3d board_point(on_board.x(), on_board.y(), 0.0);
    double pose[kPoseBlockSize] = {
        1.2 * uniform(rng), 1.2 * uniform(rng), 1.2 * uniform(rng),
        0.4 * uniform(rng), 0.4 * uniform(rng), 0.6 + 0.4 * uniform(rng)};
    if (trial == 0) std::fill(pose, pose + 3, 0.0);  // the identity rotation
    const Eigen::Vector2d observed =
        Eigen::Vector2d(600, 450) +
        300 * testing_draws::DrawVector2d([&] { return uniform(rng); });
    std::unique_ptr<ceres::CostFunction> reference(
        ReprojectionError<Model>::CreateAutoDiff(board_point, observed));
    const double* parameters[2] = {intrinsics.data(), pose};
    double r_fast[2], r_ref[2], r_plain[2], r_plain_ref[2];
    double j0_fast[2 * kN], j1_fast[2 * kPoseBlockSize];
    double j0_ref[2 * kN], j1_ref[2 * kPoseBlockSize];
    double* jac_ref[2] = {j0_ref, j1_ref};
    const bool ok_ref = reference->Evaluate(parameters, r_ref, jac_ref);
    ASSERT_EQ(fast(board_point, observed, intrinsics.data(), pose, r_fast,
                   j0_fast, j1_fast),
              ok_ref)
        << "trial " << trial;
    ASSERT_EQ(fast(board_point, observed, intrinsics.data(), pose, r_plain,
                   nullptr, nullptr),
              ok_ref);
    ASSERT_EQ(reference->Evaluate(parameters, r_plain_ref, nullptr), ok_ref);
    if (!ok_ref) continue;
    ++compared;
    for (int r = 0; r < 2; ++r) {
      EXPECT_NEAR(r_fast[r], r_ref[r], residual_tolerance) << "trial " << trial;
      // Without Jacobians both evaluate the functor in plain doubles (whose
      // division rounds differently from the dual numbers').
      EXPECT_NEAR(r_plain[r], r_plain_ref[r], residual_tolerance)
          << "trial " << trial;
    }
    // Rounding relative to the largest entry of each row (the chain rule
    // sums the same products in another order).
    for (int r = 0; r < 2; ++r) {
      double scale = 1e-12;
      for (int k = 0; k < kN; ++k) {
        scale = std::max(scale, std::abs(j0_ref[r * kN + k]));
      }
      for (int k = 0; k < kPoseBlockSize; ++k) {
        scale = std::max(scale, std::abs(j1_ref[r * kPoseBlockSize + k]));
      }
      for (int k = 0; k < kN; ++k) {
        EXPECT_NEAR(j0_fast[r * kN + k], j0_ref[r * kN + k], 1e-12 * scale)
            << "trial " << trial << " row " << r << " intrinsic " << k;
      }
      for (int k = 0; k < kPoseBlockSize; ++k) {
        EXPECT_NEAR(j1_fast[r * kPoseBlockSize + k],
                    j1_ref[r * kPoseBlockSize + k], 1e-12 * scale)
            << "trial " << trial << " row " << r << " pose " << k;
      }
    }
    // Only the pose's Jacobian wanted (the intrinsics held constant).
    double j1_only[2 * kPoseBlockSize];
    ASSERT_TRUE(fast(board_point, observed, intrinsics.data(), pose, r_fast,
                     nullptr, j1_only));
    for (int k = 0; k < 2 * kPoseBlockSize; ++k) {
      EXPECT_EQ(j1_only[k], j1_fast[k]);
    }
  }
  // The scene must exercise the comparison, not skip it.
  EXPECT_GT(compared, 150);
}

TEST(ReprojectionCostTest, MatchesAutomaticDifferentiationForEveryModel) {
  for (CameraModelId id : kAllCameraModels) {
    SCOPED_TRACE(CameraModelName(id));
    DispatchCameraModel(id, [&](auto model) {
      using Model = decltype(model);
      const ReprojectionEvaluator cost =
          [](const Eigen::Vector3d& board_point,
             const Eigen::Vector2d& observed, const double* intrinsics,
             const double* pose, double* residual, double* d_intrinsics,
             double* d_pose) {
            std::unique_ptr<ceres::CostFunction> fast(
                ReprojectionError<Model>::Create(board_point, observed));
            const double* parameters[2] = {intrinsics, pose};
            double* jacobians[2] = {d_intrinsics, d_pose};
            const bool any = d_intrinsics != nullptr || d_pose != nullptr;
            return fast->Evaluate(parameters, residual,
                                  any ? jacobians : nullptr);
          };
      // A splined model's cost goes through its cell's cost, whose residual
      // rounds differently from the dual numbers' projection by a few ulps.
      ExpectSameAsAutoDiff<Model>(ParamsOf(id), cost,
                                  CameraModelIsSplined(id) ? 1e-9 : 0.0);
      return true;
    });
  }
}

// The runtime-model evaluation the capture advice and the rig's joint solve
// use.
TEST(ReprojectionCostTest, RuntimeModelEvaluationMatchesAutomaticDifferentiation) {
  for (CameraModelId id : kAllCameraModels) {
    SCOPED_TRACE(CameraModelName(id));
    const ReprojectionEvaluator runtime =
        [id](const Eigen::Vector3d& board_point,
             const Eigen::Vector2d& observed, const double* intrinsics,
             const double* pose, double* residual, double* d_intrinsics,
             double* d_pose) {
          return EvaluateReprojection(id, intrinsics, pose, board_point,
                                      observed, residual, d_intrinsics,
                                      d_pose);
        };
    DispatchCameraModel(id, [&](auto model) {
      ExpectSameAsAutoDiff<decltype(model)>(
          ParamsOf(id), runtime, CameraModelIsSplined(id) ? 1e-9 : 0.0);
      return true;
    });
  }
}

}  // namespace
}  // namespace puzzlecal
