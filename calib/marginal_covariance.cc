#include "calib/marginal_covariance.h"

#include <ceres/crs_matrix.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace puzzlecal {
namespace {

constexpr int kPoseSize = 6;

// S = A - sum_v B_v C_v^-1 B_v' from the Jacobian, whose first n columns are
// the free intrinsics and the rest the poses, 6 columns each. False when a
// C_v is singular.
bool SchurComplement(const ceres::CRSMatrix& jacobian, int n, int num_poses,
                     Eigen::MatrixXd* s) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::MatrixXd> b(num_poses, Eigen::MatrixXd::Zero(n, 6));
  std::vector<Eigen::Matrix<double, 6, 6>> c(
      num_poses, Eigen::Matrix<double, 6, 6>::Zero());
  Eigen::VectorXd j_int(n);
  Eigen::Matrix<double, 6, 1> j_pose;
  for (int row = 0; row < jacobian.num_rows; ++row) {
    j_int.setZero();
    j_pose.setZero();
    int pose = -1;
    for (int e = jacobian.rows[row]; e < jacobian.rows[row + 1]; ++e) {
      const int col = jacobian.cols[e];
      if (col < n) {
        j_int(col) = jacobian.values[e];
      } else {
        pose = (col - n) / kPoseSize;
        j_pose((col - n) % kPoseSize) = jacobian.values[e];
      }
    }
    a.noalias() += j_int * j_int.transpose();
    if (pose >= 0) {
      b[pose].noalias() += j_int * j_pose.transpose();
      c[pose].noalias() += j_pose * j_pose.transpose();
    }
  }
  for (int v = 0; v < num_poses; ++v) {
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(c[v]);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) {
      return false;
    }
    a.noalias() -= b[v] * ldlt.solve(b[v].transpose());
  }
  *s = a;
  return true;
}

// S^-1 unless S is (numerically) singular: S is symmetric positive definite
// unless the intrinsics are undetermined.
bool InverseIfRegular(const Eigen::MatrixXd& s, double min_eigenvalue_ratio,
                      Eigen::MatrixXd* inverse) {
  const int n = static_cast<int>(s.rows());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(s);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::VectorXd values = eig.eigenvalues();
  if (!(values(0) > min_eigenvalue_ratio * values(n - 1))) return false;
  *inverse = eig.eigenvectors() * values.cwiseInverse().asDiagonal() *
             eig.eigenvectors().transpose();
  return true;
}

}  // namespace

bool MarginalCovariance(ceres::Problem* problem, double* intrinsics,
                        const std::vector<double*>& poses,
                        const std::vector<bool>& fixed,
                        double min_eigenvalue_ratio, Eigen::MatrixXd* cov) {
  const int num_params = static_cast<int>(fixed.size());
  std::vector<int> free_index;
  for (int k = 0; k < num_params; ++k) {
    if (!fixed[k]) free_index.push_back(k);
  }
  const int n = static_cast<int>(free_index.size());
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks.push_back(intrinsics);
  for (double* pose : poses) evaluate.parameter_blocks.push_back(pose);
  evaluate.num_threads = 1;
  ceres::CRSMatrix jacobian;
  if (!problem->Evaluate(evaluate, nullptr, nullptr, nullptr, &jacobian)) {
    return false;
  }
  const int num_poses = static_cast<int>(poses.size());
  if (jacobian.num_cols != n + kPoseSize * num_poses) return false;
  Eigen::MatrixXd s, inverse;
  if (!SchurComplement(jacobian, n, num_poses, &s) ||
      !InverseIfRegular(s, min_eigenvalue_ratio, &inverse)) {
    return false;
  }
  *cov = Eigen::MatrixXd::Zero(num_params, num_params);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      (*cov)(free_index[i], free_index[j]) = inverse(i, j);
    }
  }
  return true;
}

}  // namespace puzzlecal
