// sim/rig_scenes: the exact correspondences agree with OpenCV's projection
// of the same board points through the composed poses, the standard rigs
// have the structure they promise, renders go to one folder per camera
// with the same file name for the same frame, and bad specs are refused by
// field.

#include "sim/rig_scenes.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

int Seen(const std::vector<RigCameraInput>& inputs, size_t c) {
  int seen = 0;
  for (const CalibrationView& view : inputs[c].frames) {
    seen += !view.board_points.empty();
  }
  return seen;
}

// cv::projectPoints / cv::fisheye::projectPoints of the board points of a
// view through cam_from_rig * rig_from_board.
std::vector<cv::Point2d> OpenCvProjection(
    const RigSceneCamera& cam, const Eigen::Isometry3d& rig_from_board,
    const CalibrationView& view) {
  const Eigen::Isometry3d pose = cam.cam_from_rig * rig_from_board;
  cv::Mat rotation, rvec, tvec;
  cv::eigen2cv(Eigen::Matrix3d(pose.linear()), rotation);
  cv::Rodrigues(rotation, rvec);
  cv::eigen2cv(Eigen::Vector3d(pose.translation()), tvec);
  const std::vector<double>& p = cam.camera.params;
  const cv::Matx33d k(p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
  std::vector<cv::Point3d> object;
  for (const Eigen::Vector3d& b : view.board_points) {
    object.emplace_back(b.x(), b.y(), b.z());
  }
  std::vector<cv::Point2d> pixels;
  if (cam.camera.model == CameraModelId::kKannalaBrandt) {
    cv::fisheye::projectPoints(object, pixels, rvec, tvec, k,
                               cv::Vec4d(p[4], p[5], p[6], p[7]));
  } else {
    const std::vector<double> d(p.begin() + 4, p.end());
    cv::projectPoints(object, rvec, tvec, k, d, pixels);
  }
  return pixels;
}

TEST(RigScenesTest, CorrespondencesMatchOpenCvProjection) {
  for (const RigSceneSpec& scene :
       {StereoPinholeRig(), FisheyePinholeRig(), FourCameraRig()}) {
    SCOPED_TRACE(scene.name);
    const std::vector<Eigen::Isometry3d> frames = RigFramePoses(scene);
    const std::vector<RigCameraInput> inputs = RigCorrespondences(scene, 0.0);
    ASSERT_EQ(inputs.size(), scene.cameras.size());
    int checked = 0;
    for (size_t c = 0; c < inputs.size(); ++c) {
      EXPECT_EQ(inputs[c].name, scene.cameras[c].name);
      EXPECT_EQ(inputs[c].model, scene.cameras[c].camera.model);
      ASSERT_EQ(inputs[c].frames.size(), frames.size());
      for (size_t f = 0; f < frames.size(); ++f) {
        const CalibrationView& view = inputs[c].frames[f];
        if (view.board_points.empty()) continue;
        EXPECT_GE(static_cast<int>(view.board_points.size()),
                  scene.min_visible_corners);
        // OpenCV's fisheye divides by z first: compare in front of the
        // lens only.
        const std::vector<cv::Point2d> expected =
            OpenCvProjection(scene.cameras[c], frames[f], view);
        for (size_t i = 0; i < view.board_points.size(); ++i) {
          const Eigen::Vector3d p =
              scene.cameras[c].cam_from_rig * frames[f] * view.board_points[i];
          if (p.z() < 0.2 * p.norm()) continue;
          EXPECT_NEAR(view.image_points[i].x(), expected[i].x, 1e-6);
          EXPECT_NEAR(view.image_points[i].y(), expected[i].y, 1e-6);
          EXPECT_GE(view.image_points[i].x(), 0);
          EXPECT_LE(view.image_points[i].x(), inputs[c].width - 1);
          ++checked;
        }
      }
    }
    EXPECT_GT(checked, 1000);
  }
}

TEST(RigScenesTest, NoiseHasTheRequestedSigmaAndIsSeeded) {
  const RigSceneSpec scene = StereoPinholeRig();
  const std::vector<RigCameraInput> exact = RigCorrespondences(scene, 0.0);
  const std::vector<RigCameraInput> noisy = RigCorrespondences(scene, 0.2, 5);
  const std::vector<RigCameraInput> again = RigCorrespondences(scene, 0.2, 5);
  double sum2 = 0;
  int n = 0;
  for (size_t c = 0; c < 2; ++c) {
    for (size_t f = 0; f < exact[c].frames.size(); ++f) {
      EXPECT_EQ(noisy[c].frames[f].image_points,
                again[c].frames[f].image_points);
      for (size_t i = 0; i < exact[c].frames[f].image_points.size(); ++i) {
        sum2 += (noisy[c].frames[f].image_points[i] -
                 exact[c].frames[f].image_points[i])
                    .squaredNorm();
        n += 2;
      }
    }
  }
  ASSERT_GT(n, 1000);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.2, 0.01);
}

