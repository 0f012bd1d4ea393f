// `puzzlecal render`: renders a built-in scene or a scene recipe into PNGs
// plus truth.yaml, or writes a scene out as a recipe.

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "apps/common_flags.h"
#include "apps/subcommand.h"
#include "formats/png_writer.h"
#include "sim/scene_file.h"
#include "sim/scenes.h"
#include "util/atomic_file.h"

DEFINE_string(size, "",
              "Image size WIDTHxHEIGHT of a built-in scene (default: the "
              "scene's own).");
DEFINE_string(write_recipe, "",
              "Write the scene as a recipe file (a built-in scene's recipe "
              "is a start for your own).");

namespace puzzlecal {
namespace {

// --size as width and height; 0 x 0 when not given.
bool ParseSize(const std::string& text, int* width, int* height) {
  *width = *height = 0;
  if (text.empty()) return true;
  char tail = 0;
  return std::sscanf(text.c_str(), "%dx%d%c", width, height, &tail) == 2 &&
         *width >= 1 && *height >= 1 && *width <= 20000 && *height <= 20000;
}

std::string BuiltInNamesText() {
  std::string text;
  for (const std::string& name : BuiltInSceneNames()) {
    text += (text.empty() ? "" : ", ") + name;
  }
  return text;
}

// Renders every view into FLAGS_out and writes truth.yaml there.
int RenderInto(const SceneSpec& scene) {
  std::error_code ec;
  std::filesystem::create_directories(FLAGS_out, ec);
  if (ec || !std::filesystem::is_directory(FLAGS_out)) {
    std::cerr << "puzzlecal render: cannot create the folder " << FLAGS_out
              << (ec ? ": " + ec.message() : "") << "\n";
    return kExitOutputError;
  }
  std::string error;
  const std::vector<SceneView> views = RenderScene(scene, &error);
  if (views.empty()) {
    std::cerr << "puzzlecal render: " << FLAGS_scene << ": " << error << "\n";
    return kExitNoResult;
  }
  std::vector<std::string> files;
  for (const SceneView& view : views) {
    const std::string file = scene.name + "_" + view.name + ".png";
    const std::string path = (std::filesystem::path(FLAGS_out) / file).string();
    if (!WritePngFile(path, view.image, &error)) {
      std::cerr << "puzzlecal render: " << error << "\n";
      return kExitOutputError;
    }
    int visible = 0;
    for (const TruthCorner& c : view.truth.corners) visible += c.visible;
    std::cout << path << ": " << visible << " of " << view.truth.corners.size()
              << " corners visible\n";
    files.push_back(file);
  }
  const std::string truth_path =
      (std::filesystem::path(FLAGS_out) / "truth.yaml").string();
  if (!WriteFileAtomically(truth_path, SceneTruthYaml(scene, views, files),
                           &error)) {
    std::cerr << "puzzlecal render: " << error << "\n";
    return kExitOutputError;
  }
  std::cout << truth_path << ": " << views.size() << " views\n";
  return kExitOk;
}

int RunRender() {
  if (FLAGS_scene.empty() ||
      (FLAGS_out.empty() && FLAGS_write_recipe.empty())) {
    std::cerr << "puzzlecal render: --scene and --out (or --write-recipe) are "
                 "required (see puzzlecal render --help)\n";
    return kExitUsage;
  }
  int width = 0, height = 0;
  if (!ParseSize(FLAGS_size, &width, &height)) {
    std::cerr << "puzzlecal render: --size must be WIDTHxHEIGHT (1 to 20000 "
                 "each), got '"
              << FLAGS_size << "'\n";
    return kExitUsage;
  }
  SceneSpec scene;
  std::string error;
  if (!LoadScene(FLAGS_scene, width, height, &scene, &error)) {
    std::cerr << "puzzlecal render: " << error
              << " (built-in scenes: " << BuiltInNamesText() << ")\n";
    return kExitBadInput;
  }
  if (!FLAGS_write_recipe.empty()) {
    if (!WriteFileAtomically(FLAGS_write_recipe, SceneRecipeYaml(scene),
                             &error)) {
      std::cerr << "puzzlecal render: " << error << "\n";
      return kExitOutputError;
    }
    std::cout << FLAGS_write_recipe << ": recipe of scene " << scene.name
              << "\n";
  }
  return FLAGS_out.empty() ? kExitOk : RenderInto(scene);
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    render, "render", "render synthetic views of a board with exact truth",
    "puzzlecal render --scene NAME|RECIPE.yaml --out DIR [--size WxH]\n"
    "                 [--write-recipe FILE]\n\n"
    "Renders every view of a scene (camera, board, poses, blur, noise,\n"
    "lighting, occluders) into DIR/SCENE_VIEW.png and writes\n"
    "DIR/truth.yaml: the camera model, its parameters and image size, and\n"
    "per view the file, cam_from_board (rotation matrix rows, translation\n"
    "in metres) and every corner as [x, y, col, row, visible]. The scene is\n"
    "a built-in by name (wide_pinhole, strong_fisheye, sample, ...; an\n"
    "unknown name lists them all), at its own image size or --size, or a\n"
    "recipe file (see configs/scenes/README.md). --write-recipe FILE writes\n"
    "the scene as a recipe, a start for your own (--out may then be left\n"
    "out).\n"
    "Files are written atomically; the same scene always gives the same\n"
    "images.",
    {"scene", "out", "size", "write_recipe"}, &RunRender);

}  // namespace
}  // namespace puzzlecal
