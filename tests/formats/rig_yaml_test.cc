// Rig files: the puzzlecal format read back, the opencv format read by
// cv::FileStorage (its rectification checked on projected points), ros
// camera_info files read by the camera-file reader, kalibr's camchain.

#include "formats/rig_yaml.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>

#include "formats/camera_yaml.h"
#include "sim/rig_scenes.h"
#include "sim/scenes.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// A result holding the truth of a sim rig (no calibration needed to test
// the writers).
RigCalibrationResult ResultFromScene(const RigSceneSpec& scene) {
  RigCalibrationResult result;
  const size_t n = scene.cameras.size();
  for (size_t c = 0; c < n; ++c) {
    RigCameraResult cam;
    cam.name = scene.cameras[c].name;
    cam.camera = scene.cameras[c].camera;
    cam.cam_from_rig = scene.cameras[c].cam_from_rig;
    cam.param_stddev.assign(cam.camera.params.size(), 0.01);
    cam.param_fixed.assign(cam.camera.params.size(), false);
    cam.rotation_stddev_deg = 0.002;
    cam.baseline_m =
        (cam.cam_from_rig.linear().transpose() * cam.cam_from_rig.translation())
            .norm();
    result.cameras.push_back(cam);
  }
  result.covariance_ok = true;
  result.shared_frames = Eigen::MatrixXi::Constant(n, n, 3);
  result.shared_frames(0, n - 1) = result.shared_frames(n - 1, 0) = 0;
  return result;
}

