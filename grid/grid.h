#ifndef PUZZLECAL_GRID_GRID_H_
#define PUZZLECAL_GRID_GRID_H_

// Corners -> lattice components: the minimum-spanning-tree grid of the thesis
// (k nearest neighbours, eigenvector-orientation filter, intensity-thirds edge
// penalty, Kruskal on a union-find with outlier checks), with labels that stay
// consistent under perspective, fisheye distortion and reflection:
// - every lattice direction is taken from the corner's own Hessian axes (the
//   tile edges run at +-45 degrees to the eigenvectors), never from image x/y;
// - two trees merge by one of the 8 lattice symmetries (rotation or
//   reflection) plus an offset, chosen from both trees' axes at the joining
//   edge and verified (no two corners on one label, no contradicting
//   neighbours, collinear lines);
// - a final pass removes corners that their lattice lines do not predict and
//   splits components that fall apart; then, with an image, corners left out
//   join a component, and components join one another, where the lattice
//   around a free label predicts them;
// - last, a corner removed where the predictions of its neighbours agree
//   with each other but not with it (a false corner at a lattice position
//   whose corner was not detected).

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detection/corner.h"
#include "grid/grid_component.h"

namespace puzzlecal {

// Candidate edges: k nearest neighbours, filtered (thesis section 4.1).
struct GridCandidateOptions {
  // Nearest neighbours per corner that become candidate edges. Default 8
  // (the thesis's value: the 4 tile-edge neighbours and the 4 diagonal ones
  // of an interior corner); in [1, 64].
  int num_neighbors = 8;
  // A candidate edge is kept only when the two corners' eigenvector
  // orientations differ by more than this (mod 180 degrees): tile-edge
  // neighbours differ by about 90, diagonal ones by about 0. Default 45 (the
  // thesis's value, halfway); in [0, 90).
  double min_orientation_difference_deg = 45.0;
  // Edges shorter than this (pixels) are dropped: two detections of one
  // corner. Default 1; finite, >= 0.
  double min_edge_length_px = 1.0;
  // Corners with |x| or |y| above this (pixels) are ignored as invalid (keeps
  // the arithmetic finite). Default 1e6; in (0, 1e9].
  double max_abs_coordinate_px = 1e6;

  // False with a reason when a field is out of range.
  bool Check(std::string* why = nullptr) const;
};

// Image tests of a candidate edge (with an image only).
struct GridEdgeImageOptions {
  // Grey levels sampled evenly along an edge (at (s + 0.5) / n of its length)
  // for the intensity penalty. Default 15 (the thesis's value: 5 per third);
  // in [3, 1000].
  int intensity_samples = 15;
  // An edge is penalised when the mean grey levels of its first and last
  // thirds differ by more than this fraction of its mean: it crosses a tile
  // instead of running along a tile edge. Default 0.5 (the thesis's value);
  // finite, > 0.
  double intensity_difference_fraction = 0.5;
  // The weight of a penalised edge is its length times this factor. Default
  // 3 (the thesis's value; above merge.neighbor_weight_ratio, so a penalised
  // edge never joins normal ones); finite, >= 1.
  double penalty_factor = 3.0;
  // Refuse penalised edges instead of taking them up later at the higher
  // weight: where the true neighbours of a corner at the rim were not
  // detected, a penalised tile diagonal could otherwise join and mislabel
  // it, while the corners of the few penalised true lattice edges are
  // joined by other paths. Default true.
  bool refuse_penalised_edges = true;
  // An edge is refused when the tiles beside it change colour halfway: it
  // spans two tiles through an undetected corner (lengths alone cannot tell
  // when tile sizes vary by 3x along a fisheye line). The sides are sampled
  // at this fraction of the edge length to either side of it. Default 0.1
  // (inside the tiles next to the edge); in (0, 0.5].
  double side_offset_fraction = 0.1;
  // ... and the edge is refused when both left-right differences exceed this
  // fraction of their mean grey level. Default 0.2 (well above the noise of
  // a uniform tile, well below the contrast of a tile edge); 0 turns the test
  // off; finite, >= 0.
  double side_min_contrast = 0.2;

