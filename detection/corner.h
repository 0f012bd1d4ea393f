#ifndef PUZZLECAL_DETECTION_CORNER_H_
#define PUZZLECAL_DETECTION_CORNER_H_

#include <Eigen/Core>

namespace puzzlecal {

// One detected checkerboard saddle point.
struct Corner {
  // Sub-pixel position; OpenCV pixel convention (centre of the top-left pixel
  // is (0,0), x right, y down).
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  // Detector response at the corner (larger is stronger; unitless).
  double response = 0.0;
  // Angle in radians, in (-pi, pi], of the first Hessian eigenvector (the one
  // of the positive eigenvalue). Corners that are neighbours along a tile edge
  // differ by about 90 degrees.
  double orientation = 0.0;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_DETECTION_CORNER_H_
