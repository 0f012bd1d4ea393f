#ifndef PUZZLECAL_DECODE_POSITION_SEARCH_H_
#define PUZZLECAL_DECODE_POSITION_SEARCH_H_

// Finding where a component's edge bits sit on the PuzzleBoard torus.
//
// A hypothesis maps labels to board ids: id = M * ij + t, M one of the four
// rotations (composed with a reflection for mirrored labels), t an integer
// offset. Because the vertical-edge bit depends only on (y mod 3, x mod 167)
// and the horizontal one on (x mod 3, y mod 167), the observed bits are first
// voted into 3 x 167 bins per edge direction (this votes over the period-3
// repetitions of a large view), then correlated with the A and B codes for
// every residue (ty mod 3, tx mod 167) and (tx mod 3, ty mod 167). The score
// of any t is then the sum of two table entries (score = agreeing edges -
// disagreeing edges), so all 4 x 251,001 torus positions are scored at once
// and the positions inside the printed board are enumerated exactly.

#include <Eigen/Core>
#include <vector>

#include "target/board.h"

namespace puzzlecal {

// One read edge bit in label coordinates: the edge from `from` to
// from + (1, 0) (axis 0) or from + (0, 1) (axis 1).
struct LabelEdgeVote {
  Eigen::Vector2i from = Eigen::Vector2i::Zero();
  int axis = 0;
  int bit = 0;  // 1 = white disc
};

// The label -> board map id = rotation * ij + offset.
struct LabelToBoard {
  Eigen::Matrix2i rotation = Eigen::Matrix2i::Identity();
  Eigen::Vector2i offset = Eigen::Vector2i::Zero();
  Eigen::Vector2i Apply(const Eigen::Vector2i& ij) const {
    return rotation * ij + offset;
  }
};

// The four label -> board rotations of the given handedness (+1: proper
// rotations, -1: rotations composed with the reflection j -> -j), in order
// 0, 90, 180, 270 degrees.
std::vector<Eigen::Matrix2i> LabelRotations(int handedness);

struct PositionSearchResult {
  // "In-board" below: every id inside the printed board (offset unwrapped
  // so ids are in [origin, origin + size)), give or take `overhang` rows
  // and columns on each side.
  bool found = false;  // at least one in-board hypothesis was scored
  // Best in-board hypothesis that agrees with the observed tile colour (when
  // known).
  LabelToBoard best;
  int best_score = 0;    // agreeing - disagreeing edges at `best`
  // Best score of any other in-board hypothesis; best_score - 2 * num_edges
  // - 2 when there is none (the margin in edges is then num_edges + 1).
  int second_score = 0;
  int hypotheses = 0;    // in-board hypotheses scored
  int num_edges = 0;     // votes (read edges)
  int edges_agreeing = 0;  // at `best`
  int bins_read = 0;     // code bins with a non-zero vote
  int bins_agreeing = 0;   // bins whose majority matches the code at `best`
  // Best score anywhere on the torus (any rotation of this handedness,
  // tile colour ignored).
  int torus_best_score = 0;
};

// Scores all hypotheses of the given handedness for `votes`, whose labels lie
// in [label_min, label_max]. `dark_tile_parity` (0/1, -1 unknown) is the
// parity of i + j of the dark label tiles (see EdgeBitReading). With
// `inverted`, the bits and tile colours are matched as if the print were
// contrast-inverted (a diagnostic for refusals). `overhang` > 0 also
// scores the positions that put up to that many of the labels' outermost
// rows or columns beyond the printed board on each side (see
// DecodeOptions::max_label_overhang); they count as in-board hypotheses.
PositionSearchResult SearchPuzzleBoardPosition(
    const std::vector<LabelEdgeVote>& votes, const Eigen::Vector2i& label_min,
    const Eigen::Vector2i& label_max, int handedness, int dark_tile_parity,
    const Board& board, bool inverted = false, int overhang = 0);

// The code bit of label edge `vote` under `map` (board edge rules of docs/puzzleboard.md).
int BoardBitOfLabelEdge(const LabelToBoard& map, const Eigen::Vector2i& from,
                        int axis);

// log10 of P(X >= k) for X ~ Binomial(n, 1/2).
double Log10BinomialTailHalf(int n, int k);

}  // namespace puzzlecal

#endif  // PUZZLECAL_DECODE_POSITION_SEARCH_H_
