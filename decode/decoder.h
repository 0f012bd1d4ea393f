#ifndef PUZZLECAL_DECODE_DECODER_H_
#define PUZZLECAL_DECODE_DECODER_H_

// From labelled grid components to board ids.
//
// PuzzleBoard: every component's edge bits are read (decode/edge_bits.h) and
// its label -> board map (rotation + offset) is searched over all positions
// (decode/position_search.h). The handedness of that map is not guessed: a
// board seen from its printed side keeps its (col, row) axes turning like the
// image axes, so the sign of the labels' image orientation fixes whether the
// labels are mirrored. Only the four rotations of that handedness are
// accepted; the other handedness (a mirrored image or print) and inverted
// contrast are tried only to name the reason of a refusal.
//
// Acceptance rule (per component; all must hold). The thresholds come from
// the agreement statistics printed by bench/bench_decode (true positions on
// clean and noisy renders versus best matches of random codes, mirrored and
// inverted prints and plain checkerboards):
//  1. bits_read >= min_bits_read (a 3 x 3-tile window has 24 edges);
//  2. agreement = bits_agreeing / bits_read >= min_agreement;
//  3. margin = agreeing edges at the best position minus at the second-best
//     position inside the printed board (any rotation; "inside" allows
//     max_label_overhang outermost label rows or columns beyond it, here
//     and in rules 4 and 5) >= the larger of
//     min_margin and the margin at which, with the bit error rate
//     q = max(1 - agreement, 0.02) the view shows, the best position is
//     10^min_log10_odds times likelier than the second: each edge of margin
//     is worth ((1 - q) / q)^2. Noisy views need a wider lead (q = 0.2: 4
//     edges; q = 0.1: 3; clean: 2);
//  4. the false-alarm figure log10(NFA) <= max_log10_nfa, where NFA = number
//     of in-board hypotheses x P(Binomial(bins_read, 1/2) >= bins_agreeing):
//     the expected number of positions a random pattern would match this
//     well (bins = distinct code bits after voting the period-3 repeats);
//  5. no position anywhere on the torus scores strictly better than the best
//     in-board one (else the board file or the print is not the one seen).
// Accepted components are joined into one observation; corners with at
// least `drop_corner_min_disagreeing_edges` incident edges that disagree with
// the code are dropped, and ids claimed by two corners are dropped (all).
//
// Plain checkerboard (and PuzzleBoard components that are not decoded):
// `absolute_ids` is false and each point carries its component's relative
// label, made right-handed (labels of a mirrored component get j -> -j) and
// shifted so the component's smallest label is (0, 0); labels of different
// components are not comparable (see `component`). A checkerboard component
// whose label extent equals the board's cols x rows (either orientation) gets
// board ids instead (absolute_ids true), chosen among the board's symmetric
// equivalents as the one whose +col axis points most to the image's +x.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "decode/edge_bits.h"
#include "decode/position_search.h"
#include "detection/corner.h"
#include "grid/grid_component.h"
#include "target/board.h"

namespace puzzlecal {

struct DecodeOptions {
  // How edge bits are read (disc sampling, confidence threshold).
  EdgeBitOptions bits;
  // Components with fewer labelled corners are not decoded. Default 4; >= 1.
  int min_corners = 4;
  // Components whose labels span more than this along an axis are refused
  // (guards the dense label array). Default 4096; >= 2.
  int max_label_extent = 4096;
  // Corners off the position their lattice neighbours predict by more than
  // this fraction of the local edge length are dropped before decoding
  // (mislabelled corners; see LatticeOutliers). Default 0.3 (perspective at
  // a 20-degree view and strong fisheye bend lines by < 0.15); > 0.
  double max_lattice_deviation = 0.3;
  // Positions may put up to this many of a component's outermost label
  // rows or columns beyond the printed board (on each side); the corners
  // whose ids then fall off the board are dropped. A row of corners joined
  // to the lattice one step askew (the grid took a diagonal for an axis)
  // widens the labels past the board and would otherwise hide the true
  // position: on a render of a steep view through a strongly distorting
  // fisheye (bench_advise, the splined lens's fourth advised view) a
  // 166-corner component whose bits agree 277 of 281 at the true position
  // was refused, at 54 % agreement elsewhere, because 11 of its corners
  // carried such labels. The extra positions count in the false-alarm
  // figure (rule 4). Default 1; 0 keeps every label on the board; [0, 3].
  int max_label_overhang = 1;
  // Rule 1: minimum number of read edge bits. Default 20 (a 3 x 3-tile window
  // holds 24); >= 1.
  int min_bits_read = 20;
  // Rule 2: minimum fraction of read bits agreeing with the code at the best
  // position. Default 0.7 (true positions with 20 % flipped bits measure
  // 0.74-0.85 (5th-95th percentile); random codes on full views 0.44-0.53,
  // their best 3x3-tile window match up to 0.83); in [0.5, 1].
  double min_agreement = 0.7;
  // Rule 3: minimum lead of the best position over the second best, in
  // agreeing edges. Default 2; >= 1.
  int min_margin = 2;
  // Rule 3: required odds (log10) of the best over the second-best position
  // given the observed bit error rate. Default 4 (at 20 % flipped bits,
  // odds of 10^2 let 1 in 150 5x5-tile windows through with wrong ids);
  // >= 0.
  double min_log10_odds = 4.0;
  // Rule 4: maximum log10 of the expected number of false matches. Default
  // -3 (about one random pattern in 1000 passes; a clean 3 x 3-tile window
  // on the 72 x 52 board reaches -3.4, at -2 random-code windows were
  // accepted 1 in 200); <= 0.
  double max_log10_nfa = -3.0;
  // Rule 5: refuse when a position outside the printed board matches
  // strictly better. Default true.
  bool refuse_better_off_board = true;
  // Corners with at least this many incident read edges that disagree with
  // the code at the accepted position are dropped (mislabelled corners).
  // Default 3 (of up to 4); >= 1.
  int drop_corner_min_disagreeing_edges = 3;

