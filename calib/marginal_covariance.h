#ifndef PUZZLECAL_CALIB_MARGINAL_COVARIANCE_H_
#define PUZZLECAL_CALIB_MARGINAL_COVARIANCE_H_

// Covariance of the intrinsics of a bundle adjustment with the poses
// marginalised out, from the Jacobian at the solution, summed in a fixed
// order so that the result does not depend on threads.

#include <ceres/problem.h>

#include <Eigen/Core>
#include <vector>

namespace puzzlecal {

// Inverse of the Schur complement S = A - sum_v B_v C_v^-1 B_v' of J'J
// (A: the intrinsics, C_v: the 6-parameter pose block `poses[v]`), for the
// residual blocks of `problem`. The intrinsics are the parameter blocks
// `intrinsics`, in the order of the intrinsics vector (the blocks the
// problem holds constant left out). `fixed[k]` marks intrinsics held
// constant: they get zero rows and columns of `cov` (which is fixed.size()
// square), and the blocks' manifolds leave exactly them out. False when a
// C_v or S is singular (the smallest eigenvalue of S below
// min_eigenvalue_ratio times the largest).
bool MarginalCovariance(ceres::Problem* problem,
                        const std::vector<double*>& intrinsics,
                        const std::vector<double*>& poses,
                        const std::vector<bool>& fixed,
                        double min_eigenvalue_ratio, Eigen::MatrixXd* cov);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_MARGINAL_COVARIANCE_H_
