#ifndef PUZZLECAL_FORMATS_CAMERA_YAML_H_
#define PUZZLECAL_FORMATS_CAMERA_YAML_H_

// Camera files: writing and reading a calibrated camera in four formats.
// - puzzlecal (default): model, image size, named parameters with standard
//   deviations, RMS, views and corners used;
// - opencv: readable by cv::FileStorage (%YAML:1.0, camera_matrix and
//   distortion_coefficients as !!opencv-matrix, image size, model);
// - ros: camera_info (plumb_bob / rational_polynomial / equidistant);
// - kalibr: a camchain with cam0 (pinhole + radtan / equidistant).
// Writes are atomic (util/atomic_file.h) and refuse to lose information
// (for example k3 != 0 into Kalibr's radtan), except for a non-central
// camera: opencv, ros and kalibr get its far-field part, with a comment in
// the file and a note for the user on what was left out and what it costs
// (DescribeCameraFileOmission). A calibration's verdict is the puzzlecal
// format's `verdict` field and a comment line at the top of the others
// ("# verdict: ..."; their readers skip comments). Reading recognises all
// four formats; messages name the file and the field.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "camera/camera_models.h"
#include "camera/model_fit.h"
#include "formats/yaml_fields.h"

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
// format; the others have no place for it but the verdict, which they
// carry as a comment line).
struct CameraFileStats {
  bool has_stats = false;            // false: the fields below are not set
  std::vector<double> param_stddev;  // one per parameter, 0 for fixed ones
  // The intrinsics' covariance (n x n in the model's order, 0 for fixed
  // ones), what the projection uncertainty of the camera is computed from;
  // empty: unknown.
  Eigen::MatrixXd covariance;
  double rms_px = 0;  // per coordinate, see CalibrationResult
  int num_views_used = 0;
  int num_corners_used = 0;
  int num_outliers = 0;
  std::vector<CameraFileView> views;  // the views used, in input order
  // The calibration's verdict line (evidence/verdict.h); "" writes none.
  // The puzzlecal format's `verdict` field; the first comment line of the
  // opencv, ros and kalibr formats.
  std::string verdict;
  // Where the calibration's board corners were (see MeasureCalibrationRange):
  // the error figure of a format that leaves part of the camera out is
  // given for points this near, up to this field angle (the puzzlecal
  // format keeps the field angle: where the calibration was observed, for
  // comparisons). 0: unknown (then no figure, resp. the whole image).
  double closest_board_distance_m = 0;
  double max_field_angle_deg = 0;
};

// The statistics of `result` with its used views; `view_files[v]` names view
// v, and `first_corner_m` is the board point of the first printed corner in
// the calibration's board frame (poses are moved to a frame with its origin
// there).
CameraFileStats CameraFileStatsOfResult(
    const CalibrationResult& result, const std::vector<std::string>& view_files,
    const Eigen::Vector3d& first_corner_m);

// The nearest board corner (distance from the camera origin, metres) and the
// largest field angle (degrees from the optical axis) over the inlier
// corners of the views a calibration used.
struct CalibrationRange {
  double closest_board_distance_m = 0;
  double max_field_angle_deg = 0;
};
CalibrationRange MeasureCalibrationRange(
    const std::vector<CalibrationView>& views, const CalibrationResult& result);

// Everything a calibration's camera file carries besides the camera: the
// statistics of `result` (CameraFileStatsOfResult), its verdict line, and
// where its board corners were (MeasureCalibrationRange over `views`, the
// views it was calibrated from). What `puzzlecal calibrate` writes.
CameraFileStats CalibrationFileStats(const CalibrationResult& result,
                                     const std::vector<CalibrationView>& views,
                                     const std::vector<std::string>& view_files,
                                     const Eigen::Vector3d& first_corner_m,
                                     const std::string& verdict_line);

