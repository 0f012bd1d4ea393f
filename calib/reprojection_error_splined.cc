// The splined models' ReprojectionCost (the rig's joint solve, the capture
// advice and the evidence take a splined corner's Jacobians through it; the
// single-camera solve uses SplinedReprojectionCost directly): through the
// cost of the point's spline cell (calib/splined_reprojection.h), with
// dual numbers over kannala-brandt's part, the pupil and the point and the
// 4 x 4 knots' B-spline weights written directly, instead of dual numbers
// over all of the model's 200-odd parameters. The same derivatives
// (ReprojectionCostTest compares them with automatic differentiation) at a
// tenth of the cost; d residual / d intrinsics is zero outside the cell's
// knots.

#include <algorithm>
#include <vector>

#include "calib/reprojection_error.h"
#include "calib/splined_reprojection.h"

namespace puzzlecal {
namespace {

template <typename Model>
bool EvaluateInCell(const Eigen::Vector3d& board_point,
                    const Eigen::Vector2d& observed,
                    double const* const* parameters, double* residual,
                    double** jacobians) {
  using Cost = SplinedReprojectionCost<Model>;
  const double* intrinsics = parameters[0];
  const double* pose = parameters[1];
  const Eigen::Vector3d point_cam = IsometryFromPoseBlock(pose) * board_point;
  const Cost cost(board_point, observed,
                  SplineCellOf<Model>(intrinsics, point_cam));
  // The cost's blocks point into the caller's vectors; it only reads them.
  const std::vector<double*> blocks = cost.Blocks(
      const_cast<double*>(intrinsics), const_cast<double*>(pose));
  double* d_intrinsics = jacobians != nullptr ? jacobians[0] : nullptr;
  double* d_pose = jacobians != nullptr ? jacobians[1] : nullptr;
  if (d_intrinsics == nullptr && d_pose == nullptr) {
    return cost.Evaluate(blocks.data(), residual, nullptr);
  }
  double d_base[2 * Cost::kBase];
  double d_knots[Cost::kNumKnotBlocks][2 * Cost::kKnotRowSize];
  double d_pupil[2 * 2];
  double d_pose_unwanted[2 * kPoseBlockSize];
  std::vector<double*> block_jacobians = {
      d_base, d_pose != nullptr ? d_pose : d_pose_unwanted};
  for (auto& row : d_knots) block_jacobians.push_back(row);
  if (Cost::kPupilSize > 0) block_jacobians.push_back(d_pupil);
  if (!cost.Evaluate(blocks.data(), residual, block_jacobians.data())) {
    return false;
  }
  if (d_intrinsics == nullptr) return true;
  constexpr int n = Model::kNumParams;
  std::fill(d_intrinsics, d_intrinsics + 2 * n, 0.0);
  const int first_row = cost.cell()[0];
  for (int r = 0; r < 2; ++r) {
    double* row = d_intrinsics + r * n;
    std::copy(d_base + r * Cost::kBase, d_base + (r + 1) * Cost::kBase, row);
    for (int a = 0; a < Cost::kNumKnotBlocks; ++a) {
      std::copy(d_knots[a] + r * Cost::kKnotRowSize,
                d_knots[a] + (r + 1) * Cost::kKnotRowSize,
                row + Model::kSplineBegin +
                    Cost::kKnotRowSize * (first_row + a));
    }
    for (int k = 0; k < Cost::kPupilSize; ++k) {
      row[Model::kPupilIndex + k] = d_pupil[r * Cost::kPupilSize + k];
    }
  }
  return true;
}

}  // namespace

template <>
bool ReprojectionCost<KannalaBrandtSplinedModel>::Evaluate(
    double const* const* parameters, double* residuals,
    double** jacobians) const {
  return EvaluateInCell<KannalaBrandtSplinedModel>(
      functor_.board_point(), functor_.observed_pixel(), parameters, residuals,
      jacobians);
}

template <>
bool ReprojectionCost<KannalaBrandtSplinedNoncentralModel>::Evaluate(
    double const* const* parameters, double* residuals,
    double** jacobians) const {
  return EvaluateInCell<KannalaBrandtSplinedNoncentralModel>(
      functor_.board_point(), functor_.observed_pixel(), parameters, residuals,
      jacobians);
}

template class ReprojectionCost<KannalaBrandtSplinedModel>;
template class ReprojectionCost<KannalaBrandtSplinedNoncentralModel>;

}  // namespace puzzlecal
