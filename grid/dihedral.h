#ifndef PUZZLECAL_GRID_DIHEDRAL_H_
#define PUZZLECAL_GRID_DIHEDRAL_H_

#include <Eigen/Core>

namespace puzzlecal {

// The 4 lattice unit steps, indexed counter-clockwise in label space:
// 0 = +i, 1 = +j, 2 = -i, 3 = -j.
inline int Mod4(int k) { return ((k % 4) + 4) % 4; }
inline Eigen::Vector2i LatticeStep(int k) {
  static const int kSteps[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  const int m = Mod4(k);
  return Eigen::Vector2i(kSteps[m][0], kSteps[m][1]);
}

// One of the 8 symmetries of the square lattice (rotations and reflections),
// acting on step indices: k -> sign * k + shift (mod 4). sign = -1 is a
// reflection.
struct Dihedral {
  int sign = 1;
  int shift = 0;

  int Apply(int k) const { return Mod4(sign * k + shift); }
  // (this o other)(k) = this(other(k)).
  Dihedral Compose(const Dihedral& other) const {
    return {sign * other.sign, Mod4(sign * other.shift + shift)};
  }
  Dihedral Inverse() const { return {sign, Mod4(-sign * shift)}; }
  // The linear map on labels: step k maps to step Apply(k).
  Eigen::Vector2i Apply(const Eigen::Vector2i& v) const {
    return v.x() * LatticeStep(Apply(0)) + v.y() * LatticeStep(Apply(1));
  }
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_GRID_DIHEDRAL_H_
