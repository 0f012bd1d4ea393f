#ifndef PUZZLECAL_TESTS_DECODE_TRUTH_COMPONENTS_H_
#define PUZZLECAL_TESTS_DECODE_TRUTH_COMPONENTS_H_

// Helpers for decode/ tests and bench: renders of a board with exact truth,
// and grid components built from that truth with labels that mimic grid/
// (an unknown rotation/reflection and offset of the board ids).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "camera/camera_models.h"
#include "detection/corner.h"
#include "grid/grid_component.h"
#include "sim/render.h"
#include "target/board.h"
#include "tests/support/draws.h"

namespace puzzlecal {
namespace decode_testing {

inline Board MakePuzzleBoard(int cols, int rows, int x0, int y0,
                             double tile_m) {
  return MakeBoard(BoardType::kPuzzleBoard, cols, rows, Eigen::Vector2i(x0, y0),
                   tile_m);
}

inline Camera PinholeCamera(int width, int height, double f) {
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.params = {f, f, 0.5 * (width - 1), 0.5 * (height - 1), 0, 0, 0, 0, 0};
  camera.width = width;
  camera.height = height;
  return camera;
}

// Kannala-Brandt fisheye with r = f * theta (equidistant) plus distortion.
inline Camera FisheyeCamera(int width, int height, double f, double k1 = 0.0) {
  Camera camera;
  camera.model = CameraModelId::kKannalaBrandt;
  camera.params = {f, f, 0.5 * (width - 1), 0.5 * (height - 1), k1, 0, 0, 0};
  camera.width = width;
  camera.height = height;
  return camera;
}

// Pose that looks at board point `target_id` (may be fractional) from
// `distance_m`, with the board tilted by `tilt_deg` about its x axis, turned
// by `roll_deg` about the optical axis and shifted by `shift_m` in the image
// plane.
inline Eigen::Isometry3d LookAt(
    const Board& board, const Eigen::Vector2d& target_id, double distance_m,
    double tilt_deg, double roll_deg = 0.0,
    const Eigen::Vector2d& shift_m = Eigen::Vector2d::Zero()) {
  const double deg = M_PI / 180.0;
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(roll_deg * deg, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(tilt_deg * deg, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Vector3d target(target_id.x() * board.tile_size_m,
                               target_id.y() * board.tile_size_m, 0.0);
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  cam_from_board.linear() = rotation;
  cam_from_board.translation() =
      Eigen::Vector3d(shift_m.x(), shift_m.y(), distance_m) - rotation * target;
  return cam_from_board;
}

// Corners and one component per connected piece, built from the visible
// truth corners that `keep` accepts. Labels are ij = label_from_id * (id -
// id0) + label_offset, like grid/ would give (relative, possibly mirrored).
struct TruthGrid {
  std::vector<Corner> corners;
  std::vector<GridComponent> components;
  std::vector<Eigen::Vector2i> truth_id;  // per corner
};

inline Eigen::Matrix2i RandomSignedPermutation(std::mt19937* rng) {
  Eigen::Matrix2i m = Eigen::Matrix2i::Zero();
  const bool swap = (*rng)() & 1;
  const int sx = ((*rng)() & 1) ? 1 : -1;
  const int sy = ((*rng)() & 1) ? 1 : -1;
  if (swap) {
    m(0, 1) = sx;
    m(1, 0) = sy;
  } else {
    m(0, 0) = sx;
    m(1, 1) = sy;
  }
  return m;
}

// One component holding every visible corner accepted by `keep`.
inline TruthGrid OneComponentFromTruth(
    const RenderTruth& truth, const Eigen::Matrix2i& label_from_id,
    const Eigen::Vector2i& label_offset,
    const std::function<bool(const Eigen::Vector2i&)>& keep = nullptr,
    double position_noise_px = 0.0, uint32_t seed = 1) {
  TruthGrid grid;
  grid.components.emplace_back();
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, position_noise_px);
  for (const TruthCorner& c : truth.corners) {
    if (!c.visible || (keep && !keep(c.id))) continue;
    Corner corner;
    corner.xy = c.xy;
    if (position_noise_px > 0)
      corner.xy += testing_draws::DrawVector2d([&] { return noise(rng); });
    grid.components[0].corner.push_back(static_cast<int>(grid.corners.size()));
    grid.components[0].ij.push_back(label_from_id * c.id + label_offset);
    grid.corners.push_back(corner);
    grid.truth_id.push_back(c.id);
  }
  return grid;
}

}  // namespace decode_testing
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_DECODE_TRUTH_COMPONENTS_H_
