#ifndef PUZZLECAL_SIM_SCENES_H_
#define PUZZLECAL_SIM_SCENES_H_

// Synthetic scenes: a camera, a board and a set of views, rendered with exact
// truth. The standard scenes (factories below) are what the tests use and
// what `puzzlecal render --scene NAME` renders; they are defined only here.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "sim/render.h"
#include "target/board.h"

namespace puzzlecal {

// Where the camera stands relative to the board. The camera looks at
// `target` (tile units of the corner-id frame, on the board plane) from
// `distance_m`, seeing the board under `view_angle_deg` (the angle between
// the viewing ray and the board plane: 90 = head on) with the tilt about the
// in-plane axis at `tilt_direction_deg` (0 = tilt about the board's x axis);
// it is then rolled by `roll_deg` about its optical axis and turned so the
// target appears `off_axis_deg` from the optical axis, towards image
// direction `off_axis_direction_deg` (0 = right, 90 = down).
struct ViewPose {
  Eigen::Vector2d target = Eigen::Vector2d::Zero();
  double distance_m = 1.0;       // > 0
  double view_angle_deg = 90.0;  // in (0, 90]
  double tilt_direction_deg = 0.0;
  double roll_deg = 0.0;
  double off_axis_deg = 0.0;  // in [0, 180)
  double off_axis_direction_deg = 0.0;
};

// The cam_from_board transform of a ViewPose.
Eigen::Isometry3d PoseFromView(const Board& board, const ViewPose& view);

// Uniform double in [lo, hi] from mt19937_64 (fully specified, so the same
// seed draws the same views everywhere).
double UniformDraw(std::mt19937_64* rng, double lo, double hi);

// A random ViewPose of `board`, drawn from `rng` in a fixed order (on every
// compiler): the target (row, then column) within the printed area grown by
// ranges.target_margin_tiles, the distance, view angle, tilt direction, roll,
// and an off-axis angle uniform over the image disc of directions (not
// clustered at the axis). `Ranges` is RandomViews or RigRandomFrames
// (sim/rig_scenes.h): both name these fields alike.
template <typename Ranges>
ViewPose DrawViewPose(const Board& board, const Ranges& ranges,
                      std::mt19937_64* rng) {
  ViewPose view;
  // One draw per statement: two draws as one call's arguments come in an
  // order each compiler picks. The row is drawn before the column, the
  // order the built-in scenes have always been drawn in.
  const double target_y = UniformDraw(
      rng, board.origin.y() - ranges.target_margin_tiles,
      board.origin.y() + board.rows - 1 + ranges.target_margin_tiles);
  const double target_x = UniformDraw(
      rng, board.origin.x() - ranges.target_margin_tiles,
      board.origin.x() + board.cols - 1 + ranges.target_margin_tiles);
  view.target = Eigen::Vector2d(target_x, target_y);
  view.distance_m =
      UniformDraw(rng, ranges.min_distance_m, ranges.max_distance_m);
  view.view_angle_deg =
      UniformDraw(rng, ranges.min_view_angle_deg, ranges.max_view_angle_deg);
  view.tilt_direction_deg = UniformDraw(rng, 0.0, 360.0);
  view.roll_deg = UniformDraw(rng, -ranges.max_roll_deg, ranges.max_roll_deg);
  view.off_axis_deg =
      ranges.max_off_axis_deg * std::sqrt(UniformDraw(rng, 0.0, 1.0));
  view.off_axis_direction_deg = UniformDraw(rng, 0.0, 360.0);
  return view;
}

// One view of a scene: a pose and the occluders in front of it.
struct SceneViewSpec {
  std::string name;  // file stem, e.g. "view_003"
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  std::vector<Occluder> occluders;
  // Motion blur of this view alone (none: the scene's render options).
  MotionBlur motion_blur;
};

// Random poses: each draws uniformly from the ranges below (degrees, metres).
struct RandomViews {
  int count = 0;                // views to draw; 0 = none
  uint64_t seed = 1;            // same seed, same views
  double min_distance_m = 0.5;  // camera to target
  double max_distance_m = 1.5;
  double min_view_angle_deg = 40.0;  // angle between ray and board plane
  double max_view_angle_deg = 90.0;
  double max_roll_deg = 180.0;     // roll in [-max, max]
  double max_off_axis_deg = 20.0;  // target off the optical axis
  // Target drawn from the board's printed area grown by this many tiles on
  // each side (> 0 puts the image border across the board more often).
  double target_margin_tiles = 0.0;
  int occluders_per_view = 0;  // discs placed over the board
  double min_occluder_radius_px = 10.0;
  double max_occluder_radius_px = 40.0;
};

// A tilt series: the board centre head on at `distance_m`, then seen under
// each of `view_angles_deg`.
struct TiltSeries {
  std::vector<double> view_angles_deg;
  double distance_m = 1.0;
  double tilt_direction_deg = 0.0;
};

// Distances chosen so the board centre's tiles measure `tile_px` pixels
// each (head on, image centre): small-tile tests.
struct TileSizeSeries {
  std::vector<double> tile_px;
  double view_angle_deg = 90.0;
  double roll_deg = 0.0;  // about the optical axis, so edges are not
                          // aligned with the pixel grid
};

struct SceneSpec {
  std::string name;
  Camera camera;
  Board board;
  // Options of every view; view i uses seed render.seed + i.
  RenderOptions render;
  // Views: the explicit ones first, then the generated ones.
  std::vector<SceneViewSpec> views;
  RandomViews random_views;
  TiltSeries tilt_series;
  TileSizeSeries tile_size_series;

