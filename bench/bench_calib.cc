// Calibration speed and accuracy on synthetic views with known truth.
// Prints one JSON object: calibration times for 20, 100 and 300 views of
// boards with 88 (11 x 8) and 368 (23 x 16) corners (pinhole-radtan; 1 and 2
// threads with the covariance) and for 192 fisheye views of the 11 x 8
// board, split into initialisation and solve + covariance, and an accuracy
// table for the three camera models, puzzlecal next to OpenCV on the same
// correspondences.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <opencv2/calib3d.hpp>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "sim/synthetic_views.h"
#include "tests/calib/opencv_reference.h"

namespace {

using puzzlecal::CalibrationOptions;
using puzzlecal::CalibrationResult;
using puzzlecal::Camera;
using puzzlecal::CameraModelId;
using puzzlecal::sim::MakeSyntheticData;
using puzzlecal::sim::SyntheticData;
using puzzlecal::sim::SyntheticScene;

SyntheticScene Scene(CameraModelId model, int views, int cols, int rows) {
  SyntheticScene scene;
  scene.num_views = views;
  scene.board_cols = cols;
  scene.board_rows = rows;
  scene.tile = 0.33 / (cols - 1);  // same board width for both sizes
  if (model == CameraModelId::kKannalaBrandt) {
    scene.camera = puzzlecal::sim::TruthFisheye190();
    scene.max_direction_deg = 85;
    scene.max_corner_angle_deg = 95;
    scene.min_visible_fraction = 0.3;
    scene.min_tilt_deg = 0;
    scene.max_tilt_deg = 60;
    scene.min_distance = 0.8;
    scene.max_distance = 1.6;
  } else {
    scene.camera = model == CameraModelId::kPinholeRadtan
                       ? puzzlecal::sim::TruthRadtan()
                       : puzzlecal::sim::TruthRational();
    scene.max_direction_deg = 32;
    scene.min_visible_fraction = 1.0;
  }
  return scene;
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since)
      .count();
}

}  // namespace

