#ifndef PUZZLECAL_TARGET_BOARD_H_
#define PUZZLECAL_TARGET_BOARD_H_

#include <Eigen/Core>
#include <string>
#include <vector>

namespace puzzlecal {

enum class BoardType {
  kPuzzleBoard,   // absolute ids from the edge bits (target/puzzleboard.h)
  kCheckerboard,  // plain checkerboard; ids only up to the board's symmetry
};

// What a board type means to the code that prints, renders, decodes and
// checks it. Every type-dependent property is read from here (BoardTraits
// switches over the types without a default, so the compiler names the
// place a new type must fill in).
struct BoardTypeTraits {
  // Every tile edge carries a bit, so corner ids are absolute and any 3 x 3
  // tiles place a view on the board (PuzzleBoard). Without them a view is
  // labelled only up to the board's symmetry, and only when it shows the
  // whole board.
  bool absolute_ids;
  // `origin` places the board on the pattern's 501 x 501 torus; otherwise
  // it is (0, 0).
  bool has_origin;
  // The printed margin from the outer inner corners to the page edge, in
  // tiles.
  double border_tiles;
  // Renders draw tiles beyond the printed border as paper (a plain
  // checkerboard ends there; a PuzzleBoard render keeps its code going, as
  // a larger print of the same pattern would).
  bool pattern_ends_at_border;
};
BoardTypeTraits BoardTraits(BoardType type);

// "puzzleboard" / "checkerboard".
const char* BoardTypeName(BoardType type);
bool BoardTypeFromName(const std::string& name, BoardType* type);

// Geometry of a printed target. Corner id (col, row) sits at
// (col * tile_size_m, row * tile_size_m, 0) in the board frame.
// Largest number of inner corners along one side that a board file may give
// (a checkerboard; a PuzzleBoard is limited to 501 by its code). Bounds
// memory and work for a mistyped size.
inline constexpr int kMaxBoardSide = 2000;
// Largest tile side a board file may give, in metres: a larger one is a
// length in millimetres or centimetres written as metres (30 for 30 mm
// tiles made a rig's baseline 120 km and advised the board 190 m away).
inline constexpr double kMaxTileSizeM = 1.0;

struct Board {
  // Which pattern is printed.
  BoardType type = BoardType::kPuzzleBoard;
  // Number of inner corners along x (columns) and y (rows).
  int cols = 11;
  int rows = 8;
  // Id of the first printed corner. For a PuzzleBoard this is its place on
  // the 501 x 501 torus (both in [0, 501)); a checkerboard uses (0, 0).
  Eigen::Vector2i origin = Eigen::Vector2i::Zero();
  // Tile edge length in metres (> 0).
  double tile_size_m = 0.02;

  // True when the fields describe a usable board; otherwise `why` (if not
  // null) names the offending field.
  bool Check(std::string* why = nullptr) const;

  // The type's properties (BoardTraits(type)).
  BoardTypeTraits Traits() const { return BoardTraits(type); }
  int NumCorners() const { return cols * rows; }
  // True when `id` is one of the printed corners
  // [origin.x, origin.x + cols) x [origin.y, origin.y + rows).
  bool Contains(const Eigen::Vector2i& id) const;
  // 3D point of corner `id` on the board plane (z = 0), in metres.
  Eigen::Vector3d Point(const Eigen::Vector2i& id) const;
  // All printed corner ids, row-major (row, then col).
  std::vector<Eigen::Vector2i> AllIds() const;
};

// A board of `type` with cols x rows inner corners starting at `origin`
// (a checkerboard's origin is (0, 0)) and tiles of `tile_size_m` metres. Not
// checked: call Board::Check on boards that come from outside the program.
Board MakeBoard(BoardType type, int cols, int rows,
                const Eigen::Vector2i& origin, double tile_size_m);

// An image's view of a board: absolute corner ids and their pixel positions.
struct BoardObservation {
  std::vector<Eigen::Vector2i> id;
  std::vector<Eigen::Vector2d> xy;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_TARGET_BOARD_H_
