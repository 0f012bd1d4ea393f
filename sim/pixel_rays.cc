#include "sim/pixel_rays.h"

#include <cmath>
#include <limits>
#include <opencv2/core.hpp>

#include "util/failure.h"

namespace puzzlecal {

bool CheckRenderCamera(const Camera& camera, std::string* why) {
  const int expected = CameraModelNumParams(camera.model);
  if (static_cast<int>(camera.params.size()) != expected) {
    return Fail(std::string("camera model ") + CameraModelName(camera.model) +
                    " needs " + std::to_string(expected) + " parameters, got " +
                    std::to_string(camera.params.size()),
                why);
  }
  for (double p : camera.params) {
    if (!std::isfinite(p)) return Fail("camera parameters must be finite", why);
  }
  if (!(camera.params[0] > 0 && camera.params[1] > 0)) {
    return Fail("camera focal lengths fx, fy must be positive", why);
  }
  constexpr int kMaxSize = 20000;
  if (camera.width < 1 || camera.height < 1 || camera.width > kMaxSize ||
      camera.height > kMaxSize) {
    return Fail("camera image size must be in [1, 20000] x [1, 20000], got " +
                    std::to_string(camera.width) + " x " +
                    std::to_string(camera.height),
                why);
  }
  return true;
}

bool PixelRayGrid::Compute(const Camera& camera, std::string* why) {
  rays_.clear();
  origin_z_.clear();
  num_invalid_ = 0;
  if (!CheckRenderCamera(camera, why)) return false;
  camera_ = camera;
  const int grid_w = camera.width + 1, grid_h = camera.height + 1;
  rays_.assign(3 * static_cast<size_t>(grid_w) * grid_h, 0.0);
  const bool central = CameraModelIsCentral(camera.model);
  if (!central) origin_z_.assign(static_cast<size_t>(grid_w) * grid_h, 0.0);
  std::vector<int> invalid_per_row(grid_h, 0);
  const double max_radius = MaxMonotonicRadius(camera);
  // Rows are independent, so any thread count gives the same grid.
  cv::parallel_for_(cv::Range(0, grid_h), [&](const cv::Range& range) {
    for (int cy = range.start; cy < range.end; ++cy) {
      for (int cx = 0; cx < grid_w; ++cx) {
        double* ray =
            rays_.data() + 3 * (static_cast<size_t>(cy) * grid_w + cx);
        const Eigen::Vector2d pixel(cx - 0.5, cy - 0.5);
        ViewingRay viewing_ray;
        const UnprojectStatus status = UnprojectPixelToRay(
            camera.model, camera.params.data(), pixel, &viewing_ray);
        for (int k = 0; k < 3; ++k) ray[k] = viewing_ray.direction(k);
        if (!central) {
          origin_z_[static_cast<size_t>(cy) * grid_w + cx] =
              viewing_ray.origin.z();
        }
        if (!status.converged || !std::isfinite(ray[0]) ||
            !std::isfinite(ray[1]) || !std::isfinite(ray[2]) ||
            !(FieldRadius(camera, Eigen::Vector3d(ray[0], ray[1], ray[2])) <
              max_radius)) {
          ray[0] = ray[1] = ray[2] = std::numeric_limits<double>::quiet_NaN();
          ++invalid_per_row[cy];
        }
      }
    }
  });
  for (int n : invalid_per_row) num_invalid_ += n;
  return true;
}

bool PixelRayGrid::Matches(const Camera& camera) const {
  return !rays_.empty() && camera.model == camera_.model &&
         camera.width == camera_.width && camera.height == camera_.height &&
         camera.params == camera_.params;
}

}  // namespace puzzlecal