int main(int argc, char** argv) {
  // argv[1]: repeats per problem size (default 3); argv[2]: largest number
  // of views to time (default 300); argv[3]: only the timing cases of this
  // model (e.g. kannala-brandt, to profile one case; default all).
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  const int max_views = argc > 2 ? std::atoi(argv[2]) : 300;
  const std::string only_model = argc > 3 ? argv[3] : "";
  std::printf("{\n  \"timing\": [\n");
  const int view_counts[] = {20, 100, 300};
  const int boards[][2] = {{11, 8}, {23, 16}};
  bool first = true;
  struct Case {
    CameraModelId model;
    bool covariance;
    int cols, rows, views, threads;
  };
  std::vector<Case> cases;
  for (bool covariance : {false, true}) {
    for (const auto& board : boards) {
      for (int views : view_counts) {
        for (int threads : {1, 2}) {
          if (!covariance && threads > 1) continue;
          cases.push_back({CameraModelId::kPinholeRadtan, covariance, board[0],
                           board[1], views, threads});
        }
      }
    }
  }
  // A fisheye set the size of a long deltille recording.
  for (int threads : {1, 2}) {
    cases.push_back({CameraModelId::kKannalaBrandt, true, 11, 8, 192, threads});
  }
  for (const Case& c : cases) {
    if (c.views > max_views) continue;
    if (!only_model.empty() &&
        only_model != puzzlecal::CameraModelName(c.model)) {
      continue;
    }
    const CameraModelId model = c.model;
    CalibrationOptions options;
    options.compute_covariance = c.covariance;
    options.num_threads = c.threads;
    const SyntheticScene scene = Scene(model, c.views, c.cols, c.rows);
    const SyntheticData data = MakeSyntheticData(scene);
    std::vector<double> times, cpu_times, init_times, solve_times, cov_times;
    CalibrationResult result;
    bool ok = true;
    // The largest problems run once: the figures are minutes, not noise.
    const int runs = data.num_corners > 30000 ? 1 : repeats;
    for (int r = 0; r < runs; ++r) {
      std::string error;
      const auto start = std::chrono::steady_clock::now();
      const std::clock_t cpu_start = std::clock();
      ok &= puzzlecal::Calibrate(data.views, model, scene.camera.width,
                                 scene.camera.height, options, &result, &error);
      cpu_times.push_back(static_cast<double>(std::clock() - cpu_start) /
                          CLOCKS_PER_SEC);
      times.push_back(Seconds(start));
      init_times.push_back(result.initialization_seconds);
      solve_times.push_back(result.solve_seconds -
                            result.initialization_seconds);
      cov_times.push_back(result.covariance_seconds);
    }
    std::sort(times.begin(), times.end());
    std::sort(cpu_times.begin(), cpu_times.end());
    std::sort(init_times.begin(), init_times.end());
    std::sort(solve_times.begin(), solve_times.end());
    std::sort(cov_times.begin(), cov_times.end());
    std::printf(
        "%s    {\"model\": \"%s\", \"covariance\": %s, "
        "\"threads\": %d, \"views\": %d, "
        "\"corners_per_board\": %d, \"corners\": %d, \"ok\": %s, "
        "\"runs\": %d, \"best_s\": %.3f, \"median_s\": %.3f, "
        "\"best_cpu_s\": %.3f, \"init_s\": %.3f, "
        "\"solve_and_covariance_s\": %.3f, \"covariance_s\": %.4f, "
        "\"iterations\": %d, \"rms_px\": %.4f}",
        first ? "" : ",\n", puzzlecal::CameraModelName(model),
        c.covariance ? "true" : "false", c.threads, c.views, c.cols * c.rows,
        data.num_corners, ok ? "true" : "false", runs, times.front(),
        times[times.size() / 2], cpu_times.front(), init_times.front(),
        solve_times.front(), cov_times.front(), result.iterations,
        result.rms_px);
    first = false;
    std::fflush(stdout);
  }
  std::printf("\n  ],\n  \"accuracy\": [\n");
  // 20 views, sigma = 0.1 px, the scenes of tests/calib/calibrate_test.cc.
  first = true;
  for (CameraModelId model :
       {CameraModelId::kPinholeRadtan, CameraModelId::kPinholeRational,
        CameraModelId::kKannalaBrandt}) {
    SyntheticScene scene = Scene(model, 20, 11, 8);
    scene.tile = 0.03;
    if (model != CameraModelId::kKannalaBrandt) {
      scene.min_tilt_deg = 20;
      scene.max_tilt_deg = 60;
      scene.min_distance = 0.8;
      scene.max_distance = 1.6;
    }
    const SyntheticData data = MakeSyntheticData(scene);
    CalibrationResult result;
    std::string error;
    const auto start = std::chrono::steady_clock::now();
    const bool ok = puzzlecal::Calibrate(data.views, model, scene.camera.width,
                                         scene.camera.height,
                                         CalibrationOptions(), &result, &error);
    const double seconds = Seconds(start);
    int free_params = 6 * result.num_views_used;
    for (bool fixed : result.param_fixed) free_params += fixed ? 0 : 1;
    const double floor =
        scene.noise_px *
        std::sqrt(1.0 - free_params / (2.0 * result.num_corners_used));
    const auto& t = scene.camera.params;
    const auto& p = result.camera.params;
    const auto cv_start = std::chrono::steady_clock::now();
    const puzzlecal::testing::OpenCvCalibration cv =
        puzzlecal::testing::CalibrateWithOpenCv(
            data.views, model, scene.camera.width, scene.camera.height);
    const double cv_seconds = Seconds(cv_start);
    auto row = [&](const char* who, bool converged,
                   const std::vector<double>& q, double rms_point, double secs,
                   const std::string& note) {
      std::printf(
          "%s    {\"model\": \"%s\", \"solver\": \"%s\", "
          "\"ok\": %s",
          first ? "" : ",\n", puzzlecal::CameraModelName(model), who,
          converged ? "true" : "false");
      first = false;
      if (converged && q.size() >= 4) {
        std::printf(
            ", \"dfx_rel_pct\": %.4f, \"dfy_rel_pct\": %.4f, "
            "\"dcx_px\": %.3f, \"dcy_px\": %.3f, "
            "\"rms_point_px\": %.5f, \"rms_over_floor\": %.4f, "
            "\"seconds\": %.3f",
            100 * std::abs(q[0] - t[0]) / t[0],
            100 * std::abs(q[1] - t[1]) / t[1], std::abs(q[2] - t[2]),
            std::abs(q[3] - t[3]), rms_point,
            rms_point / std::sqrt(2.0) / floor, secs);
      }
      if (!note.empty()) {
        std::string clean = note;
        for (char& c : clean) {
          if (c == '"' || c == '\\' || c == '\n') c = ' ';
        }
        std::printf(", \"note\": \"%s\"", clean.c_str());
      }
      std::printf("}");
    };
    row("puzzlecal", ok, p, result.rms_point_px, seconds, ok ? "" : error);
    row("opencv", cv.ok, cv.params, cv.rms_point_px, cv_seconds, cv.error);
    std::fflush(stdout);
  }
  std::printf("\n  ]\n}\n");
  return 0;
}
