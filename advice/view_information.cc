#include "advice/view_information.h"

#include <ceres/rotation.h>

#include <Eigen/Cholesky>

#include "calib/reprojection_error.h"

namespace puzzlecal {
namespace {

template <typename Model>
bool ModelViewInformation(const Camera& camera,
                          const std::vector<Eigen::Vector3d>& board_points,
                          const Eigen::Isometry3d& cam_from_board,
                          double weight, Eigen::MatrixXd* information) {
  constexpr int kN = Model::kNumParams;
  double pose[kPoseBlockSize];
  const Eigen::Matrix3d rotation = cam_from_board.linear();
  ceres::RotationMatrixToAngleAxis(
      ceres::ColumnMajorAdapter3x3(rotation.data()), pose);
  for (int k = 0; k < 3; ++k) pose[3 + k] = cam_from_board.translation()(k);

  Eigen::Matrix<double, kN, kN> a = Eigen::Matrix<double, kN, kN>::Zero();
  Eigen::Matrix<double, kN, kPoseBlockSize> b =
      Eigen::Matrix<double, kN, kPoseBlockSize>::Zero();
  Eigen::Matrix<double, kPoseBlockSize, kPoseBlockSize> c =
      Eigen::Matrix<double, kPoseBlockSize, kPoseBlockSize>::Zero();
  Eigen::Matrix<double, 2, kN, Eigen::RowMajor> j_intrinsics;
  Eigen::Matrix<double, 2, kPoseBlockSize, Eigen::RowMajor> j_pose;
  const double* parameters[2] = {camera.params.data(), pose};
  double* jacobians[2] = {j_intrinsics.data(), j_pose.data()};
  int used = 0;
  for (const Eigen::Vector3d& point : board_points) {
    Eigen::Vector2d pixel;
    if (!camera.Project(cam_from_board * point, &pixel)) continue;
    const ReprojectionCost<Model> cost(point, pixel);
    double residual[2];
    if (!cost.Evaluate(parameters, residual, jacobians) ||
        !j_intrinsics.allFinite() || !j_pose.allFinite()) {
      continue;
    }
    a.noalias() += j_intrinsics.transpose() * j_intrinsics;
    b.noalias() += j_intrinsics.transpose() * j_pose;
    c.noalias() += j_pose.transpose() * j_pose;
    ++used;
  }
  if (used < 3) return false;
  const Eigen::LDLT<Eigen::Matrix<double, kPoseBlockSize, kPoseBlockSize>> ldlt(
      c);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) {
    return false;
  }
  const Eigen::Matrix<double, kN, kN> schur = a - b * ldlt.solve(b.transpose());
  *information = weight * schur;
  return information->allFinite();
}

}  // namespace

bool ViewInformation(const Camera& camera,
                     const std::vector<Eigen::Vector3d>& board_points,
                     const Eigen::Isometry3d& cam_from_board, double weight,
                     Eigen::MatrixXd* information) {
  if (static_cast<int>(camera.params.size()) !=
      CameraModelNumParams(camera.model)) {
    return false;
  }
  return DispatchCameraModel(camera.model, [&](auto model) {
    return ModelViewInformation<decltype(model)>(
        camera, board_points, cam_from_board, weight, information);
  });
}

}  // namespace puzzlecal
