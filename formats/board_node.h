#ifndef PUZZLECAL_FORMATS_BOARD_NODE_H_
#define PUZZLECAL_FORMATS_BOARD_NODE_H_

// The board as a YAML map, for files that hold one inside (scene recipes,
// truth.yaml). Exposes yaml-cpp: only readers and writers of such files
// include it.

#include <yaml-cpp/yaml.h>

#include <string>

#include "formats/yaml_fields.h"
#include "target/board.h"

namespace puzzlecal {

// The board map at `path` ("" for the root) of a file read by `reader`:
// type, cols, rows, origin, tile_size_m (see board_file.h); unknown fields
// are errors.
bool ParseBoardNode(const YAML::Node& node, const std::string& path,
                    FieldReader* reader, Board* board);

// The board as a map of its fields, numbers that read back exactly.
void EmitBoardNode(YAML::Emitter& out, const Board& board);

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_BOARD_NODE_H_
