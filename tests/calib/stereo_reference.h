#ifndef PUZZLECAL_TESTS_CALIB_STEREO_REFERENCE_H_
#define PUZZLECAL_TESTS_CALIB_STEREO_REFERENCE_H_

// A stereo scene and its correspondences in the form cv::stereoCalibrate
// takes, for comparing the rig calibration with OpenCV's on the same corners.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "calib/rig_calibration.h"
#include "sim/rig_scenes.h"

namespace puzzlecal {
namespace testing {

// sim's stereo pinhole pair with both cameras seeing the whole board in
// every frame it keeps: 30 frames, far (1.1-1.4 m) and nearly head on.
inline RigSceneSpec WholeBoardStereoRig() {
  RigSceneSpec scene = StereoPinholeRig();
  scene.random_frames.count = 30;
  scene.random_frames.min_distance_m = 1.1;
  scene.random_frames.max_distance_m = 1.4;
  scene.random_frames.max_off_axis_deg = 8;
  scene.random_frames.max_roll_deg = 20;
  scene.min_visible_corners = scene.board.NumCorners();
  return scene;
}

// The frames both cameras of `all` see: the rig input of those frames and
// OpenCV's point lists of them.
struct SharedStereoFrames {
  std::vector<RigCameraInput> inputs;
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image[2];
};

// False when a shared frame's board points differ between the cameras
// (OpenCV needs the same points in both).
inline bool CollectSharedStereoFrames(const std::vector<RigCameraInput>& all,
                                      SharedStereoFrames* out) {
  out->inputs = all;
  for (RigCameraInput& input : out->inputs) input.frames.clear();
  for (size_t f = 0; f < all[0].frames.size(); ++f) {
    if (all[0].frames[f].board_points.empty() ||
        all[1].frames[f].board_points.empty()) {
      continue;
    }
    if (all[0].frames[f].board_points != all[1].frames[f].board_points) {
      return false;
    }
    out->object.emplace_back();
    for (const Eigen::Vector3d& p : all[0].frames[f].board_points) {
      out->object.back().emplace_back(p.x(), p.y(), p.z());
    }
    for (int c = 0; c < 2; ++c) {
      out->inputs[c].frames.push_back(all[c].frames[f]);
      out->image[c].emplace_back();
      for (const Eigen::Vector2d& p : all[c].frames[f].image_points) {
        out->image[c].back().emplace_back(p.x(), p.y());
      }
    }
  }
  return true;
}

}  // namespace testing
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_CALIB_STEREO_REFERENCE_H_