  bool Check(std::string* why = nullptr) const;
};

// Kruskal's merges of two trees (thesis section 4.2) and the checks that
// keep their labels consistent.
struct GridMergeOptions {
  // At both ends of the joining edge, every tree edge already at that corner
  // on the same lattice line has a weight within this factor of the joining
  // edge's weight. Default 2.9 (thesis eq. 4.2, there against all edges at
  // the corner; here per line, since steep views foreshorten one axis by
  // more than that); finite, > 1.
  double neighbor_weight_ratio = 2.9;
  // Mean edge weight of the larger tree / mean edge weight of the smaller
  // tree lies in (min, max), per lattice axis where both trees have edges
  // along it. Default (0.3, 2.9) (thesis eq. 4.3); min in (0, 1), max finite
  // and > 1.
  double tree_mean_weight_ratio_min = 0.3;
  double tree_mean_weight_ratio_max = 2.9;
  // Three consecutive corners on one lattice line turn by less than 90
  // degrees with |sin| of the turning angle at most this. Default 0.342 =
  // sin 20 degrees (the thesis's value); in (0, 1].
  double max_collinearity_sin = 0.342;
  // ... and the ratio of their two spacings lies within [1 / max, max]:
  // perspective and fisheye change the spacing slowly. Default 2; finite,
  // >= 1.
  double max_line_spacing_ratio = 2.0;
  // A lattice step must point within this angle (degrees) of the corner's
  // axis estimate (eigenvector +- 45 degrees); steps near 45 degrees are
  // ambiguous between the two axes and are not used. The image directions
  // of the two tile edges at a corner lie on either side of the
  // eigenvectors (which bisect them), at 45 - theta/2 degrees from the
  // estimate for tile edges theta degrees apart: theta = 20 (steep views
  // under fisheye, tiles of aspect 5 and more at the rim) gives 35. Without
  // an image this band also keeps out "knight" edges (1 tile along one axis,
  // 2 along the other) of views steeper than 25 degrees, which pass the
  // orientation filter and look like lattice steps. Default 38; in (0, 45].
  double max_axis_deviation_deg = 38.0;
  // The same with an image and image_tests.refuse_penalised_edges: knight edges
  // cross tiles and the intensity test refuses them, so the band can be
  // narrower and tile edges meeting at a narrower angle are accepted.
  // Default 44; in (0, 45].
  double max_axis_deviation_with_image_deg = 44.0;
  // With an image, two corners that a merge makes lattice neighbours and
  // whose step is in that ambiguous band still agree when the step lies
  // within this angle of the direction each one's frame expects and the
  // image shows a tile edge between them (one such pair along the seam of
  // two large trees would otherwise refuse the whole merge). Default 50
  // (above 45: the band itself); in (0, 90).
  double max_adjacency_deviation_with_image_deg = 50.0;
  // Two corners that a merge makes lattice neighbours are at most this
  // factor farther apart (or closer) than the tree edges on the same lattice
  // line at either corner (or, for a corner without any tree edge, the
  // joining edge). Default 2 (as max_line_spacing_ratio); finite, >= 1.
  double max_adjacency_length_ratio = 2.0;
  // ... and, when a corner has tree edges only across that line, at most
  // this factor: the foreshortening of one axis against the other in steep
  // views (1 / sin(viewing angle) and more under perspective; tiles at the
  // rim of a strong fisheye reach aspect 5-6). Default 8; finite, >= 1.
  double max_axis_aspect_ratio = 8.0;
  // Kruskal passes over the sorted edges; a later pass retries the edges
  // between trees that an earlier pass refused (the trees have grown
  // since). Default 2; in [1, 10].
  int kruskal_passes = 2;

  bool Check(std::string* why = nullptr) const;
};

// The final pass over the trees: corners their lattice does not predict are
// removed, trees that fall apart are split.
struct GridCleanupOptions {
  // With an image, a corner stays only when the four tiles around it
  // alternate dark/light: drops L-junctions at the board's border and
  // clutter. Default true.
  bool check_saddle_pattern = true;
  // The tiles are sampled at this fraction of the lattice diagonals from the
  // corner. Default 0.3 (inside each tile, clear of its edges); in (0, 0.5].
  double saddle_sample_fraction = 0.3;
  // A corner is predicted from the next three corners on each of its
  // lattice lines (quadratic extrapolation); the prediction holds when the
  // error is at most this fraction of the spacing of the nearest two (with
  // only two further corners the merge's collinearity test is used).
  // Corners contradicted by more lines than support them are removed. The
  // extrapolation 3 p1 - 3 p2 + p3 multiplies the detector's position noise
  // by sqrt(19) = 4.4: 1.5 px at the rim of a strong fisheye, where tiles
  // are 15 px, is 0.44 of the spacing. Default 0.5; finite, > 0.
  double line_prediction_tolerance = 0.5;
  // Components with fewer corners are dropped (not returned). Default 4 (a
  // single tile); >= 1.
  int min_component_size = 4;

