#ifndef PUZZLECAL_GRID_NEAREST_NEIGHBORS_H_
#define PUZZLECAL_GRID_NEAREST_NEIGHBORS_H_

#include <Eigen/Core>
#include <vector>

namespace puzzlecal {

// The k nearest other points of every point, by a uniform bucket grid: near
// linear time for image corner sets. The grid spans the 1 %..99 % quantiles
// of the coordinates, so a few far-away points do not coarsen it (they fall
// into the border cells and are still found exactly).
// points: finite coordinates. On return (*neighbors)[i * k + m] is the m-th
// nearest other point of point i (ascending distance, ties by index), or -1
// when there are fewer than k other points.
void FindNearestNeighbors(const std::vector<Eigen::Vector2d>& points, int k,
                          std::vector<int>* neighbors);

}  // namespace puzzlecal

#endif  // PUZZLECAL_GRID_NEAREST_NEIGHBORS_H_
