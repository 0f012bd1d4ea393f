#include "calib/marginal_covariance.h"

#include <ceres/cost_function.h>
#include <ceres/problem.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <unordered_map>
#include <utility>
#include <vector>

namespace puzzlecal {
namespace {

constexpr int kPoseSize = 6;

// Where a parameter block's Jacobian columns go: the free intrinsics'
// columns from `column` on, or pose `pose`'s 6 columns; neither for a block
// outside both (the problem's other blocks, held as they are).
struct BlockColumns {
  int column = -1;
  int pose = -1;
  int tangent_size = 0;
};

// The accumulation of S = A - sum_v B_v C_v^-1 B_v' over the residual
// blocks, in the order the problem holds them.
class SchurAccumulator {
 public:
  SchurAccumulator(int n, int num_poses)
      : a_(Eigen::MatrixXd::Zero(n, n)),
        b_(num_poses, Eigen::MatrixXd::Zero(n, kPoseSize)),
        c_(num_poses, Eigen::Matrix<double, kPoseSize, kPoseSize>::Zero()) {
    j_intrinsics_.reserve(n);
  }

  // Residual `row` of a residual block: its Jacobian blocks `jacobians`
  // (row-major, num_residuals rows, nullptr for blocks without columns).
  void AddRow(const std::vector<BlockColumns>& blocks,
              const std::vector<double*>& jacobians, int row) {
    j_intrinsics_.clear();
    Eigen::Matrix<double, kPoseSize, 1> j_pose =
        Eigen::Matrix<double, kPoseSize, 1>::Zero();
    int pose = -1;
    for (size_t b = 0; b < blocks.size(); ++b) {
      if (jacobians[b] == nullptr) continue;
      const BlockColumns& block = blocks[b];
      const double* values = jacobians[b] + row * block.tangent_size;
      if (block.pose >= 0) {
        pose = block.pose;
        for (int k = 0; k < kPoseSize; ++k) j_pose(k) += values[k];
        continue;
      }
      // Only the non-zero entries: a splined model's row touches about 40
      // of its 210 intrinsics, and the products of the zeros would cost 25
      // times the rest.
      for (int k = 0; k < block.tangent_size; ++k) {
        if (values[k] != 0) {
          j_intrinsics_.emplace_back(block.column + k, values[k]);
        }
      }
    }
    for (const auto& [i, value_i] : j_intrinsics_) {
      for (const auto& [j, value_j] : j_intrinsics_) {
        a_(i, j) += value_i * value_j;
      }
    }
    if (pose >= 0) {
      for (const auto& [i, value_i] : j_intrinsics_) {
        b_[pose].row(i) += value_i * j_pose.transpose();
      }
      c_[pose].noalias() += j_pose * j_pose.transpose();
    }
  }

  // S; false when a C_v is singular.
  bool Finish(Eigen::MatrixXd* s) {
    for (size_t v = 0; v < c_.size(); ++v) {
      const Eigen::LDLT<Eigen::Matrix<double, kPoseSize, kPoseSize>> ldlt(
          c_[v]);
      if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) {
        return false;
      }
      a_.noalias() -= b_[v] * ldlt.solve(b_[v].transpose());
    }
    *s = a_;
    return true;
  }

 private:
  Eigen::MatrixXd a_;
  std::vector<Eigen::MatrixXd> b_;
  std::vector<Eigen::Matrix<double, kPoseSize, kPoseSize>> c_;
  std::vector<std::pair<int, double>> j_intrinsics_;
};

// S from the Jacobian of every residual block at the current values (after
// the loss function and in the blocks' tangent spaces, as the solver sees
// it), evaluated block by block: a compressed Jacobian of the whole problem
// (ceres::Problem::Evaluate) cost more to build than the rest of the
// covariance. n: the intrinsics' free columns. False when a residual block
// cannot be evaluated or a C_v is singular.
bool SchurComplement(ceres::Problem* problem,
                     const std::vector<double*>& intrinsics,
                     const std::vector<double*>& poses, int n,
                     Eigen::MatrixXd* s) {
  std::unordered_map<const double*, BlockColumns> columns;
  int column = 0;
  for (double* block : intrinsics) {
    BlockColumns& entry = columns[block];
    entry.column = column;
    entry.tangent_size = problem->ParameterBlockTangentSize(block);
    column += entry.tangent_size;
  }
  if (column != n) return false;
  for (size_t v = 0; v < poses.size(); ++v) {
    BlockColumns& entry = columns[poses[v]];
    entry.pose = static_cast<int>(v);
    entry.tangent_size = problem->ParameterBlockTangentSize(poses[v]);
    if (entry.tangent_size != kPoseSize) return false;
  }
  std::vector<ceres::ResidualBlockId> residual_blocks;
  problem->GetResidualBlocks(&residual_blocks);
  SchurAccumulator accumulator(n, static_cast<int>(poses.size()));
  std::vector<double*> parameter_blocks;
  std::vector<BlockColumns> blocks;
  std::vector<double*> jacobians;
  std::vector<double> storage, residuals;
  bool first = true;
  for (ceres::ResidualBlockId id : residual_blocks) {
    problem->GetParameterBlocksForResidualBlock(id, &parameter_blocks);
    const int num_residuals =
        problem->GetCostFunctionForResidualBlock(id)->num_residuals();
    blocks.assign(parameter_blocks.size(), BlockColumns());
    size_t size = 0;
    for (size_t b = 0; b < parameter_blocks.size(); ++b) {
      const auto found = columns.find(parameter_blocks[b]);
      if (found == columns.end() ||
          problem->IsParameterBlockConstant(parameter_blocks[b])) {
        continue;
      }
      blocks[b] = found->second;
      size += static_cast<size_t>(num_residuals) * blocks[b].tangent_size;
    }
    storage.resize(size);
    residuals.resize(num_residuals);
    jacobians.assign(parameter_blocks.size(), nullptr);
    size_t offset = 0;
    for (size_t b = 0; b < parameter_blocks.size(); ++b) {
      if (blocks[b].tangent_size == 0) continue;
      jacobians[b] = storage.data() + offset;
      offset += static_cast<size_t>(num_residuals) * blocks[b].tangent_size;
    }
    double cost = 0;
    // The first evaluation tells an evaluation callback that the values are
    // new (it then evaluates every corner ahead); the rest read them.
    const bool ok =
        first ? problem->EvaluateResidualBlock(id, /*apply_loss_function=*/true,
                                               &cost, residuals.data(),
                                               jacobians.data())
              : problem->EvaluateResidualBlockAssumingParametersUnchanged(
                    id, /*apply_loss_function=*/true, &cost,
                    residuals.data(), jacobians.data());
    first = false;
    if (!ok) return false;
    for (int row = 0; row < num_residuals; ++row) {
      accumulator.AddRow(blocks, jacobians, row);
    }
  }
  return accumulator.Finish(s);
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
  Eigen::MatrixXd s, inverse;
  if (!SchurComplement(problem, intrinsics, poses, n, &s) ||
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
