#include "formats/board_file.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>
#include <vector>

#include "formats/board_node.h"
#include "formats/yaml_emit.h"
#include "formats/yaml_fields.h"

namespace puzzlecal {
namespace {

constexpr Presence kRequired = Presence::kRequired;
constexpr Presence kOptional = Presence::kOptional;

}  // namespace

bool ParseBoardNode(const YAML::Node& node, const std::string& path,
                    FieldReader* r, Board* board) {
  if (!r->OnlyKeys(node, path,
                   {"type", "cols", "rows", "origin", "tile_size_m"})) {
    return false;
  }
  Board b;
  std::string type;
  if (!r->String(node, path, "type", kRequired, &type)) return false;
  if (!BoardTypeFromName(type, &b.type)) {
    return r->Fail(FieldReader::Join(path, "type"),
                   "must be puzzleboard or checkerboard, got '" + type + "'");
  }
  if (!r->Int(node, path, "cols", kRequired, &b.cols) ||
      !r->Int(node, path, "rows", kRequired, &b.rows) ||
      !r->Double(node, path, "tile_size_m", kRequired, &b.tile_size_m)) {
    return false;
  }
  std::vector<double> origin = {0, 0};
  if (!r->Doubles(node, path, "origin", kOptional, 2, &origin)) return false;
  for (int i = 0; i < 2; ++i) {
    if (origin[i] != std::floor(origin[i]) || std::abs(origin[i]) > 1e6) {
      return r->Fail(FieldReader::Join(path, "origin"),
                     "must hold two integers");
    }
    b.origin[i] = static_cast<int>(origin[i]);
  }
  std::string why;
  if (!b.Check(&why)) {
    // Board::Check names the field first ("cols and rows must ...").
    const std::string field = why.rfind("tile_size_m", 0) == 0 ? "tile_size_m"
                              : why.rfind("origin", 0) == 0    ? "origin"
                                                               : "cols/rows";
    return r->Fail(FieldReader::Join(path, field), why);
  }
  *board = b;
  return true;
}

void EmitBoardNode(YAML::Emitter& out, const Board& board) {
  out << YAML::BeginMap;
  out << YAML::Key << "type" << YAML::Value << BoardTypeName(board.type);
  out << YAML::Key << "cols" << YAML::Value << board.cols;
  out << YAML::Key << "rows" << YAML::Value << board.rows;
  out << YAML::Key << "origin" << YAML::Value << YAML::Flow << YAML::BeginSeq
      << board.origin.x() << board.origin.y() << YAML::EndSeq;
  out << YAML::Key << "tile_size_m" << YAML::Value;
  EmitExact(out, board.tile_size_m);
  out << YAML::EndMap;
}

bool LoadBoardFile(const std::string& path, Board* board, std::string* error) {
  YAML::Node root;
  if (!LoadYaml(path, &root, error)) return false;
  FieldReader reader(path, error);
  return ParseBoardNode(root, "", &reader, board);
}

}  // namespace puzzlecal
