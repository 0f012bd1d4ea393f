#include "calib/camera_models.h"

namespace puzzlecal {

const char* CameraModelName(CameraModelId id) {
  return DispatchCameraModel(id, [](auto model) { return decltype(model)::kName; });
}

bool CameraModelIdFromName(const std::string& name, CameraModelId* id) {
  for (CameraModelId candidate : kAllCameraModels) {
    if (name == CameraModelName(candidate)) {
      *id = candidate;
      return true;
    }
  }
  return false;
}

std::string CameraModelNames() {
  std::string names;
  for (CameraModelId id : kAllCameraModels) {
    if (!names.empty()) names += ", ";
    names += CameraModelName(id);
  }
  return names;
}

int CameraModelNumParams(CameraModelId id) {
  return DispatchCameraModel(
      id, [](auto model) { return decltype(model)::kNumParams; });
}

std::vector<std::string> CameraModelParamNames(CameraModelId id) {
  return DispatchCameraModel(id, [](auto model) {
    const auto& names = decltype(model)::kParamNames;
    return std::vector<std::string>(names.begin(), names.end());
  });
}

bool CameraModelIsPinhole(CameraModelId id) {
  return id == CameraModelId::kPinholeRadtan ||
         id == CameraModelId::kPinholeRational;
}

bool ProjectPoint(CameraModelId id, const double* params,
                  const Eigen::Vector3d& point_cam, Eigen::Vector2d* pixel) {
  return DispatchCameraModel(id, [&](auto model) {
    return decltype(model)::Project(params, point_cam.data(), pixel->data());
  });
}

UnprojectStatus UnprojectPixel(CameraModelId id, const double* params,
                               const Eigen::Vector2d& pixel,
                               Eigen::Vector3d* ray) {
  return DispatchCameraModel(id, [&](auto model) {
    return decltype(model)::Unproject(params, pixel.data(), ray->data());
  });
}

}  // namespace puzzlecal
