#ifndef PUZZLECAL_CALIB_REPROJECTION_COST_IMPL_H_
#define PUZZLECAL_CALIB_REPROJECTION_COST_IMPL_H_

// ReprojectionCost<Model>::Evaluate, for the file that instantiates the
// models' costs (calib/reprojection_error.cc; the splined models' Evaluate
// is specialized in reprojection_error_splined.cc) and nothing else: every
// other file links those instances.

#include <ceres/jet.h>
#include <ceres/rotation.h>

#include "calib/reprojection_error.h"

namespace puzzlecal {

template <typename Model>
bool ReprojectionCost<Model>::Evaluate(double const* const* parameters,
                                       double* residuals,
                                       double** jacobians) const {
  const double* intrinsics = parameters[0];
  const double* pose = parameters[1];
  if (jacobians == nullptr ||
      (jacobians[0] == nullptr && jacobians[1] == nullptr)) {
    return functor_(intrinsics, pose, residuals);
  }
  // p and d p / d w, 3 wide.
  const TurnedBoardPoint turned = TurnBoardPoint(pose, functor_.board_point());
  // d pixel / d (intrinsics, p), N + 3 wide.
  using ProjectionJet = ceres::Jet<double, kNumParams + 3>;
  ProjectionJet params[kNumParams];
  for (int k = 0; k < kNumParams; ++k) {
    params[k] = ProjectionJet(intrinsics[k], k);
  }
  ProjectionJet point_cam[3];
  for (int j = 0; j < 3; ++j) {
    point_cam[j] = ProjectionJet(turned.point(j) + pose[3 + j], kNumParams + j);
  }
  ProjectionJet pixel[2];
  if (!Model::Project(params, point_cam, pixel)) return false;
  const Eigen::Vector2d& observed = functor_.observed_pixel();
  residuals[0] = pixel[0].a - observed.x();
  residuals[1] = pixel[1].a - observed.y();
  for (int r = 0; r < 2; ++r) {
    if (jacobians[0] != nullptr) {
      for (int k = 0; k < kNumParams; ++k) {
        jacobians[0][r * kNumParams + k] = pixel[r].v[k];
      }
    }
    if (jacobians[1] != nullptr) {
      const double d_pixel_d_point[3] = {pixel[r].v[kNumParams],
                                         pixel[r].v[kNumParams + 1],
                                         pixel[r].v[kNumParams + 2]};
      PoseJacobianRow(d_pixel_d_point, turned,
                      jacobians[1] + r * kPoseBlockSize);
    }
  }
  return true;
}

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_REPROJECTION_COST_IMPL_H_
