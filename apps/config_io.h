#ifndef PUZZLECAL_APPS_CONFIG_IO_H_
#define PUZZLECAL_APPS_CONFIG_IO_H_

// Readers for the YAML files in configs/: board definitions and synthetic
// scene recipes, and the writer of a rendered scene's truth.yaml. Every
// message names the file and the field.

#include <string>
#include <vector>

#include "decode/board.h"
#include "sim/scenes.h"

namespace puzzlecal {

// Board YAML (configs/boards/*.yaml):
//   type: puzzleboard | checkerboard
//   cols: 11            # inner corners along x, >= 2
//   rows: 8             # inner corners along y, >= 2
//   origin: [0, 0]      # PuzzleBoard only: first corner on the 501 x 501 torus
//   tile_size_m: 0.060  # tile edge in metres
// Unknown fields are errors (they are usually typos).
bool LoadBoardFile(const std::string& path, Board* board, std::string* error);

// Scene recipe YAML (configs/scenes/*.yaml): see configs/scenes/README.md.
// A relative `board:` path is taken relative to the scene file's folder.
bool LoadSceneFile(const std::string& path, SceneSpec* scene,
                   std::string* error);

// truth.yaml of a rendered scene: the camera (model, parameter names and
// values, image size), the board, and per view the image file, the
// cam_from_board pose (rotation matrix rows, translation in metres) and the
// corners as rows [x, y, col, row, visible]. `files` holds each view's image
// file name (same order as `views`).
std::string SceneTruthYaml(const SceneSpec& scene,
                           const std::vector<SceneView>& views,
                           const std::vector<std::string>& files);

}  // namespace puzzlecal

#endif  // PUZZLECAL_APPS_CONFIG_IO_H_
