// Render time per 1600 x 1200 image, supersampling 4, pinhole and fisheye.
// Prints JSON: the first render through a camera also unprojects its pixel
// rays ("cold"); later renders reuse them ("warm").

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <opencv2/core.hpp>
#include <vector>

#include "sim/pixel_rays.h"
#include "sim/render.h"

namespace puzzlecal {
namespace {

double Ms(std::chrono::steady_clock::time_point a,
          std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

struct Figures {
  double cold_ms = 0;
  double warm_best_ms = 0;
  double warm_median_ms = 0;
  double rays_ms = 0;
  // Process CPU time per warm render (all threads), median: less sensitive
  // to other load on the machine than wall time.
  double warm_cpu_median_ms = 0;
  int runs = 0;
};

Figures Measure(const Camera& camera, const Board& board,
                const Eigen::Isometry3d& pose, int runs) {
  RenderOptions options;
  options.supersampling = 4;
  options.noise_sigma = 0.02;
  options.vignetting = 0.3;
  Figures figures;
  auto t0 = std::chrono::steady_clock::now();
  PixelRayGrid rays;
  rays.Compute(camera);
  auto t1 = std::chrono::steady_clock::now();
  RenderBoard(board, rays, pose, options);
  auto t2 = std::chrono::steady_clock::now();
  figures.rays_ms = Ms(t0, t1);
  figures.cold_ms = Ms(t0, t2);
  std::vector<double> times, cpu_times;
  for (int i = 0; i < runs; ++i) {
    options.seed = i + 2;
    const std::clock_t cpu_start = std::clock();
    auto a = std::chrono::steady_clock::now();
    const cv::Mat image = RenderBoard(board, rays, pose, options);
    auto b = std::chrono::steady_clock::now();
    if (image.empty()) return figures;
    times.push_back(Ms(a, b));
    cpu_times.push_back(1000.0 * (std::clock() - cpu_start) / CLOCKS_PER_SEC);
  }
  std::sort(cpu_times.begin(), cpu_times.end());
  figures.warm_cpu_median_ms = cpu_times[cpu_times.size() / 2];
  std::sort(times.begin(), times.end());
  figures.warm_best_ms = times.front();
  figures.warm_median_ms = times[times.size() / 2];
  figures.runs = runs;
  return figures;
}

Eigen::Isometry3d Pose(double distance, double angle) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
  // Board 23 x 16 corners of 30 mm at (50, 100): centre the board.
  const Eigen::Vector3d center((50 + 11) * 0.03, (100 + 7.5) * 0.03, 0);
  pose.translation() = Eigen::Vector3d(0, 0, distance) - pose.linear() * center;
  return pose;
}

}  // namespace
}  // namespace puzzlecal

int main() {
  using namespace puzzlecal;
  Board board;
  board.cols = 23;
  board.rows = 16;
  board.origin = Eigen::Vector2i(50, 100);
  board.tile_size_m = 0.03;

  Camera pinhole;
  pinhole.model = CameraModelId::kPinholeRadtan;
  pinhole.params = {1400, 1400, 799.5, 599.5, -0.2, 0.08, 0.0005, -0.0003, 0.0};
  pinhole.width = 1600;
  pinhole.height = 1200;
  Camera fisheye;
  fisheye.model = CameraModelId::kKannalaBrandt;
  fisheye.params = {520, 520, 799.5, 599.5, 0.03, -0.01, 0.002, -0.0002};
  fisheye.width = 1600;
  fisheye.height = 1200;

  constexpr int kRuns = 7;
  const Figures p = Measure(pinhole, board, Pose(1.0, 0.4), kRuns);
  const Figures f = Measure(fisheye, board, Pose(0.5, 0.4), kRuns);
  std::printf(
      "{\n  \"image\": \"1600x1200\",\n  \"supersampling\": 4,\n"
      "  \"threads\": %d,\n  \"runs\": %d,\n",
      cv::getNumThreads(), kRuns);
  auto print = [](const char* name, const Figures& x, bool last) {
    std::printf(
        "  \"%s\": {\"ray_grid_ms\": %.1f, \"cold_ms\": %.1f, "
        "\"warm_best_ms\": %.1f, \"warm_median_ms\": %.1f, "
        "\"warm_cpu_median_ms\": %.1f}%s\n",
        name, x.rays_ms, x.cold_ms, x.warm_best_ms, x.warm_median_ms,
        x.warm_cpu_median_ms, last ? "" : ",");
  };
  print("pinhole-radtan", p, false);
  print("kannala-brandt", f, true);
  std::printf("}\n");
  return 0;
}
