// Speed of the corner detector, single-threaded: milliseconds per megapixel
// on 1600x1200 and 4032x3024 renders (and on one deltille fisheye photo when
// the data set is present). Best and median of several runs, with the stage
// breakdown of the best run. Prints JSON.
//
// Usage: bench_detection [runs]

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calib/camera_models.h"
#include "decode/board.h"
#include "detection/detector.h"
#include "sim/render.h"

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
  for (int r = 0; r < runs; ++r) {
    DetectorSummary summary;
    corners = static_cast<int>(DetectCorners(image, {}, &summary).size());
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

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) {
  using namespace puzzlecal;
  cv::setNumThreads(1);
  const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 9;
  const cv::Mat small = RenderView(1600, 1200, 30.0);
  const cv::Mat large = RenderView(4032, 3024, 40.0);
  std::string photo_path;
  const char* data = std::getenv("PUZZLECAL_DATA");
  for (const char* dir : {data != nullptr ? data : "", "../shared"}) {
    if (*dir == '\0') continue;
    const std::string path = std::string(dir) + "/deltille/fisheye/0036.png";
    if (!cv::imread(path, cv::IMREAD_GRAYSCALE).empty()) {
      photo_path = path;
      break;
    }
  }
  std::printf("{\n  \"threads\": 1,\n  \"images\": [\n");
  Measure("render_puzzleboard_1600x1200", small, runs, false);
  if (!photo_path.empty()) {
    Measure("deltille_fisheye_0036", cv::imread(photo_path, cv::IMREAD_GRAYSCALE),
            runs, false);
  }
  Measure("render_puzzleboard_4032x3024", large, runs, true);
  std::printf("  ]\n}\n");
  return 0;
}
