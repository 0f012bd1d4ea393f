// Sub-pixel accuracy of the corner detector against sim/ truth, side by side
// with cv::cornerSubPix (started from the detector's integer peaks) and
// cv::findChessboardCornersSB, over blur x noise; recall per tile size; the
// error tail (p50/p90/p99) on demo-like PuzzleBoard renders per refinement
// method. Prints JSON.
//
// Usage: bench_detection_accuracy [views_per_cell]

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "detection/detector.h"
#include "sim/render.h"
#include "sim/scenes.h"
#include "target/board.h"

namespace puzzlecal {
namespace {

struct ErrorStats {
  double sum_sq = 0.0;
  int matched = 0;
  int expected = 0;
  void Add(double error) {
    sum_sq += error * error;
    ++matched;
  }
  double Rms() const { return matched > 0 ? std::sqrt(sum_sq / matched) : NAN; }
  double Recall() const {
    return expected > 0 ? static_cast<double>(matched) / expected : NAN;
  }
};

// Nearest point of `points` to `p`, its distance in *distance; -1 if none.
int Nearest(const std::vector<Eigen::Vector2d>& points,
            const Eigen::Vector2d& p, double* distance) {
  int best = -1;
  double best_d = INFINITY;
  for (size_t i = 0; i < points.size(); ++i) {
    const double d = (points[i] - p).norm();
    if (d < best_d) {
      best_d = d;
      best = static_cast<int>(i);
    }
  }
  *distance = best_d;
  return best;
}

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * v.size()))];
}

// A distortion-free pinhole of focal length `fx` whose principal point is
// `offset` from the image centre.
Camera PinholeCamera(double fx, int width, int height,
                     const Eigen::Vector2d& offset) {
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.width = width;
  camera.height = height;
  camera.params = {
      fx, fx, width / 2.0 + offset.x(), height / 2.0 + offset.y(), 0, 0, 0,
      0,  0};
  return camera;
}

// The pose that turns the board by `rotation` about its centre and puts the
// centre `z` metres ahead on the optical axis.
Eigen::Isometry3d CentredPose(const Board& board,
                              const Eigen::Matrix3d& rotation, double z) {
  const Eigen::Vector3d centre((board.cols - 1) * 0.5 * board.tile_size_m,
                               (board.rows - 1) * 0.5 * board.tile_size_m, 0.0);
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  cam_from_board.linear() = rotation;
  cam_from_board.translation() = Eigen::Vector3d(0, 0, z) - rotation * centre;
  return cam_from_board;
}

std::vector<Eigen::Vector2d> VisibleCorners(const RenderTruth& truth) {
  std::vector<Eigen::Vector2d> xy;
  for (const TruthCorner& t : truth.corners) {
    if (t.visible) xy.push_back(t.xy);
  }
  return xy;
}

std::vector<Eigen::Vector2d> DetectedPoints(const cv::Mat& image,
                                            const DetectorOptions& options) {
  std::vector<Eigen::Vector2d> found;
  for (const Corner& c : DetectCorners(image, options)) found.push_back(c.xy);
  return found;
}

// Every truth corner counts as expected; the ones with a point of `found`
// within `match_radius` add their distance to it.
void Score(const std::vector<Eigen::Vector2d>& found,
           const std::vector<Eigen::Vector2d>& truth_xy, double match_radius,
           ErrorStats* stats) {
  stats->expected += static_cast<int>(truth_xy.size());
  for (const Eigen::Vector2d& t : truth_xy) {
    double d;
    if (Nearest(found, t, &d) >= 0 && d < match_radius) stats->Add(d);
  }
}

// cv::cornerSubPix started from the detector's integer peaks that lie within
// `match_radius` of a truth corner, with the window the detector picks (half
// the tile, 2-12 px).
std::vector<Eigen::Vector2d> CornerSubPixFromPeaks(
    const cv::Mat& image, const std::vector<Eigen::Vector2d>& truth_xy,
    double match_radius, double tile_px) {
  DetectorOptions options;
  options.subpixel = SubpixelMethod::kNone;
  std::vector<cv::Point2f> start;
  for (const Corner& c : DetectCorners(image, options)) {
    double d;
    if (Nearest(truth_xy, c.xy, &d) >= 0 && d < match_radius) {
      start.emplace_back(c.xy.x(), c.xy.y());
    }
  }
  if (!start.empty()) {
    const int window =
        std::clamp(static_cast<int>(std::floor(0.5 * tile_px)), 2, 12);
    cv::cornerSubPix(
        image, start, cv::Size(window, window), cv::Size(-1, -1),
        cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50,
                         0.001));
  }
  std::vector<Eigen::Vector2d> found;
  for (const cv::Point2f& p : start) found.emplace_back(p.x, p.y);
  return found;
}

