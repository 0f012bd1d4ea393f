#ifndef PUZZLECAL_CALIB_REPROJECTION_ERROR_H_
#define PUZZLECAL_CALIB_REPROJECTION_ERROR_H_

// Ceres cost functor: the pixel error of one board corner seen in one view.
// Parameter blocks: the camera model's intrinsics (Model::kNumParams values)
// and the view's cam_from_board pose as angle-axis (3) + translation (3).

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

namespace puzzlecal {

// Pose block layout: angle-axis rotation then translation (metres).
inline constexpr int kPoseBlockSize = 6;

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

  static ceres::CostFunction* Create(const Eigen::Vector3d& board_point,
                                     const Eigen::Vector2d& observed_pixel) {
    return new ceres::AutoDiffCostFunction<ReprojectionError, 2,
                                           Model::kNumParams, kPoseBlockSize>(
        new ReprojectionError(board_point, observed_pixel));
  }

 private:
  Eigen::Vector3d board_point_;
  Eigen::Vector2d observed_pixel_;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_REPROJECTION_ERROR_H_
