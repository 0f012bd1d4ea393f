// The opencv (cv::FileStorage) and ros (camera_info) camera formats: the
// same camera matrix and distortion list, in two spellings.

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "formats/camera_file_formats.h"
#include "formats/yaml_emit.h"
#include "formats/yaml_fields.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

// Key of a kannala-brandt camera's coefficients in the opencv format.
constexpr char kOpenCvFisheyeKey[] = "fisheye_distortion_coefficients";

}  // namespace

namespace camera_file {

// OpenCV's FileStorage wants "%YAML:1.0" and its own matrix tag.
std::string FormatOpenCv(const Camera& camera) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "model" << YAML::Value << CameraModelName(camera.model);
  out << YAML::Key << "image_width" << YAML::Value << camera.width;
  out << YAML::Key << "image_height" << YAML::Value << camera.height;
  EmitOpenCvMatrix(out, "camera_matrix", 3, 3,
                   RowMajor(CameraMatrixOf(camera)));
  const std::vector<double> distortion = DistortionOf(camera);
  // A fisheye's k1..k4 under OpenCV's usual key would be read as pinhole
  // k1 k2 p1 p2 by cv::undistort and friends; its own key (the D of
  // cv::fisheye) makes pinhole readers fail loudly instead.
  const bool fisheye = CameraModelIsFisheye(camera.model);
  if (fisheye) {
    out << YAML::Key << "distortion_model" << YAML::Value << "fisheye";
  }
  EmitOpenCvMatrix(out, fisheye ? kOpenCvFisheyeKey : "distortion_coefficients",
                   1, static_cast<int>(distortion.size()), distortion);
  out << YAML::EndMap;
  return std::string("%YAML:1.0\n---\n") + out.c_str() + "\n";
}
std::string FormatRos(const Camera& camera, const std::string& camera_name) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  const auto& p = camera.params;
  out << YAML::BeginMap;
  out << YAML::Key << "image_width" << YAML::Value << camera.width;
  out << YAML::Key << "image_height" << YAML::Value << camera.height;
  out << YAML::Key << "camera_name" << YAML::Value << camera_name;
  EmitRosMatrix(out, "camera_matrix", 3, 3, RowMajor(CameraMatrixOf(camera)));
  out << YAML::Key << "distortion_model" << YAML::Value
      << RosDistortionModel(camera.model);
  const std::vector<double> distortion = DistortionOf(camera);
  EmitRosMatrix(out, "distortion_coefficients", 1,
                static_cast<int>(distortion.size()), distortion);
  EmitRosMatrix(out, "rectification_matrix", 3, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  EmitRosMatrix(out, "projection_matrix", 3, 4,
                {p[0], 0, p[2], 0, 0, p[1], p[3], 0, 0, 0, 1, 0});
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}
bool ParseOpenCvOrRos(const YAML::Node& map, const std::string& path, bool ros,
                      FieldReader& r, Camera* camera) {
  CameraModelId id = CameraModelId::kPinholeRadtan;
  std::vector<double> k, d;
  if (!r.Matrix(map, path, "camera_matrix", kRequired, 3, 3, &k)) {
    return false;
  }
  const std::string distortion_key = !ros && map[kOpenCvFisheyeKey]
                                         ? kOpenCvFisheyeKey
                                         : "distortion_coefficients";
  const std::string distortion_field = FieldReader::Join(path, distortion_key);
  if (!r.Matrix(map, path, distortion_key, kRequired, 0, 0, &d)) return false;
  if (ros) {
    std::string model;
    if (!r.String(map, path, "distortion_model", kRequired, &model)) {
      return false;
    }
    if (model == "plumb_bob") {
      id = CameraModelId::kPinholeRadtan;
    } else if (model == "rational_polynomial") {
      id = CameraModelId::kPinholeRational;
    } else if (model == "equidistant" || model == "fisheye") {
      id = CameraModelId::kKannalaBrandt;
    } else {
      return r.Fail(FieldReader::Join(path, "distortion_model"),
                    "unknown model '" + model +
                        "' (known: plumb_bob, rational_polynomial, "
                        "equidistant)");
    }
  } else if (map["model"]) {
    if (!ReadModel(map, path, r, &id)) return false;
    if (CameraModelIsFisheye(id) != (distortion_key == kOpenCvFisheyeKey)) {
      return r.Fail(
          distortion_field,
          std::string("model ") + CameraModelName(id) +
              (CameraModelIsFisheye(id) ? " keeps its coefficients under "
                                        : " cannot use ") +
              kOpenCvFisheyeKey);
    }
  } else if (distortion_key == kOpenCvFisheyeKey) {
    id = CameraModelId::kKannalaBrandt;
  } else {
    // OpenCV's own files carry no model: tell it by the number of
    // coefficients (4 or 5: plumb_bob, 8: rational).
    if (d.size() == 8)
      id = CameraModelId::kPinholeRational;
    else if (d.size() == 4 || d.size() == 5)
      id = CameraModelId::kPinholeRadtan;
    else {
      return r.Fail(distortion_field,
                    std::to_string(d.size()) +
                        " coefficients without a 'model' field (expected 4, "
                        "5 or 8)");
    }
  }
  ResetCamera(id, camera);
  if (!ReadImageSize(map, path, r, camera)) return false;
  if (!SetIntrinsics(k, FieldReader::Join(path, "camera_matrix.data"), r,
                     camera)) {
    return false;
  }
  const size_t count = camera->params.size() - kDistortionBegin;
  // plumb_bob may omit k3; the other models need all coefficients.
  const size_t min_count = id == CameraModelId::kPinholeRadtan ? 4 : count;
  return SetDistortion(d, FieldReader::Join(distortion_field, "data"),
                       min_count, r, camera);
}

}  // namespace camera_file
}  // namespace puzzlecal
