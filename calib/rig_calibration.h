#ifndef PUZZLECAL_CALIB_RIG_CALIBRATION_H_
#define PUZZLECAL_CALIB_RIG_CALIBRATION_H_

// Calibration of a rig of cameras that see one planar board at the same
// instants ("frames"). Each camera is first calibrated alone (Calibrate,
// calib/calibrate.h); the cam_from_rig of every camera then starts from the
// frames it shares with another camera (a robust average over those
// frames, chained along a maximum spanning tree of shared frames from the
// reference camera), and one Ceres problem refines all intrinsics, every
// cam_from_rig (the reference camera, index 0, is the rig frame: identity)
// and one rig_from_board per frame together, with the single camera's robust
// loss and k-sigma outlier rejection (per camera). The covariance of the
// intrinsics and extrinsics comes from a deterministic Schur complement of
// the Jacobian (the frame poses eliminated).
//
// The cameras of a frame need not see the same corners: each corner ties
// its camera to the frame's board pose, so cameras that see disjoint parts
// of a PuzzleBoard (absolute ids) are tied together as well as cameras that
// see all of it.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "camera/calibration_view.h"
#include "camera/camera_models.h"

namespace puzzlecal {

// The input of one camera: its model, image size and one view per rig frame
// (frames[f] of every camera is the same instant; a view without points
// means the camera did not see the board then).
struct RigCameraInput {
  std::string name;  // for messages and files (the image subfolder)
  CameraModelId model = CameraModelId::kPinholeRadtan;
  int width = 0;
  int height = 0;
  std::vector<CalibrationView> frames;
  // Per frame (or empty): why the camera's image of the frame gave no view
  // ("" where it gave one or the camera has no image of it), for the
  // frames' notes; the calibration does not read it.
  std::vector<std::string> frame_unusable_reason;
  // Parameters held at their initial values for this camera (by name), on
  // top of the options' fixed_params; e.g. {"k3"} for a pinhole-radtan
  // camera written to Kalibr's 4-coefficient radtan. Default empty.
  std::vector<std::string> fixed_params;
  // Starting intrinsics of this camera (a known calibration), in the
  // model's order; empty (the default): automatic initialisation. With
  // every parameter in fixed_params, only the rig's poses are fitted.
  std::vector<double> initial_params;
};

// A plain checkerboard whose corner grid maps onto itself under a half turn
// about its centre (in the board plane): a camera cannot tell the two
// labellings apart, so two cameras of one frame may label the board in
// opposite orientations. Their board poses of that frame are then half a
// turn apart, which the rig's relative pose (from the other frames) makes
// plain; CalibrateRig relabels such a view (id -> the id half a turn away)
// and uses the frame. A PuzzleBoard's ids are absolute: no such ambiguity.
struct RigBoardSymmetry {
  bool half_turn = false;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // board frame, metres
};

struct RigCalibrationOptions {
  // Options of each camera's own calibration (initialisation, fixed
  // parameters) and of the joint solve: robust loss and scale, outlier
  // rejection (k, rounds, minimum threshold), iteration limit and
  // tolerances, covariance eigenvalue ratio, min_corners_per_view (a camera
  // takes part in a frame with at least this many corners), max_rms_px and
  // max_focal_relative_stddev (failure limits, applied per camera).
  CalibrationOptions camera;
  // Two cameras are tied directly when they share at least this many frames
  // in which both were posed by their own calibration. Default 1: one
  // shared frame determines the relative pose (the joint solve then uses
  // every frame). >= 1.
  int min_shared_frames = 1;
  // A frame estimate of a camera pair whose rotation differs from the
  // robust centre by more than this (degrees) is left out of the starting
  // average. Default 2 degrees: single-camera poses agree to a small
  // fraction of that; a wrong pose (mirrored board) differs by far more.
  // > 0.
  double max_start_rotation_deviation_deg = 2.0;

