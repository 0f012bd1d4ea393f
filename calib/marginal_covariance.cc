#include "calib/marginal_covariance.h"

#include <ceres/crs_matrix.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <utility>
#include <vector>

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
  // A row's intrinsics entries as (column, value) pairs: a splined model's
  // row touches about 40 of its 210 intrinsics, and the products of the
  // zeros would cost 25 times the rest.
  std::vector<std::pair<int, double>> j_int;
  j_int.reserve(n);
  Eigen::Matrix<double, 6, 1> j_pose;
  for (int row = 0; row < jacobian.num_rows; ++row) {
    j_int.clear();
    j_pose.setZero();
    int pose = -1;
    for (int e = jacobian.rows[row]; e < jacobian.rows[row + 1]; ++e) {
      const int col = jacobian.cols[e];
      if (col < n) {
        if (jacobian.values[e] != 0)
          j_int.emplace_back(col, jacobian.values[e]);
      } else {
        pose = (col - n) / kPoseSize;
        j_pose((col - n) % kPoseSize) = jacobian.values[e];
      }
    }
    for (const auto& [i, value_i] : j_int) {
      for (const auto& [j, value_j] : j_int) a(i, j) += value_i * value_j;
    }
    if (pose >= 0) {
      for (const auto& [i, value_i] : j_int) {
        b[pose].row(i) += value_i * j_pose.transpose();
      }
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
// unless the intrinsics are undetermined. The test is on S scaled to a unit
// diagonal (D S D, D = diag(S)^-1/2), so that it does not depend on the
// parameters' units: a pupil shift in metres next to spline values in
// radians and focal lengths in pixels spans 14 orders of magnitude in S's
// eigenvalues although every parameter is determined, while a direction
// the data leave free has a near-zero eigenvalue in any units.
bool InverseIfRegular(const Eigen::MatrixXd& s, double min_eigenvalue_ratio,
                      Eigen::MatrixXd* inverse) {
  const int n = static_cast<int>(s.rows());
  const Eigen::VectorXd diagonal = s.diagonal();
  if (!(diagonal.minCoeff() > 0)) return false;
  const Eigen::VectorXd d = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = d.asDiagonal() * s * d.asDiagonal();
  // The eigenvalues alone for the test (a third of the work of the
  // eigenvectors too), then the inverse by Cholesky.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled,
                                                     Eigen::EigenvaluesOnly);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::VectorXd values = eig.eigenvalues();
  if (!(values(0) > min_eigenvalue_ratio * values(n - 1))) return false;
  const Eigen::LLT<Eigen::MatrixXd> llt(scaled);
  if (llt.info() != Eigen::Success) return false;
  *inverse = d.asDiagonal() * llt.solve(Eigen::MatrixXd::Identity(n, n)) *
             d.asDiagonal();
  return true;
}

}  // namespace

bool MarginalCovariance(ceres::Problem* problem,
                        const std::vector<double*>& intrinsics,
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
  evaluate.parameter_blocks = intrinsics;
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
