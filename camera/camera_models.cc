#include "camera/camera_models.h"

#include <algorithm>

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

CameraFamily CameraModelFamily(CameraModelId id) {
  return DispatchCameraModel(
      id, [](auto model) { return decltype(model)::kFamily; });
}

bool CameraModelIsPinhole(CameraModelId id) {
  return CameraModelFamily(id) == CameraFamily::kPinhole;
}

bool CameraModelIsFisheye(CameraModelId id) {
  return CameraModelFamily(id) == CameraFamily::kFisheye;
}

bool CameraModelIsCentral(CameraModelId id) {
  return DispatchCameraModel(
      id, [](auto model) { return decltype(model)::kCentral; });
}

double FieldRadius(const Camera& camera, const Eigen::Vector3d& ray) {
  return DispatchCameraModel(camera.model, [&](auto model) {
    return decltype(model)::FieldRadius(ray.data());
  });
}

double MaxMonotonicRadius(const Camera& camera) {
  return DispatchCameraModel(camera.model, [&](auto model) {
    return decltype(model)::MaxMonotonicRadius(camera.params.data());
  });
}

double BorderFractionWithoutRay(const Camera& camera, int samples_per_side) {
  const double max_radius = MaxMonotonicRadius(camera);
  const int n = std::max(1, samples_per_side);
  const double w = camera.width, h = camera.height;
  int without = 0, samples = 0;
  auto sample = [&](double x, double y) {
    ++samples;
    Eigen::Vector3d ray;
    if (!camera.Unproject(Eigen::Vector2d(x, y), &ray).converged ||
        !(FieldRadius(camera, ray) < max_radius)) {
      ++without;
    }
  };
  for (int k = 0; k < n; ++k) {
    const double s = (k + 0.5) / n;
    sample(-0.5, -0.5 + s * h);
    sample(w - 0.5, -0.5 + s * h);
    sample(-0.5 + s * w, -0.5);
    sample(-0.5 + s * w, h - 0.5);
  }
  return static_cast<double>(without) / samples;
}

bool CameraModelIsSplined(CameraModelId id) {
  return DispatchCameraModel(id, [](auto model) {
    return CameraModelIsSplinedModel<decltype(model)>();
  });
}

bool CameraModelParamIsStructural(CameraModelId id, int k) {
  return CameraModelIsSplined(id) &&
         k == KannalaBrandtSplinedModel::kGridRadiusIndex;
}

Camera FarFieldCamera(const Camera& camera) {
  Camera far = camera;
  far.model = DispatchCameraModel(
      camera.model, [](auto model) { return decltype(model)::kFarFieldId; });
  if (far.model != camera.model) {
    // The far-field model's parameters are the first ones of the model's.
    far.params.resize(
        std::min<size_t>(far.params.size(), CameraModelNumParams(far.model)));
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
