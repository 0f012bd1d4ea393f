#ifndef PUZZLECAL_SIM_RIG_SCENES_H_
#define PUZZLECAL_SIM_RIG_SCENES_H_

// Synthetic multi-camera rigs with exact truth: cameras at known
// cam_from_rig, a board at one known rig_from_board per frame, and what
// each camera sees of it (rendered images or exact corner projections).
// The rig frame is the first camera's.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "calib/rig_calibration.h"
#include "camera/camera_models.h"
#include "sim/render.h"
#include "target/board.h"

namespace puzzlecal {

struct RigSceneCamera {
  std::string name;  // image subfolder, e.g. "cam0"
  Camera camera;
  // P_cam = cam_from_rig * P_rig; the first camera's is the identity.
  Eigen::Isometry3d cam_from_rig = Eigen::Isometry3d::Identity();
  // Full field of view of the lens in degrees (the image circle of a
  // fisheye, see RenderOptions::field_of_view_deg); 0 = unlimited.
  double field_of_view_deg = 0;
};

// Random frames: frame k puts the board in front of camera
// aim_cameras[k % size] (all cameras in turn when empty), posed as a
// ViewPose (sim/scenes.h) drawn uniformly from the ranges below.
struct RigRandomFrames {
  int count = 0;      // frames to draw
  uint64_t seed = 1;  // same seed, same frames
  std::vector<int> aim_cameras;
  double min_distance_m = 0.4;  // camera to target
  double max_distance_m = 0.9;
  double min_view_angle_deg = 45.0;  // angle between ray and board plane
  double max_view_angle_deg = 90.0;
  double max_roll_deg = 30.0;
  double max_off_axis_deg = 20.0;  // target off the aimed camera's axis
  // Target drawn from the printed area grown by this many tiles per side.
  double target_margin_tiles = 0.0;
};

struct RigSceneSpec {
  std::string name;
  Board board;
  std::vector<RigSceneCamera> cameras;  // [0] is the rig frame
  // Options of every image (camera c, frame f uses seed render.seed +
  // 1000 * c + f; field_of_view_deg comes from the camera).
  RenderOptions render;
  // Frames: the explicit ones, then the random ones.
  std::vector<Eigen::Isometry3d> rig_from_board;
  RigRandomFrames random_frames;
  // A camera's image of a frame exists only when it shows at least this many
  // visible corners (fewer: the camera "did not see" the frame and no file
  // is written). Default 12.
  int min_visible_corners = 12;
  // Cameras not synchronised: in the frames listed (indices), every camera
  // but the first sees the board moved by `moved_by_m` metres (in the rig
  // frame, in a direction drawn from moved_seed and the frame index), as a
  // hand-held board moves between two exposures. Default none.
  std::vector<int> moved_frames;
  double moved_by_m = 0.0;
  uint64_t moved_seed = 1;

  // False with a reason naming the field when the rig cannot be rendered.
  bool Check(std::string* why = nullptr) const;
};

// Every frame's rig_from_board (explicit, then random), deterministic.
std::vector<Eigen::Isometry3d> RigFramePoses(const RigSceneSpec& scene);

// The board pose camera `c` sees in frame `f` (`frames`: RigFramePoses):
// the frame's, moved for the cameras after the first in the moved frames.
Eigen::Isometry3d RigFramePoseSeenBy(
    const RigSceneSpec& scene, const std::vector<Eigen::Isometry3d>& frames,
    size_t c, size_t f);

// The exact correspondences of the rig: per camera one view per frame with
// the visible corners (TruthCorner::visible; empty when fewer than
// min_visible_corners), Gaussian noise of `noise_px` per coordinate
// (seeded by `seed`) added to the pixels. Ready for CalibrateRig.
std::vector<RigCameraInput> RigCorrespondences(const RigSceneSpec& scene,
                                               double noise_px,
                                               uint64_t seed = 1);

// How far a calibrated camera's cam_from_rig is from the truth, also in
// the units of the covariance the calibration states for it.
struct CamFromRigError {
  double rotation_deg = 0;  // angle of the rotation between the two
  // rotation_deg / rotation_stddev_deg (infinite without a stddev).
  double rotation_over_sigma = 0;
  double translation_m = 0;  // length of the translation difference
  // Chi-square of the translation difference under the stated 3 x 3
  // translation covariance (3 degrees of freedom; infinite when that
  // covariance is not positive definite).
  double translation_chi2 = 0;
};
CamFromRigError CompareCamFromRig(const RigCameraResult& estimate,
                                  const Eigen::Isometry3d& truth);

// What RenderRigScene wrote.
struct RigRenderSummary {
  int num_frames = 0;
  std::vector<int> images_per_camera;  // files written per camera
  int frames_seen_by_one_camera = 0;   // frames with exactly one image
};

// Renders every camera's view of every frame into DIR/<camera name>/
// frame_NNN.png (only images with min_visible_corners), so that the same
// file name in different subfolders is the same instant. False with a
// reason when the scene is invalid or a file cannot be written.
bool RenderRigScene(const RigSceneSpec& scene, const std::string& dir,
                    RigRenderSummary* summary, std::string* why);

// File name of frame `index` ("frame_007.png").
std::string RigFrameFileName(int index);

// The standard rigs (sizes are small so tests stay fast).
// Two pinhole-radtan cameras 12 cm apart, turned 4 degrees towards each
// other.
RigSceneSpec StereoPinholeRig(int width = 640, int height = 480);
// A 190-degree Kannala-Brandt reference and a pinhole-radtan turned 50
// degrees away (they overlap only in part); some frames only the pinhole
// or only the fisheye sees.
RigSceneSpec FisheyePinholeRig(int width = 640, int height = 480);
// Two Kannala-Brandt fisheyes of `fov_deg` (beyond 180 by default) side by
// side, 11 cm apart, the second to the left of the first (so that the
// rectified x axis points from the second to the first), nearly parallel.
RigSceneSpec StereoFisheyeRig(int width = 640, int height = 480,
                              double fov_deg = 190.0);
// Four cameras of three models: a fisheye reference, pinholes turned +50
// (radtan) and -50 degrees (rational) and a radtan turned +100 degrees that
// shares frames with the +50 one (and the fisheye's rim) only.
RigSceneSpec FourCameraRig(int width = 640, int height = 480);

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_RIG_SCENES_H_
