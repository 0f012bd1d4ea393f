#include "target/board.h"

#include <cmath>

#include "target/puzzleboard_codes.h"
#include "util/enum_names.h"
#include "util/failure.h"
#include "util/string_format.h"

namespace puzzlecal {

constexpr EnumName<BoardType> kBoardTypeNames[] = {
    {BoardType::kPuzzleBoard, "puzzleboard"},
    {BoardType::kCheckerboard, "checkerboard"},
};

const char* BoardTypeName(BoardType type) {
  return NameOf(kBoardTypeNames, type, "unknown");
}

bool BoardTypeFromName(const std::string& name, BoardType* type) {
  return ValueOf(kBoardTypeNames, name, type);
}

BoardTypeTraits BoardTraits(BoardType type) {
  switch (type) {
    case BoardType::kPuzzleBoard:
      return {/*absolute_ids=*/true, /*has_origin=*/true,
              /*border_tiles=*/0.5, /*pattern_ends_at_border=*/false};
    case BoardType::kCheckerboard:
      return {/*absolute_ids=*/false, /*has_origin=*/false,
              /*border_tiles=*/1.0, /*pattern_ends_at_border=*/true};
  }
  return {};  // not reached: every type is a case above
}

bool Board::Check(std::string* why) const {
  if (cols < 2 || rows < 2) {
    return Fail("cols and rows must both be >= 2 (inner corners)", why);
  }
  if (cols > kMaxBoardSide || rows > kMaxBoardSide) {
    return Fail("cols and rows must be <= " + std::to_string(kMaxBoardSide) +
                    " (inner corners; a typo?)",
                why);
  }
  if (!(std::isfinite(tile_size_m) && tile_size_m > 0.0)) {
    return Fail("tile_size_m must be a positive number of metres", why);
  }
  if (tile_size_m > kMaxTileSizeM) {
    return Fail(StringPrintf("tile_size_m is %g m, more than %g m: it is in "
                             "metres (30 mm tiles are 0.030)",
                             tile_size_m, kMaxTileSizeM),
                why);
  }
  if (Traits().has_origin) {
    if (cols > kPuzzleBoardPeriod || rows > kPuzzleBoardPeriod) {
      return Fail("cols and rows must be <= 501 for a PuzzleBoard", why);
    }
    if (origin.x() < 0 || origin.y() < 0 || origin.x() >= kPuzzleBoardPeriod ||
        origin.y() >= kPuzzleBoardPeriod) {
      return Fail("origin must lie in [0, 501) x [0, 501)", why);
    }
  } else if (origin != Eigen::Vector2i::Zero()) {
    return Fail("origin must be [0, 0] for a checkerboard", why);
  }
  return true;
}

bool Board::Contains(const Eigen::Vector2i& id) const {
  return id.x() >= origin.x() && id.x() < origin.x() + cols &&
         id.y() >= origin.y() && id.y() < origin.y() + rows;
}

Eigen::Vector3d Board::Point(const Eigen::Vector2i& id) const {
  return Eigen::Vector3d(id.x() * tile_size_m, id.y() * tile_size_m, 0.0);
}

std::vector<Eigen::Vector2i> Board::AllIds() const {
  std::vector<Eigen::Vector2i> ids;
  ids.reserve(NumCorners());
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      ids.emplace_back(origin.x() + col, origin.y() + row);
    }
  }
  return ids;
}

Board MakeBoard(BoardType type, int cols, int rows,
                const Eigen::Vector2i& origin, double tile_size_m) {
  Board board;
  board.type = type;
  board.cols = cols;
  board.rows = rows;
  board.origin = origin;
  board.tile_size_m = tile_size_m;
  return board;
}

}  // namespace puzzlecal
