#ifndef PUZZLECAL_FUZZ_CAMERA_YAML_CASE_H_
#define PUZZLECAL_FUZZ_CAMERA_YAML_CASE_H_

// Fuzz case (d): the camera file reader (formats/camera_yaml.h ReadCameraFile,
// all four formats). A file that loads must hold a usable camera (the
// model's number of finite parameters, a positive image size) that the
// writers can format again and the reader read back to the same model and
// size; a refused file must say why, naming the file.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "camera/camera_models.h"
#include "formats/camera_yaml.h"
#include "fuzz/yaml_file.h"

namespace puzzlecal {
namespace fuzz {

inline std::string RunCameraYamlCase(const uint8_t* data, size_t size) {
  TemporaryFile file(data, size, "camera.yaml");
  Camera camera;
  std::string error;
  if (!ReadCameraFile(file.path(), &camera, &error)) {
    if (error.empty()) return "a refused file without a message";
    if (error.find(file.path()) == std::string::npos) {
      return "the message does not name the file: " + error;
    }
    return "";
  }
  if (static_cast<int>(camera.params.size()) !=
      CameraModelNumParams(camera.model)) {
    return "a loaded camera with the wrong number of parameters";
  }
  for (double p : camera.params) {
    if (!std::isfinite(p)) return "a loaded camera with a non-finite parameter";
  }
  if (camera.width <= 0 || camera.height <= 0) {
    return "a loaded camera without a positive image size";
  }
  for (CameraFileFormat format :
       {CameraFileFormat::kPuzzlecal, CameraFileFormat::kOpenCv,
        CameraFileFormat::kRos, CameraFileFormat::kKalibr}) {
    std::string text;
    if (!FormatCameraFile(camera, CameraFileStats(), format, &text, &error)) {
      continue;  // the format cannot hold this camera (said in `error`)
    }
    Camera again;
    if (!ParseCameraFile(text, "formatted", &again, nullptr, &error)) {
      return std::string("a formatted ") + CameraFileFormatName(format) +
             " file does not read back: " + error;
    }
    if (again.model != camera.model || again.width != camera.width ||
        again.height != camera.height ||
        again.params.size() != camera.params.size()) {
      return std::string("the ") + CameraFileFormatName(format) +
             " round trip changes the camera";
    }
  }
  return "";
}

}  // namespace fuzz
}  // namespace puzzlecal

#endif  // PUZZLECAL_FUZZ_CAMERA_YAML_CASE_H_