std::string TempPath(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("puzzlecal_rig_yaml_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

Eigen::MatrixXd ReadMatrix(const cv::FileStorage& fs, const char* key) {
  cv::Mat m;
  fs[key] >> m;
  Eigen::MatrixXd e;
  cv::cv2eigen(m, e);
  return e;
}

TEST(RigYamlTest, PuzzlecalFormatReadsBack) {
  const RigCalibrationResult result = ResultFromScene(FourCameraRig());
  const std::string path = TempPath("rig.yaml");
  std::string error;
  ASSERT_TRUE(WriteRigFiles(path, CameraFileFormat::kPuzzlecal, result, nullptr,
                            &error))
      << error;
  std::vector<RigFileCamera> cameras;
  ASSERT_TRUE(ReadRigFile(path, &cameras, &error)) << error;
  ASSERT_EQ(cameras.size(), 4u);
  for (size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(cameras[c].name, result.cameras[c].name);
    EXPECT_EQ(cameras[c].camera.model, result.cameras[c].camera.model);
    EXPECT_EQ(cameras[c].camera.width, result.cameras[c].camera.width);
    EXPECT_EQ(cameras[c].camera.params, result.cameras[c].camera.params);
    EXPECT_TRUE(cameras[c].cam_from_rig.matrix().isApprox(
        result.cameras[c].cam_from_rig.matrix(), 1e-15));
  }
  // Named parameters and their standard deviations, as in a camera file.
  const YAML::Node root = YAML::LoadFile(path);
  EXPECT_DOUBLE_EQ(root["cameras"][1]["parameters"]["fx"].as<double>(),
                   result.cameras[1].camera.params[0]);
  EXPECT_DOUBLE_EQ(root["cameras"][1]["parameter_stddev"]["k1"].as<double>(),
                   0.01);
  EXPECT_EQ(root["cameras"][2]["model"].as<std::string>(), "pinhole-rational");
}

TEST(RigYamlTest, PuzzlecalReaderNamesTheBadField) {
  const RigCalibrationResult result = ResultFromScene(StereoPinholeRig());
  std::vector<RigFileText> files;
  std::string error;
  ASSERT_TRUE(FormatRigFiles(result, CameraFileFormat::kPuzzlecal, "rig.yaml",
                             &files, &error));
  YAML::Node root = YAML::Load(files[0].text);
  root["cameras"][1]["cam_from_rig"]["R"][0][0] = 3.0;
  std::vector<RigFileCamera> cameras;
  EXPECT_FALSE(ParseRigFile(YAML::Dump(root), "bad.yaml", &cameras, &error));
  EXPECT_NE(error.find("bad.yaml"), std::string::npos) << error;
  EXPECT_NE(error.find("field 'cameras[1].cam_from_rig.R': not a rotation"),
            std::string::npos)
      << error;
  root = YAML::Load(files[0].text);
  root["cameras"][0].remove("cam_from_rig");
  EXPECT_FALSE(ParseRigFile(YAML::Dump(root), "bad.yaml", &cameras, &error));
  EXPECT_NE(error.find("field 'cameras[0].cam_from_rig': missing"),
            std::string::npos)
      << error;
  // A camera's own fields are named under its entry.
  root = YAML::Load(files[0].text);
  root["cameras"][1]["parameters"].remove("fx");
  EXPECT_FALSE(ParseRigFile(YAML::Dump(root), "bad.yaml", &cameras, &error));
  EXPECT_NE(error.find("bad.yaml: field 'cameras[1].parameters.fx': missing"),
            std::string::npos)
      << error;
  EXPECT_FALSE(ParseRigFile("a: [", "broken.yaml", &cameras, &error));
  EXPECT_NE(error.find("broken.yaml"), std::string::npos) << error;
}

// The rectification of an opencv file: a point seen by both cameras lands
// on the same rectified row, and the essential and fundamental matrices
// hold for its (undistorted) projections.
void ExpectRectifies(const RigSceneSpec& scene, const std::string& path) {
  cv::FileStorage fs(path, cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  EXPECT_EQ(static_cast<std::string>(fs["name2"]), scene.cameras[1].name);
  const Eigen::Matrix3d r = ReadMatrix(fs, "R");
  const Eigen::Vector3d t = ReadMatrix(fs, "T");
  const Eigen::Isometry3d& expected = scene.cameras[1].cam_from_rig;
  EXPECT_TRUE(r.isApprox(expected.linear(), 1e-12));
  EXPECT_TRUE(t.isApprox(expected.translation(), 1e-12));
  const Eigen::Matrix3d k1 = ReadMatrix(fs, "K1"), k2 = ReadMatrix(fs, "K2");
  EXPECT_DOUBLE_EQ(k2(0, 0), scene.cameras[1].camera.params[0]);
  const Eigen::MatrixXd d2 = ReadMatrix(fs, "D2");
  EXPECT_EQ(d2.size(), static_cast<int>(scene.cameras[1].camera.params.size()) -
                           kDistortionBegin);
  const Eigen::Matrix3d e = ReadMatrix(fs, "E"), f = ReadMatrix(fs, "F");
  const Eigen::Matrix3d r1 = ReadMatrix(fs, "R1"), r2 = ReadMatrix(fs, "R2");
  const Eigen::MatrixXd p1 = ReadMatrix(fs, "P1"), p2 = ReadMatrix(fs, "P2");
  const Eigen::Matrix4d q = ReadMatrix(fs, "Q");
  // Points in front of both cameras.
  for (const Eigen::Vector3d& x :
       {Eigen::Vector3d(0.1, -0.05, 1.0), Eigen::Vector3d(-0.2, 0.1, 1.5),
        Eigen::Vector3d(0.3, 0.2, 0.8)}) {
    const Eigen::Vector3d x2 = r * x + t;
    const Eigen::Vector3d a = p1 * (r1 * x).homogeneous();
    // P2 takes points in the first rectified frame; R2 turns the second
    // camera's frame into its own rectified frame (offset by the baseline).
    const Eigen::Vector3d b = p2 * (r1 * x).homogeneous();
    const Eigen::Vector2d pa = a.hnormalized(), pb = b.hnormalized();
    EXPECT_LT((pb - (p2.leftCols<3>() * r2 * x2).hnormalized()).norm(), 1e-6);
    EXPECT_NEAR(pa.y(), pb.y(), 1e-6);
    // Q maps (x, y, disparity) back to the point in the rectified frame.
    const Eigen::Vector4d back =
        q * Eigen::Vector4d(pa.x(), pa.y(), pa.x() - pb.x(), 1.0);
    EXPECT_LT((back.hnormalized() - r1 * x).norm(), 1e-6);
    const Eigen::Vector3d n1 = x / x.z(), n2 = x2 / x2.z();
    EXPECT_NEAR(n2.dot(e * n1), 0, 1e-12);
    EXPECT_NEAR((k2 * n2).dot(f * (k1 * n1)), 0, 1e-9);
  }
}

TEST(RigYamlTest, OpenCvFormatOfAPinholePairRectifies) {
  const RigSceneSpec scene = StereoPinholeRig();
  const std::string path = TempPath("stereo_opencv.yaml");
  std::string error;
  ASSERT_TRUE(WriteRigFiles(path, CameraFileFormat::kOpenCv,
                            ResultFromScene(scene), nullptr, &error))
      << error;
  ExpectRectifies(scene, path);
}

TEST(RigYamlTest, OpenCvFormatOfAFisheyePairRectifies) {
  RigSceneSpec scene = StereoPinholeRig();
  for (RigSceneCamera& cam : scene.cameras) {
    cam.camera = FisheyeLensCamera(640, 480, 180.0);
  }
  const std::string path = TempPath("fisheye_opencv.yaml");
  std::string error;
  ASSERT_TRUE(WriteRigFiles(path, CameraFileFormat::kOpenCv,
                            ResultFromScene(scene), nullptr, &error))
      << error;
  ExpectRectifies(scene, path);
  // A pinhole target of the stated field (cv::fisheye::stereoRectify's
  // defaults give a focal length of a few pixels on a 180-degree lens).
  cv::FileStorage fs(path, cv::FileStorage::READ);
  const Eigen::MatrixXd p1 = ReadMatrix(fs, "P1");
  EXPECT_NEAR(p1(0, 0), 319.5 / std::tan(60 * M_PI / 180), 1.0);
  const std::string note = fs["rectification"];
  EXPECT_NE(note.find("field 120.0"), std::string::npos) << note;
}

// A fisheye next to a pinhole turned 50 degrees away: the common field lies
// off the rectified axis; the target keeps it (a sane focal length, both
// cameras cover their rectified images) instead of a few-pixel focal length.
TEST(RigYamlTest, OpenCvFormatOfADivergingFisheyePinholePairRectifies) {
  const RigSceneSpec scene = FisheyePinholeRig(1280, 960);
  const std::string path = TempPath("fisheye_pinhole_opencv.yaml");
  std::string error;
  ASSERT_TRUE(WriteRigFiles(path, CameraFileFormat::kOpenCv,
                            ResultFromScene(scene), nullptr, &error))
      << error;
  ExpectRectifies(scene, path);
  StereoRectification rect;
  ASSERT_TRUE(StereoRectify(scene.cameras[0].camera, scene.cameras[1].camera,
                            scene.cameras[1].cam_from_rig, &rect, &error))
      << error;
  EXPECT_TRUE(rect.own_target);
  EXPECT_GT(rect.p1(0, 0), 0.5 * scene.cameras[1].camera.params[0]);
  EXPECT_LT(rect.p1(0, 0), 2.0 * scene.cameras[1].camera.params[0]);
  EXPECT_GT(rect.valid_fraction[0], 0.5);
  EXPECT_GT(rect.valid_fraction[1], 0.5);
  EXPECT_LT(rect.max_row_difference_px, 1e-3);
}

// A pinhole pair whose fitted distortion folds over inside the image (a
// strong k1 alone, as a fit to central corners gives): cv::stereoRectify's
// crop to the undistorted border follows a border that is not there; the
// target chosen here keeps the whole common view, centred.
TEST(RigYamlTest, OpenCvFormatOfAFoldingPinholePairRectifiesTheWholeView) {
  RigSceneSpec scene = StereoPinholeRig();
  for (RigSceneCamera& cam : scene.cameras) {
    for (size_t k = kDistortionBegin; k < cam.camera.params.size(); ++k) {
      cam.camera.params[k] = 0;
    }
    cam.camera.params[kDistortionBegin] = -0.6;  // folds at r^2 = 1 / 1.8
  }
  ASSERT_GT(BorderFractionWithoutRay(scene.cameras[1].camera), 0.0);
  const std::string path = TempPath("folding_opencv.yaml");
  std::string error;
  ASSERT_TRUE(WriteRigFiles(path, CameraFileFormat::kOpenCv,
                            ResultFromScene(scene), nullptr, &error))
      << error;
  ExpectRectifies(scene, path);
  StereoRectification rect;
  ASSERT_TRUE(StereoRectify(scene.cameras[0].camera, scene.cameras[1].camera,
                            scene.cameras[1].cam_from_rig, &rect, &error))
      << error;
  EXPECT_TRUE(rect.own_target);
  EXPECT_NE(rect.own_target_reason.find("folds over"), std::string::npos)
      << rect.own_target_reason;
  const Camera& camera = scene.cameras[0].camera;
  EXPECT_GT(rect.p1(0, 0), 0.5 * camera.params[0]);
  EXPECT_LT(rect.p1(0, 0), 1.2 * camera.params[0]);
  EXPECT_NEAR(rect.p1(0, 2), 0.5 * (camera.width - 1), 0.15 * camera.width);
  EXPECT_NEAR(rect.p1(1, 2), 0.5 * (camera.height - 1), 1e-9);
  EXPECT_GT(rect.valid_fraction[0], 0.8);
  EXPECT_GT(rect.valid_fraction[1], 0.8);
}

TEST(RigYamlTest, RosFormatWritesOneCameraInfoPerCamera) {
  const RigSceneSpec scene = StereoPinholeRig();
  const RigCalibrationResult result = ResultFromScene(scene);
  const std::string path = TempPath("stereo_ros.yaml");
  std::vector<std::string> written;
  std::string error;
  ASSERT_TRUE(
      WriteRigFiles(path, CameraFileFormat::kRos, result, &written, &error))
      << error;
  ASSERT_EQ(written.size(), 2u);
  EXPECT_EQ(fs::path(written[1]).filename(), "stereo_ros_cam1.yaml");
  StereoRectification rect;
  ASSERT_TRUE(StereoRectify(scene.cameras[0].camera, scene.cameras[1].camera,
                            scene.cameras[1].cam_from_rig, &rect, &error));
  for (int c = 0; c < 2; ++c) {
    Camera camera;
    ASSERT_TRUE(ReadCameraFile(written[c], &camera, &error)) << error;
    EXPECT_EQ(camera.params, scene.cameras[c].camera.params);
    const YAML::Node root = YAML::LoadFile(written[c]);
    EXPECT_EQ(root["camera_name"].as<std::string>(), scene.cameras[c].name);
    const std::vector<double> r =
        root["rectification_matrix"]["data"].as<std::vector<double>>();
    const std::vector<double> p =
        root["projection_matrix"]["data"].as<std::vector<double>>();
    const Eigen::Matrix3d& expected_r = c == 0 ? rect.r1 : rect.r2;
    const Eigen::Matrix<double, 3, 4>& expected_p = c == 0 ? rect.p1 : rect.p2;
    for (int i = 0; i < 9; ++i)
      EXPECT_DOUBLE_EQ(r[i], expected_r(i / 3, i % 3));
    for (int i = 0; i < 12; ++i) {
      EXPECT_DOUBLE_EQ(p[i], expected_p(i / 4, i % 4));
    }
  }
  // The second camera's P carries the baseline: P2(0, 3) = -fx' * baseline.
  EXPECT_NEAR(-rect.p2(0, 3) / rect.p2(0, 0),
              scene.cameras[1].cam_from_rig.translation().norm(), 1e-9);
}

TEST(RigYamlTest, KalibrFormatChainsNeighbours) {
  const RigSceneSpec scene = FourCameraRig();
  RigCalibrationResult result = ResultFromScene(scene);
  // Kalibr has no rational model: a rational camera with k4..k6 is refused
  // by name.
  std::vector<RigFileText> files;
  std::string error;
  EXPECT_FALSE(FormatRigFiles(result, CameraFileFormat::kKalibr, "chain.yaml",
                              &files, &error));
  EXPECT_NE(error.find("'cam2'"), std::string::npos) << error;
  result.cameras[2].camera.model = CameraModelId::kPinholeRadtan;
  result.cameras[2].camera.params.resize(9);
  ASSERT_TRUE(FormatRigFiles(result, CameraFileFormat::kKalibr, "chain.yaml",
                             &files, &error))
      << error;
  const YAML::Node root = YAML::Load(files[0].text);
  for (int c = 1; c < 4; ++c) {
    const std::string key = "cam" + std::to_string(c);
    const Eigen::Matrix4d expected =
        (scene.cameras[c].cam_from_rig *
         scene.cameras[c - 1].cam_from_rig.inverse())
            .matrix();
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        EXPECT_NEAR(root[key]["T_cn_cnm1"][i][j].as<double>(), expected(i, j),
                    1e-15);
      }
    }
    EXPECT_EQ(root[key]["rostopic"].as<std::string>(),
              "/" + scene.cameras[c].name + "/image_raw");
  }
  EXPECT_FALSE(root["cam0"]["T_cn_cnm1"]);
  EXPECT_EQ(root["cam0"]["distortion_model"].as<std::string>(), "equidistant");
  // Camera 0 and 3 share no frame in this result.
  EXPECT_EQ(root["cam0"]["cam_overlaps"].as<std::vector<int>>(),
            (std::vector<int>{1, 2}));
}

}  // namespace
}  // namespace puzzlecal
