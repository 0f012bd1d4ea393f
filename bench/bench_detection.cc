// Speed of the corner detector, single-threaded: milliseconds per megapixel
// on 1600x1200 and 4032x3024 renders (and on one deltille fisheye photo when
// the data set is present). Best and median of several runs, with the stage
// breakdown of the best run. Prints JSON.
//
// Usage: bench_detection [runs]

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "detection/detector.h"
#include "grid/grid.h"
#include "sim/render.h"
#include "target/board.h"
#include "tests/support/deltille_data.h"

namespace puzzlecal {
namespace {

// A PuzzleBoard filling much of a pinhole view, tiles of about `tile_px`.
cv::Mat RenderView(int width, int height, double tile_px) {
  Board board;
  board.type = BoardType::kPuzzleBoard;
  board.cols = static_cast<int>(0.8 * width / tile_px);
  board.rows = static_cast<int>(0.8 * height / tile_px);
  board.tile_size_m = 0.01;
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.width = width;
  camera.height = height;
  const double f = 0.8 * width;
  camera.params = {f, f, width / 2.0, height / 2.0, -0.1, 0.02, 0, 0, 0};
  const double z = f * board.tile_size_m / tile_px;
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Vector3d centre((board.cols - 1) * 0.5 * board.tile_size_m,
                               (board.rows - 1) * 0.5 * board.tile_size_m, 0);
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  cam_from_board.linear() = rotation;
  cam_from_board.translation() = Eigen::Vector3d(0, 0, z) - rotation * centre;
  RenderOptions options;
  options.blur_sigma_px = 1.0;
  options.noise_sigma = 0.01;
  options.supersampling = 2;
  return RenderBoard(board, camera, cam_from_board, options);
}

void Measure(const std::string& name, const cv::Mat& image, int runs,
             bool last) {
  std::vector<double> totals;
  DetectorSummary best;
  best.ms_total = 1e30;
  int corners = 0;
  CornerDetector detector;  // kept across runs, as a caller of many images
  for (int r = 0; r < runs; ++r) {
    DetectorSummary summary;
    corners = static_cast<int>(detector.Detect(image, &summary).size());
    totals.push_back(summary.ms_total);
    if (summary.ms_total < best.ms_total) best = summary;
  }
  std::sort(totals.begin(), totals.end());
  const double mp = image.cols * static_cast<double>(image.rows) / 1e6;
  std::printf(
      "    {\"image\": \"%s\", \"width\": %d, \"height\": %d, \"corners\": %d, "
      "\"runs\": %d, \"best_ms\": %.2f, \"median_ms\": %.2f, "
      "\"best_ms_per_mp\": %.2f, \"median_ms_per_mp\": %.2f, "
      "\"best_stages_ms\": {\"preprocess\": %.2f, \"response\": %.2f, "
      "\"nms\": %.2f, \"filter\": %.2f, \"refine\": %.2f}}%s\n",
      name.c_str(), image.cols, image.rows, corners, runs, totals.front(),
      totals[totals.size() / 2], totals.front() / mp,
      totals[totals.size() / 2] / mp, best.ms_preprocess, best.ms_response,
      best.ms_nms, best.ms_filter, best.ms_refine, last ? "" : ",");
}

// Per deltille photo: corners on the board (inside the convex hull of the
// largest grid/ component, grown by 0.35 of its median neighbour spacing)
// and off it. The photos show an 11x8-corner board: 88 corners.
void DeltillePhotos(const std::string& dir) {
  std::printf("  \"deltille_fisheye\": [\n");
  int photos = 0, complete = 0, total_on = 0, total_off = 0;
  bool first = true;
  CornerDetector detector;
  for (const std::string& file : testing_data::DeltillePhotoFiles(dir)) {
    const std::string file_name =
        std::filesystem::path(file).filename().string();
    const char* name = file_name.c_str();
    const cv::Mat image = cv::imread(file, cv::IMREAD_GRAYSCALE);
    if (image.empty()) continue;
    DetectorSummary summary;
    const std::vector<Corner> corners = detector.Detect(image, &summary);
    const std::vector<GridComponent> components = BuildGrid(corners, image);
    int on = 0, largest = 0;
    if (!components.empty()) {
      const GridComponent& c = components.front();
      largest = static_cast<int>(c.corner.size());
      std::vector<cv::Point2f> points;
      std::vector<double> spacing;
      for (size_t k = 0; k < c.corner.size(); ++k) {
        const Eigen::Vector2d& p = corners[c.corner[k]].xy;
        points.emplace_back(p.x(), p.y());
        double nearest = 1e30;
        for (size_t m = 0; m < c.corner.size(); ++m) {
          if (m != k) {
            nearest = std::min(nearest, (corners[c.corner[m]].xy - p).norm());
          }
        }
        spacing.push_back(nearest);
      }
      std::sort(spacing.begin(), spacing.end());
      const double grow = spacing.empty() ? 0.0 : 0.35 * spacing[spacing.size() / 2];
      std::vector<cv::Point2f> hull;
      if (points.size() >= 3) cv::convexHull(points, hull);
      for (const Corner& corner : corners) {
        if (hull.size() >= 3 &&
            cv::pointPolygonTest(hull, cv::Point2f(corner.xy.x(), corner.xy.y()),
                                 true) > -grow) {
          ++on;
        }
      }
    }
    const int off = static_cast<int>(corners.size()) - on;
    ++photos;
    complete += on >= 88 ? 1 : 0;
    total_on += on;
    total_off += off;
    std::printf("%s    {\"photo\": \"%s\", \"corners\": %d, \"on_board\": %d, "
                "\"off_board\": %d, \"largest_component\": %d, \"ms\": %.1f}",
                first ? "" : ",\n", name, static_cast<int>(corners.size()), on,
                off, largest, summary.ms_total);
    first = false;
  }
  std::printf("\n  ],\n  \"deltille_summary\": {\"photos\": %d, "
              "\"photos_with_88_on_board\": %d, \"mean_on_board\": %.1f, "
              "\"mean_off_board\": %.1f},\n",
              photos, complete, photos ? total_on / double(photos) : 0.0,
              photos ? total_off / double(photos) : 0.0);
}

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) {
  using namespace puzzlecal;
  cv::setNumThreads(1);
  const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 9;
  const cv::Mat small = RenderView(1600, 1200, 30.0);
  const cv::Mat large = RenderView(4032, 3024, 40.0);
  std::string photo_path;
  const std::string folder = testing_data::DeltilleFolder();
  if (!folder.empty() &&
      !cv::imread(folder + "/0036.png", cv::IMREAD_GRAYSCALE).empty()) {
    photo_path = folder + "/0036.png";
  }
  std::printf("{\n  \"threads\": 1,\n");
  if (!photo_path.empty()) {
    DeltillePhotos(photo_path.substr(0, photo_path.rfind('/')));
  }
  std::printf("  \"images\": [\n");
  Measure("render_puzzleboard_1600x1200", small, runs, false);
  if (!photo_path.empty()) {
    Measure("deltille_fisheye_0036", cv::imread(photo_path, cv::IMREAD_GRAYSCALE),
            runs, false);
  }
  Measure("render_puzzleboard_4032x3024", large, runs, true);
  std::printf("  ]\n}\n");
  return 0;
}
