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

// A board point turned by a pose block's rotation (its angle-axis, the
// first 3 values), with the derivatives of the turned point by the
// angle-axis: the rotation's share of the chain rule that the costs take
// through the camera-frame point (they differentiate the projection by the
// point only, 3-wide instead of 6).
struct TurnedBoardPoint {
  Eigen::Vector3d point;        // R(w) X
  Eigen::Matrix3d d_point_d_w;  // d point / d w
};
TurnedBoardPoint TurnBoardPoint(const double* angle_axis,
                                const Eigen::Vector3d& board_point);

// The 6 values of a pose block's Jacobian row (d/dw, then d/dt) of a
// residual whose derivative by the camera-frame point is `d_residual_d_point`
// (3 values), the point being the turned point plus the translation.
void PoseJacobianRow(const double* d_residual_d_point,
                     const TurnedBoardPoint& turned, double* row);

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
// The splined models' cost instead goes through the corner's spline cell
// (specialized below; calib/reprojection_error_splined.cc): the same
// derivatives, the knots outside the cell exactly 0, the residual to a few
// ulps.
template <typename Model>
class ReprojectionCost
    : public ceres::SizedCostFunction<2, Model::kNumParams, kPoseBlockSize> {
 public:
  static constexpr int kNumParams = Model::kNumParams;

  ReprojectionCost(const Eigen::Vector3d& board_point,
                   const Eigen::Vector2d& observed_pixel)
      : functor_(board_point, observed_pixel) {}

  // Defined in calib/reprojection_cost_impl.h (the splined models': in
  // calib/reprojection_error_splined.cc), which only the file that compiles
  // the models' costs includes: an inline definition here would
  // be compiled again (Model::Project on N + 3-wide dual numbers, the
  // heaviest code the solvers have) in every file that creates a cost, the
  // extern template declarations below notwithstanding.
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  ReprojectionError<Model> functor_;
};

template <typename Model>
ceres::CostFunction* ReprojectionError<Model>::Create(
    const Eigen::Vector3d& board_point, const Eigen::Vector2d& observed_pixel) {
  return new ReprojectionCost<Model>(board_point, observed_pixel);
}

// The splined models' cost goes through the point's spline cell
// (calib/reprojection_error_splined.cc).
template <>
bool ReprojectionCost<KannalaBrandtSplinedModel>::Evaluate(
    double const* const* parameters, double* residuals,
    double** jacobians) const;
template <>
bool ReprojectionCost<KannalaBrandtSplinedNoncentralModel>::Evaluate(
    double const* const* parameters, double* residuals,
    double** jacobians) const;

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
