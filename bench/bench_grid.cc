// BuildGrid timings for the corner counts of the thesis's Table 6.4 (88, 368,
// 3204 and 3744 corners): boards of 11x8, 23x16, 89x36 and 72x52 inner corners
// seen through a pinhole camera at a 60-degree viewing angle, corners projected
// with exact ids (plus 0.1 px noise), orientations from the projected geometry
// and a drawn checkerboard image for the intensity penalty. Prints JSON: the
// best and median wall and thread-CPU time of repeated runs per size, the
// fastest wall time of each stage over the runs, and the labelled corners.

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "camera/camera_models.h"
#include "grid/grid.h"

namespace puzzlecal {
namespace {

// CPU time of this thread: on a loaded machine wall time also counts the
// time other processes held the core.
double ThreadCpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

struct Scene {
  std::vector<Corner> corners;
  cv::Mat image;
};

// cols x rows inner corners, tiles of about `tile_px` pixels in the image.
Scene MakeScene(int cols, int rows, double tile_px, unsigned seed) {
  const double tile_m = 0.01;
  const double focal = 1000;
  const double viewing_angle_deg = 60;
  // Distance so that a frontal tile would be tile_px wide.
  const double distance = focal * tile_m / tile_px;
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.params = {focal, focal, 0, 0, -0.02, 0, 0, 0, 0};
  const Eigen::Vector3d centre((cols - 1) * tile_m / 2, (rows - 1) * tile_m / 2,
                               0);
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd((90 - viewing_angle_deg) * M_PI / 180,
                         Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  auto project = [&](double x, double y) {
    const Eigen::Vector3d cam =
        rotation * (Eigen::Vector3d(x * tile_m, y * tile_m, 0) - centre) +
        Eigen::Vector3d(0, 0, distance);
    Eigen::Vector2d pixel(-1e9, -1e9);
    camera.Project(cam, &pixel);
    return pixel;
  };

  // Principal point and image size so that the whole board (with its
  // border tiles) is in the image with a 20 px margin.
  Eigen::Vector2d low(1e18, 1e18), high(-1e18, -1e18);
  for (int r = -1; r <= rows; ++r) {
    for (int c = -1; c <= cols; ++c) {
      const Eigen::Vector2d p = project(c, r);
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
  }
  camera.params[2] = 20 - low.x();
  camera.params[3] = 20 - low.y();
  camera.width = static_cast<int>(high.x() - low.x()) + 40;
  camera.height = static_cast<int>(high.y() - low.y()) + 40;
  const int width = camera.width;
  const int height = camera.height;

  Scene scene;
  scene.image = cv::Mat(height, width, CV_8UC1, cv::Scalar(110));
  for (int r = -1; r < rows; ++r) {
    for (int c = -1; c < cols; ++c) {
      const bool black = ((r + c) % 2 + 2) % 2 == 0;
      cv::Point polygon[4];
      const Eigen::Vector2d quad[4] = {project(c, r), project(c + 1, r),
                                       project(c + 1, r + 1),
                                       project(c, r + 1)};
      for (int k = 0; k < 4; ++k)
        polygon[k] = cv::Point(static_cast<int>(std::lround(quad[k].x() * 16)),
                               static_cast<int>(std::lround(quad[k].y() * 16)));
      cv::fillConvexPoly(scene.image, polygon, 4, cv::Scalar(black ? 30 : 220),
                         cv::LINE_AA, 4);
    }
  }
  cv::GaussianBlur(scene.image, scene.image, cv::Size(5, 5), 0.8);

  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector2d p = project(c, r);
      const Eigen::Vector2d du = (project(c + 0.05, r) - p).normalized();
      const Eigen::Vector2d dv = (project(c, r + 0.05) - p).normalized();
      const Eigen::Vector2d bisector = (c + r) % 2 == 0
                                           ? Eigen::Vector2d(du + dv)
                                           : Eigen::Vector2d(du - dv);
      Corner corner;
      // One draw per statement (y first): as two arguments of one call they
      // come in an order each compiler picks.
      const double noise_y = noise(rng);
      corner.xy = p + Eigen::Vector2d(noise(rng), noise_y);
      corner.orientation = std::atan2(bisector.y(), bisector.x());
      corner.response = 1;
      scene.corners.push_back(corner);
    }
  }
  // Detector output is ordered by response, not by position.
  std::shuffle(scene.corners.begin(), scene.corners.end(), rng);
  return scene;
}

}  // namespace
}  // namespace puzzlecal

int main() {
  using namespace puzzlecal;
  struct Size {
    int cols, rows;
    double tile_px;
    double goal_ms;
  };
  const Size sizes[] = {{11, 8, 60, 0.1},
                        {23, 16, 40, 0.4},
                        {89, 36, 16, 3.0},
                        {72, 52, 16, 3.5}};
  std::printf("{\n  \"benchmark\": \"BuildGrid\",\n  \"results\": [\n");
  for (size_t s = 0; s < std::size(sizes); ++s) {
    const Size& size = sizes[s];
    const Scene scene = MakeScene(size.cols, size.rows, size.tile_px, 1 + s);
    const int repeats = size.cols * size.rows > 1000 ? 30 : 200;
    std::vector<double> times, cpu_times;
    GridSummary summary, best_summary;  // best: fastest of each stage
    std::vector<GridComponent> components;
    for (int r = 0; r < repeats; ++r) {
      const auto start = std::chrono::steady_clock::now();
      const double cpu_start = ThreadCpuMs();
      components = BuildGrid(scene.corners, scene.image, {}, &summary);
      cpu_times.push_back(ThreadCpuMs() - cpu_start);
      if (r == 0) best_summary = summary;
      best_summary.neighbors_ms =
          std::min(best_summary.neighbors_ms, summary.neighbors_ms);
      best_summary.weights_ms =
          std::min(best_summary.weights_ms, summary.weights_ms);
      best_summary.kruskal_ms =
          std::min(best_summary.kruskal_ms, summary.kruskal_ms);
      best_summary.cleanup_ms =
          std::min(best_summary.cleanup_ms, summary.cleanup_ms);
      times.push_back(std::chrono::duration<double, std::milli>(
                          std::chrono::steady_clock::now() - start)
                          .count());
    }
    std::sort(times.begin(), times.end());
    std::sort(cpu_times.begin(), cpu_times.end());
    std::printf(
        "    {\"corners\": %zu, \"board\": \"%dx%d\", \"image\": \"%dx%d\", "
        "\"best_ms\": %.4f, \"median_ms\": %.4f, \"cpu_best_ms\": %.4f, "
        "\"cpu_median_ms\": %.4f, \"goal_ms\": %.1f, "
        "\"largest_component\": %d, \"components\": %d, "
        "\"neighbors_ms\": %.4f, \"weights_ms\": %.4f, \"kruskal_ms\": %.4f, "
        "\"cleanup_ms\": %.4f, \"removed_not_saddle\": %d, "
        "\"removed_by_prediction\": %d, \"removed_off_lattice\": %d}%s\n",
        scene.corners.size(), size.cols, size.rows, scene.image.cols,
        scene.image.rows, times.front(), times[times.size() / 2],
        cpu_times.front(), cpu_times[cpu_times.size() / 2], size.goal_ms,
        summary.largest_component, summary.num_components,
        best_summary.neighbors_ms, best_summary.weights_ms,
        best_summary.kruskal_ms, best_summary.cleanup_ms,
        summary.num_removed_not_saddle, summary.num_removed_by_prediction,
        summary.num_removed_off_lattice, s + 1 < std::size(sizes) ? "," : "");
  }
  std::printf("  ]\n}\n");
  return 0;
}
