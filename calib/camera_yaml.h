#ifndef PUZZLECAL_CALIB_CAMERA_YAML_H_
#define PUZZLECAL_CALIB_CAMERA_YAML_H_

// Camera files: writing and reading a calibrated camera in four formats.
// - puzzlecal (default): model, image size, named parameters with standard
//   deviations, RMS, views and corners used;
// - opencv: readable by cv::FileStorage (%YAML:1.0, camera_matrix and
//   distortion_coefficients as !!opencv-matrix, image size, model);
// - ros: camera_info (plumb_bob / rational_polynomial / equidistant);
// - kalibr: a camchain with cam0 (pinhole + radtan / equidistant).
// Writes are atomic (calib/atomic_file.h) and refuse to lose information
// (for example k3 != 0 into Kalibr's radtan). Reading recognises all four
// formats; messages name the file and the field.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "calib/camera_models.h"

namespace puzzlecal {

enum class CameraFileFormat { kPuzzlecal, kOpenCv, kRos, kKalibr };

// "puzzlecal", "opencv", "ros", "kalibr".
const char* CameraFileFormatName(CameraFileFormat format);
bool CameraFileFormatFromName(const std::string& name,
                              CameraFileFormat* format);

// One calibration view as the puzzlecal format lists it under `views`.
struct CameraFileView {
  std::string file;  // the image file
  // P_cam = R * P_board + t, metres. The board frame has its origin at the
  // board's first printed corner (a PuzzleBoard's `origin`), x along the
  // columns, y along the rows, z = 0 on the board.
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  double rms_px = 0;  // this view's RMS, per coordinate, inliers
  int corners = 0;    // corners this view contributed (inliers)
};

// What a calibration adds to the camera itself (written by the puzzlecal
// format; the others have no place for it).
struct CameraFileStats {
  bool has_stats = false;            // false: the fields below are not set
  std::vector<double> param_stddev;  // one per parameter, 0 for fixed ones
  double rms_px = 0;                 // per coordinate, see CalibrationResult
  int num_views_used = 0;
  int num_corners_used = 0;
  int num_outliers = 0;
  std::vector<CameraFileView> views;  // the views used, in input order
};

// The statistics of `result` with its used views; `view_files[v]` names view
// v, and `first_corner_m` is the board point of the first printed corner in
// the calibration's board frame (poses are moved to a frame with its origin
// there).
CameraFileStats CameraFileStatsOfResult(
    const CalibrationResult& result, const std::vector<std::string>& view_files,
    const Eigen::Vector3d& first_corner_m);

// Name written into the ros format's camera_name.
inline constexpr const char* kDefaultCameraName = "camera";
// Image topic written into the kalibr camchain's cam0/rostopic.
inline constexpr const char* kDefaultRosTopic = "/cam0/image_raw";

// Names the ros and kalibr formats carry (the others ignore them).
struct CameraFileNames {
  std::string camera_name = kDefaultCameraName;  // ros: camera_name
  std::string rostopic = kDefaultRosTopic;       // kalibr: cam0/rostopic
};

// Whether `format` can hold a camera of `model`, asked before a calibration
// starts: true with the parameters the calibration must hold at 0 for it
// (`fixed`, by name; kalibr's radtan has no k3, so {"k3"} for
// pinhole-radtan), false with a reason when no setting of the parameters fits
// (pinhole-rational in kalibr).
bool CameraFormatFixedParams(CameraFileFormat format, CameraModelId model,
                             std::vector<std::string>* fixed,
                             std::string* error);

// The text of a camera file; false (with a reason) when the format cannot
// hold the camera without loss or the camera is invalid.
bool FormatCameraFile(const Camera& camera, const CameraFileStats& stats,
                      CameraFileFormat format, std::string* text,
                      std::string* error,
                      const CameraFileNames& names = CameraFileNames());

// Writes a camera file atomically.
bool WriteCameraFile(const std::string& path, CameraFileFormat format,
                     const Camera& camera, const CameraFileStats& stats,
                     std::string* error,
                     const CameraFileNames& names = CameraFileNames());
// The same for a calibration result (camera and its statistics).
bool WriteCameraFile(const std::string& path, CameraFileFormat format,
                     const CalibrationResult& result, std::string* error,
                     const CameraFileNames& names = CameraFileNames());

// Parses camera file text in any of the four formats; `source` names the
// text in messages. `format` (optional) returns the format found.
bool ParseCameraFile(const std::string& text, const std::string& source,
                     Camera* camera, CameraFileFormat* format,
                     std::string* error);
// Reads a camera file in any of the four formats.
bool ReadCameraFile(const std::string& path, Camera* camera,
                    std::string* error);
// Reads the `views` list of a puzzlecal-format camera file (empty when the
// file has none).
bool ReadCameraFileViews(const std::string& path,
                         std::vector<CameraFileView>* views,
                         std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_CAMERA_YAML_H_