  bool Check(std::string* why = nullptr) const;
};

// What happened to one grid component.
struct ComponentDecoding {
  int component = -1;     // index into the components argument
  bool decoded = false;   // absolute ids assigned
  std::string reason;     // why not, when not decoded
  int num_corners = 0;    // usable labelled corners
  int handedness = 0;     // +1 labels turn like the image, -1 mirrored, 0 ?
  int edges = 0;          // lattice edges between two labelled corners
  int bits_read = 0;      // edges whose bit was read
  int bits_agreeing = 0;  // read bits agreeing with the code at the best position
  double agreement = 0.0; // bits_agreeing / bits_read
  int bins_read = 0;      // distinct code bits seen (after period-3 voting)
  int bins_agreeing = 0;
  int margin = 0;         // agreeing edges: best minus second-best position
  int hypotheses = 0;     // in-board positions x rotations scored
  double log10_nfa = 0.0; // rule 4 figure at the best position
  // Agreement of the best match under the other handedness and under
  // inverted contrast (computed only when the component is refused; -1 when
  // not computed). A value near 1 names a mirrored / inverted print.
  double mirrored_agreement = -1.0;
  double inverted_agreement = -1.0;
  // Label -> board map: id = rotation * ij + offset (ids unwrapped into the
  // board's printed range). Valid when decoded (PuzzleBoard) or when a
  // checkerboard component got board ids.
  Eigen::Matrix2i rotation = Eigen::Matrix2i::Identity();
  Eigen::Vector2i offset = Eigen::Vector2i::Zero();
  // Corners removed: invalid or duplicate labels, off their lattice
  // neighbours, disagreeing bits, colliding ids.
  int corners_dropped = 0;
};

struct DecodeResult {
  // PuzzleBoard: at least one component got absolute ids. Checkerboard: a
  // component spans the whole board and got board ids.
  bool decoded = false;
  // True when observation.id are board ids; false when they are relative
  // labels (see the header comment for the convention).
  bool absolute_ids = false;
  std::string reason;  // why not decoded, when not
  // Ids (absolute in [origin, origin + size) for a decoded PuzzleBoard) and
  // pixel positions.
  BoardObservation observation;
  std::vector<int> corner_index;  // per observation point: index into corners
  std::vector<int> component;     // per observation point: component index
  std::vector<ComponentDecoding> components;  // one per input component
};

// Decodes the components of one image. `image`: 8-bit, 16-bit or float grey
// (colour images are converted); only read for a PuzzleBoard.
DecodeResult DecodeBoard(const Board& board, const std::vector<Corner>& corners,
                         const std::vector<GridComponent>& components,
                         const cv::Mat& image,
                         const DecodeOptions& options = DecodeOptions());

// The PuzzleBoard decision for one component from its edge readings (the
// part of DecodeBoard after ReadEdgeBits; exposed so tests can corrupt bits).
// `decoding->handedness` must be set (LabelHandedness). On acceptance fills
// `map` and `keep` (per lattice point: 0 = dropped for disagreeing edges, or
// as beyond the board or on its outermost row where labels overhang it).
bool DecodeComponentBits(const LabelLattice& lattice,
                         const EdgeBitReading& reading, const Board& board,
                         const DecodeOptions& options,
                         ComponentDecoding* decoding, LabelToBoard* map,
                         std::vector<char>* keep);

}  // namespace puzzlecal

#endif  // PUZZLECAL_DECODE_DECODER_H_
