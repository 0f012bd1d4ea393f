#ifndef PUZZLECAL_SIM_PIXEL_RAYS_H_
#define PUZZLECAL_SIM_PIXEL_RAYS_H_

// Viewing rays (with their origins, for non-central cameras) through the
// corners of every pixel of a camera, unprojected
// once so that many renders through the same camera share the iterative
// Unproject work. Rays at sub-pixel positions are interpolated bilinearly
// between the four corners of their pixel (the error is second order in the
// pixel size, far below 1e-4 px for real lenses).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "camera/camera_models.h"

namespace puzzlecal {

// False with a reason when `camera` cannot be rendered: unknown parameter
// count, non-finite parameters, non-positive focal lengths, image size
// outside [1, 20000].
bool CheckRenderCamera(const Camera& camera, std::string* why = nullptr);

class PixelRayGrid {
 public:
  // Unprojects the (width + 1) x (height + 1) pixel corners of `camera`.
  // False with a reason (and an empty grid) when the camera is unusable.
  bool Compute(const Camera& camera, std::string* why = nullptr);

  // True when this grid was computed for exactly this camera.
  bool Matches(const Camera& camera) const;
  bool empty() const { return rays_.empty(); }
  const Camera& camera() const { return camera_; }

  // Unit ray in the camera frame through the pixel corner (cx - 0.5,
  // cy - 0.5), cx in [0, width], cy in [0, height]. NaN where Unproject did
  // not converge or lies beyond MaxMonotonicRadius (fold-over region).
  const double* Ray(int cx, int cy) const {
    return rays_.data() +
           3 * (static_cast<size_t>(cy) * (camera_.width + 1) + cx);
  }
  // Where that ray starts: (0, 0, OriginZ) in the camera frame, metres (0
  // for central cameras; see ViewingRay).
  double OriginZ(int cx, int cy) const {
    return origin_z_.empty()
               ? 0.0
               : origin_z_[static_cast<size_t>(cy) * (camera_.width + 1) + cx];
  }
  // True when every ray starts at the camera origin.
  bool central() const { return origin_z_.empty(); }
  // Number of pixel corners without a ray.
  int num_invalid() const { return num_invalid_; }

 private:
  Camera camera_;
  std::vector<double> rays_;
  std::vector<double> origin_z_;  // per pixel corner; empty when central
  int num_invalid_ = 0;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_PIXEL_RAYS_H_
