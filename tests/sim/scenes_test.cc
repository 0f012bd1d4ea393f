#include "sim/scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace puzzlecal {
namespace {

constexpr double kDegree = M_PI / 180.0;

// Angle between the ray from the camera centre to the board point and the
// board plane, in degrees.
double ViewAngleDeg(const Eigen::Isometry3d& cam_from_board,
                    const Eigen::Vector3d& board_point) {
  const Eigen::Vector3d center =
      -(cam_from_board.linear().transpose() * cam_from_board.translation());
  const Eigen::Vector3d ray = (board_point - center).normalized();
  return std::asin(std::abs(ray.z())) / kDegree;
}

TEST(ScenesTest, EveryStandardSceneRendersWithVisibleCorners) {
  for (const std::string& name : StandardSceneNames()) {
    SceneSpec scene;
    ASSERT_TRUE(MakeStandardScene(name, 320, 240, &scene)) << name;
    scene.render.supersampling = 2;  // keeps the test fast
    std::string why;
    ASSERT_TRUE(scene.Check(&why)) << name << ": " << why;
    const std::vector<SceneView> views = RenderScene(scene, &why);
    ASSERT_FALSE(views.empty()) << name << ": " << why;
    for (const SceneView& view : views) {
      EXPECT_EQ(view.image.cols, 320);
      EXPECT_EQ(view.image.rows, 240);
      int visible = 0;
      for (const TruthCorner& c : view.truth.corners) visible += c.visible;
      EXPECT_GT(visible, 4) << name << " " << view.name;
    }
  }
  SceneSpec unknown;
  EXPECT_FALSE(MakeStandardScene("no_such_scene", 320, 240, &unknown));
}

TEST(ScenesTest, PoseFromViewLooksAtTheTarget) {
  Board board;
  board.cols = 11;
  board.rows = 8;
  board.tile_size_m = 0.05;
  ViewPose view;
  view.target = Eigen::Vector2d(3.0, 2.0);
  view.distance_m = 0.8;
  view.view_angle_deg = 35.0;
  view.tilt_direction_deg = 30.0;
  view.roll_deg = 20.0;
  const Eigen::Vector3d target(0.15, 0.10, 0.0);
  Eigen::Isometry3d pose = PoseFromView(board, view);
  Eigen::Vector3d in_cam = pose * target;
  EXPECT_NEAR(in_cam.x(), 0.0, 1e-12);
  EXPECT_NEAR(in_cam.y(), 0.0, 1e-12);
  EXPECT_NEAR(in_cam.z(), 0.8, 1e-12);
  EXPECT_NEAR(ViewAngleDeg(pose, target), 35.0, 1e-9);
  // Off axis: the target is 100 degrees from the optical axis, to the left.
  view.off_axis_deg = 100.0;
  view.off_axis_direction_deg = 180.0;
  pose = PoseFromView(board, view);
  in_cam = pose * target;
  EXPECT_NEAR(std::atan2(in_cam.head<2>().norm(), in_cam.z()) / kDegree, 100.0,
              1e-9);
  EXPECT_LT(in_cam.x(), 0.0);
  EXPECT_NEAR(in_cam.y(), 0.0, 1e-12);
  EXPECT_NEAR(in_cam.norm(), 0.8, 1e-12);
  // The camera sees the printed side (camera centre at z < 0 on the board).
  const Eigen::Vector3d center =
      -(pose.linear().transpose() * pose.translation());
  EXPECT_LT(center.z(), 0.0);
}

TEST(ScenesTest, TiltSeriesHasTheRequestedViewingAngles) {
  const SceneSpec scene = TiltSeriesScene(320, 240);
  const std::vector<SceneViewSpec> specs = SceneViewSpecs(scene);
  ASSERT_EQ(specs.size(), 8u);
  const Eigen::Vector3d board_center =
      scene.board.Point(scene.board.origin) +
      0.5 * Eigen::Vector3d((scene.board.cols - 1) * scene.board.tile_size_m,
                            (scene.board.rows - 1) * scene.board.tile_size_m,
                            0);
  for (size_t i = 0; i < specs.size(); ++i) {
    EXPECT_NEAR(ViewAngleDeg(specs[i].cam_from_board, board_center),
                90.0 - 10.0 * i, 1e-9);
  }
}

TEST(ScenesTest, StrongFisheyeSeesCornersBeyondNinetyDegrees) {
  SceneSpec scene = StrongFisheyeScene(320, 240);
  scene.render.supersampling = 1;
  std::string why;
  const std::vector<SceneView> views = RenderScene(scene, &why);
  ASSERT_FALSE(views.empty()) << why;
  int beyond = 0;
  for (const SceneView& view : views) {
    for (const TruthCorner& c : view.truth.corners) {
      if (!c.visible) continue;
      const Eigen::Vector3d p =
          view.truth.cam_from_board * scene.board.Point(c.id);
      if (p.z() < 0) ++beyond;
    }
  }
  EXPECT_GT(beyond, 20);
}

TEST(ScenesTest, SmallTilesSpanFourToTwelvePixels) {
  const SceneSpec scene = SmallTilesScene(320, 240);
  const std::vector<SceneViewSpec> specs = SceneViewSpecs(scene);
  const std::vector<double> expected = {4, 5, 6, 8, 10, 12};
  ASSERT_EQ(specs.size(), expected.size());
  const Eigen::Vector2i center(scene.board.origin.x() + scene.board.cols / 2,
                               scene.board.origin.y() + scene.board.rows / 2);
  for (size_t i = 0; i < specs.size(); ++i) {
    Eigen::Vector2d a, b;
    ASSERT_TRUE(scene.camera.Project(
        specs[i].cam_from_board * scene.board.Point(center), &a));
    ASSERT_TRUE(scene.camera.Project(
        specs[i].cam_from_board *
            scene.board.Point(center + Eigen::Vector2i(1, 0)),
        &b));
    // Head on up to a 10-degree tilt and mild distortion: within 15 %.
    EXPECT_NEAR((b - a).norm(), expected[i], 0.15 * expected[i]);
  }
}

TEST(ScenesTest, RenderingIsDeterministic) {
  SceneSpec scene = WidePinholeScene(200, 150);
  scene.random_views.count = 2;
  const std::vector<SceneView> a = RenderScene(scene);
  const std::vector<SceneView> b = RenderScene(scene);
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(cv::norm(a[i].image, b[i].image, cv::NORM_INF), 0.0);
  }
}

