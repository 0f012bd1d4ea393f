#include "sim/scenes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "util/angles.h"
#include "util/failure.h"

namespace puzzlecal {

double UniformDraw(std::mt19937_64* rng, double lo, double hi) {
  const double unit = ((*rng)() >> 11) * (1.0 / 9007199254740992.0);
  return lo + (hi - lo) * unit;
}

namespace {

std::string ViewName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "view_%03d", index);
  return name;
}

Eigen::Vector2d BoardCenterTiles(const Board& board) {
  return Eigen::Vector2d(board.origin.x() + 0.5 * (board.cols - 1),
                         board.origin.y() + 0.5 * (board.rows - 1));
}

bool Finite(double v) { return std::isfinite(v); }

// Occluders over random board points that project into the image.
std::vector<Occluder> RandomOccluders(const SceneSpec& scene,
                                      const Eigen::Isometry3d& pose,
                                      std::mt19937_64* rng) {
  const RandomViews& r = scene.random_views;
  const Board& board = scene.board;
  std::vector<Occluder> occluders;
  for (int i = 0; i < r.occluders_per_view; ++i) {
    for (int attempt = 0; attempt < 50; ++attempt) {
      const double u =
          UniformDraw(rng, board.origin.x(), board.origin.x() + board.cols - 1);
      const double v =
          UniformDraw(rng, board.origin.y(), board.origin.y() + board.rows - 1);
      const double radius =
          UniformDraw(rng, r.min_occluder_radius_px, r.max_occluder_radius_px);
      const double grey = UniformDraw(rng, 0.2, 0.7);
      Eigen::Vector2d pixel;
      const Eigen::Vector3d point =
          pose *
          Eigen::Vector3d(u * board.tile_size_m, v * board.tile_size_m, 0.0);
      if (!scene.camera.Project(point, &pixel) || !pixel.allFinite() ||
          pixel.x() < 0 || pixel.y() < 0 || pixel.x() > scene.camera.width ||
          pixel.y() > scene.camera.height) {
        continue;
      }
      Occluder o;
      o.center_px = pixel;
      o.radius_px = radius;
      o.grey = grey;
      occluders.push_back(o);
      break;
    }
  }
  return occluders;
}

}  // namespace

Eigen::Isometry3d PoseFromView(const Board& board, const ViewPose& view) {
  const double s = board.tile_size_m;
  const Eigen::Vector3d target(view.target.x() * s, view.target.y() * s, 0.0);
  // From the target towards the camera: the printed side's normal (-z),
  // tilted about the in-plane axis.
  const Eigen::Vector3d axis(std::cos(view.tilt_direction_deg * kDegree),
                             std::sin(view.tilt_direction_deg * kDegree), 0.0);
  const Eigen::Vector3d to_camera =
      Eigen::AngleAxisd((90.0 - view.view_angle_deg) * kDegree, axis) *
      Eigen::Vector3d(0, 0, -1);
  const Eigen::Vector3d camera_center = target + view.distance_m * to_camera;
  // Camera axes in the board frame: z at the target, x as close to the
  // board's x as possible, y = z cross x (down on the page when head on).
  const Eigen::Vector3d z = -to_camera;
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - z.x() * z;
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitY() - z.y() * z;
  x.normalize();
  Eigen::Matrix3d board_from_cam;
  board_from_cam.col(0) = x;
  board_from_cam.col(1) = z.cross(x);
  board_from_cam.col(2) = z;
  board_from_cam = board_from_cam * Eigen::AngleAxisd(view.roll_deg * kDegree,
                                                      Eigen::Vector3d::UnitZ())
                                        .toRotationMatrix();
  // Turn the camera so the target direction becomes `off_axis` from its
  // axis: target_in_cam = Q * e_z, and board_from_cam' = board_from_cam Q^T.
  const double phi = view.off_axis_direction_deg * kDegree;
  const Eigen::Matrix3d q =
      Eigen::AngleAxisd(view.off_axis_deg * kDegree,
                        Eigen::Vector3d(-std::sin(phi), std::cos(phi), 0.0))
          .toRotationMatrix();
  board_from_cam = board_from_cam * q.transpose();
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  cam_from_board.linear() = board_from_cam.transpose();
  cam_from_board.translation() = -(board_from_cam.transpose() * camera_center);
  return cam_from_board;
}

