#ifndef PUZZLECAL_FUZZ_CONFIG_YAML_CASE_H_
#define PUZZLECAL_FUZZ_CONFIG_YAML_CASE_H_

// Fuzz case (c): the board and scene YAML readers (formats/board_file.h,
// sim/scene_file.h). Byte 0 chooses the reader (even: LoadBoardFile, odd:
// LoadSceneFile); the other bytes are the file. A file that loads must describe
// a valid board / scene; a refused one must say why, naming the file.

#include <cstddef>
#include <cstdint>
#include <string>

#include "formats/board_file.h"
#include "fuzz/yaml_file.h"
#include "sim/scene_file.h"
#include "sim/scenes.h"
#include "target/board.h"

namespace puzzlecal {
namespace fuzz {

inline std::string RunConfigYamlCase(const uint8_t* data, size_t size) {
  if (size == 0) return "";
  const bool scene = (data[0] & 1) != 0;
  TemporaryFile file(data + 1, size - 1, scene ? "scene.yaml" : "board.yaml");
  std::string error;
  if (scene) {
    SceneSpec spec;
    if (LoadSceneFile(file.path(), &spec, &error)) {
      std::string why;
      if (!spec.Check(&why)) return "a loaded scene fails Check: " + why;
      return "";
    }
  } else {
    Board board;
    if (LoadBoardFile(file.path(), &board, &error)) {
      std::string why;
      if (!board.Check(&why)) return "a loaded board fails Check: " + why;
      return "";
    }
  }
  if (error.empty()) return "a refused file without a message";
  if (error.find(file.path()) == std::string::npos) {
    return "the message does not name the file: " + error;
  }
  return "";
}

}  // namespace fuzz
}  // namespace puzzlecal

#endif  // PUZZLECAL_FUZZ_CONFIG_YAML_CASE_H_
