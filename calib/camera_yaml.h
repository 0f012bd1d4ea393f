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

// What a calibration adds to the camera itself (written by the puzzlecal
// format; the others have no place for it).
struct CameraFileStats {
  bool has_stats = false;            // false: the fields below are not set
  std::vector<double> param_stddev;  // one per parameter, 0 for fixed ones
  double rms_px = 0;                 // per coordinate, see CalibrationResult
  int num_views_used = 0;
  int num_corners_used = 0;
  int num_outliers = 0;
  // The calibration's verdict line (calib/verdict.h); "" writes none.
  std::string verdict;
};

// Name written into the ros format's camera_name.
inline constexpr const char* kDefaultCameraName = "camera";

// The text of a camera file; false (with a reason) when the format cannot
// hold the camera without loss or the camera is invalid.
bool FormatCameraFile(const Camera& camera, const CameraFileStats& stats,
                      CameraFileFormat format, std::string* text,
                      std::string* error);

// Writes a camera file atomically.
bool WriteCameraFile(const std::string& path, CameraFileFormat format,
                     const Camera& camera, const CameraFileStats& stats,
                     std::string* error);
// The same for a calibration result (camera and its statistics) and,
// when not empty, its verdict line.
bool WriteCameraFile(const std::string& path, CameraFileFormat format,
                     const CalibrationResult& result, std::string* error,
                     const std::string& verdict = "");

// Parses camera file text in any of the four formats; `source` names the
// text in messages. `format` (optional) returns the format found.
bool ParseCameraFile(const std::string& text, const std::string& source,
                     Camera* camera, CameraFileFormat* format,
                     std::string* error);
// Reads a camera file in any of the four formats.
bool ReadCameraFile(const std::string& path, Camera* camera,
                    std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_CAMERA_YAML_H_
