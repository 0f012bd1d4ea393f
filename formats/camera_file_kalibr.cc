// The kalibr camera format (camchain: cam0 with intrinsics and
// distortion_coeffs).

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

namespace camera_file {

bool FormatKalibr(const Camera& camera, const std::string& rostopic,
                  std::string* text, std::string* error) {
  const auto& p = camera.params;
  std::vector<double> coeffs;
  const char* model = "radtan";
  switch (camera.model) {
    case CameraModelId::kPinholeRational:
      for (int k = 8; k < 12; ++k) {
        if (p[k] != 0) {
          return Fail("kalibr has no rational distortion model (k" +
                          std::to_string(k - 5) + " = " + std::to_string(p[k]) +
                          "): write the opencv or ros format, or calibrate "
                          "pinhole-radtan with --format kalibr (k3 held at 0)",
                      error);
        }
      }
      [[fallthrough]];
    case CameraModelId::kPinholeRadtan:
      if (p[8] != 0) {
        return Fail(
            "kalibr's radtan model has no k3 (k3 = " + std::to_string(p[8]) +
                "): write the opencv or ros format, or calibrate "
                "with --format kalibr (k3 held at 0)",
            error);
      }
      coeffs = {p[4], p[5], p[6], p[7]};
      break;
    case CameraModelId::kKannalaBrandt:
    case CameraModelId::kKannalaBrandtNoncentral:  // its far-field part
    // Their kannala-brandt part; FormatCameraFile hands this function the
    // best-fitting kannala-brandt instead (CameraForFormat).
    case CameraModelId::kKannalaBrandtSplined:
    case CameraModelId::kKannalaBrandtSplinedNoncentral:
      model = "equidistant";
      coeffs = {p[4], p[5], p[6], p[7]};
      break;
  }
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap << YAML::Key << "cam0" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "camera_model" << YAML::Value << "pinhole";
  out << YAML::Key << "intrinsics" << YAML::Value;
  EmitFlow(out, {p[0], p[1], p[2], p[3]});
  out << YAML::Key << "distortion_model" << YAML::Value << model;
  out << YAML::Key << "distortion_coeffs" << YAML::Value;
  EmitFlow(out, coeffs);
  out << YAML::Key << "resolution" << YAML::Value << YAML::Flow
      << YAML::BeginSeq << camera.width << camera.height << YAML::EndSeq;
  out << YAML::Key << "rostopic" << YAML::Value << rostopic;
  out << YAML::EndMap << YAML::EndMap;
  *text = std::string(out.c_str()) + "\n";
  return true;
}

// ---- reading ----
bool ParseKalibr(const YAML::Node& map, const std::string& path, FieldReader& r,
                 Camera* camera) {
  YAML::Node cam;
  if (!r.Child(map, path, "cam0", kRequired, &cam)) return false;
  const std::string cam_path = FieldReader::Join(path, "cam0");
  std::string camera_model, distortion_model;
  if (!r.String(cam, cam_path, "camera_model", kRequired, &camera_model)) {
    return false;
  }
  if (camera_model != "pinhole") {
    return r.Fail(FieldReader::Join(cam_path, "camera_model"),
                  "only 'pinhole' is supported, got '" + camera_model + "'");
  }
  if (!r.String(cam, cam_path, "distortion_model", kRequired,
                &distortion_model)) {
    return false;
  }
  CameraModelId id;
  if (distortion_model == "radtan") {
    id = CameraModelId::kPinholeRadtan;
  } else if (distortion_model == "equidistant") {
    id = CameraModelId::kKannalaBrandt;
  } else {
    return r.Fail(FieldReader::Join(cam_path, "distortion_model"),
                  "unknown model '" + distortion_model +
                      "' (known: radtan, equidistant)");
  }
  ResetCamera(id, camera);
  std::vector<double> intrinsics, coeffs, resolution;
  if (!r.Doubles(cam, cam_path, "intrinsics", kRequired, 4, &intrinsics)) {
    return false;
  }
  if (!(intrinsics[0] > 0) || !(intrinsics[1] > 0)) {
    return r.Fail(FieldReader::Join(cam_path, "intrinsics"),
                  "focal lengths must be positive");
  }
  for (int k = 0; k < 4; ++k) camera->params[k] = intrinsics[k];
  if (!r.Doubles(cam, cam_path, "distortion_coeffs", kRequired, 4, &coeffs)) {
    return false;
  }
  for (int k = 0; k < 4; ++k) camera->params[kDistortionBegin + k] = coeffs[k];
  if (!r.Doubles(cam, cam_path, "resolution", kRequired, 2, &resolution)) {
    return false;
  }
  // Whole numbers in a sane range before the cast (a double beyond int's
  // range would make it undefined).
  if (!std::all_of(resolution.begin(), resolution.end(), [](double v) {
        return v >= 1 && v <= 1e6 && v == std::floor(v);
      })) {
    return r.Fail(FieldReader::Join(cam_path, "resolution"),
                  "must be [width, height], whole numbers in [1, 1000000]");
  }
  camera->width = static_cast<int>(resolution[0]);
  camera->height = static_cast<int>(resolution[1]);
  return true;
}

}  // namespace camera_file
}  // namespace puzzlecal