// What a format leaves out of a camera. opencv, ros and kalibr have no
// non-central model: they get the far-field part of kannala-brandt-noncentral
// (kannala-brandt with the same k1..k4, FarFieldCamera) without the pupil
// shift e1 e2, and the file says so in a comment.
struct CameraFileOmission {
  bool lossy = false;     // false: the file holds the camera exactly
  std::string left_out;   // e.g. "e1 = 0.00095 m, e2 = 0.00031 m"
  double distance_m = 0;  // the distance max_error_px is for (0: unknown)
  // Largest pixel distance between the camera's and the file's projection
  // of points at distance_m from the camera origin, over the image pixels
  // up to max_field_angle_deg from the axis (0: all the model can image).
  double max_error_px = 0;
  double max_field_angle_deg = 0;
  // A splined camera in a format without splines: the file holds the
  // best-fitting kannala-brandt over the observed field; its RMS and
  // largest far-field difference from the splined projection (pixels).
  bool fitted = false;
  double fit_rms_px = 0;
  double fit_max_px = 0;
  // What the file holds when lossy (CameraForFormat's camera).
  Camera held;
  std::string note;  // one line for the user; empty when !lossy
};
// The camera a file in `format` holds for `camera`: the camera itself in
// the puzzlecal format and for central models the format has; the
// far-field part of a non-central camera; for a splined camera the
// kannala-brandt that fits its far-field projection best over the image
// pixels within stats.max_field_angle_deg (when 0: within the circle its
// spline grid covers). `fit` (optional) gets the fit's figures.
Camera CameraForFormat(const Camera& camera, CameraFileFormat format,
                       const CameraFileStats& stats,
                       CameraFitReport* fit = nullptr);
// `stats` supplies closest_board_distance_m and max_field_angle_deg.
CameraFileOmission DescribeCameraFileOmission(const Camera& camera,
                                              CameraFileFormat format,
                                              const CameraFileStats& stats);
// The largest pixel distance between `camera` and FarFieldCamera(camera) for
// points at `distance_m` (> 0) along the rays of the image pixels (sampled
// every 8 pixels and along the border) up to `max_field_angle_deg` (0: no
// limit). 0 for central cameras.
double FarFieldErrorPx(const Camera& camera, double distance_m,
                       double max_field_angle_deg);

// The ros camera_info distortion_model of a puzzlecal model: plumb_bob,
// rational_polynomial, or equidistant (kannala-brandt; a non-central camera
// is written as its far-field part).
const char* RosDistortionModel(CameraModelId id);

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

// Writes a camera file atomically. `note` (optional) returns
// DescribeCameraFileOmission's note: what the format left out and what that
// costs (empty when nothing); print it.
bool WriteCameraFile(const std::string& path, CameraFileFormat format,
                     const Camera& camera, const CameraFileStats& stats,
                     std::string* error, std::string* note = nullptr,
                     const CameraFileNames& names = CameraFileNames());
// The same for a calibration result (camera and its statistics); `range`
// (from MeasureCalibrationRange) sizes the error figure of a lossy format.
bool WriteCameraFile(const std::string& path, CameraFileFormat format,
                     const CalibrationResult& result, std::string* error,
                     const CalibrationRange& range = CalibrationRange(),
                     std::string* note = nullptr,
                     const CameraFileNames& names = CameraFileNames());

// Parses camera file text in any of the four formats; `source` names the
// text in messages. `format` (optional) returns the format found; `stats`
// (optional) what the puzzlecal format carries besides the camera
// (parameter_stddev, parameter_covariance, rms_px, views_used,
// corners_used, outliers, max_field_angle_deg, verdict, views; has_stats
// false when the text has no rms_px, as the other formats).
bool ParseCameraFile(const std::string& text, const std::string& source,
                     Camera* camera, CameraFileFormat* format,
                     std::string* error, CameraFileStats* stats = nullptr);
// The same for a camera held by a YAML map at `path` of a larger file ("":
// the file's root; a rig file's "cameras[1]"), its messages through
// `reader`. `opencv_header`: the file began with OpenCV's "%YAML:1.0".
bool ParseCameraNode(const YAML::Node& node, const std::string& path,
                     bool opencv_header, FieldReader* reader, Camera* camera,
                     CameraFileFormat* format);
// Reads a camera file in any of the four formats; `stats` (optional) as
// ParseCameraFile's.
bool ReadCameraFile(const std::string& path, Camera* camera, std::string* error,
                    CameraFileStats* stats = nullptr);
// Reads the `views` list of a puzzlecal-format camera file (empty when the
// file has none).
bool ReadCameraFileViews(const std::string& path,
                         std::vector<CameraFileView>* views,
                         std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_CAMERA_YAML_H_
