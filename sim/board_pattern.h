#ifndef PUZZLECAL_SIM_BOARD_PATTERN_H_
#define PUZZLECAL_SIM_BOARD_PATTERN_H_

// What is printed where on a board: tiles, PuzzleBoard discs, paper margin.
// Shared by the renderer (point queries) and the printable-board writer
// (edge bits and tile colours).

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "sim/render.h"
#include "target/board.h"
#include "target/puzzleboard_codes.h"

namespace puzzlecal {

// What a point of the board plane shows.
enum class BoardInk : uint8_t {
  kNone,   // off the paper
  kPaper,  // the white margin around the pattern
  kBlack,  // black print (tile or disc)
  kWhite,  // white part of the pattern (tile or disc)
};

// Extent of a printed pattern in tile units of the corner-id frame (corner
// (x, y) at (x, y)): PuzzleBoard pages end half a tile outside the outermost
// corners (docs/puzzleboard.md, 'Printed boards'); checkerboards have full border tiles.
struct PatternExtent {
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
};
PatternExtent PrintedPatternExtent(const Board& board);

// Fractions of a small area of the board plane covered by each kind of ink
// (they sum to 1). Paper and white print are both white.
struct InkMix {
  double black = 0.0;
  double white = 0.0;
  double none = 0.0;  // off the paper
};

class BoardPattern {
 public:
  // `board` must pass Board::Check; paper_margin_tiles >= 0 is the white
  // paper beyond the printed pattern, in tiles.
  BoardPattern(const Board& board, const PatternVariant& variant,
               double paper_margin_tiles);

  // Ink at (u, v) in tile units of the corner-id frame (board-plane metres
  // divided by the tile size).
  BoardInk Sample(double u, double v) const;

  // Ink fractions over the footprint of one supersample around (u, v).
  // `footprint` maps a step of one sample spacing in image x (column 0) and
  // image y (column 1) to tile units: the Jacobian d(u, v)/d(pixel) times the
  // sample spacing. Each boundary (tile edge, disc rim, pattern and paper
  // border) is smoothed by a linear ramp as wide as the footprint's extent
  // across it, which is the exact box-filter coverage for boundaries along
  // the sample axes and unbiased for the others. A zero footprint gives the
  // hard point sample.
  // (Tile edges and disc rims use the exact coverage of the sample's
  // parallelogram by a straight boundary; X-junctions and the rectangle
  // borders multiply per-axis coverages.)
  InkMix SampleArea(double u, double v, const Eigen::Matrix2d& footprint) const;

  // What crosses the axis-aligned box [min_u, max_u] x [min_v, max_v] (tile
  // units): nothing (Sample() anywhere is its colour), one straight tile
  // edge only (SampleArea() with the whole box's footprint is exact), or
  // more (corners, disc rims, borders: supersample). Conservative: may
  // answer kComplex for a simpler box.
  enum class BoxContent { kUniform, kOneEdge, kComplex };
  BoxContent Classify(double min_u, double min_v, double max_u,
                      double max_v) const;

  // Bit (0 black disc, 1 white disc) of the edges as printed by this
  // variant's code (absolute ids; no mirroring or inversion applied).
  int VerticalEdgeBit(int x, int y) const;
  int HorizontalEdgeBit(int x, int y) const;

  const PatternExtent& extent() const { return extent_; }

 private:
  using CodeTable = std::array<std::array<uint8_t, kPuzzleBoardCodeLength>,
                               kPuzzleBoardCodeRows>;

  BoardInk SampleUnmirrored(double u, double v) const;
  // Black fraction of the printed pattern (tiles and discs, before
  // inversion) around (u, v).
  double PatternBlack(double u, double v,
                      const Eigen::Matrix2d& footprint) const;
  bool TileIsBlack(int x, int y) const;

  Board board_;
  PatternVariant variant_;
  PatternExtent extent_;
  PatternExtent paper_;
  bool random_code_ = false;
  CodeTable code_a_{};
  CodeTable code_b_{};
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_BOARD_PATTERN_H_
