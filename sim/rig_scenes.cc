#include "sim/rig_scenes.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>

#include "formats/png_writer.h"
#include "sim/pixel_rays.h"
#include "sim/scenes.h"
#include "util/angles.h"

namespace puzzlecal {
namespace {

// A camera centred at `centre` (rig frame, metres) whose optical axis is
// turned by `yaw_deg` about the rig's y axis (positive: towards +x) and
// `pitch_deg` about its x axis.
Eigen::Isometry3d CamFromRig(const Eigen::Vector3d& centre, double yaw_deg,
                             double pitch_deg = 0) {
  const Eigen::Matrix3d rig_from_cam =
      (Eigen::AngleAxisd(yaw_deg * kDegree, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(pitch_deg * kDegree, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  Eigen::Isometry3d cam_from_rig = Eigen::Isometry3d::Identity();
  cam_from_rig.linear() = rig_from_cam.transpose();
  cam_from_rig.translation() = -(rig_from_cam.transpose() * centre);
  return cam_from_rig;
}

Board RigBoard() {
  // 23 x 16 = 368 inner corners, 3 cm tiles.
  return MakeBoard(BoardType::kPuzzleBoard, 23, 16, Eigen::Vector2i(120, 40),
                   0.03);
}

RenderOptions RigRender() {
  RenderOptions render;
  render.blur_sigma_px = 0.7;
  render.noise_sigma = 0.01;
  return render;
}

std::vector<TruthCorner> VisibleCorners(
    const RigSceneSpec& scene, size_t c,
    const Eigen::Isometry3d& rig_from_board) {
  const RigSceneCamera& cam = scene.cameras[c];
  RenderOptions options = scene.render;
  options.field_of_view_deg = cam.field_of_view_deg;
  return ProjectBoardCorners(scene.board, cam.camera,
                             cam.cam_from_rig * rig_from_board, options);
}

}  // namespace

bool RigSceneSpec::Check(std::string* why) const {
  auto fail = [why](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  std::string reason;
  if (!board.Check(&reason)) return fail("board: " + reason);
  if (cameras.size() < 2) return fail("cameras: a rig needs at least two");
  for (size_t c = 0; c < cameras.size(); ++c) {
    const RigSceneCamera& cam = cameras[c];
    const std::string field = "cameras[" + std::to_string(c) + "]";
    if (cam.name.empty()) return fail(field + ".name: empty");
    for (size_t o = 0; o < c; ++o) {
      if (cameras[o].name == cam.name) {
        return fail(field + ".name: '" + cam.name + "' used twice");
      }
    }
    if (static_cast<int>(cam.camera.params.size()) !=
        CameraModelNumParams(cam.camera.model)) {
      return fail(field + ".camera: wrong number of parameters");
    }
    if (cam.camera.width <= 0 || cam.camera.height <= 0) {
      return fail(field + ".camera: no image size");
    }
    if (!cam.cam_from_rig.matrix().allFinite()) {
      return fail(field + ".cam_from_rig: not finite");
    }
    if (!(cam.field_of_view_deg >= 0 && cam.field_of_view_deg <= 360)) {
      return fail(field + ".field_of_view_deg: must be in [0, 360]");
    }
  }
  if (!cameras[0].cam_from_rig.isApprox(Eigen::Isometry3d::Identity())) {
    return fail(
        "cameras[0].cam_from_rig: the first camera is the rig frame "
        "(identity)");
  }
  const RigRandomFrames& r = random_frames;
  if (r.count < 0) return fail("random_frames.count: must be >= 0");
  for (int a : r.aim_cameras) {
    if (a < 0 || a >= static_cast<int>(cameras.size())) {
      return fail("random_frames.aim_cameras: no camera " + std::to_string(a));
    }
  }
  if (!(r.min_distance_m > 0 && r.max_distance_m >= r.min_distance_m)) {
    return fail("random_frames: need 0 < min_distance_m <= max_distance_m");
  }
  if (!(r.min_view_angle_deg > 0 && r.max_view_angle_deg <= 90 &&
        r.min_view_angle_deg <= r.max_view_angle_deg)) {
    return fail("random_frames: view angles must be in (0, 90], min <= max");
  }
  if (!(r.max_off_axis_deg >= 0 && r.max_off_axis_deg < 180)) {
    return fail("random_frames.max_off_axis_deg: must be in [0, 180)");
  }
  if (rig_from_board.empty() && r.count == 0) return fail("no frames");
  if (min_visible_corners < 0) {
    return fail("min_visible_corners: must be >= 0");
  }
  return render.Check(why);
}

std::vector<Eigen::Isometry3d> RigFramePoses(const RigSceneSpec& scene) {
  std::vector<Eigen::Isometry3d> poses = scene.rig_from_board;
  const RigRandomFrames& r = scene.random_frames;
  const Board& board = scene.board;
  std::mt19937_64 rng(r.seed);
  for (int k = 0; k < r.count; ++k) {
    const int aim =
        r.aim_cameras.empty()
            ? k % static_cast<int>(scene.cameras.size())
            : r.aim_cameras[k % static_cast<int>(r.aim_cameras.size())];
    const ViewPose view = DrawViewPose(board, r, &rng);
    poses.push_back(scene.cameras[aim].cam_from_rig.inverse() *
                    PoseFromView(board, view));
  }
  return poses;
}

CamFromRigError CompareCamFromRig(const RigCameraResult& estimate,
                                  const Eigen::Isometry3d& truth) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  CamFromRigError error;
  error.rotation_deg =
      RotationDifferenceDeg(estimate.cam_from_rig.linear(), truth.linear());
  error.rotation_over_sigma =
      estimate.rotation_stddev_deg > 0
          ? error.rotation_deg / estimate.rotation_stddev_deg
          : kInfinity;
  const Eigen::Vector3d difference =
      estimate.cam_from_rig.translation() - truth.translation();
  error.translation_m = difference.norm();
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(
      estimate.extrinsics_covariance.block<3, 3>(3, 3));
  error.translation_chi2 =
      ldlt.info() == Eigen::Success && ldlt.vectorD().minCoeff() > 0
          ? difference.dot(ldlt.solve(difference))
          : kInfinity;
  return error;
}

Eigen::Isometry3d RigFramePoseSeenBy(
    const RigSceneSpec& scene, const std::vector<Eigen::Isometry3d>& frames,
    size_t c, size_t f) {
  Eigen::Isometry3d pose = frames[f];
  if (c == 0 || std::find(scene.moved_frames.begin(), scene.moved_frames.end(),
                          static_cast<int>(f)) == scene.moved_frames.end()) {
    return pose;
  }
  std::mt19937_64 rng(scene.moved_seed * 1000003 + f);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d direction;
  do {
    // One draw per statement, z first (see DrawViewPose in sim/scenes.h).
    const double z = normal(rng);
    const double y = normal(rng);
    const double x = normal(rng);
    direction = Eigen::Vector3d(x, y, z);
  } while (!(direction.norm() > 1e-6));
  pose.translation() += scene.moved_by_m * direction.normalized();
  return pose;
}

std::vector<RigCameraInput> RigCorrespondences(const RigSceneSpec& scene,
                                               double noise_px, uint64_t seed) {
  const std::vector<Eigen::Isometry3d> frames = RigFramePoses(scene);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<RigCameraInput> inputs(scene.cameras.size());
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    RigCameraInput& input = inputs[c];
    input.name = scene.cameras[c].name;
    input.model = scene.cameras[c].camera.model;
    input.width = scene.cameras[c].camera.width;
    input.height = scene.cameras[c].camera.height;
    input.frames.resize(frames.size());
    for (size_t f = 0; f < frames.size(); ++f) {
      CalibrationView& view = input.frames[f];
      view.name = RigFrameFileName(static_cast<int>(f));
      const std::vector<TruthCorner> corners =
          VisibleCorners(scene, c, RigFramePoseSeenBy(scene, frames, c, f));
      const int visible = static_cast<int>(
          std::count_if(corners.begin(), corners.end(),
                        [](const TruthCorner& t) { return t.visible; }));
      if (visible < scene.min_visible_corners) continue;
      for (const TruthCorner& corner : corners) {
        if (!corner.visible) continue;
        view.board_points.push_back(scene.board.Point(corner.id));
        const double dx = normal(rng), dy = normal(rng);
        view.image_points.push_back(corner.xy +
                                    noise_px * Eigen::Vector2d(dx, dy));
      }
    }
  }
  return inputs;
}

std::string RigFrameFileName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%03d.png", index);
  return name;
}

bool RenderRigScene(const RigSceneSpec& scene, const std::string& dir,
                    RigRenderSummary* summary, std::string* why) {
  auto fail = [why](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  std::string reason;
  if (!scene.Check(&reason)) return fail("rig '" + scene.name + "': " + reason);
  const std::vector<Eigen::Isometry3d> frames = RigFramePoses(scene);
  RigRenderSummary local;
  local.num_frames = static_cast<int>(frames.size());
  local.images_per_camera.assign(scene.cameras.size(), 0);
  std::vector<int> images_per_frame(frames.size(), 0);
  namespace fs = std::filesystem;
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    const RigSceneCamera& cam = scene.cameras[c];
    const fs::path folder = fs::path(dir) / cam.name;
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (ec) {
      return fail("cannot create '" + folder.string() + "': " + ec.message());
    }
    PixelRayGrid rays;
    if (!rays.Compute(cam.camera, &reason)) {
      return fail("rig '" + scene.name + "', camera '" + cam.name +
                  "': " + reason);
    }
    for (size_t f = 0; f < frames.size(); ++f) {
      RenderOptions options = scene.render;
      options.field_of_view_deg = cam.field_of_view_deg;
      options.seed = scene.render.seed + 1000 * c + f;
      const Eigen::Isometry3d cam_from_board =
          cam.cam_from_rig * RigFramePoseSeenBy(scene, frames, c, f);
      const std::vector<TruthCorner> corners =
          ProjectBoardCorners(scene.board, cam.camera, cam_from_board, options);
      const int visible = static_cast<int>(
          std::count_if(corners.begin(), corners.end(),
                        [](const TruthCorner& t) { return t.visible; }));
      if (visible < scene.min_visible_corners) continue;
      RenderSummary render_summary;
      const cv::Mat image = RenderBoard(scene.board, rays, cam_from_board,
                                        options, nullptr, &render_summary);
      if (!render_summary.ok) {
        return fail("rig '" + scene.name + "', camera '" + cam.name +
                    "', frame " + std::to_string(f) + ": " +
                    render_summary.reason);
      }
      const fs::path file = folder / RigFrameFileName(static_cast<int>(f));
      std::string why;
      if (!WritePngFile(file.string(), image, &why)) return fail(why);
      ++local.images_per_camera[c];
      ++images_per_frame[f];
    }
  }
  local.frames_seen_by_one_camera = static_cast<int>(
      std::count(images_per_frame.begin(), images_per_frame.end(), 1));
  if (summary != nullptr) *summary = local;
  return true;
}

RigSceneSpec StereoPinholeRig(int width, int height) {
  RigSceneSpec scene;
  scene.name = "stereo_pinhole";
  scene.board = RigBoard();
  RigSceneCamera left, right;
  left.name = "cam0";
  left.camera = WidePinholeCamera(width, height, 70.0, -0.12);
  right.name = "cam1";
  right.camera = WidePinholeCamera(width, height, 66.0, -0.08);
  right.camera.params[2] -= 0.02 * width;  // a different principal point
  right.cam_from_rig =
      CamFromRig(Eigen::Vector3d(0.12, 0.004, -0.002), -4.0, 0.7);
  scene.cameras = {left, right};
  scene.render = RigRender();
  RigRandomFrames& r = scene.random_frames;
  r.count = 16;
  r.seed = 31;
  r.min_distance_m = 0.7;
  r.max_distance_m = 1.1;
  r.min_view_angle_deg = 45;
  r.max_view_angle_deg = 80;
  r.max_off_axis_deg = 12;
  return scene;
}

RigSceneSpec FisheyePinholeRig(int width, int height) {
  RigSceneSpec scene;
  scene.name = "fisheye_pinhole";
  scene.board = RigBoard();
  RigSceneCamera fisheye, pinhole;
  fisheye.name = "cam0";
  fisheye.camera = FisheyeLensCamera(width, height, 190.0);
  fisheye.field_of_view_deg = 190.0;
  pinhole.name = "cam1";
  pinhole.camera = WidePinholeCamera(width, height, 75.0, -0.15);
  pinhole.cam_from_rig = CamFromRig(Eigen::Vector3d(0.08, 0.0, 0.01), 50.0);
  scene.cameras = {fisheye, pinhole};
  scene.render = RigRender();
  RigRandomFrames& r = scene.random_frames;
  r.count = 30;
  r.seed = 32;
  r.min_distance_m = 0.45;
  r.max_distance_m = 0.8;
  r.min_view_angle_deg = 45;
  r.max_view_angle_deg = 85;
  r.max_off_axis_deg = 45;
  r.target_margin_tiles = 2;
  return scene;
}

RigSceneSpec StereoFisheyeRig(int width, int height, double fov_deg) {
  RigSceneSpec scene;
  scene.name = "stereo_fisheye";
  scene.board = RigBoard();
  RigSceneCamera left, right;
  left.name = "cam0";
  left.camera = FisheyeLensCamera(width, height, fov_deg);
  left.field_of_view_deg = fov_deg;
  right.name = "cam1";
  right.camera = FisheyeLensCamera(width, height, fov_deg, 0.94);
  right.field_of_view_deg = fov_deg;
  right.cam_from_rig =
      CamFromRig(Eigen::Vector3d(-0.11, 0.003, 0.002), 3.0, -0.5);
  scene.cameras = {left, right};
  scene.render = RigRender();
  RigRandomFrames& r = scene.random_frames;
  r.count = 24;
  r.seed = 34;
  r.min_distance_m = 0.4;
  r.max_distance_m = 0.7;
  r.min_view_angle_deg = 45;
  r.max_view_angle_deg = 85;
  r.max_off_axis_deg = 40;
  r.target_margin_tiles = 1;
  return scene;
}

RigSceneSpec FourCameraRig(int width, int height) {
  RigSceneSpec scene;
  scene.name = "four_cameras";
  scene.board = RigBoard();
  RigSceneCamera cams[4];
  cams[0].name = "cam0";
  cams[0].camera = FisheyeLensCamera(width, height, 190.0);
  cams[0].field_of_view_deg = 190.0;
  cams[1].name = "cam1";
  cams[1].camera = WidePinholeCamera(width, height, 75.0, -0.15);
  cams[1].cam_from_rig = CamFromRig(Eigen::Vector3d(0.07, 0.0, 0.0), 50.0);
  cams[2].name = "cam2";
  cams[2].camera.model = CameraModelId::kPinholeRational;
  {
    const Camera radtan = WidePinholeCamera(width, height, 80.0, -0.2);
    cams[2].camera = radtan;
    cams[2].camera.model = CameraModelId::kPinholeRational;
    cams[2].camera.params = radtan.params;
    cams[2].camera.params.resize(12, 0.0);
    cams[2].camera.params[8] = 0.0;   // k3
    cams[2].camera.params[9] = 0.05;  // k4
  }
  cams[2].cam_from_rig = CamFromRig(Eigen::Vector3d(-0.07, 0.0, 0.0), -50.0);
  cams[3].name = "cam3";
  cams[3].camera = WidePinholeCamera(width, height, 75.0, -0.1);
  cams[3].cam_from_rig = CamFromRig(Eigen::Vector3d(0.1, 0.0, -0.05), 100.0);
  scene.cameras.assign(cams, cams + 4);
  scene.render = RigRender();
  RigRandomFrames& r = scene.random_frames;
  r.count = 32;
  r.seed = 33;
  r.min_distance_m = 0.45;
  r.max_distance_m = 0.8;
  r.min_view_angle_deg = 45;
  r.max_view_angle_deg = 85;
  r.max_off_axis_deg = 30;
  r.target_margin_tiles = 2;
  return scene;
}

}  // namespace puzzlecal
