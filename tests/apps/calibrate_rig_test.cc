// `puzzlecal calibrate-rig` end to end on rig renders (sim/rig_scenes.h):
// detection, decoding and the rig calibration against the exact truth, the
// output formats, the report, and the refusals. The program is the one
// built beside this test (<build>/apps/puzzlecal).

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "apps/subcommand.h"
#include "calib/rig_calibration.h"
#include "formats/rig_yaml.h"
#include "sim/rig_scenes.h"
#include "tests/support/files.h"
#include "tests/support/program_run.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using testing_files::ReadFile;
using testing_program::ProgramPath;
using testing_program::ProgramRun;

constexpr double kMaxRotationErrorDeg = 0.005;
constexpr double kMaxTranslationErrorOfBaseline = 0.001;
constexpr double kMaxFocalRelativeError = 0.0005;

// A folder of this test process's own: ctest runs the test cases as
// separate processes at the same time.
fs::path ScratchRoot() {
  return fs::temp_directory_path() /
         ("puzzlecal_rig_test_" + std::to_string(getpid()));
}

// This process's folder goes when its tests are done.
[[maybe_unused]] const ::testing::Environment* const kRigScratchCleanup =
    ::testing::AddGlobalTestEnvironment(
        new testing_program::RemoveAtEnd(ScratchRoot()));

ProgramRun RunProgram(const std::string& arguments) {
  return testing_program::RunProgram(arguments, ScratchRoot());
}

std::string WriteBoardFile(const Board& board, const fs::path& dir) {
  const fs::path path = dir / "board.yaml";
  std::ofstream out(path);
  out << "type: puzzleboard\ncols: " << board.cols << "\nrows: " << board.rows
      << "\norigin: [" << board.origin.x() << ", " << board.origin.y()
      << "]\ntile_size_m: " << board.tile_size_m << "\n";
  return path.string();
}

// A rendered rig in a fresh temporary folder: images/<camera>/frame_NNN.png
// and board.yaml.
struct RenderedRig {
  RigSceneSpec scene;
  fs::path root;
  fs::path images;
  std::string board;
  RigRenderSummary summary;
};

RenderedRig Render(const RigSceneSpec& scene, const std::string& name) {
  RenderedRig rig;
  rig.scene = scene;
  rig.root = ScratchRoot() / name;
  fs::remove_all(rig.root);
  rig.images = rig.root / "images";
  std::string why;
  EXPECT_TRUE(RenderRigScene(scene, rig.images.string(), &rig.summary, &why))
      << why;
  rig.board = WriteBoardFile(scene.board, rig.root);
  return rig;
}

void ExpectMatchesTruth(const RigSceneSpec& scene,
                        const std::vector<RigFileCamera>& cameras) {
  ASSERT_EQ(cameras.size(), scene.cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    SCOPED_TRACE("camera " + scene.cameras[c].name);
    EXPECT_EQ(cameras[c].name, scene.cameras[c].name);
    const Camera& truth = scene.cameras[c].camera;
    for (int k = 0; k < 2; ++k) {
      EXPECT_LT(std::abs(cameras[c].camera.params[k] - truth.params[k]),
                kMaxFocalRelativeError * truth.params[k])
          << cameras[c].camera.params[k] << " vs " << truth.params[k];
    }
    const Eigen::Isometry3d& expected = scene.cameras[c].cam_from_rig;
    const double rotation_error = RotationDifferenceDeg(
        cameras[c].cam_from_rig.linear(), expected.linear());
    const double baseline =
        (expected.linear().transpose() * expected.translation()).norm();
    const double translation_error =
        (cameras[c].cam_from_rig.translation() - expected.translation()).norm();
    std::cout << scene.cameras[c].name << ": rotation error " << rotation_error
              << " deg, translation error " << translation_error * 1000
              << " mm of " << baseline * 1000 << " mm, fx error "
              << cameras[c].camera.params[0] - truth.params[0] << " px\n";
    EXPECT_LT(rotation_error, kMaxRotationErrorDeg);
    EXPECT_LE(translation_error, kMaxTranslationErrorOfBaseline * baseline);
  }
}

// The line of the program's output that starts with `prefix` ("" if none).
std::string OutputLine(const std::string& output, const std::string& prefix) {
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(prefix, 0) == 0) return line;
  }
  return "";
}

