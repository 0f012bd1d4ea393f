// `puzzlecal compare`: a calibrated camera file next to the truth of a
// rendered set (truth.yaml of `puzzlecal render`).

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "apps/common_flags.h"
#include "apps/subcommand.h"
#include "camera/camera_models.h"
#include "formats/camera_yaml.h"
#include "sim/scene_file.h"

DEFINE_string(truth, "", "truth.yaml written by `puzzlecal render`.");

namespace puzzlecal {
namespace {

int RunCompare() {
  if (FLAGS_camera.empty() || FLAGS_truth.empty()) {
    std::cerr << "puzzlecal compare: --camera and --truth are required.\n";
    return kExitUsage;
  }
  Camera camera;
  std::string error;
  if (!ReadCameraFile(FLAGS_camera, &camera, &error)) {
    std::cerr << "puzzlecal compare: " << error << "\n";
    return kExitBadInput;
  }
  SceneTruth truth;
  if (!ReadSceneTruthFile(FLAGS_truth, &truth, &error)) {
    std::cerr << "puzzlecal compare: " << error << "\n";
    return kExitBadInput;
  }
  if (truth.camera.model != camera.model) {
    std::cerr << "puzzlecal compare: " << FLAGS_camera << " holds a "
              << CameraModelName(camera.model) << " camera, " << FLAGS_truth
              << " a " << CameraModelName(truth.camera.model) << " camera.\n";
    return kExitBadInput;
  }
  const std::vector<std::string> names = CameraModelParamNames(camera.model);
  std::printf("%-4s %16s %16s %14s\n", "", "calibrated", "truth", "difference");
  for (size_t i = 0; i < names.size(); ++i) {
    std::printf("%-4s %16.6f %16.6f %14.6f\n", names[i].c_str(),
                camera.params[i], truth.camera.params[i],
                camera.params[i] - truth.camera.params[i]);
  }
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    compare, "compare", "print a camera file next to a rendered set's truth",
    "puzzlecal compare --camera camera.yaml --truth DIR/truth.yaml\n\n"
    "Prints each parameter of the calibrated camera, the truth the set was "
    "rendered with, and the difference.",
    {"camera", "truth"}, &RunCompare);

}  // namespace
}  // namespace puzzlecal