bool SceneSpec::Check(std::string* why) const {
  // Names become file names (scene_view.png): plain names only.
  auto plain_name = [](const std::string& text) {
    return !text.empty() && text.front() != '.' &&
           text.find_first_of("/\\") == std::string::npos &&
           text.find('\0') == std::string::npos;
  };
  if (!plain_name(name)) {
    return Fail("name: '" + name +
                    "' must be non-empty, without / or \\, not starting with .",
                why);
  }
  std::string reason;
  if (!CheckRenderCamera(camera, &reason))
    return Fail("camera: " + reason, why);
  if (!board.Check(&reason)) return Fail("board: " + reason, why);
  if (!render.Check(&reason)) return Fail("render: " + reason, why);
  for (size_t i = 0; i < views.size(); ++i) {
    if (!plain_name(views[i].name)) {
      return Fail(
          "views[" + std::to_string(i) + "].name: '" + views[i].name +
              "' must be non-empty, without / or \\, not starting with .",
          why);
    }
    const Eigen::Matrix3d r = views[i].cam_from_board.linear();
    if (!views[i].cam_from_board.matrix().allFinite() ||
        (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
        r.determinant() < 0) {
      return Fail("views[" + std::to_string(i) +
                      "].cam_from_board: not a finite rigid transform",
                  why);
    }
  }
  const RandomViews& rv = random_views;
  if (rv.count < 0 || rv.count > 10000) {
    return Fail("random_views.count must be in [0, 10000]", why);
  }
  if (rv.count > 0) {
    if (!(Finite(rv.min_distance_m) && rv.min_distance_m > 0 &&
          rv.max_distance_m >= rv.min_distance_m &&
          Finite(rv.max_distance_m))) {
      return Fail("random_views: need 0 < min_distance_m <= max_distance_m",
                  why);
    }
    if (!(rv.min_view_angle_deg > 0 &&
          rv.max_view_angle_deg >= rv.min_view_angle_deg &&
          rv.max_view_angle_deg <= 90)) {
      return Fail(
          "random_views: need 0 < min_view_angle_deg <= "
          "max_view_angle_deg <= 90",
          why);
    }
    if (!(Finite(rv.max_roll_deg) && Finite(rv.max_off_axis_deg) &&
          rv.max_off_axis_deg >= 0 && rv.max_off_axis_deg < 180 &&
          Finite(rv.target_margin_tiles))) {
      return Fail(
          "random_views: max_roll_deg, target_margin_tiles must be "
          "finite, max_off_axis_deg in [0, 180)",
          why);
    }
    if (rv.occluders_per_view < 0 || rv.occluders_per_view > 100 ||
        !(rv.min_occluder_radius_px >= 0 &&
          rv.max_occluder_radius_px >= rv.min_occluder_radius_px &&
          Finite(rv.max_occluder_radius_px))) {
      return Fail(
          "random_views: occluders_per_view in [0, 100] and "
          "0 <= min_occluder_radius_px <= max_occluder_radius_px",
          why);
    }
  }
  for (double angle : tilt_series.view_angles_deg) {
    if (!(angle > 0 && angle <= 90)) {
      return Fail("tilt_series.view_angles_deg must lie in (0, 90]", why);
    }
  }
  if (!tilt_series.view_angles_deg.empty() &&
      !(Finite(tilt_series.distance_m) && tilt_series.distance_m > 0)) {
    return Fail("tilt_series.distance_m must be positive", why);
  }
  for (double px : tile_size_series.tile_px) {
    if (!(Finite(px) && px > 0.5)) {
      return Fail("tile_size_series.tile_px must be > 0.5", why);
    }
  }
  if (!tile_size_series.tile_px.empty() &&
      !(tile_size_series.view_angle_deg > 0 &&
        tile_size_series.view_angle_deg <= 90)) {
    return Fail("tile_size_series.view_angle_deg must lie in (0, 90]", why);
  }
  if (views.empty() && rv.count == 0 && tilt_series.view_angles_deg.empty() &&
      tile_size_series.tile_px.empty()) {
    return Fail(
        "the scene has no views (views, random_views, tilt_series "
        "or tile_size_series)",
        why);
  }
  return true;
}

std::vector<SceneViewSpec> SceneViewSpecs(const SceneSpec& scene) {
  std::vector<SceneViewSpec> specs = scene.views;
  int index = static_cast<int>(specs.size());
  for (SceneViewSpec& spec : specs) {
    if (spec.name.empty()) spec.name = ViewName(&spec - specs.data());
  }
  const Board& board = scene.board;
  const RandomViews& rv = scene.random_views;
  std::mt19937_64 rng(rv.seed);
  for (int i = 0; i < rv.count; ++i) {
    const ViewPose view = DrawViewPose(board, rv, &rng);
    SceneViewSpec spec;
    spec.name = ViewName(index++);
    spec.cam_from_board = PoseFromView(board, view);
    spec.occluders = RandomOccluders(scene, spec.cam_from_board, &rng);
    specs.push_back(spec);
  }
  for (double angle : scene.tilt_series.view_angles_deg) {
    ViewPose view;
    view.target = BoardCenterTiles(board);
    view.distance_m = scene.tilt_series.distance_m;
    view.view_angle_deg = angle;
    view.tilt_direction_deg = scene.tilt_series.tilt_direction_deg;
    SceneViewSpec spec;
    char name[32];
    std::snprintf(name, sizeof(name), "tilt_%02d",
                  static_cast<int>(std::lround(angle)));
    spec.name = name;
    spec.cam_from_board = PoseFromView(board, view);
    specs.push_back(spec);
  }
  for (double px : scene.tile_size_series.tile_px) {
    ViewPose view;
    view.target = BoardCenterTiles(board);
    // Head on at the image centre a tile of s metres at distance d spans
    // fx * s / d pixels.
    view.distance_m = scene.camera.params[0] * board.tile_size_m / px;
    view.view_angle_deg = scene.tile_size_series.view_angle_deg;
    view.roll_deg = scene.tile_size_series.roll_deg;
    SceneViewSpec spec;
    char name[32];
    std::snprintf(name, sizeof(name), "tile_%04.1fpx", px);
    spec.name = name;
    spec.cam_from_board = PoseFromView(board, view);
    specs.push_back(spec);
  }
  return specs;
}

std::vector<SceneView> RenderScene(const SceneSpec& scene, std::string* why) {
  std::string reason;
  if (!scene.Check(&reason)) {
    if (why != nullptr) *why = "scene '" + scene.name + "': " + reason;
    return {};
  }
  PixelRayGrid rays;
  if (!rays.Compute(scene.camera, &reason)) {
    if (why != nullptr) *why = "scene '" + scene.name + "': " + reason;
    return {};
  }
  const std::vector<SceneViewSpec> specs = SceneViewSpecs(scene);
  std::vector<SceneView> views;
  views.reserve(specs.size());
  for (size_t i = 0; i < specs.size(); ++i) {
    RenderOptions options = scene.render;
    options.seed = scene.render.seed + i;
    options.occluders.insert(options.occluders.end(),
                             specs[i].occluders.begin(),
                             specs[i].occluders.end());
    if (specs[i].motion_blur.length_px > 0) {
      options.motion_blur = specs[i].motion_blur;
    }
    SceneView view;
    view.name = specs[i].name;
    RenderSummary summary;
    view.image = RenderBoard(scene.board, rays, specs[i].cam_from_board,
                             options, &view.truth, &summary);
    if (!summary.ok) {
      if (why != nullptr) {
        *why = "scene '" + scene.name + "', view " + view.name + ": " +
               summary.reason;
      }
      return {};
    }
    views.push_back(std::move(view));
  }
  return views;
}

Camera WidePinholeCamera(int width, int height, double hfov_deg, double k1) {
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  const double f = 0.5 * width / std::tan(0.5 * hfov_deg * kDegree);
  camera.params = {f,
                   f * 1.001,
                   0.5 * (width - 1) + 0.013 * width,
                   0.5 * (height - 1) - 0.009 * height,
                   k1,
                   0.25 * k1 * k1,
                   0.0006,
                   -0.0004,
                   0.0};
  camera.width = width;
  camera.height = height;
  return camera;
}

Camera FisheyeLensCamera(int width, int height, double fov_deg,
                         double circle_fraction) {
  Camera camera;
  camera.model = CameraModelId::kKannalaBrandt;
  const double k1 = 0.01, k2 = -0.002;
  const double theta = 0.5 * fov_deg * kDegree;
  const double t2 = theta * theta;
  const double radius = 0.5 * circle_fraction * height;
  const double f = radius / (theta * (1.0 + k1 * t2 + k2 * t2 * t2));
  camera.params = {f,
                   f * 0.998,
                   0.5 * (width - 1) + 0.004 * width,
                   0.5 * (height - 1) + 0.006 * height,
                   k1,
                   k2,
                   0.0,
                   0.0};
  camera.width = width;
  camera.height = height;
  return camera;
}

Camera NoncentralFisheyeCamera(int width, int height, double fov_deg,
                               double circle_fraction, double e1, double e2) {
  Camera camera = FisheyeLensCamera(width, height, fov_deg, circle_fraction);
  camera.model = CameraModelId::kKannalaBrandtNoncentral;
  camera.params.push_back(e1);
  camera.params.push_back(e2);
  return camera;
}

namespace {

Board PuzzleBoard23x16() {
  return MakeBoard(BoardType::kPuzzleBoard, 23, 16, Eigen::Vector2i(50, 100),
                   0.03);
}

}  // namespace

SceneSpec WidePinholeScene(int width, int height) {
  SceneSpec scene;
  scene.name = "wide_pinhole";
  scene.camera = WidePinholeCamera(width, height);
  scene.board = PuzzleBoard23x16();
  scene.render.blur_sigma_px = 0.8;
  scene.render.noise_sigma = 0.02;
  scene.render.lighting_gradient = 0.2;
  scene.render.vignetting = 0.2;
  RandomViews& rv = scene.random_views;
  rv.count = 6;
  rv.seed = 11;
  rv.min_distance_m = 0.3;
  rv.max_distance_m = 0.6;
  rv.min_view_angle_deg = 40;
  rv.max_view_angle_deg = 90;
  rv.max_roll_deg = 30;
  rv.max_off_axis_deg = 40;
  rv.target_margin_tiles = 3;
  rv.occluders_per_view = 2;
  rv.min_occluder_radius_px = 0.03 * width;
  rv.max_occluder_radius_px = 0.07 * width;
  return scene;
}

SceneSpec StrongFisheyeScene(int width, int height) {
  SceneSpec scene;
  scene.name = "strong_fisheye";
  scene.camera = FisheyeLensCamera(width, height, 190.0);
  scene.board = PuzzleBoard23x16();
  scene.render.blur_sigma_px = 0.7;
  scene.render.noise_sigma = 0.015;
  scene.render.vignetting = 0.3;
  scene.render.field_of_view_deg = 190.0;
  // Two views that put the board at the rim of the lens, beyond 90 degrees
  // from the optical axis.
  for (int i = 0; i < 2; ++i) {
    ViewPose view;
    view.target = BoardCenterTiles(scene.board);
    view.distance_m = 0.35;
    view.view_angle_deg = 60;
    view.tilt_direction_deg = 90 + 180 * i;
    view.off_axis_deg = 88;
    view.off_axis_direction_deg = 180 * i;
    SceneViewSpec spec;
    spec.name = "rim_" + std::to_string(i);
    spec.cam_from_board = PoseFromView(scene.board, view);
    scene.views.push_back(spec);
  }
  RandomViews& rv = scene.random_views;
  rv.count = 6;
  rv.seed = 12;
  rv.min_distance_m = 0.25;
  rv.max_distance_m = 0.5;
  rv.min_view_angle_deg = 45;
  rv.max_view_angle_deg = 90;
  rv.max_roll_deg = 45;
  rv.max_off_axis_deg = 70;
  return scene;
}

SceneSpec TiltSeriesScene(int width, int height) {
  SceneSpec scene;
  scene.name = "tilt_series";
  scene.camera = WidePinholeCamera(width, height, 60.0, -0.08);
  scene.board = PuzzleBoard23x16();
  scene.render.blur_sigma_px = 0.7;
  scene.render.noise_sigma = 0.01;
  for (int angle = 90; angle >= 20; angle -= 10) {
    scene.tilt_series.view_angles_deg.push_back(angle);
  }
  // The 0.69 m wide board fills about 70 % of the image width head on.
  scene.tilt_series.distance_m = 0.69 / (0.7 * 2 * std::tan(30 * kDegree));
  scene.tilt_series.tilt_direction_deg = 90;  // tilt about the board's y axis
  return scene;
}

SceneSpec SmallTilesScene(int width, int height) {
  SceneSpec scene;
  scene.name = "small_tiles";
  scene.camera = WidePinholeCamera(width, height, 60.0, -0.05);
  scene.board.type = BoardType::kPuzzleBoard;
  scene.board.cols = 72;
  scene.board.rows = 52;
  scene.board.origin = Eigen::Vector2i(100, 200);
  scene.board.tile_size_m = 0.01;
  scene.render.blur_sigma_px = 0.6;
  scene.render.noise_sigma = 0.01;
  scene.tile_size_series.tile_px = {4, 5, 6, 8, 10, 12};
  scene.tile_size_series.view_angle_deg = 80;
  scene.tile_size_series.roll_deg = 7;
  return scene;
}

SceneSpec FisheyeCheckerboardScene(int width, int height) {
  SceneSpec scene;
  scene.name = "fisheye_checkerboard";
  scene.camera = FisheyeLensCamera(width, height, 190.0);
  scene.board.type = BoardType::kCheckerboard;
  scene.board.cols = 11;
  scene.board.rows = 8;
  scene.board.tile_size_m = 0.02;
  scene.render.blur_sigma_px = 0.7;
  scene.render.noise_sigma = 0.015;
  scene.render.vignetting = 0.3;
  scene.render.field_of_view_deg = 190.0;
  RandomViews& rv = scene.random_views;
  rv.count = 6;
  rv.seed = 13;
  rv.min_distance_m = 0.12;
  rv.max_distance_m = 0.3;
  rv.min_view_angle_deg = 45;
  rv.max_view_angle_deg = 90;
  rv.max_roll_deg = 30;
  rv.max_off_axis_deg = 60;
  return scene;
}

SceneSpec DarkFisheyeScene(int width, int height) {
  SceneSpec scene;
  scene.name = "dark_fisheye";
  scene.camera = FisheyeLensCamera(width, height, 190.0, 0.96);
  scene.board = PuzzleBoard23x16();
  // Measured on the deltille photos: mean grey about 42 of 255, black
  // outside the lens circle, a bright board in a dim room, strong falloff.
  scene.render.black_level = 0.03;
  scene.render.white_level = 0.85;
  scene.render.background_level = 0.12;
  scene.render.vignetting = 0.7;
  scene.render.lighting_gradient = 0.15;
  scene.render.blur_sigma_px = 1.0;
  scene.render.noise_sigma = 0.015;
  scene.render.field_of_view_deg = 190.0;
  RandomViews& rv = scene.random_views;
  rv.count = 6;
  rv.seed = 14;
  rv.min_distance_m = 0.2;
  rv.max_distance_m = 0.45;
  rv.min_view_angle_deg = 45;
  rv.max_view_angle_deg = 90;
  rv.max_roll_deg = 20;
  rv.max_off_axis_deg = 50;
  return scene;
}

SceneSpec NoncentralFisheyeScene(int width, int height) {
  SceneSpec scene;
  scene.name = "noncentral_fisheye";
  scene.camera = NoncentralFisheyeCamera(width, height);
  scene.board.type = BoardType::kCheckerboard;
  scene.board.cols = 11;
  scene.board.rows = 8;
  scene.board.tile_size_m = 0.02;
  scene.render.blur_sigma_px = 0.7;
  scene.render.noise_sigma = 0.015;
  scene.render.vignetting = 0.3;
  scene.render.field_of_view_deg = 190.0;
  for (int i = 0; i < 2; ++i) {
    ViewPose view;
    view.target = BoardCenterTiles(scene.board);
    view.distance_m = 0.15;
    view.view_angle_deg = 60;
    view.tilt_direction_deg = 90 + 180 * i;
    view.off_axis_deg = 88;
    view.off_axis_direction_deg = 180 * i;
    SceneViewSpec spec;
    spec.name = "rim_" + std::to_string(i);
    spec.cam_from_board = PoseFromView(scene.board, view);
    scene.views.push_back(spec);
  }
  RandomViews& rv = scene.random_views;
  rv.count = 8;
  rv.seed = 15;
  rv.min_distance_m = 0.08;
  rv.max_distance_m = 0.25;
  rv.min_view_angle_deg = 45;
  rv.max_view_angle_deg = 90;
  rv.max_roll_deg = 30;
  rv.max_off_axis_deg = 70;
  return scene;
}

SceneSpec SampleScene(int width, int height) {
  SceneSpec scene;
  scene.name = "sample";
  scene.camera = WidePinholeCamera(width, height, 90.0, -0.2);
  scene.board = PuzzleBoard23x16();
  scene.render.blur_sigma_px = 0.8;
  scene.render.noise_sigma = 0.02;
  scene.render.lighting_gradient = 0.2;
  scene.render.vignetting = 0.2;
  RandomViews& rv = scene.random_views;
  rv.count = 16;
  rv.seed = 5;
  rv.min_distance_m = 0.35;
  rv.max_distance_m = 0.8;
  rv.min_view_angle_deg = 35;
  rv.max_view_angle_deg = 85;
  rv.max_roll_deg = 45;
  rv.max_off_axis_deg = 35;
  rv.target_margin_tiles = 3;
  rv.occluders_per_view = 1;
  rv.min_occluder_radius_px = 20;
  rv.max_occluder_radius_px = 45;
  return scene;
}

std::vector<std::string> StandardSceneNames() {
  return {"wide_pinhole",      "strong_fisheye",       "tilt_series",
          "small_tiles",       "fisheye_checkerboard", "dark_fisheye",
          "noncentral_fisheye"};
}

bool MakeStandardScene(const std::string& name, int width, int height,
                       SceneSpec* scene) {
  // Each factory's default arguments are its own size.
  const bool sized = width > 0 && height > 0;
  if (name == "wide_pinhole") {
    *scene = sized ? WidePinholeScene(width, height) : WidePinholeScene();
  } else if (name == "strong_fisheye") {
    *scene = sized ? StrongFisheyeScene(width, height) : StrongFisheyeScene();
  } else if (name == "tilt_series") {
    *scene = sized ? TiltSeriesScene(width, height) : TiltSeriesScene();
  } else if (name == "small_tiles") {
    *scene = sized ? SmallTilesScene(width, height) : SmallTilesScene();
  } else if (name == "fisheye_checkerboard") {
    *scene = sized ? FisheyeCheckerboardScene(width, height)
                   : FisheyeCheckerboardScene();
  } else if (name == "dark_fisheye") {
    *scene = sized ? DarkFisheyeScene(width, height) : DarkFisheyeScene();
  } else if (name == "noncentral_fisheye") {
    *scene = sized ? NoncentralFisheyeScene(width, height)
                   : NoncentralFisheyeScene();
  } else {
    return false;
  }
  return true;
}

}  // namespace puzzlecal
