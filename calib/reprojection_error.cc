#include "calib/reprojection_error.h"

#include <ceres/rotation.h>

#include "calib/reprojection_cost_impl.h"

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

bool EvaluateReprojection(CameraModelId model, const double* intrinsics,
                          const double* pose,
                          const Eigen::Vector3d& board_point,
                          const Eigen::Vector2d& observed, double* residual,
                          double* d_intrinsics, double* d_pose) {
  return DispatchCameraModel(model, [&](auto m) {
    using Model = decltype(m);
    const ReprojectionCost<Model> cost(board_point, observed);
    const double* parameters[2] = {intrinsics, pose};
    double* jacobians[2] = {d_intrinsics, d_pose};
    const bool any = d_intrinsics != nullptr || d_pose != nullptr;
    return cost.Evaluate(parameters, residual, any ? jacobians : nullptr);
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