  // False with a reason naming the field when the scene cannot be rendered.
  bool Check(std::string* why = nullptr) const;
};

struct SceneView {
  std::string name;
  cv::Mat image;  // CV_8UC1
  RenderTruth truth;
};

// All views of the scene (explicit ones, then the random ones, the tilt
// series and the tile-size series), in that order. Deterministic. Empty with
// `why` set when the scene fails Check or a view fails to render.
std::vector<SceneView> RenderScene(const SceneSpec& scene,
                                   std::string* why = nullptr);

// The explicit and generated view specs of a scene, in RenderScene's order.
std::vector<SceneViewSpec> SceneViewSpecs(const SceneSpec& scene);

// Cameras by field of view, intrinsics scaled to the image size.
// Pinhole-radtan with a horizontal field of view `hfov_deg` and barrel
// distortion `k1` (k2 = k1^2 / 4, small tangential terms).
Camera WidePinholeCamera(int width, int height, double hfov_deg = 100.0,
                         double k1 = -0.25);
// Kannala-Brandt lens whose `fov_deg` field of view fills a circle of
// `circle_fraction` of the image height (0.96 like the deltille photos).
Camera FisheyeLensCamera(int width, int height, double fov_deg = 190.0,
                         double circle_fraction = 0.96);

// FisheyeLensCamera as kannala-brandt-noncentral with the entrance pupil
// shift e1 e2 (metres; the defaults are as measured on the deltille lens).
Camera NoncentralFisheyeCamera(int width, int height, double fov_deg = 190.0,
                               double circle_fraction = 0.96,
                               double e1 = 0.95e-3, double e2 = 0.31e-3);

// The standard scenes. Default sizes are small so tests stay fast; every
// factory takes 1600 x 1200 as well.
// Wide pinhole, boards cut by the image border, two occluders per view.
SceneSpec WidePinholeScene(int width = 640, int height = 480);
// A 190-degree Kannala-Brandt lens; some corners lie beyond 90 degrees from
// the optical axis.
SceneSpec StrongFisheyeScene(int width = 640, int height = 480);
// Viewing angles 90, 80, ..., 20 degrees (pinhole).
SceneSpec TiltSeriesScene(int width = 640, int height = 480);
// Tiles of 4, 5, 6, 8, 10 and 12 pixels (pinhole, 72 x 52 board).
SceneSpec SmallTilesScene(int width = 640, int height = 480);
// The deltille dataset's plain 11 x 8 checkerboard through a fisheye.
SceneSpec FisheyeCheckerboardScene(int width = 640, int height = 480);
// Dark, strongly vignetted fisheye images with a black image circle, like
// the deltille photos (their own size is 1600 x 1200).
SceneSpec DarkFisheyeScene(int width = 800, int height = 600);
// The deltille checkerboard through a 190-degree lens with a moving entrance
// pupil (NoncentralFisheyeCamera), close up (8 to 25 cm) where the pupil
// shift shows, and two views at the rim beyond 90 degrees.
SceneSpec NoncentralFisheyeScene(int width = 640, int height = 480);
// The demo's sample set (testdata/sample, recipe testdata/sample_scene.yaml):
// a 90-degree pinhole with barrel distortion, the 23 x 16 PuzzleBoard from 16
// seeded random poses, boards often cut by the border, one occluder per view.
// Not one of the standard scenes: some of its views are meant to fail (a
// board nearly edge-on, one mostly hidden).
SceneSpec SampleScene(int width = 800, int height = 600);

// Names of the standard scenes ("wide_pinhole", "strong_fisheye",
// "tilt_series", "small_tiles", "fisheye_checkerboard", "dark_fisheye",
// "noncentral_fisheye").
std::vector<std::string> StandardSceneNames();
// The standard scene of that name at that size (0 x 0: the factory's own
// default size); false for unknown names.
bool MakeStandardScene(const std::string& name, int width, int height,
                       SceneSpec* scene);

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_SCENES_H_
