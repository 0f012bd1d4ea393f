#ifndef PUZZLECAL_PIPELINE_UNDISTORT_H_
#define PUZZLECAL_PIPELINE_UNDISTORT_H_

// Undistortion to a pinhole camera without distortion: the target camera
// (focal length and principal point chosen from the region of the image the
// source model can invert) and the pixel maps for cv::remap.

#include <opencv2/core.hpp>
#include <string>

#include "camera/camera_models.h"

namespace puzzlecal {

struct UndistortOptions {
  // Field of the target, as alpha of cv::getOptimalNewCameraMatrix: 0 keeps
  // only target pixels with a source pixel behind them (no black border), 1
  // keeps every invertible source pixel (black border). In [0, 1]; default 0.
  double alpha = 0;
  // Rays further than this from the optical axis are left out of the target
  // (a pinhole image cannot hold 90 degrees and more; fisheye lenses are cut
  // here). Degrees in (0, 89]; default 60, a 120-degree diagonal field at
  // most.
  double max_angle_deg = 60;
  // Near the fold of a distortion (where it stops being one-to-one) one
  // source pixel is stretched over ever more target pixels. A target pixel
  // is kept while the area ratio source/target around its ray, relative to
  // that on the axis, is at least this. In (0, 1); default 0.05 (stretched
  // 20x in area at most).
  double min_area_ratio = 0.05;
  // Samples along each image side to trace the invertible region. >= 4;
  // default 64.
  int border_samples = 64;
  // A source pixel counts as invertible when Unproject converges and
  // re-projects within this many pixels. > 0; default 0.01.
  double tolerance_px = 0.01;

  bool Check(std::string* why = nullptr) const;
};

// What the undistortion chose, and why.
struct UndistortResult {
  Camera target;  // pinhole-radtan, all distortion coefficients 0
  // Share of the sampled source image border whose pixels the model can
  // invert (1 = all; less where the distortion folds over, has no inverse,
  // or the ray is beyond max_angle_deg).
  double border_invertible_fraction = 1;
  // Largest field angle of the target's corners from its axis, degrees.
  double target_max_angle_deg = 0;
  // Share of target pixels with a source pixel behind them.
  double target_covered_fraction = 1;
  // True when the field was limited by max_angle_deg.
  bool limited_by_max_angle = false;

  // A few lines for the user: the target camera, and where the model has no
  // inverse.
  std::string Summary(const UndistortOptions& options) const;
};

// Chooses the target camera for `source` (its own image size).
UndistortResult ChooseUndistortTarget(const Camera& source,
                                      const UndistortOptions& options);

// Maps for cv::remap (CV_32FC1 each, the target's size): target pixel ->
// source pixel; -1 where the target pixel has no invertible source pixel.
void MakeUndistortMaps(const Camera& source, const Camera& target,
                       const UndistortOptions& options, cv::Mat* map_x,
                       cv::Mat* map_y);

}  // namespace puzzlecal

#endif  // PUZZLECAL_PIPELINE_UNDISTORT_H_