// Each camera's own calibration gets the single-camera verdict: the same
// line on the output and in summary.md (at the top and in the camera's
// section), with the camera's figures from the rig file and its evidence
// charts, each a drawn PNG.
void ExpectReportJudgesEachCamera(const RigSceneSpec& scene,
                                  const std::string& output,
                                  const YAML::Node& rig_file,
                                  const fs::path& report) {
  const std::string summary = ReadFile(report / "summary.md");
  ASSERT_FALSE(summary.empty()) << "no " << (report / "summary.md");
  const size_t first_section = summary.find("\n## ");
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    const std::string& name = scene.cameras[c].name;
    SCOPED_TRACE("camera " + name);
    const std::string line = OutputLine(output, name + ": verdict: ");
    ASSERT_FALSE(line.empty()) << output;
    EXPECT_LT(summary.find("- " + line + "\n"), first_section) << summary;
    const size_t begin = summary.find("\n## Camera " + name + "\n");
    ASSERT_NE(begin, std::string::npos) << summary;
    const std::string section =
        summary.substr(begin, summary.find("\n## ", begin + 1) - begin);
    EXPECT_NE(section.find("**" + line + "**"), std::string::npos) << section;
    const YAML::Node cam = rig_file["cameras"][c];
    ASSERT_EQ(cam["name"].as<std::string>(), name);
    const std::string rms =
        StringPrintf("| RMS reprojection error (px per coordinate) | %.4f |",
                     cam["rms_px"].as<double>());
    EXPECT_NE(section.find(rms), std::string::npos) << rms << "\n" << section;
    EXPECT_NE(section.find(StringPrintf("| corners used | %d |",
                                        cam["corners_used"].as<int>())),
              std::string::npos)
        << section;
    EXPECT_NE(section.find(
                  StringPrintf("| outliers | %d |", cam["outliers"].as<int>())),
              std::string::npos)
        << section;
    for (const char* chart :
         {"_cross_validation.png", "_uncertainty.png", "_residual_bins.png"}) {
      const std::string file = name + chart;
      EXPECT_NE(section.find("](" + file + ")"), std::string::npos)
          << file << " not linked\n"
          << section;
      const cv::Mat image = cv::imread((report / file).string());
      ASSERT_FALSE(image.empty()) << file;
      cv::Scalar mean, stddev;
      cv::meanStdDev(image, mean, stddev);
      EXPECT_GT(stddev[0], 5) << file << " is blank";
    }
  }
}

TEST(CalibrateRigTest, FisheyeAndPinholeRendersMeetTheFigures) {
  // 1280 x 960: at 640 x 480 the fisheye's focal length is 137 px (1 px =
  // 0.4 degrees) and its rotation sigma alone is 0.009 degrees.
  const RenderedRig rig =
      Render(FisheyePinholeRig(1280, 960), "fisheye_pinhole");
  ASSERT_EQ(rig.summary.images_per_camera.size(), 2u);
  EXPECT_GT(rig.summary.frames_seen_by_one_camera, 0);
  const fs::path out = rig.root / "rig.yaml";
  const fs::path report = rig.root / "report";
  const ProgramRun run = RunProgram(
      "calibrate-rig --images " + rig.images.string() + " --board " +
      rig.board + " --model kannala-brandt,pinhole-radtan --out " +
      out.string() + " --report " + report.string() + " --threads 2");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  std::vector<RigFileCamera> cameras;
  std::string error;
  ASSERT_TRUE(ReadRigFile(out.string(), &cameras, &error)) << error;
  ExpectMatchesTruth(rig.scene, cameras);
  ExpectReportJudgesEachCamera(rig.scene, run.all(), YAML::LoadFile(out),
                               report);
  const cv::Mat pair = cv::imread((report / "rectified_pair.png").string());
  EXPECT_EQ(pair.cols, 2 * 1280);
  EXPECT_EQ(pair.rows, 960);
  std::cout << run.all();
}

// One camera of a rectification file as a user reads it: K, D, R, P.
struct RectifiedCamera {
  bool fisheye = false;
  cv::Mat k, d, r, p;
  int width = 0, height = 0;
};

// Rectifies `pixels` through OpenCV's own undistortion (not puzzlecal's).
std::vector<cv::Point2d> OpenCvRectify(const RectifiedCamera& cam,
                                       const std::vector<cv::Point2d>& pixels) {
  std::vector<cv::Point2d> out;
  if (pixels.empty()) return out;
  if (cam.fisheye) {
    cv::fisheye::undistortPoints(pixels, out, cam.k, cam.d, cam.r, cam.p);
  } else {
    cv::undistortPoints(pixels, out, cam.k, cam.d, cam.r, cam.p);
  }
  return out;
}