  bool Check(std::string* why) const;
};

// What the calibration found for one camera.
struct RigCameraResult {
  std::string name;
  Camera camera;                     // model, parameters, image size
  std::vector<double> param_stddev;  // one per parameter, 0 for fixed ones
  std::vector<bool> param_fixed;
  // P_cam = cam_from_rig * P_rig (metres); identity for the reference.
  Eigen::Isometry3d cam_from_rig = Eigen::Isometry3d::Identity();
  // Standard deviation of the rotation of cam_from_rig (degrees: square
  // root of the trace of the covariance of the small rotation that
  // perturbs it) and of the translation (metres, per axis of t), 0 for the
  // reference camera or without covariance.
  double rotation_stddev_deg = 0;
  Eigen::Vector3d translation_stddev_m = Eigen::Vector3d::Zero();
  // Distance of the camera's centre from the reference camera's centre
  // (metres) and its standard deviation.
  double baseline_m = 0;
  double baseline_stddev_m = 0;
  // Covariance of cam_from_rig as angle-axis (3) and translation (3), in
  // that order; zero for the reference camera.
  Eigen::Matrix<double, 6, 6> extrinsics_covariance =
      Eigen::Matrix<double, 6, 6>::Zero();
  // The camera's own calibration (the starting point): its whole result,
  // so that the single-camera evidence and verdict can be made from it.
  CalibrationResult single;
  double single_rms_px = 0;
  int single_views_used = 0;
  // The joint solve, this camera's corners: RMS per coordinate of the
  // inliers, frames in which the camera took part, inlier corners, corners
  // rejected as outliers.
  double rms_px = 0;
  int num_frames_used = 0;
  int num_corners_used = 0;
  int num_outliers = 0;
  // Per frame: whether the camera took part, per corner the pixel residual
  // (projected minus observed; empty when not taking part) and whether it
  // was kept.
  std::vector<bool> frame_used;
  std::vector<std::vector<Eigen::Vector2d>> residuals;
  std::vector<std::vector<bool>> inlier;
  // Per frame: true when the camera's board labels were turned by half a
  // turn to agree with the rig (RigBoardSymmetry), and a note on the frame
  // ("" when there is nothing to say): what was done, or why the camera's
  // view was not used.
  std::vector<bool> relabelled;
  std::vector<std::string> frame_note;
  // Per frame: how far (degrees) the camera's board pose relative to the
  // camera it was placed from lay from the rig's when that left its view
  // of the frame out (the frame shows another moment, or the board moved);
  // 0 where it did not.
  std::vector<double> start_disagreement_deg;
  // Per frame: the camera's own pose of the board (its own calibration,
  // in the rig's labels: turned where relabelled) and whether it has one.
  std::vector<Eigen::Isometry3d> alone_cam_from_board;
  std::vector<bool> alone_posed;
};

struct RigCalibrationResult {
  std::vector<RigCameraResult> cameras;  // in input order; [0] = reference
  // The board points of a relabelled view are this transform of the
  // input's (the board's half turn; identity without a symmetry).
  Eigen::Isometry3d half_turn = Eigen::Isometry3d::Identity();
  // Per frame: whether any camera took part, and the board pose.
  std::vector<bool> frame_used;
  std::vector<Eigen::Isometry3d> rig_from_board;  // identity when not used
  // Number of frames each pair of cameras shares in the joint solve
  // (symmetric; the diagonal holds each camera's frames).
  Eigen::MatrixXi shared_frames;
  // For each camera, the camera its starting cam_from_rig was chained from
  // (-1 for the reference).
  std::vector<int> start_parent;
  double rms_px = 0;  // all cameras, per coordinate, inliers
  int num_frames_used = 0;
  int num_corners_used = 0;
  int num_outliers = 0;
  int outlier_rounds = 0;
  int iterations = 0;  // Levenberg-Marquardt iterations of the joint solves
  bool covariance_ok = false;
  std::string termination;    // Ceres' message of the last joint solve
  double seconds_single = 0;  // the cameras' own calibrations
  double seconds_joint = 0;   // start, joint solves and covariance
};

// A readable summary of a result (cameras, extrinsics with their standard
// deviations, residuals, frames).
std::string RigCalibrationReport(const RigCalibrationResult& result);

// Calibrates the rig. False with a reason naming the camera when a camera
// cannot be calibrated alone, never shares a frame with another camera (so
// its place in the rig is undetermined), or the joint solve fails; `result`
// then holds what is known so far.
bool CalibrateRig(const std::vector<RigCameraInput>& cameras,
                  const RigCalibrationOptions& options,
                  RigCalibrationResult* result, std::string* error);
// The same for a board with a symmetry (see RigBoardSymmetry).
bool CalibrateRig(const std::vector<RigCameraInput>& cameras,
                  const RigBoardSymmetry& symmetry,
                  const RigCalibrationOptions& options,
                  RigCalibrationResult* result, std::string* error);

// Angle of the rotation a * b^-1 in degrees (how far two rotations differ).
double RotationDifferenceDeg(const Eigen::Matrix3d& a,
                             const Eigen::Matrix3d& b);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_RIG_CALIBRATION_H_
