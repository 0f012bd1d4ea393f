#ifndef PUZZLECAL_SIM_VIEW_FAULTS_H_
#define PUZZLECAL_SIM_VIEW_FAULTS_H_

// Faults of single views with known truth, applied to synthetic
// correspondences (sim/synthetic_views.h): the corners of the chosen views
// are projected again through a changed camera or from a bent board, and
// keep the noise they were drawn with. The evidence's tests render each
// failure mode from here:
// - a focal length change between photos (autofocus, zoom): the views see
//   the camera with fx, fy scaled;
// - a bent board (a hand-held foam board, a print not flat): the board
//   surface is displaced along its normal by a smooth warp of a few mm,
//   while the calibration still takes it for flat.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "camera/camera_models.h"
#include "sim/synthetic_views.h"

namespace puzzlecal {
namespace sim {

// The shapes of a bent board: displacement along the board normal as a
// function of the position on the board, in metres at the board's rim.
enum class BoardWarp {
  kBowl,   // w = sag * (r / R)^2: the centre flat, the rim bent away
  kTwist,  // w = sag * (x / hx) * (y / hy): opposite corners up and down
};

// The board-frame displacement (metres, along z) of `point` on a board of
// `cols` x `rows` inner corners of `tile` metres.
inline double BoardWarpAt(BoardWarp warp, double sag_m, int cols, int rows,
                          double tile, const Eigen::Vector3d& point) {
  const double hx = 0.5 * (cols - 1) * tile;
  const double hy = 0.5 * (rows - 1) * tile;
  const double x = (point.x() - hx) / hx;
  const double y = (point.y() - hy) / hy;
  switch (warp) {
    case BoardWarp::kBowl:
      return sag_m * (x * x + y * y) / 2.0;
    case BoardWarp::kTwist:
      return sag_m * x * y;
  }
  return 0;
}

// Re-projects the corners of `views` of `data` through `camera` with the
// board points displaced by `displace(view, board_point)` (board frame),
// keeping each corner's noise. A corner that no longer projects into the
// image keeps its old position.
template <typename Displace>
void ReprojectViews(const Camera& camera, const std::vector<int>& views,
                    Displace displace, SyntheticData* data) {
  for (int v : views) {
    if (v < 0 || v >= static_cast<int>(data->views.size())) continue;
    CalibrationView& view = data->views[v];
    for (size_t i = 0; i < view.board_points.size(); ++i) {
      const Eigen::Vector3d board = displace(v, view.board_points[i]);
      Eigen::Vector2d pixel;
      if (!camera.Project(data->cam_from_board[v] * board, &pixel)) continue;
      const Eigen::Vector2d noise = view.image_points[i] - data->exact[v][i];
      data->exact[v][i] = pixel;
      view.image_points[i] = pixel + noise;
    }
  }
}

// The views of `views` see `camera` with its focal length times `scale`.
inline void ApplyFocalChange(const Camera& camera, double scale,
                             const std::vector<int>& views,
                             SyntheticData* data) {
  Camera changed = camera;
  changed.params[0] *= scale;
  changed.params[1] *= scale;
  ReprojectViews(
      changed, views, [](int, const Eigen::Vector3d& point) { return point; },
      data);
}

// The board is bent by `warp` of `sag_m` metres in the views of `views`.
inline void ApplyBoardBend(const SyntheticScene& scene, BoardWarp warp,
                           double sag_m, const std::vector<int>& views,
                           SyntheticData* data) {
  ReprojectViews(
      scene.camera, views,
      [&](int, const Eigen::Vector3d& point) {
        return Eigen::Vector3d(
            point.x(), point.y(),
            point.z() + BoardWarpAt(warp, sag_m, scene.board_cols,
                                    scene.board_rows, scene.tile, point));
      },
      data);
}

}  // namespace sim
}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_VIEW_FAULTS_H_
