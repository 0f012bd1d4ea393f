#ifndef PUZZLECAL_CAMERA_CALIBRATION_VIEW_H_
#define PUZZLECAL_CAMERA_CALIBRATION_VIEW_H_

#include <Eigen/Core>
#include <string>
#include <vector>

namespace puzzlecal {

// The correspondences of one image: board corners (board frame, metres, on
// the plane z = 0) and where they were seen (pixels, OpenCV convention).
struct CalibrationView {
  std::string name;  // for messages, usually the image file name
  std::vector<Eigen::Vector3d> board_points;
  std::vector<Eigen::Vector2d> image_points;  // same length as board_points
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_CAMERA_CALIBRATION_VIEW_H_
