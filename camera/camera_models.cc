#include "camera/camera_models.h"

namespace puzzlecal {

const char* CameraModelName(CameraModelId id) {
  return DispatchCameraModel(id,
                             [](auto model) { return decltype(model)::kName; });
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

bool CameraModelIsFisheye(CameraModelId id) {
  return id == CameraModelId::kKannalaBrandt ||
         id == CameraModelId::kKannalaBrandtNoncentral;
}

bool CameraModelIsCentral(CameraModelId id) {
  return DispatchCameraModel(
      id, [](auto model) { return decltype(model)::kCentral; });
}

Camera FarFieldCamera(const Camera& camera) {
  Camera far = camera;
  if (camera.model == CameraModelId::kKannalaBrandtNoncentral) {
    far.model = CameraModelId::kKannalaBrandt;
    far.params.resize(std::min<size_t>(far.params.size(), kPupilBegin));
  }
  return far;
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

UnprojectStatus UnprojectPixelToRay(CameraModelId id, const double* params,
                                    const Eigen::Vector2d& pixel,
                                    ViewingRay* ray) {
  return DispatchCameraModel(id, [&](auto model) {
    using Model = decltype(model);
    if constexpr (Model::kCentral) {
      ray->origin.setZero();
      return Model::Unproject(params, pixel.data(), ray->direction.data());
    } else {
      return Model::UnprojectRay(params, pixel.data(), ray->origin.data(),
                                 ray->direction.data());
    }
  });
}

}  // namespace puzzlecal
