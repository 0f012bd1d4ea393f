#ifndef PUZZLECAL_GRID_GRID_COMPONENT_H_
#define PUZZLECAL_GRID_GRID_COMPONENT_H_

#include <Eigen/Core>
#include <vector>

namespace puzzlecal {

// A connected set of corners with integer lattice labels that are consistent
// inside the component: neighbours along a tile edge differ by one unit in i
// or j. Labels are relative; the map to board ids is a rotation/reflection plus
// an offset, found by decode/.
struct GridComponent {
  std::vector<int> corner;          // indices into the detector's corner list
  std::vector<Eigen::Vector2i> ij;  // lattice label of corner[k]
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_GRID_GRID_COMPONENT_H_
