#ifndef PUZZLECAL_TESTS_CALIB_SCENES_H_
#define PUZZLECAL_TESTS_CALIB_SCENES_H_

// Rendered scenes the solver tests share.

#include "sim/synthetic_views.h"

namespace puzzlecal {
namespace testing_scenes {

// `num_views` boards seen through sim::TruthFisheye190() (a 190-degree
// Kannala-Brandt lens): anywhere in its field up to 85 degrees off the axis,
// corners up to 95 degrees, at 0.8-1.6 m, tilted up to 60 degrees, at least
// 30 % of each board inside the image.
inline sim::SyntheticScene Fisheye190Scene(int num_views) {
  sim::SyntheticScene scene;
  scene.camera = sim::TruthFisheye190();
  scene.num_views = num_views;
  scene.max_direction_deg = 85;
  scene.max_corner_angle_deg = 95;
  scene.min_visible_fraction = 0.3;
  scene.min_tilt_deg = 0;
  scene.max_tilt_deg = 60;
  scene.min_distance = 0.8;
  scene.max_distance = 1.6;
  return scene;
}

// `num_views` boards seen through sim::TruthBumpyFisheye() (a lens
// kannala-brandt cannot follow): board directions up to 70 degrees off the
// axis, at least half of each board inside the image, 0.1 px corner noise.
inline sim::SyntheticScene BumpyFisheyeScene(unsigned seed, int num_views) {
  sim::SyntheticScene scene;
  scene.camera = sim::TruthBumpyFisheye();
  scene.num_views = num_views;
  scene.noise_px = 0.1;
  scene.max_direction_deg = 70;
  scene.min_visible_fraction = 0.5;
  scene.seed = seed;
  return scene;
}

}  // namespace testing_scenes
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_CALIB_SCENES_H_
