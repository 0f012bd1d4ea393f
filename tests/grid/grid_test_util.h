#ifndef PUZZLECAL_TESTS_GRID_GRID_TEST_UTIL_H_
#define PUZZLECAL_TESTS_GRID_GRID_TEST_UTIL_H_

// Test helpers for grid/: synthetic corner sets projected through camera
// models with exact ids, and the wrong-label metric.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "detection/corner.h"
#include "grid/grid_component.h"
#include "target/board.h"
#include "tests/support/draws.h"

namespace puzzlecal {
namespace grid_test {

// Where a corner came from.
struct CornerTruth {
  int board = -1;                                // -1: clutter
  Eigen::Vector2i id = Eigen::Vector2i::Zero();  // (col, row) on that board
};

// A synthetic detector output with its truth.
struct SyntheticCorners {
  std::vector<Corner> corners;
  std::vector<CornerTruth> truth;
};

// One board in a synthetic scene.
struct SyntheticBoard {
  int cols = 11;  // inner corners
  int rows = 8;
  double tile_m = 0.02;
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
};

// The lattice of a printed board (its inner corners and tile size), posed
// at the identity.
inline SyntheticBoard GeometryOf(const Board& board) {
  SyntheticBoard geometry;
  geometry.cols = board.cols;
  geometry.rows = board.rows;
  geometry.tile_m = board.tile_size_m;
  return geometry;
}

// A pose that looks at the board centre from `distance_m` along the optical
// axis, with the board plane at `viewing_angle_deg` to the line of sight (90 =
// frontal), tilted about an in-plane axis at `tilt_axis_deg` to the board's
// x axis, and rotated in the image by `roll_deg`. `offset_px_m` shifts the
// board centre sideways in the camera frame (metres).
inline Eigen::Isometry3d LookAtBoard(
    const SyntheticBoard& board, double distance_m, double viewing_angle_deg,
    double tilt_axis_deg, double roll_deg,
    const Eigen::Vector3d& offset_m = Eigen::Vector3d::Zero()) {
  const double deg = M_PI / 180;
  const Eigen::Vector3d centre((board.cols - 1) * board.tile_m / 2,
                               (board.rows - 1) * board.tile_m / 2, 0);
  const Eigen::Vector3d tilt_axis(std::cos(tilt_axis_deg * deg),
                                  std::sin(tilt_axis_deg * deg), 0);
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(roll_deg * deg, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd((90 - viewing_angle_deg) * deg, tilt_axis))
          .toRotationMatrix();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() =
      Eigen::Vector3d(0, 0, distance_m) + offset_m - rotation * centre;
  return pose;
}

// Options for ProjectBoards.
struct SyntheticOptions {
  double position_noise_px = 0.1;      // Gaussian sigma
  double orientation_noise_deg = 2.0;  // Gaussian sigma
  int num_clutter = 0;                 // random corners off every board
  // Clutter keeps at least this many tiles (in board coordinates) away from
  // the outermost inner corners of every board.
  double clutter_margin_tiles = 1.5;
  // Discs (centre x, y, radius in pixels) whose corners are dropped.
  std::vector<Eigen::Vector3d> occluders;
  unsigned seed = 1;
};

// Pixel of board point `id` (tile units) or false when it does not project.
inline bool ProjectId(const Camera& camera, const SyntheticBoard& board,
                      const Eigen::Vector2d& id, Eigen::Vector2d* pixel) {
  const Eigen::Vector3d point(id.x() * board.tile_m, id.y() * board.tile_m, 0);
  const Eigen::Vector3d cam = board.cam_from_board * point;
  if (CameraModelIsPinhole(camera.model) && cam.z() <= 1e-6) return false;
  if (!camera.Project(cam, pixel)) return false;
  return std::isfinite(pixel->x()) && std::isfinite(pixel->y());
}

// Board coordinates (tile units) of the ray through `pixel`, false when the
// ray misses the board plane.
inline bool PixelToBoard(const Camera& camera, const SyntheticBoard& board,
                         const Eigen::Vector2d& pixel, Eigen::Vector2d* id) {
  Eigen::Vector3d ray;
  camera.Unproject(pixel, &ray);
  const Eigen::Isometry3d board_from_cam = board.cam_from_board.inverse();
  const Eigen::Vector3d origin = board_from_cam.translation();
  const Eigen::Vector3d direction = board_from_cam.linear() * ray;
  if (std::abs(direction.z()) < 1e-12) return false;
  const double lambda = -origin.z() / direction.z();
  if (lambda <= 0) return false;
  const Eigen::Vector3d hit = origin + lambda * direction;
  *id = hit.head<2>() / board.tile_m;
  return true;
}

// Projects every inner corner of every board with its exact id; orientation
// from the projected geometry: the bisector of the projected board axes at
// the corner, alternating by 90 degrees between tile-edge neighbours (as the
// first Hessian eigenvector does). Corners outside the image or under an
// occluder are left out; clutter is added at random positions with random
// orientations.
inline SyntheticCorners ProjectBoards(const Camera& camera,
                                      const std::vector<SyntheticBoard>& boards,
                                      const SyntheticOptions& options) {
  SyntheticCorners out;
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto occluded = [&](const Eigen::Vector2d& p) {
    for (const Eigen::Vector3d& o : options.occluders)
      if ((p - o.head<2>()).norm() < o.z()) return true;
    return false;
  };
  for (int b = 0; b < static_cast<int>(boards.size()); ++b) {
    const SyntheticBoard& board = boards[b];
    for (int r = 0; r < board.rows; ++r) {
      for (int c = 0; c < board.cols; ++c) {
        const Eigen::Vector2d id(c, r);
        Eigen::Vector2d p, pu, pv;
        constexpr double kStep = 0.05;  // tiles
        if (!ProjectId(camera, board, id, &p) ||
            !ProjectId(camera, board, id + Eigen::Vector2d(kStep, 0), &pu) ||
            !ProjectId(camera, board, id + Eigen::Vector2d(0, kStep), &pv))
          continue;
        if (p.x() < 1 || p.y() < 1 || p.x() > camera.width - 2 ||
            p.y() > camera.height - 2 || occluded(p))
          continue;
        const Eigen::Vector2d du = (pu - p).normalized();
        const Eigen::Vector2d dv = (pv - p).normalized();
        const Eigen::Vector2d bisector = ((c + r) % 2 == 0)
                                             ? Eigen::Vector2d(du + dv)
                                             : Eigen::Vector2d(du - dv);
        Corner corner;
        corner.xy =
            p + options.position_noise_px *
                    testing_draws::DrawVector2d([&] { return gauss(rng); });
        corner.orientation =
            std::atan2(bisector.y(), bisector.x()) +
            options.orientation_noise_deg * M_PI / 180 * gauss(rng);
        corner.response = 1.0;
        out.corners.push_back(corner);
        out.truth.push_back({b, Eigen::Vector2i(c, r)});
      }
    }
  }
  std::uniform_real_distribution<double> ux(0, camera.width - 1);
  std::uniform_real_distribution<double> uy(0, camera.height - 1);
  std::uniform_real_distribution<double> uangle(-M_PI, M_PI);
  int added = 0;
  for (int attempt = 0; added < options.num_clutter && attempt < 100000;
       ++attempt) {
    const double y = uy(rng);  // y first (tests/support/draws.h)
    const Eigen::Vector2d p(ux(rng), y);
    bool near_board = false;
    for (const SyntheticBoard& board : boards) {
      Eigen::Vector2d id;
      const double m = options.clutter_margin_tiles;
      if (PixelToBoard(camera, board, p, &id) && id.x() > -m && id.y() > -m &&
          id.x() < board.cols - 1 + m && id.y() < board.rows - 1 + m)
        near_board = true;
    }
    if (near_board) continue;
    Corner corner;
    corner.xy = p;
    corner.orientation = uangle(rng);
    corner.response = 1.0;
    out.corners.push_back(corner);
    out.truth.push_back({-1, Eigen::Vector2i::Zero()});
    ++added;
  }
  return out;
}

// A pinhole camera with mild radial distortion.
inline Camera PinholeCamera(int width = 1280, int height = 960,
                            double focal = 1000) {
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.params = {
      focal, focal, (width - 1) / 2.0, (height - 1) / 2.0, -0.05, 0.01, 0,
      0,     0};
  camera.width = width;
  camera.height = height;
  return camera;
}

// A strong fisheye (Kannala-Brandt, about 190 degrees across the width).
inline Camera FisheyeCamera(int width = 1600, int height = 1200) {
  Camera camera;
  camera.model = CameraModelId::kKannalaBrandt;
  camera.params = {
      460,   460,    (width - 1) / 2.0, (height - 1) / 2.0, 0.02, -0.01,
      0.002, -0.0005};
  camera.width = width;
  camera.height = height;
  return camera;
}

// The label metric. For each component, the board it belongs to is the board
// most of its corners come from; corners of other boards and clutter in it
// are `foreign` (a component of clutter alone is not counted). Among its own
// board's corners, the component's best lattice transform (one of the 8
// rotations/reflections plus an offset, chosen to fit the most corners) maps
// labels to truth ids; a corner it does not map to its truth id is `wrong` --
// equivalently, the wrong corners are the fewest that must be removed so that
// for every remaining pair the label difference, under the transform, equals
// the truth id difference.
struct LabelCheck {
  int labelled = 0;  // board corners in some component (own board)
  int wrong = 0;     // wrong labels (see above)
  int foreign = 0;   // clutter or other-board corners in a component
  int components = 0;
  int largest = 0;
  std::vector<int> boards_of_component;  // majority board per component
};

inline LabelCheck CheckLabels(const std::vector<GridComponent>& components,
                              const std::vector<CornerTruth>& truth) {
  LabelCheck check;
  check.components = static_cast<int>(components.size());
  for (const GridComponent& component : components) {
    check.largest =
        std::max(check.largest, static_cast<int>(component.corner.size()));
    std::map<int, int> board_count;
    for (int c : component.corner)
      if (truth[c].board >= 0) ++board_count[truth[c].board];
    int board = -1, best = 0;
    for (const auto& [b, count] : board_count)
      if (count > best) board = b, best = count;
    check.boards_of_component.push_back(board);
    // Components of clutter alone are harmless (decode/ refuses them).
    if (board < 0) continue;
    check.foreign += static_cast<int>(component.corner.size()) - best;
    int best_fit = 0;
    for (int sign : {1, -1}) {
      for (int rot = 0; rot < 4; ++rot) {
        // Linear part: i -> step(rot), j -> step(rot + sign).
        static const int kStep[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
        const int* ci = kStep[rot];
        const int* cj = kStep[((rot + sign) % 4 + 4) % 4];
        std::map<std::pair<int, int>, int> offsets;
        for (size_t k = 0; k < component.corner.size(); ++k) {
          const CornerTruth& t = truth[component.corner[k]];
          if (t.board != board) continue;
          const Eigen::Vector2i& l = component.ij[k];
          const int mx = l.x() * ci[0] + l.y() * cj[0];
          const int my = l.x() * ci[1] + l.y() * cj[1];
          ++offsets[{t.id.x() - mx, t.id.y() - my}];
        }
        for (const auto& [offset, count] : offsets)
          best_fit = std::max(best_fit, count);
      }
    }
    check.labelled += best;
    check.wrong += best - best_fit;
  }
  return check;
}

// Board corners present in the input (the denominator of the coverage).
inline int CountBoardCorners(const std::vector<CornerTruth>& truth) {
  return static_cast<int>(
      std::count_if(truth.begin(), truth.end(),
                    [](const CornerTruth& t) { return t.board >= 0; }));
}

}  // namespace grid_test
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_GRID_GRID_TEST_UTIL_H_
