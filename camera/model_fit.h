#ifndef PUZZLECAL_CAMERA_MODEL_FIT_H_
#define PUZZLECAL_CAMERA_MODEL_FIT_H_

// The camera of another model that projects the far field most like a given
// one: for the file formats that cannot hold a model (opencv, ros and kalibr
// have no splined model), the best-fitting model they can hold, with the
// error it leaves stated.

#include <string>

#include "camera/camera_models.h"

namespace puzzlecal {

struct CameraFitOptions {
  // The pixels compared: a grid with this spacing over the image. Default
  // 8. >= 1.
  int step_px = 8;
  // Only pixels whose ray (under the source camera) is at most this far off
  // the axis, degrees; 0 (the default) means no limit. The calibration's
  // observed field is the honest limit: beyond it neither camera is known.
  double max_field_angle_deg = 0;
  // Levenberg-Marquardt iterations at most. Default 50. >= 1.
  int max_iterations = 50;

  bool Check(std::string* why) const;
};

struct CameraFitReport {
  bool ok = false;
  std::string error;   // why not, when !ok
  int num_pixels = 0;  // pixels compared
  // |fit(ray) - source pixel| over the compared pixels.
  double rms_px = 0;
  double max_px = 0;
  int iterations = 0;
};

// The camera of model `target` whose far-field projection is nearest (least
// squares in pixels) to `source`'s over the grid pixels of `source` within
// the field: the rays of those pixels under FarFieldCamera(source) projected
// through the target model. Starts from `source`'s parameters of the same
// names (0 for the rest). `report` says how well it fits; the returned
// camera is the start when the fit fails.
Camera FitCameraModel(const Camera& source, CameraModelId target,
                      const CameraFitOptions& options, CameraFitReport* report);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CAMERA_MODEL_FIT_H_
