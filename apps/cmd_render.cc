// `puzzlecal render`: renders a scene recipe into PNGs plus truth.yaml.

#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "apps/common_flags.h"
#include "apps/config_io.h"
#include "apps/subcommand.h"
#include "util/atomic_file.h"
#include "sim/scenes.h"

namespace puzzlecal {
namespace {

int RunRender() {
  if (FLAGS_scene.empty() || FLAGS_out.empty()) {
    std::cerr << "puzzlecal render: --scene and --out are required (see "
                 "puzzlecal render --help)\n";
    return kExitUsage;
  }
  SceneSpec scene;
  std::string error;
  if (!LoadSceneFile(FLAGS_scene, &scene, &error)) {
    std::cerr << "puzzlecal render: " << error << "\n";
    return kExitBadInput;
  }
  std::error_code ec;
  std::filesystem::create_directories(FLAGS_out, ec);
  if (ec || !std::filesystem::is_directory(FLAGS_out)) {
    std::cerr << "puzzlecal render: cannot create the folder " << FLAGS_out
              << (ec ? ": " + ec.message() : "") << "\n";
    return kExitOutputError;
  }
  const std::vector<SceneView> views = RenderScene(scene, &error);
  if (views.empty()) {
    std::cerr << "puzzlecal render: " << FLAGS_scene << ": " << error << "\n";
    return kExitNoResult;
  }
  std::vector<std::string> files;
  for (const SceneView& view : views) {
    const std::string file = scene.name + "_" + view.name + ".png";
    std::vector<uchar> png;
    if (!cv::imencode(".png", view.image, png)) {
      std::cerr << "puzzlecal render: cannot encode " << file << "\n";
      return kExitOutputError;
    }
    const std::string path = (std::filesystem::path(FLAGS_out) / file).string();
    if (!WriteFileAtomically(path, std::string(png.begin(), png.end()),
                             &error)) {
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

PUZZLECAL_REGISTER_SUBCOMMAND(
    render, "render", "render synthetic views of a board with exact truth",
    "puzzlecal render --scene configs/scenes/NAME.yaml --out DIR\n\n"
    "Renders every view of the scene recipe (camera, board, poses, blur,\n"
    "noise, lighting, occluders; see configs/scenes/README.md) into\n"
    "DIR/NAME_VIEW.png and writes DIR/truth.yaml: the camera model, its\n"
    "parameters and image size, and per view the file, cam_from_board\n"
    "(rotation matrix rows, translation in metres) and every corner as\n"
    "[x, y, col, row, visible]. Files are written atomically; the same\n"
    "recipe always gives the same images.",
    {"scene", "out"}, &RunRender);

}  // namespace
}  // namespace puzzlecal