// Share of the rectified image whose pixel maps into the camera's image
// (OpenCV's own rectification maps).
double OpenCvValidFraction(const RectifiedCamera& cam) {
  cv::Mat map_x, map_y;
  const cv::Size size(cam.width, cam.height);
  if (cam.fisheye) {
    cv::fisheye::initUndistortRectifyMap(cam.k, cam.d, cam.r, cam.p, size,
                                         CV_32FC1, map_x, map_y);
  } else {
    cv::initUndistortRectifyMap(cam.k, cam.d, cam.r, cam.p, size, CV_32FC1,
                                map_x, map_y);
  }
  int inside = 0;
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      const float x = map_x.at<float>(v, u), y = map_y.at<float>(v, u);
      inside += x >= 0 && y >= 0 && x <= cam.width - 1 && y <= cam.height - 1;
    }
  }
  return static_cast<double>(inside) / (size.width * size.height);
}

// The scene's own corners (exact projections), matched by board point in
// every frame both cameras see, rectified with the file's matrices by
// OpenCV: the median row difference is at most 0.1 px, and each camera
// covers a non-empty part of its rectified image.
void ExpectFileRectifiesOwnCorners(const RigSceneSpec& scene,
                                   const RectifiedCamera& first,
                                   const RectifiedCamera& second) {
  const std::vector<RigCameraInput> views = RigCorrespondences(scene, 0.0);
  std::vector<double> rows;
  for (size_t f = 0; f < views[0].frames.size(); ++f) {
    const CalibrationView& a = views[0].frames[f];
    const CalibrationView& b = views[1].frames[f];
    std::vector<cv::Point2d> pa, pb;
    for (size_t i = 0; i < a.board_points.size(); ++i) {
      for (size_t j = 0; j < b.board_points.size(); ++j) {
        if ((a.board_points[i] - b.board_points[j]).norm() > 1e-9) continue;
        pa.emplace_back(a.image_points[i].x(), a.image_points[i].y());
        pb.emplace_back(b.image_points[j].x(), b.image_points[j].y());
      }
    }
    const std::vector<cv::Point2d> ra = OpenCvRectify(first, pa);
    const std::vector<cv::Point2d> rb = OpenCvRectify(second, pb);
    for (size_t i = 0; i < ra.size(); ++i) {
      rows.push_back(std::abs(ra[i].y - rb[i].y));
    }
  }
  ASSERT_GT(rows.size(), 50u);
  std::nth_element(rows.begin(), rows.begin() + rows.size() / 2, rows.end());
  const double median = rows[rows.size() / 2];
  const double valid1 = OpenCvValidFraction(first);
  const double valid2 = OpenCvValidFraction(second);
  std::cout << "rectified rows of " << rows.size()
            << " corner pairs: median difference " << median
            << " px; valid region " << valid1 << ", " << valid2 << "\n";
  EXPECT_LE(median, 0.1);
  EXPECT_GT(valid1, 0.05);
  EXPECT_GT(valid2, 0.05);
}

RectifiedCamera ReadOpenCvCamera(const cv::FileStorage& storage, int n,
                                 bool fisheye, int width, int height) {
  RectifiedCamera cam;
  const std::string i = std::to_string(n);
  storage["K" + i] >> cam.k;
  storage["D" + i] >> cam.d;
  storage["R" + i] >> cam.r;
  storage["P" + i] >> cam.p;
  cam.fisheye = fisheye;
  cam.width = width;
  cam.height = height;
  return cam;
}

cv::Mat RosMatrix(const YAML::Node& node, int rows, int cols) {
  const std::vector<double> data = node["data"].as<std::vector<double>>();
  cv::Mat m(rows, cols, CV_64F);
  for (int k = 0; k < rows * cols; ++k)
    m.at<double>(k / cols, k % cols) = data[k];
  return m;
}

RectifiedCamera ReadRosCamera(const fs::path& path, bool fisheye) {
  const YAML::Node root = YAML::LoadFile(path.string());
  RectifiedCamera cam;
  cam.k = RosMatrix(root["camera_matrix"], 3, 3);
  const int n =
      static_cast<int>(root["distortion_coefficients"]["data"].size());
  cam.d = RosMatrix(root["distortion_coefficients"], 1, n);
  cam.r = RosMatrix(root["rectification_matrix"], 3, 3);
  cam.p = RosMatrix(root["projection_matrix"], 3, 4);
  cam.fisheye = fisheye;
  cam.width = root["image_width"].as<int>();
  cam.height = root["image_height"].as<int>();
  return cam;
}

