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
  // are formed over the Jacobian's non-zero columns (about 40 of 211) and
  // added into their rows and columns, the other entries' products being
  // exactly 0.
  std::vector<int> columns;
  columns.reserve(n);
  Eigen::Matrix<double, 2, Eigen::Dynamic> j_columns(2, n);
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
    const int m = static_cast<int>(columns.size());
    j_columns.resize(2, m);
    for (int k = 0; k < m; ++k) j_columns.col(k) = j_intrinsics.col(columns[k]);
    const Eigen::MatrixXd a_part = j_columns.transpose() * j_columns;
    const Eigen::Matrix<double, Eigen::Dynamic, kPoseBlockSize> b_part =
        j_columns.transpose() * j_pose;
    for (int r = 0; r < m; ++r) {
      for (int k = 0; k < m; ++k) a(columns[r], columns[k]) += a_part(r, k);
      b.row(columns[r]) += b_part.row(r);
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