TEST(ScenesTest, BadScenesSayWhy) {
  SceneSpec scene = WidePinholeScene(200, 150);
  scene.camera.params.pop_back();
  std::string why;
  EXPECT_TRUE(RenderScene(scene, &why).empty());
  EXPECT_NE(why.find("camera"), std::string::npos) << why;
  scene = WidePinholeScene(200, 150);
  scene.random_views.count = 0;
  EXPECT_FALSE(scene.Check(&why));
  EXPECT_NE(why.find("no views"), std::string::npos) << why;
  scene = TiltSeriesScene(200, 150);
  scene.tilt_series.view_angles_deg.push_back(95.0);
  EXPECT_FALSE(scene.Check(&why));
  EXPECT_NE(why.find("tilt_series"), std::string::npos) << why;
  // Names become file names: nothing that leaves the output folder.
  for (const std::string bad : {"../x", "a/b", ".hidden", ""}) {
    scene = WidePinholeScene(200, 150);
    scene.name = bad;
    EXPECT_FALSE(scene.Check(&why)) << bad;
    EXPECT_NE(why.find("name"), std::string::npos) << why;
  }
  scene = WidePinholeScene(200, 150);
  SceneViewSpec escaping;
  escaping.name = "../../escape";
  scene.views.insert(scene.views.begin(), escaping);
  EXPECT_FALSE(scene.Check(&why));
  EXPECT_NE(why.find("views[0].name"), std::string::npos) << why;
}

}  // namespace
}  // namespace puzzlecal