TEST(CalibrateRigTest, FisheyePairFilesRectifyTheirOwnCorners) {
  const RenderedRig rig = Render(StereoFisheyeRig(), "fisheye_pair");
  for (const char* format : {"opencv", "ros"}) {
    SCOPED_TRACE(format);
    const fs::path out = rig.root / (std::string(format) + ".yaml");
    const fs::path report = rig.root / (std::string(format) + "_report");
    const ProgramRun run = RunProgram(
        "calibrate-rig --images " + rig.images.string() + " --board " +
        rig.board + " --model kannala-brandt --format " + format + " --out " +
        out.string() + " --threads 2" +
        (std::string(format) == "opencv" ? " --report " + report.string()
                                         : std::string()));
    ASSERT_EQ(run.exit_code, kExitOk) << run.all();
    std::cout << run.all();
    EXPECT_NE(run.all().find("rectification: a pinhole target"),
              std::string::npos)
        << run.all();
    if (std::string(format) == "opencv") {
      cv::FileStorage storage(out.string(), cv::FileStorage::READ);
      ASSERT_TRUE(storage.isOpened());
      const std::string note = storage["rectification"];
      EXPECT_NE(note.find("field 120.0"), std::string::npos) << note;
      ExpectFileRectifiesOwnCorners(
          rig.scene, ReadOpenCvCamera(storage, 1, true, 640, 480),
          ReadOpenCvCamera(storage, 2, true, 640, 480));
      // The report's rectified pair is drawn upright from the file: the
      // board seen by the first camera is in its left half.
      EXPECT_TRUE(fs::exists(report / "rectified_pair.png"));
    } else {
      ExpectFileRectifiesOwnCorners(
          rig.scene, ReadRosCamera(rig.root / "ros_cam0.yaml", true),
          ReadRosCamera(rig.root / "ros_cam1.yaml", true));
    }
  }
}

// A second camera out of sync: in three frames it saw the board 4 mm away
// from where the first did. The frames are named by file on the output and
// in summary.md, marked in rig.yaml's frames list, and the rig verdict is
// not good.
TEST(CalibrateRigTest, UnsynchronisedFramesAreNamedByFile) {
  RigSceneSpec scene = StereoPinholeRig();
  scene.moved_frames = {2, 6, 11};
  scene.moved_by_m = 0.004;
  const RenderedRig rig = Render(scene, "unsynchronised");
  const fs::path out = rig.root / "rig.yaml";
  const fs::path report = rig.root / "report";
  const ProgramRun run =
      RunProgram("calibrate-rig --images " + rig.images.string() + " --board " +
                 rig.board + " --model pinhole-radtan --out " + out.string() +
                 " --report " + report.string() + " --threads 2");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  const std::string verdict = OutputLine(run.all(), "rig: verdict: ");
  EXPECT_EQ(verdict.rfind("rig: verdict: moved-frames", 0), 0u) << run.all();
  const YAML::Node file = YAML::LoadFile(out.string());
  EXPECT_EQ(file["verdict"]["kind"].as<std::string>(), "moved-frames");
  ASSERT_EQ(file["frames"].size(), static_cast<size_t>(rig.summary.num_frames));
  const std::string summary = ReadFile(report / "summary.md");
  for (int f = 0; f < rig.summary.num_frames; ++f) {
    const bool moved = f == 2 || f == 6 || f == 11;
    const YAML::Node frame = file["frames"][f];
    EXPECT_EQ(frame["cameras"][1]["file"].as<std::string>(),
              (rig.images / "cam1" / RigFrameFileName(f)).string());
    if (!frame["moved"]) continue;
    EXPECT_EQ(frame["moved"].as<bool>(), moved) << "frame " << f;
    EXPECT_EQ(verdict.find(RigFrameFileName(f)) != std::string::npos, moved)
        << verdict;
    EXPECT_EQ(
        summary.find("| " + RigFrameFileName(f) + " |") != std::string::npos,
        true);
  }
  EXPECT_NE(summary.find("**" + verdict + "**"), std::string::npos);
}