std::string Num(double v) {
  if (!std::isfinite(v)) return "null";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4f", v);
  return buffer;
}

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) {
  using namespace puzzlecal;
  cv::setNumThreads(1);
  const int views = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const double blurs[] = {0.5, 1.0, 2.0, 3.0};
  const double noises[] = {0.0, 0.01, 0.03, 0.05};

  Board board;
  board.type = BoardType::kCheckerboard;
  board.cols = 11;
  board.rows = 8;
  board.tile_size_m = 0.02;

  std::printf(
      "{\n  \"board\": \"checkerboard 11x8 corners\",\n"
      "  \"views_per_cell\": %d,\n  \"tiles_px\": \"20..60\",\n"
      "  \"cells\": [\n",
      views);
  bool first_cell = true;
  for (double blur : blurs) {
    for (double noise : noises) {
      ErrorStats ours, centroid, gradient, subpix, sb;
      int sb_views = 0;
      for (int v = 0; v < views; ++v) {
        // Tile size 20..60 px, a rotation about the optical axis and a tilt.
        const double tile_px = 20.0 + 40.0 * v / std::max(1, views - 1);
        const double fx = 800.0;
        const Camera camera =
            PinholeCamera(fx, static_cast<int>(tile_px * 15),
                          static_cast<int>(tile_px * 12), {-0.3, 0.2});
        const double z = fx * board.tile_size_m / tile_px;
        const Eigen::Matrix3d rotation =
            (Eigen::AngleAxisd(0.15 + 0.37 * v, Eigen::Vector3d::UnitZ()) *
             Eigen::AngleAxisd(0.12 * ((v % 3) - 1), Eigen::Vector3d::UnitX()) *
             Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()))
                .toRotationMatrix();
        RenderOptions render;
        render.blur_sigma_px = blur;
        render.noise_sigma = noise;
        render.seed = 1000 + v;
        RenderTruth truth;
        const cv::Mat image = RenderBoard(
            board, camera, CentredPose(board, rotation, z), render, &truth);
        if (image.empty()) continue;
        const std::vector<Eigen::Vector2d> truth_xy = VisibleCorners(truth);
        const double match_radius = std::max(2.0, 0.3 * tile_px);

        DetectorOptions options;
        Score(DetectedPoints(image, options), truth_xy, match_radius, &ours);
        options.subpixel = SubpixelMethod::kCentroid;
        Score(DetectedPoints(image, options), truth_xy, match_radius,
              &centroid);
        options.subpixel = SubpixelMethod::kGradientOrthogonality;
        Score(DetectedPoints(image, options), truth_xy, match_radius,
              &gradient);
        Score(CornerSubPixFromPeaks(image, truth_xy, match_radius, tile_px),
              truth_xy, match_radius, &subpix);

        std::vector<cv::Point2f> sb_corners;
        if (cv::findChessboardCornersSB(
                image, cv::Size(board.cols, board.rows), sb_corners,
                cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY)) {
          ++sb_views;
          std::vector<Eigen::Vector2d> found;
          for (const cv::Point2f& p : sb_corners) found.emplace_back(p.x, p.y);
          Score(found, truth_xy, match_radius, &sb);
        }
      }
      std::printf(
          "%s    {\"blur_px\": %.1f, \"noise\": %.2f, "
          "\"ours_rms_px\": %s, \"ours_recall\": %s, "
          "\"thesis_centroid_rms_px\": %s, "
          "\"gradient_orthogonality_rms_px\": %s, "
          "\"cornersubpix_rms_px\": %s, \"sb_rms_px\": %s, "
          "\"sb_views_found\": %d, \"views\": %d}",
          first_cell ? "" : ",\n", blur, noise, Num(ours.Rms()).c_str(),
          Num(ours.Recall()).c_str(), Num(centroid.Rms()).c_str(),
          Num(gradient.Rms()).c_str(), Num(subpix.Rms()).c_str(),
          Num(sb.Rms()).c_str(), sb_views, views);
      std::fflush(stdout);
      first_cell = false;
    }
  }
  std::printf("\n  ],\n");

  // Accuracy by tilt (the angle between the board's normal and the optical
  // axis, about the board's horizontal axis): corners of a steep board are
  // foreshortened across the tilt, and the detector's window sees a skewed
  // saddle. Tile size given frontal (the foreshortened side is cos(tilt) of
  // it), blur 0.8 px, noise 1 %, three draws of the in-plane rotation.
  // Both boards: a PuzzleBoard's edge marks sit half a tile from the
  // corners, a foreshortened half tile at a steep tilt.
  std::printf("  \"rms_by_tilt\": [\n");
  bool first_tilt = true;
  Board tilted_puzzle = board;
  tilted_puzzle.type = BoardType::kPuzzleBoard;
  for (const Board* tilted : {&board, &tilted_puzzle})
    for (double tile_px : {10.0, 20.0}) {
      for (double tilt_deg : {0.0, 30.0, 45.0, 55.0, 60.0, 65.0, 70.0, 75.0}) {
        ErrorStats ours, subpix;
        for (int v = 0; v < 3; ++v) {
          const double fx = 800.0;
          const Camera camera =
              PinholeCamera(fx, static_cast<int>(tile_px * 16),
                            static_cast<int>(tile_px * 13), {-0.3, 0.2});
          const double z = fx * tilted->tile_size_m / tile_px;
          const Eigen::Matrix3d rotation =
              (Eigen::AngleAxisd(tilt_deg * M_PI / 180,
                                 Eigen::Vector3d::UnitX()) *
               Eigen::AngleAxisd(0.2 + 0.5 * v, Eigen::Vector3d::UnitZ()))
                  .toRotationMatrix();
          RenderOptions render;
          render.blur_sigma_px = 0.8;
          render.noise_sigma = 0.01;
          render.seed = 2000 + v;
          RenderTruth truth;
          const cv::Mat image =
              RenderBoard(*tilted, camera, CentredPose(*tilted, rotation, z),
                          render, &truth);
          if (image.empty()) continue;
          const std::vector<Eigen::Vector2d> truth_xy = VisibleCorners(truth);
          const double match_radius =
              std::max(1.5, 0.3 * tile_px * std::cos(tilt_deg * M_PI / 180));
          Score(DetectedPoints(image, DetectorOptions()), truth_xy,
                match_radius, &ours);
          Score(CornerSubPixFromPeaks(image, truth_xy, match_radius, tile_px),
                truth_xy, match_radius, &subpix);
        }
        std::printf(
            "%s    {\"board\": \"%s\", \"tile_px_frontal\": %.0f, "
            "\"tilt_deg\": %.0f, "
            "\"ours_rms_px\": %s, \"ours_recall\": %s, "
            "\"cornersubpix_rms_px\": %s}",
            first_tilt ? "" : ",\n",
            tilted->type == BoardType::kPuzzleBoard ? "puzzleboard"
                                                    : "checkerboard",
            tile_px, tilt_deg, Num(ours.Rms()).c_str(),
            Num(ours.Recall()).c_str(), Num(subpix.Rms()).c_str());
        std::fflush(stdout);
        first_tilt = false;
      }
    }
  std::printf("\n  ],\n");

  // Recall per tile size (blur 0.8 px, noise 1 %, PuzzleBoard 11x8, mild
  // tilt), same defaults throughout; false = detections on the board farther
  // than 1.5 px from every corner.
  std::printf("  \"recall_by_tile_px\": [\n");
  Board puzzle;
  puzzle.type = BoardType::kPuzzleBoard;
  puzzle.cols = 11;
  puzzle.rows = 8;
  puzzle.tile_size_m = 0.02;
  bool first_tile = true;
  for (double tile_px :
       {4.0, 5.0, 6.0, 8.0, 10.0, 15.0, 25.0, 50.0, 100.0, 200.0}) {
    int expected = 0, found = 0, false_on_board = 0;
    for (int v = 0; v < 2; ++v) {
      const double fx = 1000.0;
      const Camera camera =
          PinholeCamera(fx, static_cast<int>(tile_px * 15 + 40),
                        static_cast<int>(tile_px * 12 + 40), {0, 0});
      const double z = fx * puzzle.tile_size_m / tile_px;
      const Eigen::Matrix3d rotation =
          (Eigen::AngleAxisd(0.3 + 0.5 * v, Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitX()))
              .toRotationMatrix();
      const Eigen::Isometry3d cam_from_board = CentredPose(puzzle, rotation, z);
      RenderOptions render;
      render.blur_sigma_px = 0.8;
      render.noise_sigma = 0.01;
      render.supersampling = tile_px > 60 ? 2 : 4;
      render.seed = 7 + v;
      RenderTruth truth;
      const cv::Mat image =
          RenderBoard(puzzle, camera, cam_from_board, render, &truth);
      if (image.empty()) continue;
      std::vector<Eigen::Vector2d> truth_xy, found_xy;
      for (const TruthCorner& t : truth.corners) {
        if (t.visible && t.xy.x() > 3 && t.xy.y() > 3 &&
            t.xy.x() < image.cols - 4 && t.xy.y() < image.rows - 4) {
          truth_xy.push_back(t.xy);
        }
      }
      for (const Corner& c : DetectCorners(image)) found_xy.push_back(c.xy);
      const double radius = std::max(1.5, std::min(3.0, 0.25 * tile_px));
      for (const Eigen::Vector2d& t : truth_xy) {
        double d;
        ++expected;
        if (Nearest(found_xy, t, &d) >= 0 && d < radius) ++found;
      }
      for (const Eigen::Vector2d& f : found_xy) {
        double d;
        Nearest(truth_xy, f, &d);
        if (d >= radius && d < 1.5 * tile_px) ++false_on_board;
      }
    }
    std::printf(
        "%s    {\"tile_px\": %.0f, \"visible\": %d, \"found\": %d, "
        "\"recall\": %s, \"false_on_board\": %d}",
        first_tile ? "" : ",\n", tile_px, expected, found,
        Num(expected ? double(found) / expected : NAN).c_str(), false_on_board);
    first_tile = false;
  }
  std::printf("\n  ],\n");

  // Error tail on demo-like PuzzleBoard renders (the bundled sample set's
  // recipe: 90-degree wide pinhole with barrel distortion, 23x16 board,
  // blur 0.8 px, noise 2 %, 16 random views): error against truth per
  // corner with tiles >= 8 px, per refinement method, and by local tile
  // size (PuzzleBoard discs start a third of a tile from each corner).
  SceneSpec scene = SampleScene(800, 600);
  std::string why;
  const std::vector<SceneView> scene_views = RenderScene(scene, &why);
  std::printf("  \"puzzleboard_demo_error\": [\n");
  const std::pair<const char*, SubpixelMethod> methods[] = {
      {"saddle_fit", SubpixelMethod::kSaddleFit},
      {"gradient_orthogonality", SubpixelMethod::kGradientOrthogonality},
      {"thesis_centroid", SubpixelMethod::kCentroid}};
  bool first_method = true;
  for (const auto& [method_name, method] : methods) {
    DetectorOptions options;
    options.subpixel = method;
    std::vector<double> errors;
    std::vector<double> by_tile[4];  // 8-12, 12-16, 16-24, >= 24 px
    int expected = 0;
    for (const SceneView& view : scene_views) {
      std::vector<Eigen::Vector2d> found_xy;
      for (const Corner& c : DetectCorners(view.image, options)) {
        found_xy.push_back(c.xy);
      }
      const std::vector<TruthCorner>& t = view.truth.corners;
      for (const TruthCorner& corner : t) {
        if (!corner.visible || corner.xy.x() < 3 || corner.xy.y() < 3 ||
            corner.xy.x() > view.image.cols - 4 ||
            corner.xy.y() > view.image.rows - 4) {
          continue;
        }
        double tile = INFINITY;
        for (const TruthCorner& other : t) {
          const Eigen::Vector2i d = other.id - corner.id;
          if (std::abs(d.x()) + std::abs(d.y()) == 1 &&
              std::isfinite(other.xy.x())) {
            tile = std::min(tile, (other.xy - corner.xy).norm());
          }
        }
        if (!(tile >= 8.0)) continue;
        ++expected;
        double d;
        if (Nearest(found_xy, corner.xy, &d) < 0 ||
            d >= std::max(1.5, std::min(3.0, 0.25 * tile))) {
          continue;
        }
        errors.push_back(d);
        by_tile[tile < 12 ? 0 : tile < 16 ? 1 : tile < 24 ? 2 : 3].push_back(d);
      }
    }
    std::printf(
        "%s    {\"method\": \"%s\", \"views\": %d, \"corners\": %d, "
        "\"found\": %d, \"p50_px\": %s, \"p90_px\": %s, "
        "\"p99_px\": %s, \"by_tile_px\": [",
        first_method ? "" : ",\n", method_name,
        static_cast<int>(scene_views.size()), expected,
        static_cast<int>(errors.size()), Num(Percentile(errors, 0.5)).c_str(),
        Num(Percentile(errors, 0.9)).c_str(),
        Num(Percentile(errors, 0.99)).c_str());
    const char* bins[] = {"8-12", "12-16", "16-24", ">=24"};
    for (int b = 0; b < 4; ++b) {
      std::printf(
          "%s{\"tile_px\": \"%s\", \"n\": %d, \"p50_px\": %s, "
          "\"p90_px\": %s}",
          b ? ", " : "", bins[b], static_cast<int>(by_tile[b].size()),
          Num(Percentile(by_tile[b], 0.5)).c_str(),
          Num(Percentile(by_tile[b], 0.9)).c_str());
    }
    std::printf("]}");
    first_method = false;
  }
  std::printf("\n  ]\n}\n");
  return 0;
}
