#ifndef PUZZLECAL_FORMATS_CAMERA_FILE_FORMATS_H_
#define PUZZLECAL_FORMATS_CAMERA_FILE_FORMATS_H_

// The camera file formats one by one (camera_file_<format>.cc), for
// camera_yaml.cc, which chooses among them; not for use elsewhere. Each
// format has a writer (text from a camera) and a reader (a camera from the
// YAML map at `path` of a file read by a FieldReader).

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "formats/camera_yaml.h"
#include "formats/yaml_fields.h"

namespace puzzlecal {
namespace camera_file {

inline constexpr Presence kRequired = Presence::kRequired;

// puzzlecal (camera_file_puzzlecal.cc)
std::string FormatPuzzlecal(const Camera& camera, const CameraFileStats& stats);
bool ParsePuzzlecal(const YAML::Node& map, const std::string& path,
                    FieldReader& r, Camera* camera);
bool ParseViews(const YAML::Node& root, FieldReader& r,
                std::vector<CameraFileView>* views);
// What the file carries besides `camera` (its views included).
bool ParseStats(const YAML::Node& root, const Camera& camera, FieldReader& r,
                CameraFileStats* stats);

// opencv and ros (camera_file_opencv_ros.cc)
// OpenCV's FileStorage wants "%YAML:1.0" and its own matrix tag.
std::string FormatOpenCv(const Camera& camera);
std::string FormatRos(const Camera& camera, const std::string& camera_name);
bool ParseOpenCvOrRos(const YAML::Node& map, const std::string& path, bool ros,
                      FieldReader& r, Camera* camera);

// kalibr (camera_file_kalibr.cc)
bool FormatKalibr(const Camera& camera, const std::string& rostopic,
                  std::string* text, std::string* error);
bool ParseKalibr(const YAML::Node& map, const std::string& path, FieldReader& r,
                 Camera* camera);

// Shared by the readers (camera_file_reading.cc)
void ResetCamera(CameraModelId id, Camera* camera);
bool ReadModel(const YAML::Node& map, const std::string& path, FieldReader& r,
               CameraModelId* id);
bool ReadImageSize(const YAML::Node& map, const std::string& path,
                   FieldReader& r, Camera* camera);
// fx fy cx cy from a row-major 3x3 camera matrix.
bool SetIntrinsics(const std::vector<double>& k, const std::string& field,
                   FieldReader& r, Camera* camera);
// Distortion coefficients into camera->params (zero-padded where the
// format allows shorter lists).
bool SetDistortion(const std::vector<double>& d, const std::string& field,
                   size_t min_count, FieldReader& r, Camera* camera);

}  // namespace camera_file
}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_CAMERA_FILE_FORMATS_H_