// One camera of a plain-checkerboard rig sees the board half covered in
// some frames (a hand over it). A part of a plain checkerboard is labelled
// from its own first corner, so its labels differ from the other camera's
// for the same corners: the rig leaves those views out, says why for each,
// and meets the truth with the rest.
TEST(CalibrateRigTest, PartlyCoveredCheckerboardViewsAreLeftOut) {
  RigSceneSpec scene = StereoPinholeRig();
  scene.board =
      MakeBoard(BoardType::kCheckerboard, 9, 6, Eigen::Vector2i::Zero(), 0.03);
  const RenderedRig rig = Render(scene, "covered");
  const fs::path board = rig.root / "checkerboard.yaml";
  std::ofstream(board) << "type: checkerboard\ncols: 9\nrows: 6\n"
                          "tile_size_m: 0.03\n";
  // Grey over the right half of the board in every other image of cam1.
  const std::vector<Eigen::Isometry3d> frames = RigFramePoses(scene);
  const Camera& camera = scene.cameras[1].camera;
  std::vector<int> covered;
  for (size_t f = 1; f < frames.size(); f += 2) {
    const fs::path file =
        rig.images / "cam1" / RigFrameFileName(static_cast<int>(f));
    if (!fs::exists(file)) continue;
    const Eigen::Isometry3d cam_from_board =
        scene.cameras[1].cam_from_rig * RigFramePoseSeenBy(scene, frames, 1, f);
    double low = camera.width, high = 0;
    for (const Eigen::Vector2i& id : scene.board.AllIds()) {
      Eigen::Vector2d pixel;
      if (!camera.Project(cam_from_board * scene.board.Point(id), &pixel)) {
        continue;
      }
      low = std::min(low, pixel.x());
      high = std::max(high, pixel.x());
    }
    if (!(high - low > 100)) continue;
    cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << file;
    cv::rectangle(image, cv::Point(static_cast<int>(0.5 * (low + high)), 0),
                  cv::Point(image.cols - 1, image.rows - 1),
                  cv::Scalar::all(128), cv::FILLED);
    ASSERT_TRUE(cv::imwrite(file.string(), image)) << file;
    covered.push_back(static_cast<int>(f));
  }
  ASSERT_GE(covered.size(), 4u);
  const fs::path out = rig.root / "rig.yaml";
  const ProgramRun run =
      RunProgram("calibrate-rig --images " + rig.images.string() + " --board " +
                 board.string() + " --model pinhole-radtan --out " +
                 out.string() + " --threads 2");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  const YAML::Node file = YAML::LoadFile(out.string());
  int left_out = 0;
  for (int f : covered) {
    const std::string use =
        file["frames"][f]["cameras"][1]["use"].as<std::string>();
    left_out += use.rfind("not used: part of the board only", 0) == 0;
  }
  // The grey edge may leave too few corners for a lattice in some.
  EXPECT_GE(left_out, static_cast<int>(covered.size()) - 1) << run.all();
  EXPECT_NE(run.all().find(": not used \u2014 part of the board only ("),
            std::string::npos)
      << run.all();
  // The rest meets the truth within the rig's stated uncertainty (a plain
  // checkerboard of 54 corners, half of one camera's views gone).
  std::vector<RigFileCamera> cameras;
  std::string error;
  ASSERT_TRUE(ReadRigFile(out.string(), &cameras, &error)) << error;
  ASSERT_EQ(cameras.size(), 2u);
  for (size_t c = 0; c < 2; ++c) {
    const YAML::Node sigma = file["cameras"][c]["parameter_stddev"];
    const Camera& truth = scene.cameras[c].camera;
    EXPECT_LT(std::abs(cameras[c].camera.params[0] - truth.params[0]),
              4 * sigma["fx"].as<double>())
        << c;
    EXPECT_LT(std::abs(cameras[c].camera.params[2] - truth.params[2]),
              4 * sigma["cx"].as<double>())
        << c;
  }
  const Eigen::Isometry3d& expected = scene.cameras[1].cam_from_rig;
  const YAML::Node cam1 = file["cameras"][1];
  EXPECT_LT(RotationDifferenceDeg(cameras[1].cam_from_rig.linear(),
                                  expected.linear()),
            4 * cam1["cam_from_rig_stddev"]["rotation_deg"].as<double>());
  EXPECT_LT(std::abs(cam1["baseline_mm"].as<double>() -
                     1000 * expected.translation().norm()),
            4 * cam1["baseline_stddev_mm"].as<double>());
}

