#ifndef PUZZLECAL_ADVICE_VIEW_INFORMATION_H_
#define PUZZLECAL_ADVICE_VIEW_INFORMATION_H_

// What one view of the board tells about the intrinsics: the Fisher
// information of its corners (unit corner noise) with the view's own pose
// eliminated, S = A - B C^-1 B' from the corners' Jacobians (A: intrinsics x
// intrinsics, B: intrinsics x pose, C: pose x pose). The sum of S over the
// views of a calibration is the information matrix whose inverse, times
// the corner noise variance, is the intrinsics' covariance the calibration
// reports (calib/marginal_covariance.h forms the same sum from the solved
// problem). Capture advice adds the S of a view not yet taken.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "camera/camera_models.h"

namespace puzzlecal {

// The information of the corners `board_points` (board frame) seen by
// `camera` from `cam_from_board`, at the pixels the camera projects them to
// (the information of a view does not depend on where the noise puts the
// corners, only on where they are). n x n over all of the model's
// parameters, times `weight` (a corner subsample stands for the whole view
// with weight = corners / subsample). A point the camera cannot project
// adds nothing. False when fewer than 3 points project (the pose is then
// undetermined and the view tells nothing).
bool ViewInformation(const Camera& camera,
                     const std::vector<Eigen::Vector3d>& board_points,
                     const Eigen::Isometry3d& cam_from_board, double weight,
                     Eigen::MatrixXd* information);

}  // namespace puzzlecal

#endif  // PUZZLECAL_ADVICE_VIEW_INFORMATION_H_
