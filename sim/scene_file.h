#ifndef PUZZLECAL_SIM_SCENE_FILE_H_
#define PUZZLECAL_SIM_SCENE_FILE_H_

// The files of a synthetic scene: recipes (configs/scenes/), the built-in
// scenes by name, and the truth.yaml of a rendered scene. Reading goes
// through formats/yaml_fields.h, so every
// message names the file and the field ("FILE: field 'camera.width': ...");
// writing through yaml-cpp's emitter with numbers that read back exactly.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "formats/board_file.h"
#include "sim/scenes.h"
#include "target/board.h"

namespace puzzlecal {

// Scene recipe YAML (configs/scenes/*.yaml): see configs/scenes/README.md.
// A relative `board:` path is taken relative to the scene file's folder.
bool LoadSceneFile(const std::string& path, SceneSpec* scene,
                   std::string* error);

// The built-in scenes: sim/scenes.h's standard scenes (StandardSceneNames)
// and the demo's sample set (SampleScene). Each is defined once, in C++;
// SceneRecipeYaml writes one out as a recipe to start from.
inline constexpr const char* kSampleSceneName = "sample";
std::vector<std::string> BuiltInSceneNames();
// The built-in scene of that name at width x height (0 x 0: its default
// size); false for unknown names.
bool MakeBuiltInScene(const std::string& name, int width, int height,
                      SceneSpec* scene);
// A built-in scene by name (at width x height, 0 x 0 for its default size)
// or else a recipe file (then the size must be 0 x 0: the recipe sets it).
bool LoadScene(const std::string& name_or_path, int width, int height,
               SceneSpec* scene, std::string* error);

// A recipe that LoadSceneFile reads back as `scene`: the camera by its
// parameters, the board inline, every render option, the explicit views by
// cam_from_board, and the random views and series that generate the rest.
// Numbers are written with the digits that read back exactly, so the
// recipe renders the same images as the scene.
std::string SceneRecipeYaml(const SceneSpec& scene);

// truth.yaml of a rendered scene: the scene name, the camera (model,
// parameter names and values, image size), the board, and per view the
// image file, the view name, the cam_from_board pose (rotation matrix rows,
// translation in metres) and the corners as rows [x, y, col, row, visible]
// (x, y = .nan when the corner cannot be projected). `files` holds each
// view's image file name (same order as `views`). Names are quoted where
// YAML needs it; numbers read back exactly.
std::string SceneTruthYaml(const SceneSpec& scene,
                           const std::vector<SceneView>& views,
                           const std::vector<std::string>& files);

// truth.yaml read back.
struct SceneTruthView {
  std::string file;  // the image file
  std::string name;  // the view name
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  std::vector<TruthCorner> corners;
};
struct SceneTruth {
  std::string scene;  // the scene name
  Camera camera;
  Board board;
  std::vector<SceneTruthView> views;
};
// `source` names the text in messages.
bool ParseSceneTruth(const std::string& text, const std::string& source,
                     SceneTruth* truth, std::string* error);
bool ReadSceneTruthFile(const std::string& path, SceneTruth* truth,
                        std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_SCENE_FILE_H_