TEST(CalibrateRigTest, StereoPinholeRendersInOpenCvFormat) {
  const RenderedRig rig = Render(StereoPinholeRig(), "stereo");
  const fs::path out = rig.root / "stereo.yaml";
  const ProgramRun run =
      RunProgram("calibrate-rig --images " + rig.images.string() + " --board " +
                 rig.board + " --model pinhole-radtan --format opencv --out " +
                 out.string() + " --threads 2");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  cv::FileStorage storage(out.string(), cv::FileStorage::READ);
  ASSERT_TRUE(storage.isOpened());
  cv::Mat r, t, k2;
  storage["R"] >> r;
  storage["T"] >> t;
  storage["K2"] >> k2;
  RigFileCamera second;
  second.name = "cam1";
  second.camera = rig.scene.cameras[1].camera;
  second.camera.params[0] = k2.at<double>(0, 0);
  second.camera.params[1] = k2.at<double>(1, 1);
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(r, rotation);
  cv::cv2eigen(t, translation);
  second.cam_from_rig.linear() = rotation;
  second.cam_from_rig.translation() = translation;
  RigFileCamera first;
  first.name = "cam0";
  first.camera = rig.scene.cameras[0].camera;
  ExpectMatchesTruth(rig.scene, {first, second});
  for (const char* key : {"E", "F", "R1", "R2", "P1", "P2", "Q"}) {
    cv::Mat m;
    storage[key] >> m;
    EXPECT_FALSE(m.empty()) << key;
  }
  ExpectFileRectifiesOwnCorners(rig.scene,
                                ReadOpenCvCamera(storage, 1, false, 640, 480),
                                ReadOpenCvCamera(storage, 2, false, 640, 480));
}

// Kalibr's radtan has 4 coefficients: --format kalibr calibrates
// pinhole-radtan cameras with k3 held at 0 (and says so by writing the
// camchain), and refuses pinhole-rational before any image is read.
TEST(CalibrateRigTest, KalibrFormatHoldsK3AtZeroAndRefusesRationalAtOnce) {
  const RenderedRig rig = Render(StereoPinholeRig(), "kalibr");
  const fs::path out = rig.root / "camchain.yaml";
  const ProgramRun run =
      RunProgram("calibrate-rig --images " + rig.images.string() + " --board " +
                 rig.board + " --model pinhole-radtan --format kalibr --out " +
                 out.string() + " --threads 2");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  const YAML::Node chain = YAML::LoadFile(out.string());
  for (const char* cam : {"cam0", "cam1"}) {
    ASSERT_TRUE(chain[cam]) << cam;
    EXPECT_EQ(chain[cam]["distortion_model"].as<std::string>(), "radtan");
    EXPECT_EQ(chain[cam]["distortion_coeffs"].size(), 4u);
    EXPECT_TRUE(chain[cam]["rostopic"]) << cam;
  }
  EXPECT_TRUE(chain["cam1"]["T_cn_cnm1"]);

  const fs::path refused = rig.root / "rational.yaml";
  const ProgramRun rational = RunProgram(
      "calibrate-rig --images " + rig.images.string() + " --board " +
      rig.board + " --model pinhole-rational --format kalibr --out " +
      refused.string());
  EXPECT_EQ(rational.exit_code, kExitUsage) << rational.all();
  EXPECT_NE(rational.all().find("kalibr"), std::string::npos) << rational.all();
  EXPECT_FALSE(fs::exists(refused));
}

TEST(CalibrateRigTest, CameraThatNeverSharesAFrameIsNamedAndNothingWritten) {
  const RenderedRig rig = Render(StereoPinholeRig(), "no_shared");
  // Odd frames only for cam0, even ones only for cam1.
  for (int f = 0; f < rig.summary.num_frames; ++f) {
    fs::remove(rig.images / (f % 2 == 0 ? "cam0" : "cam1") /
               RigFrameFileName(f));
  }
  const fs::path out = rig.root / "rig.yaml";
  const ProgramRun run =
      RunProgram("calibrate-rig --images " + rig.images.string() + " --board " +
                 rig.board + " --model pinhole-radtan --out " + out.string());
  // No file name is in both folders: refused before any image is read,
  // with the rule and both ways out.
  EXPECT_EQ(run.exit_code, kExitBadInput) << run.all();
  EXPECT_NE(run.all().find("'cam0' shares no frame with another camera"),
            std::string::npos)
      << run.all();
  EXPECT_NE(run.all().find("see the board together"), std::string::npos)
      << run.all();
  EXPECT_FALSE(fs::exists(out));
}