  bool Check(std::string* why = nullptr) const;
};

// With an image, after the cleanup: corners outside every component join one
// at a free label next to it, and components join one another, where the
// lattice predicts them (corners and board halves left out by refused
// merges of the large, quickly changing tiles next to a fisheye lens;
// occluded boards).
struct GridAttachOptions {
  // Rounds of attaching corners, while corners join (a joined corner
  // predicts the next one). Default 8; 0 turns the pass off; in [0, 100].
  int rounds = 8;
  // Predictions of a corner at a free label: quadratic extrapolation along
  // each lattice line through the label with three corners, and the
  // parallelogram of each tile at the label with three corners. A
  // prediction supports when it lands within this fraction of the local
  // spacing. Default 0.45 (below half a step: a corner one label off misses
  // by 1); in (0, 1).
  double tolerance = 0.45;
  // ... and contradicts only when it misses by more than this fraction
  // (between the two it counts neither way: true corners next to a fisheye
  // lens miss by up to 0.55, a neighbouring lattice position by 1 and more).
  // Default 0.65; in [tolerance, 1).
  double contradiction_tolerance = 0.65;
  // A corner joins when at least this many predictions support it and none
  // contradicts. Default 2 (two independent predictions agree); in [1, 8].
  int min_support = 2;
  // The tiles of a joining corner are sampled at
  // cleanup.saddle_sample_fraction or (when they do not alternate there) at
  // this fraction of the lattice diagonals: tiles of 80-170 px next to a
  // fisheye lens whose steps beyond the board's last corners (taken from the
  // other side) overshoot the shrinking border tiles into the dark rim of
  // the image circle. Default 0.15; in (0, 0.5].
  double saddle_sample_fraction = 0.15;
  // A component joins another when the other's lattice predicts one of its
  // corners at a free label next to it (as above), the image directions of
  // both lattices at that corner agree within this angle (degrees) on both
  // axes under exactly one lattice symmetry, no two corners meet on one
  // label and the predictions at each corner along the seam hold more often
  // than they fail. Default 30 (a third of the 90 degrees between the
  // axes); in (0, 90).
  double max_join_direction_deviation_deg = 30.0;
  // At most this many component joins. Default 16; 0: none; in [0, 1000].
  int max_component_joins = 16;

  bool Check(std::string* why = nullptr) const;
};

// After the attach pass, every labelled corner must lie where the lattice
// of its neighbours puts it: a false corner (clutter, a blob or a junction
// next to a lattice position whose corner was not detected) can pass the
// merge and line checks where only a few short lines reach it (at the rim
// of a fisheye view, next to occluders). Predictions of a corner from its
// neighbours (itself not used): per lattice line, interpolation between the
// neighbours on both sides and quadratic extrapolation from each side with
// three corners; per tile at the corner, the parallelogram of its three
// other corners.
struct GridOffLatticeOptions {
  // Run the check. Default true.
  bool enabled = true;
  // A corner is removed when it lies farther than this fraction of the
  // local spacing from the mean of the agreeing predictions (below).
  // Default 0.3: a third of the way to the next lattice position, above the
  // spread of true corners (detector noise amplified 1-4 times by the
  // predictions, perspective and fisheye curvature the quadratic terms
  // leave); in (0, 1).
  double tolerance = 0.3;
  // The agreeing predictions: those within this fraction of their spacing
  // of one of them, the largest such group (the neighbours agree with each
  // other, so the corner and not a neighbour is off). Default 0.15; in
  // (0, tolerance].
  double agreement = 0.15;
  // The corner is judged only when at least this many predictions agree and
  // they are more than half of all its predictions. Default 2 (two
  // independent predictions); in [2, 10].
  int min_agreeing = 2;
  // Rounds of removal (a removal changes its neighbours' predictions).
  // Default 3; in [1, 10].
  int max_rounds = 3;

  bool Check(std::string* why = nullptr) const;
};

// The options of BuildGrid, one group per stage in the order they run.
struct GridOptions {
  GridCandidateOptions candidates;    // k-NN candidate edges and their filters
  GridEdgeImageOptions image_tests;   // intensity penalty, sides test (image)
  GridMergeOptions merge;             // Kruskal's merge checks
  GridCleanupOptions cleanup;         // removal of unpredicted corners, split
  GridAttachOptions attach;           // late joins of corners and components
  GridOffLatticeOptions off_lattice;  // final check of every labelled corner

