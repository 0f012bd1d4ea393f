#ifndef PUZZLECAL_DECODE_EDGE_BITS_H_
#define PUZZLECAL_DECODE_EDGE_BITS_H_

// Reading the PuzzleBoard edge bits of one labelled grid component: the disc
// on each lattice edge between two labelled corners is compared with the
// black and white levels of the two tiles beside that edge.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "detection/corner.h"
#include "grid/grid_component.h"

namespace puzzlecal {

// A component's corners on a dense array over its label bounding box.
struct LabelLattice {
  Eigen::Vector2i min_label = Eigen::Vector2i::Zero();
  int width = 0;   // label extent along i
  int height = 0;  // label extent along j
  // Per cell (i - min_i) + width * (j - min_j): index into `xy`, or -1.
  std::vector<int> cell;
  std::vector<Eigen::Vector2d> xy;         // pixel position per point
  std::vector<Eigen::Vector2i> label;      // lattice label per point
  std::vector<int> corner_index;           // index into the corner list
  int dropped_duplicates = 0;  // corners dropped because two shared a label
  int dropped_invalid = 0;     // bad index or non-finite position

  // Point index at label (i, j), or -1.
  int At(int i, int j) const {
    const int x = i - min_label.x();
    const int y = j - min_label.y();
    if (x < 0 || y < 0 || x >= width || y >= height) return -1;
    return cell[x + width * y];
  }
  int At(const Eigen::Vector2i& ij) const { return At(ij.x(), ij.y()); }
};

// Builds the lattice of `component`. Corners with an invalid index or a
// non-finite position are skipped; labels held by two corners are dropped
// (both). Returns false with `why` when nothing usable is left or the label
// extent exceeds `max_extent` along either axis.
bool BuildLabelLattice(const std::vector<Corner>& corners,
                       const GridComponent& component, int max_extent,
                       LabelLattice* lattice, std::string* why);

// Points whose position contradicts their lattice neighbours (a corner
// given a wrong label): per lattice axis with both neighbours labelled, the
// point should lie near their midpoint; with two neighbours on one side, near
// the linear extrapolation. A prediction is bad when off by more than
// `max_deviation` times the local edge length; points with more bad than good
// predictions are returned (indices into lattice.xy).
std::vector<int> LatticeOutliers(const LabelLattice& lattice, double max_deviation);

// Orientation of the labels in the image: +1 when label axes (i, j) turn like
// the image axes (x right, y down), which is how a board seen from its printed
// side maps its (col, row) axes; -1 when the labels are mirrored; 0 when no
// corner has both a +i and a +j neighbour. Majority over all such corners.
int LabelHandedness(const LabelLattice& lattice);

struct EdgeBitOptions {
  // A bit counts as read when |confidence| reaches this (confidence = offset
  // of the disc sample from the mid level, in units of half the local
  // black-white contrast; 1 = as dark/bright as the tiles). Default 0.15.
  // Measured (bench_decode, blur 0.7 px, noise 3 %): plain checkerboard
  // edges 95th percentile 0.08; discs, 5th percentile toward the true bit:
  // 0.15 at 4 px tiles, 0.27 at 5 px, 0.37 at 6 px, 0.75 at 12 px. In (0, 1].
  double min_confidence = 0.15;
  // Minimum contrast between the two tiles beside an edge, as a fraction of
  // the image's full range (255 for 8-bit). Below it the edge is unread.
  // Default 0.04; in [0, 1).
  double min_tile_contrast = 0.04;
  // The disc is sampled at the edge midpoint and at +- this fraction of the
  // edge length along the edge (the disc radius is 1/6 of the edge), and the
  // samples are averaged. Default 1/12 (half the disc radius); in [0, 1/6].
  double disc_sample_offset = 1.0 / 12.0;
  // Each tile level is the mean of its centre and four points at +- this
  // fraction of the lattice vectors around it (away from the discs, which
  // reach 1/6 into the tile). Default 0.15; in [0, 0.3].
  double tile_sample_offset = 0.15;

  bool Check(std::string* why = nullptr) const;
};

// One lattice edge from label `from` to from + (1,0) (axis 0) or from + (0,1)
// (axis 1), with its reading.
struct EdgeBit {
  Eigen::Vector2i from = Eigen::Vector2i::Zero();
  int axis = 0;
  // Disc level relative to the mid level, in [-1, 1]: > 0 white disc (bit 1).
  double confidence = 0.0;
  bool read = false;  // |confidence| and contrast passed the thresholds
};

// Edge reading summary for one component.
struct EdgeBitReading {
  std::vector<EdgeBit> edges;  // every edge between two labelled corners
  int num_read = 0;
  // Tile colour: 0 when label tiles whose min corner (i, j) has i + j even
  // are the dark ones, 1 when the odd ones are, -1 when unknown. Voted over
  // the edges (each edge tells which of its two tiles is darker).
  int dark_tile_parity = -1;
  int dark_parity_votes = 0;   // votes for the winning parity
  int parity_votes_total = 0;  // all edges with enough contrast
};

// Reads every edge of `lattice` in `image` (8-bit, 16-bit or float, one
// channel; float images in [0, 1]). The disc position on an edge comes from a
// cubic (or quadratic) interpolation through the corners along the lattice
// line, so curved edges under fisheye distortion are followed.
EdgeBitReading ReadEdgeBits(const LabelLattice& lattice, const cv::Mat& image,
                            const EdgeBitOptions& options);

}  // namespace puzzlecal

#endif  // PUZZLECAL_DECODE_EDGE_BITS_H_