// cam1's folder a copy of cam0's (the same photos, byte for byte): refused
// before any image is read, naming both cameras, instead of a rig of two
// cameras in one place; nothing is written.
TEST(CalibrateRigTest, CameraFolderCopiedFromAnotherIsRefused) {
  const RenderedRig rig = Render(StereoPinholeRig(), "copied");
  fs::remove_all(rig.images / "cam1");
  fs::copy(rig.images / "cam0", rig.images / "cam1");
  const int photos = rig.summary.images_per_camera[0];
  const fs::path out = rig.root / "rig.yaml";
  const ProgramRun run =
      RunProgram("calibrate-rig --images " + rig.images.string() + " --board " +
                 rig.board + " --model pinhole-radtan --out " + out.string());
  EXPECT_EQ(run.exit_code, kExitBadInput) << run.all();
  EXPECT_NE(run.err.find(StringPrintf(
                "cameras 'cam0' and 'cam1' hold the same photos (%d of %d "
                "byte-identical): a rig needs one folder per camera",
                photos, photos)),
            std::string::npos)
      << run.all();
  EXPECT_FALSE(fs::exists(out));
}

// Folders whose file names differ per camera (left01.png, right01.png):
// frames are matched by name, so the program says so and how to pair them
// by order; --match_by_order then pairs the n-th images; --model auto
// chooses each camera's model.
TEST(CalibrateRigTest, DifferentNamesAreRefusedWithTheRuleAndPairedByOrder) {
  const RenderedRig rig = Render(StereoPinholeRig(), "names");
  int renamed = 0;
  for (const char* cam : {"cam0", "cam1"}) {
    for (const auto& entry : fs::directory_iterator(rig.images / cam)) {
      const std::string name = entry.path().filename().string();
      fs::rename(
          entry.path(),
          entry.path().parent_path() /
              ((std::string(cam) == "cam0" ? "left_" : "right_") + name));
      ++renamed;
    }
  }
  ASSERT_GT(renamed, 10);
  const fs::path out = rig.root / "rig.yaml";
  const std::string arguments = "calibrate-rig --images " +
                                rig.images.string() + " --board " + rig.board +
                                " --out " + out.string() + " --threads 2";
  const ProgramRun refused = RunProgram(arguments + " --model pinhole-radtan");
  EXPECT_EQ(refused.exit_code, kExitBadInput) << refused.all();
  EXPECT_NE(refused.all().find("matched by file name"), std::string::npos)
      << refused.all();
  EXPECT_NE(refused.all().find("--match_by_order"), std::string::npos)
      << refused.all();
  EXPECT_NE(refused.all().find("left_frame_000.png"), std::string::npos)
      << refused.all();
  EXPECT_FALSE(fs::exists(out));
  // Every camera sees every frame of this rig only where the board is in
  // both views: drop the images one camera lacks so that the order pairs.
  std::vector<std::string> left, right;
  for (const auto& e : fs::directory_iterator(rig.images / "cam0")) {
    left.push_back(e.path().filename().string().substr(5));
  }
  for (const auto& e : fs::directory_iterator(rig.images / "cam1")) {
    right.push_back(e.path().filename().string().substr(6));
  }
  for (const std::string& name : left) {
    if (std::find(right.begin(), right.end(), name) == right.end()) {
      fs::remove(rig.images / "cam0" / ("left_" + name));
    }
  }
  for (const std::string& name : right) {
    if (std::find(left.begin(), left.end(), name) == left.end()) {
      fs::remove(rig.images / "cam1" / ("right_" + name));
    }
  }
  const ProgramRun paired =
      RunProgram(arguments + " --model pinhole-radtan --match_by_order");
  ASSERT_EQ(paired.exit_code, kExitOk) << paired.all();
  EXPECT_NE(
      paired.all().find("shared frames: 0-1: " +
                        std::to_string(std::min(left.size(), right.size()))),
      std::string::npos)
      << paired.all();
  std::vector<RigFileCamera> cameras;
  std::string error;
  ASSERT_TRUE(ReadRigFile(out.string(), &cameras, &error)) << error;
  for (const RigFileCamera& camera : cameras) {
    EXPECT_EQ(camera.camera.model, CameraModelId::kPinholeRadtan);
  }
  EXPECT_NEAR((cameras[1].cam_from_rig.linear().transpose() *
               cameras[1].cam_from_rig.translation())
                  .norm(),
              0.12008, 0.001);
  // --model auto for one camera, a model for the other. The left lens is a
  // 70 deg pinhole: auto gives it a pinhole model (a kannala-brandt start
  // in a false basin once made it skip them all, then call the rig a
  // model error).
  const ProgramRun chosen =
      RunProgram(arguments + " --model auto,pinhole-radtan --match_by_order");
  ASSERT_EQ(chosen.exit_code, kExitOk) << chosen.all();
  EXPECT_NE(chosen.all().find("camera 'cam0': --model auto chose pinhole-"),
            std::string::npos)
      << chosen.all();
  EXPECT_NE(chosen.all().find("rig: verdict: good"), std::string::npos)
      << chosen.all();
  std::cout << OutputLine(chosen.all(), "camera 'cam0': --model auto") << "\n";
}

