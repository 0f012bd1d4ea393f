#include "advice/view_information.h"

#include <Eigen/Cholesky>
#include <vector>

#include "calib/reprojection_error.h"

namespace puzzlecal {
bool ViewInformation(const Camera& camera,
                     const std::vector<Eigen::Vector3d>& board_points,
                     const Eigen::Isometry3d& cam_from_board, double weight,
                     Eigen::MatrixXd* information) {
  const int n = CameraModelNumParams(camera.model);
  if (static_cast<int>(camera.params.size()) != n) return false;
  const PoseBlock pose = PoseBlockFromIsometry(cam_from_board);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n, kPoseBlockSize);
  Eigen::Matrix<double, kPoseBlockSize, kPoseBlockSize> c =
      Eigen::Matrix<double, kPoseBlockSize, kPoseBlockSize>::Zero();
  Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::RowMajor> j_intrinsics(2, n);
  Eigen::Matrix<double, 2, kPoseBlockSize, Eigen::RowMajor> j_pose;
  // A splined model's corner moves only the knots around it: the products
  // are added over the Jacobian's non-zero columns only (about 40 of 211),
  // the other entries' products being exactly 0.
  std::vector<int> columns;
  columns.reserve(n);
  int used = 0;
  for (const Eigen::Vector3d& point : board_points) {
    if (!ReprojectionJacobians(camera.model, camera.params.data(), pose.data(),
                               point, j_intrinsics.data(), j_pose.data()) ||
        !j_intrinsics.allFinite() || !j_pose.allFinite()) {
      continue;
    }
    columns.clear();
    for (int k = 0; k < n; ++k) {
      if (j_intrinsics(0, k) != 0 || j_intrinsics(1, k) != 0) {
        columns.push_back(k);
      }
    }
    for (int p : columns) {
      for (int q : columns) {
        a(p, q) += j_intrinsics(0, p) * j_intrinsics(0, q) +
                   j_intrinsics(1, p) * j_intrinsics(1, q);
      }
      b.row(p) += j_intrinsics(0, p) * j_pose.row(0) +
                  j_intrinsics(1, p) * j_pose.row(1);
    }
    c.noalias() += j_pose.transpose() * j_pose;
    ++used;
  }
  if (used < 3) return false;
  const Eigen::LDLT<Eigen::Matrix<double, kPoseBlockSize, kPoseBlockSize>> ldlt(
      c);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) {
    return false;
  }
  *information = weight * (a - b * ldlt.solve(b.transpose()));
  return information->allFinite();
}

}  // namespace puzzlecal
