#ifndef PUZZLECAL_GRID_LATTICE_CLEANUP_H_
#define PUZZLECAL_GRID_LATTICE_CLEANUP_H_

// The final pass of BuildGrid (grid/grid.h): every corner must be where its
// lattice lines predict it; components that fall apart are split.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "grid/grid.h"
#include "grid/lattice_forest.h"

namespace puzzlecal {

// Turns the forest into components: removes corners whose four tiles do not
// alternate like a checkerboard's (when `image` is not empty) and corners
// whose lattice lines contradict them more often than they support them
// (repeatedly), splits trees into 4-connected label sets, drops sets smaller
// than options.cleanup.min_component_size, then (with an image) attaches
// corners outside every component where a component's lattice predicts them
// (`edges`: the candidate edges, which pair them with component corners),
// removes corners off the lattice of their neighbours (options.off_lattice;
// splits again when any is removed), shifts labels to start at (0, 0) and
// sorts the components (largest first, ties by smallest corner index).
std::vector<GridComponent> ExtractComponents(
    const std::vector<Eigen::Vector2d>& xy, const cv::Mat& image,
    const LatticeForest& forest, const std::vector<GridEdge>& edges,
    const GridOptions& options, GridSummary* summary);

}  // namespace puzzlecal

#endif  // PUZZLECAL_GRID_LATTICE_CLEANUP_H_
