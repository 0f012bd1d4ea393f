#include "sim/synthetic_views.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

namespace puzzlecal {
namespace sim {

Camera MakeCamera(CameraModelId model, int width, int height,
                  std::vector<double> params) {
  Camera camera;
  camera.model = model;
  camera.width = width;
  camera.height = height;
  camera.params = std::move(params);
  return camera;
}

// A wide-angle lens with strong barrel distortion, 1280 x 960.
Camera TruthRadtan() {
  return MakeCamera(
      CameraModelId::kPinholeRadtan, 1280, 960,
      {820.0, 818.5, 642.3, 477.1, -0.28, 0.09, 0.0006, -0.0004, -0.012});
}
// OpenCV's rational model, 1280 x 960.
Camera TruthRational() {
  return MakeCamera(CameraModelId::kPinholeRational, 1280, 960,
                    {760.0, 761.2, 637.8, 482.6, 0.3, 0.02, 0.0004, 0.0007,
                     0.0005, 0.52, 0.06, 0.001});
}
// A 190 degree fisheye on a 1600 x 1200 sensor: the image circle is cut by
// the top and bottom edges, the image corners see 114 degrees off the axis.
Camera TruthFisheye190() {
  return MakeCamera(CameraModelId::kKannalaBrandt, 1600, 1200,
                    {495.0, 494.2, 801.7, 598.4, 0.02, -0.005, 0.001, -0.0002});
}

Camera TruthBumpyFisheye(double bump_px, double prism_px) {
  Camera camera = TruthFisheye190();
  camera.model = CameraModelId::kKannalaBrandtSplined;
  constexpr double kGridRadius = 1.9;
  constexpr double kBumpAngle = 50 * M_PI / 180, kBumpWidth = 0.3;
  const double focal = camera.params[0];
  camera.params.push_back(kGridRadius);
  const double spacing = 2 * kGridRadius / (kSplineKnots - 3);
  for (int row = 0; row < kSplineKnots; ++row) {
    for (int col = 0; col < kSplineKnots; ++col) {
      const double x = -kGridRadius + (col - 1) * spacing;
      const double y = -kGridRadius + (row - 1) * spacing;
      const double rho = std::hypot(x, y);
      const double bump =
          bump_px / focal *
          std::exp(-0.5 * std::pow((rho - kBumpAngle) / kBumpWidth, 2));
      const double prism = prism_px / focal * std::pow(rho / (0.5 * M_PI), 2);
      camera.params.push_back((rho > 0 ? bump * x / rho : 0.0) + prism);
      camera.params.push_back((rho > 0 ? bump * y / rho : 0.0) - prism);
    }
  }
  return camera;
}

SyntheticData MakeSyntheticData(const SyntheticScene& scene) {
  std::mt19937 rng(scene.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Camera& camera = scene.camera;
  const double board_width = (scene.board_cols - 1) * scene.tile;
  const Eigen::Vector3d board_centre(0.5 * (scene.board_cols - 1) * scene.tile,
                                     0.5 * (scene.board_rows - 1) * scene.tile,
                                     0);
  const double deg = M_PI / 180.0;
  SyntheticData data;
  int attempts = 0;
  while (static_cast<int>(data.views.size()) < scene.num_views &&
         attempts < 100000) {
    ++attempts;
    // Direction of the board centre: uniform in the cap up to max_direction.
    const double cos_max = std::cos(scene.max_direction_deg * deg);
    const double cos_theta = 1.0 - uniform(rng) * (1.0 - cos_max);
    const double theta = std::acos(cos_theta);
    const double phi = 2 * M_PI * uniform(rng);
    const Eigen::Vector3d dir(std::sin(theta) * std::cos(phi),
                              std::sin(theta) * std::sin(phi), cos_theta);
    // Board z along the viewing ray, then tilted about an axis across it.
    const Eigen::Matrix3d face =
        scene.fronto_parallel
            ? Eigen::Matrix3d::Identity()
            : Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), dir)
                  .toRotationMatrix();
    const double tilt =
        scene.fronto_parallel
            ? 0.0
            : (scene.min_tilt_deg +
               uniform(rng) * (scene.max_tilt_deg - scene.min_tilt_deg)) *
                  deg;
    const double axis_angle = 2 * M_PI * uniform(rng);
    const Eigen::Vector3d axis =
        face * Eigen::Vector3d(std::cos(axis_angle), std::sin(axis_angle), 0);
    const double spin = (uniform(rng) - 0.5) * 2 * M_PI;
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(tilt, axis).toRotationMatrix() * face *
        Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const double distance =
        board_width *
        (scene.min_distance +
         uniform(rng) * (scene.max_distance - scene.min_distance));
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rotation;
    pose.translation() = distance * dir - rotation * board_centre;

    CalibrationView view;
    std::vector<Eigen::Vector2d> exact;
    for (int row = 0; row < scene.board_rows; ++row) {
      for (int col = 0; col < scene.board_cols; ++col) {
        const Eigen::Vector3d board(col * scene.tile, row * scene.tile, 0);
        const Eigen::Vector3d cam = pose * board;
        if (std::atan2(cam.head<2>().norm(), cam.z()) >
            scene.max_corner_angle_deg * deg) {
          continue;
        }
        // The board must face the camera (its front side is seen).
        if ((cam).dot(rotation.col(2)) <= 0) continue;
        Eigen::Vector2d pixel;
        if (!camera.Project(cam, &pixel)) continue;
        if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > camera.width - 1 ||
            pixel.y() > camera.height - 1) {
          continue;
        }
        view.board_points.push_back(board);
        exact.push_back(pixel);
      }
    }
    const int total = scene.board_cols * scene.board_rows;
    if (view.board_points.size() <
        std::max<size_t>(8, std::ceil(scene.min_visible_fraction * total))) {
      continue;
    }
    std::vector<bool> outlier(exact.size(), false);
    for (size_t i = 0; i < exact.size(); ++i) {
      // One draw per statement, y first (see DrawViewPose).
      const double noise_y = normal(rng);
      const double noise_x = normal(rng);
      Eigen::Vector2d observed =
          exact[i] + scene.noise_px * Eigen::Vector2d(noise_x, noise_y);
      if (uniform(rng) < scene.outlier_fraction) {
        // A gross error: 5 to 50 px away in a random direction.
        const double angle = 2 * M_PI * uniform(rng);
        const double size = 5 + 45 * uniform(rng);
        observed =
            exact[i] + size * Eigen::Vector2d(std::cos(angle), std::sin(angle));
        outlier[i] = true;
      }
      view.image_points.push_back(observed);
    }
    view.name = "synthetic_" + std::to_string(data.views.size());
    data.num_corners += static_cast<int>(exact.size());
    data.views.push_back(std::move(view));
    data.cam_from_board.push_back(pose);
    data.exact.push_back(std::move(exact));
    data.is_outlier.push_back(std::move(outlier));
  }
  return data;
}