TEST(RigScenesTest, StandardRigsHaveTheirStructure) {
  // The fisheye + pinhole rig: the pinhole is turned 50 degrees away and
  // some frames only the fisheye sees.
  const RigSceneSpec mixed = FisheyePinholeRig();
  EXPECT_NEAR(
      Eigen::AngleAxisd(mixed.cameras[1].cam_from_rig.linear()).angle() * 180 /
          M_PI,
      50.0, 1e-9);
  const std::vector<RigCameraInput> inputs = RigCorrespondences(mixed, 0.0);
  int only_one = 0, both = 0;
  for (size_t f = 0; f < inputs[0].frames.size(); ++f) {
    const bool a = !inputs[0].frames[f].board_points.empty();
    const bool b = !inputs[1].frames[f].board_points.empty();
    only_one += a != b;
    both += a && b;
  }
  EXPECT_GT(only_one, 0);
  EXPECT_GT(both, 10);
  // Four cameras, three models; the +100 degree camera never sees a frame
  // with the -50 degree one.
  const RigSceneSpec four = FourCameraRig();
  ASSERT_EQ(four.cameras.size(), 4u);
  EXPECT_EQ(four.cameras[0].camera.model, CameraModelId::kKannalaBrandt);
  EXPECT_EQ(four.cameras[2].camera.model, CameraModelId::kPinholeRational);
  const std::vector<RigCameraInput> four_inputs = RigCorrespondences(four, 0.0);
  for (size_t c = 0; c < 4; ++c) EXPECT_GT(Seen(four_inputs, c), 5);
  int shared_1_3 = 0, shared_2_3 = 0;
  for (size_t f = 0; f < four_inputs[0].frames.size(); ++f) {
    const bool s1 = !four_inputs[1].frames[f].board_points.empty();
    const bool s2 = !four_inputs[2].frames[f].board_points.empty();
    const bool s3 = !four_inputs[3].frames[f].board_points.empty();
    shared_1_3 += s1 && s3;
    shared_2_3 += s2 && s3;
  }
  EXPECT_GT(shared_1_3, 3);
  EXPECT_EQ(shared_2_3, 0);
}

TEST(RigScenesTest, RendersOneFolderPerCameraWithFrameNames) {
  RigSceneSpec scene = FisheyePinholeRig(320, 240);
  scene.random_frames.count = 8;
  scene.render.supersampling = 2;
  const fs::path dir = fs::temp_directory_path() /
                       ("puzzlecal_rig_scenes_test_" + std::to_string(getpid()));
  fs::remove_all(dir);
  RigRenderSummary summary;
  std::string why;
  ASSERT_TRUE(RenderRigScene(scene, dir.string(), &summary, &why)) << why;
  EXPECT_EQ(summary.num_frames, 8);
  const std::vector<RigCameraInput> inputs = RigCorrespondences(scene, 0.0);
  for (size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(summary.images_per_camera[c], Seen(inputs, c));
    for (int f = 0; f < 8; ++f) {
      const fs::path file = dir / scene.cameras[c].name / RigFrameFileName(f);
      EXPECT_EQ(fs::exists(file), !inputs[c].frames[f].board_points.empty())
          << file;
      if (!fs::exists(file)) continue;
      const cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
      EXPECT_EQ(image.cols, 320);
      EXPECT_EQ(image.rows, 240);
      EXPECT_EQ(image.type(), CV_8UC1);
    }
  }
}

TEST(RigScenesTest, CheckNamesTheField) {
  std::string why;
  RigSceneSpec scene = StereoPinholeRig();
  EXPECT_TRUE(scene.Check(&why)) << why;
  scene.cameras[1].name = "cam0";
  EXPECT_FALSE(scene.Check(&why));
  EXPECT_NE(why.find("cameras[1].name"), std::string::npos) << why;
  scene = StereoPinholeRig();
  scene.cameras[0].cam_from_rig.translation().x() = 0.1;
  EXPECT_FALSE(scene.Check(&why));
  EXPECT_NE(why.find("cameras[0].cam_from_rig"), std::string::npos) << why;
  scene = StereoPinholeRig();
  scene.random_frames.aim_cameras = {2};
  EXPECT_FALSE(scene.Check(&why));
  EXPECT_NE(why.find("aim_cameras"), std::string::npos) << why;
  RigRenderSummary summary;
  EXPECT_FALSE(RenderRigScene(scene, "/nonexistent", &summary, &why));
}

}  // namespace
}  // namespace puzzlecal
