#ifndef PUZZLECAL_FORMATS_BOARD_FILE_H_
#define PUZZLECAL_FORMATS_BOARD_FILE_H_

// Board files (configs/boards/*.yaml), read through formats/yaml_fields.h so
// that every message names the file and the field.

#include <string>

#include "target/board.h"

namespace puzzlecal {

// Board YAML (configs/boards/*.yaml):
//   type: puzzleboard | checkerboard
//   cols: 11            # inner corners along x, >= 2
//   rows: 8             # inner corners along y, >= 2
//   origin: [0, 0]      # PuzzleBoard only: first corner on the 501 x 501 torus
//   tile_size_m: 0.060  # tile edge in metres
// Unknown fields are errors (they are usually typos).
bool LoadBoardFile(const std::string& path, Board* board, std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_BOARD_FILE_H_