std::vector<Eigen::Isometry3d> CentredFrontalPoses(const Camera& camera,
                                                   const Board& board,
                                                   int count, unsigned seed) {
  constexpr double kDegree = M_PI / 180.0;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double width_m = (board.cols - 1) * board.tile_size_m;
  const double distance = width_m * camera.params[0] / (0.6 * camera.width);
  const Eigen::Vector3d centre =
      0.5 * (board.Point(board.origin) +
             board.Point(board.origin +
                         Eigen::Vector2i(board.cols - 1, board.rows - 1)));
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k < count; ++k) {
    const double tilt = (6 + 4 * uniform(rng)) * kDegree;
    const double direction = 2 * M_PI * (k + uniform(rng)) / count;
    const Eigen::Vector3d axis(-std::sin(direction), std::cos(direction), 0);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(tilt, axis).toRotationMatrix();
    const double shift_y = 0.05 * (uniform(rng) - 0.5);  // y first, as above
    const double shift_x = 0.05 * (uniform(rng) - 0.5);
    const Eigen::Vector3d shift(shift_x, shift_y, 1.0);
    pose.translation() = distance * shift.normalized() - pose.linear() * centre;
    poses.push_back(pose);
  }
  return poses;
}

CalibrationView ProjectBoardView(const Camera& camera, const Board& board,
                                 const Eigen::Isometry3d& cam_from_board,
                                 double noise_px, std::mt19937* rng,
                                 const std::string& name,
                                 std::vector<Eigen::Vector2d>* exact) {
  std::normal_distribution<double> normal(0.0, 1.0);
  CalibrationView view;
  view.name = name;
  if (exact != nullptr) exact->clear();
  const Eigen::Vector3d normal_cam = cam_from_board.linear().col(2);
  for (const Eigen::Vector2i& id : board.AllIds()) {
    const Eigen::Vector3d point = board.Point(id);
    const Eigen::Vector3d cam = cam_from_board * point;
    Eigen::Vector2d pixel;
    // Beyond the radius where the distortion folds over, a lens shows
    // nothing the model could place.
    const bool seen = cam.dot(normal_cam) > 0 &&
                      FieldRadius(camera, cam) < MaxMonotonicRadius(camera) &&
                      camera.Project(cam, &pixel) && pixel.x() >= 0 &&
                      pixel.y() >= 0 && pixel.x() <= camera.width - 1 &&
                      pixel.y() <= camera.height - 1;
    const double noise_y = normal(*rng);  // y first, as above
    const double noise_x = normal(*rng);
    const Eigen::Vector2d noise(noise_x, noise_y);
    if (!seen) continue;
    view.board_points.push_back(point);
    view.image_points.push_back(pixel + noise_px * noise);
    if (exact != nullptr) exact->push_back(pixel);
  }
  return view;
}

}  // namespace sim
}  // namespace puzzlecal