// Outputs are checked before the work; the rig file is written first and
// the report built aside and renamed into place; --quiet prints only what
// was written; Ctrl-C says what was written.
TEST(CalibrateRigTest, OutputsAreCheckedFirstAndWrittenWhole) {
  const RenderedRig rig = Render(StereoPinholeRig(), "outputs");
  const fs::path out = rig.root / "rig.yaml";
  const std::string arguments = "calibrate-rig --images " +
                                rig.images.string() + " --board " + rig.board +
                                " --model pinhole-radtan --out " +
                                out.string() + " --threads 2";
  const fs::path a_file = rig.root / "afile";
  std::ofstream(a_file) << "x";
  ProgramRun run = RunProgram(arguments + " --report " + a_file.string());
  EXPECT_EQ(run.exit_code, kExitOutputError) << run.all();
  EXPECT_NE(run.all().find("is a file, not a folder"), std::string::npos)
      << run.all();
  EXPECT_EQ(run.all().find("images usable"), std::string::npos)
      << "the work started:\n"
      << run.all();
  EXPECT_FALSE(fs::exists(out));
  const fs::path other = rig.root / "other";
  fs::create_directories(other);
  std::ofstream(other / "notes.txt") << "mine";
  run = RunProgram(arguments + " --report " + other.string());
  EXPECT_EQ(run.exit_code, kExitOutputError) << run.all();
  EXPECT_NE(run.all().find("holds notes.txt"), std::string::npos) << run.all();
  EXPECT_TRUE(fs::exists(other / "notes.txt"));
  EXPECT_FALSE(fs::exists(out));

  const fs::path report = rig.root / "report";
  fs::create_directories(report);
  std::ofstream(report / "old_chart.png") << "old";
  run = RunProgram(arguments + " --report " + report.string() + " --quiet");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  std::istringstream lines(run.all());
  for (std::string line; std::getline(lines, line);) {
    EXPECT_EQ(line.rfind("wrote ", 0), 0u) << "--quiet printed: " << line;
  }
  EXPECT_TRUE(fs::exists(out));
  EXPECT_TRUE(fs::exists(report / "summary.md"));
  EXPECT_FALSE(fs::exists(report / "old_chart.png"));  // replaced whole
  for (const auto& entry : fs::directory_iterator(rig.root)) {
    EXPECT_EQ(entry.path().filename().string().find(".partial"),
              std::string::npos)
        << entry.path();
  }

  // Ctrl-C while the images are read.
  fs::remove(out);
  const fs::path log = ScratchRoot() / "interrupt.log";
  const std::string command =
      ProgramPath().string() + " " + arguments + " --report " +
      report.string() + " > " + log.string() + " 2>&1 & p=$!; sleep 0.2; " +
      "kill -INT $p; wait $p; echo exit=$? >> " + log.string();
  ASSERT_EQ(std::system(command.c_str()), 0);
  const std::string interrupted = ReadFile(log);
  if (interrupted.find("exit=130") != std::string::npos) {
    EXPECT_NE(interrupted.find("interrupted; nothing written"),
              std::string::npos)
        << interrupted;
    EXPECT_FALSE(fs::exists(out));
  } else {
    std::cout << "the run ended before the interruption:\n" << interrupted;
  }
}

TEST(CalibrateRigTest, WrongNumberOfModelsIsAUsageError) {
  const fs::path root = ScratchRoot() / "models";
  fs::create_directories(root / "a");
  fs::create_directories(root / "b");
  fs::create_directories(root / "c");
  const RigSceneSpec scene = StereoPinholeRig();
  const std::string board = WriteBoardFile(scene.board, root);
  const ProgramRun run =
      RunProgram("calibrate-rig --images " + root.string() + " --board " +
                 board + " --model pinhole-radtan,kannala-brandt --out " +
                 (root / "rig.yaml").string());
  EXPECT_EQ(run.exit_code, kExitUsage) << run.all();
  EXPECT_NE(run.all().find("2 models for 3 cameras"), std::string::npos)
      << run.all();
  const ProgramRun one = RunProgram(
      "calibrate-rig --images " + (root / "a").string() + " --board " + board +
      " --model pinhole-radtan --out " + (root / "rig.yaml").string());
  EXPECT_EQ(one.exit_code, kExitBadInput) << one.all();
  EXPECT_NE(one.all().find("at least two"), std::string::npos) << one.all();
}

}  // namespace
}  // namespace puzzlecal
