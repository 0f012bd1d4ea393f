#ifndef PUZZLECAL_CALIB_REPROJECTION_ERROR_H_
#define PUZZLECAL_CALIB_REPROJECTION_ERROR_H_

// Ceres cost functor: the pixel error of one board corner seen in one view.
// Parameter blocks: the camera model's intrinsics (Model::kNumParams values)
// and the view's cam_from_board pose as angle-axis (3) + translation (3).

#include <ceres/autodiff_cost_function.h>
#include <ceres/jet.h>
#include <ceres/rotation.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "camera/camera_models.h"

namespace puzzlecal {

// Pose block layout: angle-axis rotation then translation (metres).
inline constexpr int kPoseBlockSize = 6;
using PoseBlock = std::array<double, kPoseBlockSize>;

// A rigid transform as a pose block and back.
PoseBlock PoseBlockFromIsometry(const Eigen::Isometry3d& transform);
Eigen::Isometry3d IsometryFromPoseBlock(const double* pose);

template <typename Model>
class ReprojectionError {
 public:
  ReprojectionError(const Eigen::Vector3d& board_point,
                    const Eigen::Vector2d& observed_pixel)
      : board_point_(board_point), observed_pixel_(observed_pixel) {}

  template <typename T>
  bool operator()(const T* intrinsics, const T* cam_from_board,
                  T* residuals) const {
    const T point_board[3] = {T(board_point_.x()), T(board_point_.y()),
                              T(board_point_.z())};
    T point_cam[3];
    ceres::AngleAxisRotatePoint(cam_from_board, point_board, point_cam);
    point_cam[0] += cam_from_board[3];
    point_cam[1] += cam_from_board[4];
    point_cam[2] += cam_from_board[5];
    T pixel[2];
    // A point the model cannot project (behind a pinhole camera) makes the
    // step that led there invalid; Ceres then shrinks the step.
    if (!Model::Project(intrinsics, point_cam, pixel)) return false;
    residuals[0] = pixel[0] - T(observed_pixel_.x());
    residuals[1] = pixel[1] - T(observed_pixel_.y());
    return true;
  }

  // The cost function the solvers use: ReprojectionCost (below), the same
  // residual with its Jacobians by the chain rule through the camera-frame
  // point.
  static ceres::CostFunction* Create(const Eigen::Vector3d& board_point,
                                     const Eigen::Vector2d& observed_pixel);

  // Automatic differentiation over all N + 6 values at once: the reference
  // the tests compare ReprojectionCost with.
  const Eigen::Vector3d& board_point() const { return board_point_; }
  const Eigen::Vector2d& observed_pixel() const { return observed_pixel_; }

  static ceres::CostFunction* CreateAutoDiff(
      const Eigen::Vector3d& board_point,
      const Eigen::Vector2d& observed_pixel) {
    return new ceres::AutoDiffCostFunction<ReprojectionError, 2,
                                           Model::kNumParams, kPoseBlockSize>(
        new ReprojectionError(board_point, observed_pixel));
  }

 private:
  Eigen::Vector3d board_point_;
  Eigen::Vector2d observed_pixel_;
};

// ReprojectionError's residual with its Jacobians by the chain rule through
// the camera-frame point p = R(w) X + t: automatic differentiation of the
// rotation over the 3 angle-axis values, and of the projection over the
// intrinsics and p (N + 3 values), instead of one pass of N + 6-wide dual
// numbers through both. The rotation is then differentiated 3 wide instead
// of N + 6 wide, and the projection N + 3 wide: the Jacobian costs about
// half. The residual is computed exactly as ReprojectionError computes it.
template <typename Model>
class ReprojectionCost
    : public ceres::SizedCostFunction<2, Model::kNumParams, kPoseBlockSize> {
 public:
  static constexpr int kNumParams = Model::kNumParams;

  ReprojectionCost(const Eigen::Vector3d& board_point,
                   const Eigen::Vector2d& observed_pixel)
      : functor_(board_point, observed_pixel) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* intrinsics = parameters[0];
    const double* pose = parameters[1];
    if (jacobians == nullptr ||
        (jacobians[0] == nullptr && jacobians[1] == nullptr)) {
      return functor_(intrinsics, pose, residuals);
    }
    // d p / d w, 3 wide.
    using RotationJet = ceres::Jet<double, 3>;
    const RotationJet w[3] = {RotationJet(pose[0], 0), RotationJet(pose[1], 1),
                              RotationJet(pose[2], 2)};
    const Eigen::Vector3d& board_point = functor_.board_point();
    const RotationJet x[3] = {RotationJet(board_point.x()),
                              RotationJet(board_point.y()),
                              RotationJet(board_point.z())};
    RotationJet rotated[3];
    ceres::AngleAxisRotatePoint(w, x, rotated);
    // d pixel / d (intrinsics, p), N + 3 wide.
    using ProjectionJet = ceres::Jet<double, kNumParams + 3>;
    ProjectionJet params[kNumParams];
    for (int k = 0; k < kNumParams; ++k) {
      params[k] = ProjectionJet(intrinsics[k], k);
    }
    ProjectionJet point_cam[3];
    for (int j = 0; j < 3; ++j) {
      point_cam[j] = ProjectionJet(rotated[j].a + pose[3 + j], kNumParams + j);
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
        double* row = jacobians[1] + r * kPoseBlockSize;
        for (int c = 0; c < 3; ++c) {
          double sum = 0;
          for (int j = 0; j < 3; ++j) {
            sum += pixel[r].v[kNumParams + j] * rotated[j].v[c];
          }
          row[c] = sum;
          row[3 + c] = pixel[r].v[kNumParams + c];
        }
      }
    }
    return true;
  }

 private:
  ReprojectionError<Model> functor_;
};

template <typename Model>
ceres::CostFunction* ReprojectionError<Model>::Create(
    const Eigen::Vector3d& board_point, const Eigen::Vector2d& observed_pixel) {
  return new ReprojectionCost<Model>(board_point, observed_pixel);
}

// Each model's cost is compiled once, in reprojection_error.cc: its
// Jacobian (Model::Project on dual numbers) is the heaviest code the solvers
// instantiate, and three solver files create it.
extern template class ReprojectionCost<PinholeRadtanModel>;
extern template class ReprojectionCost<PinholeRationalModel>;
extern template class ReprojectionCost<KannalaBrandtModel>;
extern template class ReprojectionCost<KannalaBrandtNoncentralModel>;
extern template class ReprojectionCost<KannalaBrandtSplinedModel>;
extern template class ReprojectionCost<KannalaBrandtSplinedNoncentralModel>;

// The Jacobians of the reprojection error of `board_point` under `model`
// with `intrinsics` and the pose block `pose` (angle-axis, translation):
// d residual / d intrinsics (2 x n, row-major, n the model's parameter
// count) and d residual / d pose (2 x 6, row-major), as the solvers compute
// them, for code that needs them without a solve (the capture advice). False
// when the point does not project.
bool ReprojectionJacobians(CameraModelId model, const double* intrinsics,
                           const double* pose,
                           const Eigen::Vector3d& board_point,
                           double* d_intrinsics, double* d_pose);

// The same cost evaluated at a runtime model: the residual (projected minus
// `observed`) and, where the pointers are not null, the two Jacobians. For
// costs built on it (the rig's). False when the point does not project.
bool EvaluateReprojection(CameraModelId model, const double* intrinsics,
                          const double* pose,
                          const Eigen::Vector3d& board_point,
                          const Eigen::Vector2d& observed, double* residual,
                          double* d_intrinsics, double* d_pose);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_REPROJECTION_ERROR_H_
