// Reading pieces the camera formats share.

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

void ResetCamera(CameraModelId id, Camera* camera) {
  camera->model = id;
  camera->params.assign(CameraModelNumParams(id), 0.0);
}
bool ReadModel(const YAML::Node& map, const std::string& path, FieldReader& r,
               CameraModelId* id) {
  std::string name;
  if (!r.String(map, path, "model", kRequired, &name)) return false;
  if (!CameraModelIdFromName(name, id)) {
    return r.Fail(
        FieldReader::Join(path, "model"),
        "unknown model '" + name + "' (known: " + CameraModelNames() + ")");
  }
  return true;
}
bool ReadImageSize(const YAML::Node& map, const std::string& path,
                   FieldReader& r, Camera* camera) {
  if (!r.Int(map, path, "image_width", kRequired, &camera->width) ||
      !r.Int(map, path, "image_height", kRequired, &camera->height)) {
    return false;
  }
  if (camera->width <= 0) {
    return r.Fail(FieldReader::Join(path, "image_width"), "must be positive");
  }
  if (camera->height <= 0) {
    return r.Fail(FieldReader::Join(path, "image_height"), "must be positive");
  }
  return true;
}
// fx fy cx cy from a row-major 3x3 camera matrix.
bool SetIntrinsics(const std::vector<double>& k, const std::string& field,
                   FieldReader& r, Camera* camera) {
  if (k[1] != 0) return r.Fail(field, "skew is not supported");
  if (!(k[0] > 0) || !(k[4] > 0)) {
    return r.Fail(field, "focal lengths must be positive");
  }
  camera->params[0] = k[0];
  camera->params[1] = k[4];
  camera->params[2] = k[2];
  camera->params[3] = k[5];
  return true;
}
// Distortion coefficients into camera->params (zero-padded where the
// format allows shorter lists).
bool SetDistortion(const std::vector<double>& d, const std::string& field,
                   size_t min_count, FieldReader& r, Camera* camera) {
  const size_t count = camera->params.size() - kDistortionBegin;
  if (d.size() < min_count || d.size() > count) {
    return r.Fail(field,
                  std::string("expected ") +
                      (min_count == count ? std::to_string(count)
                                          : std::to_string(min_count) + " to " +
                                                std::to_string(count)) +
                      " coefficients for " + CameraModelName(camera->model) +
                      ", got " + std::to_string(d.size()));
  }
  for (size_t i = 0; i < d.size(); ++i) {
    camera->params[kDistortionBegin + i] = d[i];
  }
  return true;
}

}  // namespace camera_file
}  // namespace puzzlecal
