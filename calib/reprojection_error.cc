#include "calib/reprojection_error.h"

namespace puzzlecal {

template class ReprojectionCost<PinholeRadtanModel>;
template class ReprojectionCost<PinholeRationalModel>;
template class ReprojectionCost<KannalaBrandtModel>;
template class ReprojectionCost<KannalaBrandtNoncentralModel>;

bool ReprojectionJacobians(CameraModelId model, const double* intrinsics,
                           const double* pose,
                           const Eigen::Vector3d& board_point,
                           double* d_intrinsics, double* d_pose) {
  return DispatchCameraModel(model, [&](auto m) {
    using Model = decltype(m);
    // The observed pixel does not change the Jacobians.
    const ReprojectionCost<Model> cost(board_point, Eigen::Vector2d::Zero());
    const double* parameters[2] = {intrinsics, pose};
    double* jacobians[2] = {d_intrinsics, d_pose};
    double residual[2];
    return cost.Evaluate(parameters, residual, jacobians);
  });
}

}  // namespace puzzlecal
