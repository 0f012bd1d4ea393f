#include "calib/reprojection_error.h"

#include <ceres/rotation.h>

#include <algorithm>
#include <vector>

#include "calib/reprojection_cost_impl.h"
#include "calib/splined_reprojection.h"

namespace puzzlecal {

PoseBlock PoseBlockFromIsometry(const Eigen::Isometry3d& transform) {
  PoseBlock pose;
  const Eigen::Matrix3d rotation = transform.linear();
  ceres::RotationMatrixToAngleAxis(
      ceres::ColumnMajorAdapter3x3(rotation.data()), pose.data());
  for (int k = 0; k < 3; ++k) pose[3 + k] = transform.translation()(k);
  return pose;
}

Eigen::Isometry3d IsometryFromPoseBlock(const double* pose) {
  Eigen::Matrix3d rotation;
  ceres::AngleAxisToRotationMatrix(
      pose, ceres::ColumnMajorAdapter3x3(rotation.data()));
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.linear() = rotation;
  result.translation() = Eigen::Vector3d(pose[3], pose[4], pose[5]);
  return result;
}

TurnedBoardPoint TurnBoardPoint(const double* angle_axis,
                                const Eigen::Vector3d& board_point) {
  using RotationJet = ceres::Jet<double, 3>;
  const RotationJet w[3] = {RotationJet(angle_axis[0], 0),
                            RotationJet(angle_axis[1], 1),
                            RotationJet(angle_axis[2], 2)};
  const RotationJet x[3] = {RotationJet(board_point.x()),
                            RotationJet(board_point.y()),
                            RotationJet(board_point.z())};
  RotationJet turned[3];
  ceres::AngleAxisRotatePoint(w, x, turned);
  TurnedBoardPoint result;
  for (int j = 0; j < 3; ++j) {
    result.point(j) = turned[j].a;
    result.d_point_d_w.row(j) = turned[j].v.transpose();
  }
  return result;
}

void PoseJacobianRow(const double* d_residual_d_point,
                     const TurnedBoardPoint& turned, double* row) {
  for (int c = 0; c < 3; ++c) {
    double sum = 0;
    for (int j = 0; j < 3; ++j) {
      sum += d_residual_d_point[j] * turned.d_point_d_w(j, c);
    }
    row[c] = sum;
    row[3 + c] = d_residual_d_point[c];
  }
}

template class ReprojectionCost<PinholeRadtanModel>;
template class ReprojectionCost<PinholeRationalModel>;
template class ReprojectionCost<KannalaBrandtModel>;
template class ReprojectionCost<KannalaBrandtNoncentralModel>;

namespace {

// A splined model's reprojection through the cost of the point's spline
// cell (calib/splined_reprojection.h): dual numbers over kannala-brandt's
// part, the pupil and the point, and the 4 x 4 knots' B-spline weights
// written directly, instead of dual numbers over all of the model's 200-odd
// parameters; d_intrinsics is zero outside the cell's knots. The same
// derivatives (ReprojectionCostTest compares them with automatic
// differentiation), at a tenth of the cost: the capture advice and the
// rig's joint solve take every splined corner's Jacobian through here.
template <typename Model>
bool EvaluateSplinedReprojection(const double* intrinsics, const double* pose,
                                 const Eigen::Vector3d& board_point,
                                 const Eigen::Vector2d& observed,
                                 double* residual, double* d_intrinsics,
                                 double* d_pose) {
  using Cost = SplinedReprojectionCost<Model>;
  const Eigen::Vector3d point_cam = IsometryFromPoseBlock(pose) * board_point;
  const Cost cost(board_point, observed,
                  SplineCellOf<Model>(intrinsics, point_cam));
  // The cost's blocks point into the caller's vectors; it only reads them.
  const std::vector<double*> blocks = cost.Blocks(
      const_cast<double*>(intrinsics), const_cast<double*>(pose));
  if (d_intrinsics == nullptr && d_pose == nullptr) {
    return cost.Evaluate(blocks.data(), residual, nullptr);
  }
  double d_base[2 * Cost::kBase];
  double d_knots[Cost::kNumKnotBlocks][2 * Cost::kKnotRowSize];
  double d_pupil[2 * 2];
  double d_pose_local[2 * kPoseBlockSize];
  std::vector<double*> jacobians = {d_base,
                                    d_pose != nullptr ? d_pose : d_pose_local};
  for (auto& row : d_knots) jacobians.push_back(row);
  if (Cost::kPupilSize > 0) jacobians.push_back(d_pupil);
  if (!cost.Evaluate(blocks.data(), residual, jacobians.data())) return false;
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

bool EvaluateReprojection(CameraModelId model, const double* intrinsics,
                          const double* pose,
                          const Eigen::Vector3d& board_point,
                          const Eigen::Vector2d& observed, double* residual,
                          double* d_intrinsics, double* d_pose) {
  return DispatchCameraModel(model, [&](auto m) {
    using Model = decltype(m);
    if constexpr (CameraModelIsSplinedModel<Model>()) {
      return EvaluateSplinedReprojection<Model>(intrinsics, pose, board_point,
                                                observed, residual,
                                                d_intrinsics, d_pose);
    } else {
      const ReprojectionCost<Model> cost(board_point, observed);
      const double* parameters[2] = {intrinsics, pose};
      double* jacobians[2] = {d_intrinsics, d_pose};
      const bool any = d_intrinsics != nullptr || d_pose != nullptr;
      return cost.Evaluate(parameters, residual, any ? jacobians : nullptr);
    }
  });
}

bool ReprojectionJacobians(CameraModelId model, const double* intrinsics,
                           const double* pose,
                           const Eigen::Vector3d& board_point,
                           double* d_intrinsics, double* d_pose) {
  // The observed pixel does not change the Jacobians.
  double residual[2];
  return EvaluateReprojection(model, intrinsics, pose, board_point,
                              Eigen::Vector2d::Zero(), residual, d_intrinsics,
                              d_pose);
}

}  // namespace puzzlecal
