#ifndef PUZZLECAL_FORMATS_RIG_YAML_H_
#define PUZZLECAL_FORMATS_RIG_YAML_H_

// Rig files: writing a calibrated rig in four formats, and reading the
// puzzlecal one back.
// - puzzlecal (default): `cameras:` a list, each with name, model, image
//   size, named parameters and their standard deviations, `cam_from_rig`
//   {R: 3x3 rows, t: [x, y, z]} (P_cam = R * P_rig + t, metres) with its
//   standard deviations, and the camera's residual statistics;
// - opencv (readable by cv::FileStorage): K/D per camera and, for two
//   cameras, R, T (second from first), E, F and the rectification R1 R2 P1
//   P2 Q, checked before it is written (formats/stereo_rectification.h:
//   cv::stereoRectify for pinholes, a pinhole target of a stated field for
//   a pair with a fisheye), and `rectification`, a line saying what it
//   keeps; for more cameras R_i, T_i of each from the first;
// - ros: one camera_info file per camera (OUT_STEM_NAME.yaml), with the
//   pair's rectification R and projection P for two cameras;
// - kalibr: a camchain with T_cn_cnm1, cam_overlaps and a rostopic per
//   camera.
// Files are written atomically (util/atomic_file.h).

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/rig_calibration.h"
#include "camera/camera_models.h"
#include "formats/camera_yaml.h"
#include "formats/stereo_rectification.h"

namespace puzzlecal {

// One file of a rig output.
struct RigFileText {
  std::string path;
  std::string text;
};

// One frame of the puzzlecal rig file's `frames:` list.
struct RigFileFrame {
  // Per camera (the order of the cameras): the image file ("" = none),
  // "used" or why not, the rig's residual RMS of the view (px).
  std::vector<std::string> files;
  std::vector<std::string> use;
  std::vector<double> rms_px;
  bool compared = false;  // the figures below exist
  double transfer_px = 0;
  double pose_difference_mm = 0;
  double epipolar_px = 0;
  bool moved = false;  // looks unsynchronised or moved
};

// The judgement the puzzlecal rig file carries (`verdict:`, `frames:`).
struct RigFileJudgement {
  std::string verdict_kind;
  std::string verdict_reason;
  std::string verdict_next_step;
  std::vector<RigFileFrame> frames;
};

// The files of `result` in `format` for the output path `out_path` (one
// file, except ros: one per camera next to it, named after the camera).
// False with a reason when the format cannot hold the rig without loss.
// `judgement` (optional) goes into the puzzlecal format.
bool FormatRigFiles(const RigCalibrationResult& result, CameraFileFormat format,
                    const std::string& out_path,
                    std::vector<RigFileText>* files, std::string* error,
                    const RigFileJudgement* judgement = nullptr);

// Formats, then writes every file atomically; `written` (optional) returns
// the paths.
bool WriteRigFiles(const std::string& out_path, CameraFileFormat format,
                   const RigCalibrationResult& result,
                   std::vector<std::string>* written, std::string* error,
                   const RigFileJudgement* judgement = nullptr);

// A camera of a rig file.
struct RigFileCamera {
  std::string name;
  Camera camera;
  Eigen::Isometry3d cam_from_rig = Eigen::Isometry3d::Identity();
};

// Parses the text of a puzzlecal rig file; messages name `source` and the
// field.
bool ParseRigFile(const std::string& text, const std::string& source,
                  std::vector<RigFileCamera>* cameras, std::string* error);
bool ReadRigFile(const std::string& path, std::vector<RigFileCamera>* cameras,
                 std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_RIG_YAML_H_
