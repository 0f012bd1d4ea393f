#ifndef PUZZLECAL_UTIL_ANGLES_H_
#define PUZZLECAL_UTIL_ANGLES_H_

#include <cmath>

namespace puzzlecal {

// One degree in radians: `angle_deg * kDegree` is the angle in radians,
// `angle / kDegree` in degrees.
inline constexpr double kDegree = M_PI / 180.0;

}  // namespace puzzlecal

#endif  // PUZZLECAL_UTIL_ANGLES_H_
