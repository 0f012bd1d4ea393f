#ifndef PUZZLECAL_TESTS_SUPPORT_DRAWS_H_
#define PUZZLECAL_TESTS_SUPPORT_DRAWS_H_

// Random points drawn one coordinate at a time, in a fixed order. Written
// as one call's arguments, `Eigen::Vector2d(normal(rng), normal(rng))`
// draws in an order each compiler picks (g++ the last argument first, clang
// the first), so the same seed would make other data, and other results,
// on another compiler. The last coordinate is drawn first: the order the
// tests' data have been made in with g++.

#include <Eigen/Core>

namespace puzzlecal {
namespace testing_draws {

// (x, y) from two calls of `draw` (y first).
template <typename Draw>
Eigen::Vector2d DrawVector2d(Draw&& draw) {
  const double y = draw();
  const double x = draw();
  return Eigen::Vector2d(x, y);
}

// (x, y, z) from three calls of `draw` (z first, then y).
template <typename Draw>
Eigen::Vector3d DrawVector3d(Draw&& draw) {
  const double z = draw();
  const double y = draw();
  const double x = draw();
  return Eigen::Vector3d(x, y, z);
}

}  // namespace testing_draws
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_SUPPORT_DRAWS_H_
