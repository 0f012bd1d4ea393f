#ifndef PUZZLECAL_GRID_LATTICE_FOREST_H_
#define PUZZLECAL_GRID_LATTICE_FOREST_H_

// Kruskal's algorithm on a union-find whose trees carry lattice labels: the
// merge step of BuildGrid (grid/grid.h).

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "grid/grid.h"
#include "grid/label_table.h"

namespace puzzlecal {

// A candidate edge between corners a and b.
struct GridEdge {
  double weight = 0;  // length, times the penalty for tile-crossing edges
  double length = 0;  // pixels
  int a = 0;
  int b = 0;
  bool penalised = false;
};

// Orders edges by weight, then by (a, b): one deterministic sort.
inline bool GridEdgeLess(const GridEdge& x, const GridEdge& y) {
  if (x.weight != y.weight) return x.weight < y.weight;
  if (x.a != y.a) return x.a < y.a;
  return x.b < y.b;
}

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
  LabelTable table{0};                 // (tree, label) -> corner
};

// Runs options.merge.kruskal_passes passes of Kruskal over `sorted_edges`
// (sorted by GridEdgeLess, weight = length), merging trees by the lattice
// symmetry that the corners' axes at the joining edge imply, and only when the
// merge checks pass. `crosses_tile` (may be empty) says whether an edge gets
// the intensity penalty (weight x options.image_tests.penalty_factor); it is
// asked only for edges that join two trees when their turn comes, and penalised
// edges are taken up again at their new weight. `sides_flip` (may be empty)
// refuses an edge when its turn comes (it spans two tiles). The second and
// later passes retry the edges refused before. Counts go to `summary` (merge
// rejections are counted per attempt); `trace` (optional) gets every edge with
// its last decision.
void BuildLatticeForest(
    const LatticeNodes& nodes, const std::vector<GridEdge>& sorted_edges,
    const std::function<bool(const GridEdge&)>& crosses_tile,
    const std::function<bool(const GridEdge&)>& sides_flip,
    const GridOptions& options, GridSummary* summary, LatticeForest* forest,
    std::vector<GridEdgeTrace>* trace = nullptr);

}  // namespace puzzlecal

#endif  // PUZZLECAL_GRID_LATTICE_FOREST_H_