  // False with a reason (naming the group and field) when a field is out of
  // range.
  bool Check(std::string* why = nullptr) const;
};

// What BuildGrid did.
struct GridSummary {
  bool ok = false;      // false: no grid was built, see `message`
  std::string message;  // why not, or notes (e.g. ignored corners)

  int num_input_corners = 0;
  int num_invalid_corners = 0;  // NaN/inf/huge coordinates or orientation
  bool image_used = false;      // intensity penalty applied

  // Edges.
  int num_candidate_edges = 0;             // unique k-nearest-neighbour pairs
  int num_edges_orientation_filtered = 0;  // dropped: orientations too alike
  int num_edges_too_short = 0;             // dropped: duplicate positions
  int num_edges_considered = 0;            // given to Kruskal
  // Intensity-thirds penalty applied. Edges are sampled lazily, only when
  // Kruskal reaches one that joins two trees, so this counts those.
  int num_edges_penalised = 0;

  // Kruskal.
  int num_merges = 0;                           // accepted unions
  int num_edges_same_tree = 0;                  // both ends already joined
  int num_rejected_neighbor_weight = 0;         // eq. 4.2
  int num_rejected_tree_mean_weight = 0;        // eq. 4.3
  int num_rejected_ambiguous_axis = 0;          // step near 45 degrees
  int num_rejected_label_collision = 0;         // two corners on one label
  int num_rejected_neighbor_contradiction = 0;  // direction/length mismatch
  int num_rejected_collinearity = 0;            // lines bend or jump
  int num_rejected_sides_flip = 0;              // through a missed corner

  // Final pass.
  int num_removed_not_saddle = 0;     // tiles around it do not alternate
  int num_removed_by_prediction = 0;  // corners their lines did not predict
  int num_attached = 0;               // joined by the attach pass
  int num_removed_off_lattice = 0;    // off the lattice of its neighbours
  int num_components_joined = 0;      // joined by the attach pass
  int num_components_dropped = 0;     // below cleanup.min_component_size
  int num_components = 0;             // returned
  int num_labelled_corners = 0;       // corners in returned components
  int largest_component = 0;

  // Wall time in milliseconds.
  double neighbors_ms = 0;
  double weights_ms = 0;  // orientation filter, lengths, sort
  double kruskal_ms = 0;  // with the intensity sampling
  double cleanup_ms = 0;
  double total_ms = 0;
};

// Why Kruskal merged or did not merge the two trees of an edge.
enum class GridEdgeDecision {
  kMerged,                 // the edge joined two trees
  kSameTree,               // both ends were already in one tree
  kNeighborWeight,         // eq. 4.2
  kTreeMeanWeight,         // eq. 4.3
  kAmbiguousAxis,          // step near 45 degrees to a corner's axes
  kLabelCollision,         // two corners on one label
  kNeighborContradiction,  // direction/length mismatch of new neighbours
  kCollinearity,           // lines bend or jump
  kSidesFlip,              // runs through an undetected corner (image)
  kPenalised,              // crosses a tile, image_tests.refuse_penalised_edges
};

// "merged", "same tree", ...
const char* GridEdgeDecisionName(GridEdgeDecision decision);

// One edge given to Kruskal and what became of it (in its last pass).
struct GridEdgeTrace {
  int a = 0;  // corner indices
  int b = 0;
  double length = 0;  // pixels
  double weight = 0;  // length, times the penalty when penalised
  bool penalised = false;
  GridEdgeDecision decision = GridEdgeDecision::kSameTree;
};

// Builds lattice components from detected corners.
// corners: from detection/; image: the grey image the corners came from
// (CV_8UC1, CV_16UC1 or CV_32FC1) for the intensity penalty, or empty for
// none. Returns components sorted by size (largest first, ties by smallest
// corner index); labels of a component start at (0, 0) in its minimum.
// Deterministic. Invalid corners are ignored; bad options or an unsupported
// image type return no components with a reason in `summary`. `trace`, when
// not null, receives every edge Kruskal saw, for diagnostics.
std::vector<GridComponent> BuildGrid(
    const std::vector<Corner>& corners, const cv::Mat& image,
    const GridOptions& options = {}, GridSummary* summary = nullptr,
    std::vector<GridEdgeTrace>* trace = nullptr);

}  // namespace puzzlecal

#endif  // PUZZLECAL_GRID_GRID_H_
