#ifndef PUZZLECAL_GRID_LATTICE_FOREST_H_
#define PUZZLECAL_GRID_LATTICE_FOREST_H_

// Kruskal's algorithm on a union-find whose trees carry lattice labels: the
// merge step of BuildGrid (grid/grid.h).

#include <Eigen/Core>
#include <vector>

#include "grid/grid.h"

namespace puzzlecal {

// A candidate edge between corners a and b.
struct GridEdge {
  double weight = 0;  // length, times the penalty for tile-crossing edges
  double length = 0;  // pixels
  int a = 0;
  int b = 0;
};

// Orders edges by weight, then by (a, b): one deterministic sort.
bool GridEdgeLess(const GridEdge& x, const GridEdge& y);

// Corner geometry the forest reads.
struct LatticeNodes {
  std::vector<Eigen::Vector2d> xy;
  // Unit vector along the corner's first lattice axis estimate: the first
  // Hessian eigenvector rotated by 45 degrees.
  std::vector<Eigen::Vector2d> axis;
  std::vector<char> valid;  // false: not part of any tree
};

// Trees and labels after Kruskal.
struct LatticeForest {
  std::vector<int> tree;               // tree id per corner, -1 if invalid
  std::vector<Eigen::Vector2i> label;  // label inside its tree
};

// Runs options.kruskal_passes passes of Kruskal over `sorted_edges` (sorted by
// GridEdgeLess), merging trees by the lattice symmetry that the corners' axes
// at the joining edge imply, and only when the merge checks pass. Counts go to
// `summary` (merge rejections are counted per attempt).
void BuildLatticeForest(const LatticeNodes& nodes,
                        const std::vector<GridEdge>& sorted_edges,
                        const GridOptions& options, GridSummary* summary,
                        LatticeForest* forest);

}  // namespace puzzlecal

#endif  // PUZZLECAL_GRID_LATTICE_FOREST_H_
