#ifndef PUZZLECAL_FORMATS_STEREO_RECTIFICATION_H_
#define PUZZLECAL_FORMATS_STEREO_RECTIFICATION_H_

// The stereo rectification of a camera pair as OpenCV defines it (R1, R2
// rotate each camera into the common rectified frame; P1, P2 project
// rectified points; Q maps disparity to depth), chosen so that a user who
// rectifies with it gets images, and checked before it is written.
//
// - Two pinhole models: cv::stereoRectify (alpha 0), kept when it passes
//   the check below.
// - A pair with a fisheye (or pinholes whose cv::stereoRectify fails the
//   check, or whose distortion folds over inside the image, where
//   cv::stereoRectify's crop to the undistorted border has no border to
//   follow): the rotations of cv::stereoRectify (they depend only on the
//   relative pose) and a pinhole target chosen here: one focal length for
//   both views, principal point at the image centre, and a horizontal field
//   of view of the pair's common field (the part of the rectified
//   horizontal plane both cameras see), each side clipped to half of
//   max_field_of_view_deg from the rectified axis (the principal point may
//   then lie off-centre, or outside the image for diverging cameras). A
//   pinhole image cannot hold 180 degrees: a fisheye pair keeps the
//   central part of its field.
//
// The check: points in front of the pair, seen by both cameras, land on
// the same rectified row in both views when their pixels are rectified
// with R1 P1 and R2 P2 through the camera models (the way
// cv::fisheye::undistortPoints / cv::undistortPoints use the file); the
// focal length of the rectified views is finite and within a ratio of the
// cameras' own; each camera covers at least a share of its rectified
// image (the valid region is not empty).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "camera/camera_models.h"

namespace puzzlecal {

struct StereoRectificationOptions {
  // Largest horizontal field of view of a chosen pinhole target, degrees
  // (a pinhole view stretches its rim without bound as the field nears
  // 180). (0, 170]; default 120.
  double max_field_of_view_deg = 120;
  // The check: the largest row difference of a point seen by both cameras,
  // rectified through the camera models, in rectified pixels. The points
  // are exact, so this bounds the inversion of the models. > 0; default
  // 0.01.
  double max_row_difference_px = 0.01;
  // The check: the rectified focal length lies within [f / ratio, f * ratio]
  // of each camera's own focal length f. > 1; default 20.
  double max_focal_ratio = 20;
  // The check: each camera covers at least this share of its rectified
  // image. (0, 1); default 0.05.
  double min_valid_fraction = 0.05;

  bool Check(std::string* why = nullptr) const;
};

struct StereoRectification {
  Eigen::Matrix3d r1 = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d r2 = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 4> p1 = Eigen::Matrix<double, 3, 4>::Zero();
  Eigen::Matrix<double, 3, 4> p2 = Eigen::Matrix<double, 3, 4>::Zero();
  Eigen::Matrix4d q = Eigen::Matrix4d::Zero();
  // Of the unrectified pair.
  Eigen::Matrix3d essential = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d fundamental = Eigen::Matrix3d::Zero();
  int width = 0, height = 0;  // rectified image size
  // How it was chosen: false = cv::stereoRectify's P1 P2, true = the
  // pinhole target chosen here.
  bool own_target = false;
  // Why cv::stereoRectify's projections were not taken ("" when they were).
  std::string own_target_reason;
  // Horizontal and vertical field of view of the rectified views, degrees.
  double field_of_view_deg = 0;
  double vertical_field_of_view_deg = 0;
  // Share of each rectified image that its camera covers (the check).
  double valid_fraction[2] = {0, 0};
  // Rectified row difference of the check's points (median, largest) and
  // their number.
  double median_row_difference_px = 0;
  double max_row_difference_px = 0;
  int num_check_points = 0;

  // One line: how the target was chosen, its field, focal length and the
  // valid shares.
  std::string Summary() const;
};

// Rectifies the pair (second_from_first: P_second = R * P_first + t) and
// checks the result; false with the reason when no rectification passes the
// check. Non-central models act as their far-field part.
bool StereoRectify(const Camera& first, const Camera& second,
                   const Eigen::Isometry3d& second_from_first,
                   StereoRectification* rectification, std::string* error);
bool StereoRectify(const Camera& first, const Camera& second,
                   const Eigen::Isometry3d& second_from_first,
                   const StereoRectificationOptions& options,
                   StereoRectification* rectification, std::string* error);

// The rectified pixel of `pixel` of `camera` under rotation `r` (R1 or R2)
// and projection `p` (P1 or P2): P[:, :3] * R * ray(pixel), as
// cv::undistortPoints computes it. False when the model cannot invert the
// pixel or the ray leaves the rectified view's front.
bool RectifyPixel(const Camera& camera, const Eigen::Matrix3d& r,
                  const Eigen::Matrix<double, 3, 4>& p,
                  const Eigen::Vector2d& pixel, Eigen::Vector2d* rectified);

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_STEREO_RECTIFICATION_H_
