// The bad-input matrix: the `puzzlecal` program fed missing, empty, broken,
// odd and hostile inputs. Every case must end with a message that names the
// file and the reason, the documented exit code (apps/subcommand.h), the
// other images still processed, and no partial output.
//
// The images are rendered here (sim/render.h) into a temporary folder; the
// program is the one built beside this test (<build>/apps/puzzlecal).

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "apps/subcommand.h"
#include "camera/camera_models.h"
#include "sim/render.h"
#include "target/board.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using testing_files::ReadFile;
using testing_files::WriteFile;
using testing_program::ProgramPath;
using testing_program::ProgramRun;
using testing_program::Quote;
using testing_program::RunProgram;

// ---------------------------------------------------------------- helpers --

// Files under the folder, recursively (to check for partial output).
std::vector<std::string> FilesUnder(const fs::path& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  if (!fs::exists(folder, ec)) return files;
  for (const auto& entry : fs::recursive_directory_iterator(folder, ec)) {
    if (entry.is_regular_file()) files.push_back(entry.path().string());
  }
  return files;
}

Board PuzzleBoard11x8() {
  Board board =
      MakeBoard(BoardType::kPuzzleBoard, 11, 8, Eigen::Vector2i(0, 0), 0.06);
  return board;
}

Camera PinholeCamera() {
  Camera camera;
  camera.model = CameraModelId::kPinholeRadtan;
  camera.params = {560.0, 556.0, 321.0, 239.0, -0.08, 0.03, 0.0, 0.0, 0.0};
  camera.width = 640;
  camera.height = 480;
  return camera;
}

// Board centre `distance` in front of the camera, turned by angle_x then
// angle_y (radians) about its centre, shifted sideways by `shift`.
Eigen::Isometry3d LookAtBoard(const Board& board, double distance,
                              double angle_x, double angle_y,
                              const Eigen::Vector3d& shift) {
  const Eigen::Vector3d center(0.5 * (board.cols - 1) * board.tile_size_m,
                               0.5 * (board.rows - 1) * board.tile_size_m, 0);
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(angle_x, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(angle_y, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() =
      Eigen::Vector3d(0, 0, distance) + shift - rotation * center;
  return pose;
}

cv::Mat Render(const Eigen::Isometry3d& pose, RenderTruth* truth = nullptr) {
  RenderOptions options;
  options.supersampling = 2;
  options.blur_sigma_px = 0.8;
  options.noise_sigma = 0.01;
  RenderSummary summary;
  cv::Mat image = RenderBoard(PuzzleBoard11x8(), PinholeCamera(), pose, options,
                              truth, &summary);
  EXPECT_TRUE(summary.ok) << summary.reason;
  return image;
}

std::string EncodeImage(const cv::Mat& image, const std::string& extension) {
  std::vector<uchar> bytes;
  cv::imencode(extension, image, bytes);
  return std::string(bytes.begin(), bytes.end());
}

// The views a calibration can use: tilted in several directions.
const std::vector<Eigen::Isometry3d>& GoodPoses() {
  static const std::vector<Eigen::Isometry3d> poses = [] {
    const Board board = PuzzleBoard11x8();
    return std::vector<Eigen::Isometry3d>{
        LookAtBoard(board, 1.3, 0.35, 0.0, Eigen::Vector3d(0.0, 0.0, 0)),
        LookAtBoard(board, 1.4, -0.3, 0.25, Eigen::Vector3d(0.05, 0.03, 0)),
        LookAtBoard(board, 1.2, 0.1, -0.4, Eigen::Vector3d(-0.06, 0.0, 0)),
        LookAtBoard(board, 1.5, -0.2, -0.3, Eigen::Vector3d(0.0, -0.05, 0)),
        LookAtBoard(board, 1.35, 0.3, 0.35, Eigen::Vector3d(0.04, 0.05, 0)),
    };
  }();
  return poses;
}

// How often `needle` occurs in `text`.
int CountOf(const std::string& text, const std::string& needle) {
  int count = 0;
  for (size_t at = text.find(needle); at != std::string::npos;
       at = text.find(needle, at + needle.size())) {
    ++count;
  }
  return count;
}

// True when a line starts like a glog line ("W20261201 19:38:04.99 123
// f.cc:1]").
bool HasLogPrefix(const std::string& text) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.size() > 9 &&
        std::string("IWEF").find(line[0]) != std::string::npos &&
        std::all_of(line.begin() + 1, line.begin() + 9,
                    [](char c) { return std::isdigit(c) != 0; })) {
      return true;
    }
  }
  return false;
}

// ---------------------------------------------------------------- fixture --

class BadInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() /
                         ("puzzlecal_bad_input_" + std::to_string(getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_ / "good");
    // Rendered once for the whole suite; every case copies what it needs.
    for (size_t k = 0; k < GoodPoses().size(); ++k) {
      const cv::Mat image = Render(GoodPoses()[k]);
      WriteFile(*root_ / "good" / ("view" + std::to_string(k) + ".png"),
                EncodeImage(image, ".png"));
    }
    WriteFile(*root_ / "board.yaml",
              "type: puzzleboard\ncols: 11\nrows: 8\norigin: [0, 0]\n"
              "tile_size_m: 0.060\n");
  }

  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*root_, ec);
    delete root_;
    root_ = nullptr;
  }

  void SetUp() override {
    program_ = ProgramPath();
    ASSERT_TRUE(fs::exists(program_))
        << "the puzzlecal program is not built beside the tests: " << program_;
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    case_dir_ = *root_ / info->name();
    fs::remove_all(case_dir_);
    fs::create_directories(case_dir_);
  }

  // A folder with the good views plus whatever the case adds.
  fs::path ImagesWithGoodViews(const std::string& name, int num_good) {
    const fs::path folder = case_dir_ / name;
    fs::create_directories(folder);
    for (int k = 0; k < num_good; ++k) {
      const std::string file = "view" + std::to_string(k) + ".png";
      fs::copy_file(*root_ / "good" / file, folder / file);
    }
    return folder;
  }

  fs::path BoardFile() const { return *root_ / "board.yaml"; }

  ProgramRun Run(const std::string& arguments) const {
    return RunProgram(arguments, case_dir_);
  }

  ProgramRun Detect(const fs::path& images, const fs::path& out) const {
    return Run("detect --images " + Quote(images.string()) + " --out " +
               Quote(out.string()));
  }

  ProgramRun Calibrate(const fs::path& images, const fs::path& out,
                       const std::string& extra = "") const {
    return Run("calibrate --images " + Quote(images.string()) + " --board " +
               Quote(BoardFile().string()) +
               " --model pinhole-radtan --threads 2 --out " +
               Quote(out.string()) + " " + extra);
  }

  // Per image of detections.yaml: file name -> (corners, reason).
  struct DetectedImage {
    int corners = -1;
    std::string reason;
  };
  static std::map<std::string, DetectedImage> ReadDetections(
      const fs::path& yaml) {
    std::map<std::string, DetectedImage> images;
    const YAML::Node root = YAML::LoadFile(yaml.string());
    for (const YAML::Node& image : root["images"]) {
      DetectedImage detected;
      detected.corners = static_cast<int>(image["corners"].size());
      if (image["reason"]) detected.reason = image["reason"].as<std::string>();
      images[fs::path(image["file"].as<std::string>()).filename().string()] =
          detected;
    }
    return images;
  }

  static fs::path* root_;
  fs::path program_;
  fs::path case_dir_;
};

fs::path* BadInputTest::root_ = nullptr;

// ------------------------------------------------------------------ cases --

TEST_F(BadInputTest, MissingFolder) {
  const fs::path missing = case_dir_ / "no_such_folder";
  const fs::path out = case_dir_ / "detections.yaml";
  const ProgramRun detect = Detect(missing, out);
  EXPECT_EQ(detect.exit_code, kExitBadInput) << detect.all();
  EXPECT_NE(detect.err.find(missing.string()), std::string::npos) << detect.err;
  EXPECT_NE(detect.err.find("no such file"), std::string::npos) << detect.err;
  EXPECT_FALSE(fs::exists(out));

  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun calibrate = Calibrate(missing, camera);
  EXPECT_EQ(calibrate.exit_code, kExitBadInput) << calibrate.all();
  EXPECT_NE(calibrate.err.find(missing.string()), std::string::npos)
      << calibrate.err;
  EXPECT_FALSE(fs::exists(camera));
}

TEST_F(BadInputTest, EmptyFolder) {
  const fs::path empty = case_dir_ / "empty";
  fs::create_directories(empty);
  const fs::path out = case_dir_ / "detections.yaml";
  const ProgramRun detect = Detect(empty, out);
  EXPECT_EQ(detect.exit_code, kExitBadInput) << detect.all();
  EXPECT_NE(detect.err.find(empty.string()), std::string::npos) << detect.err;
  EXPECT_NE(detect.err.find("no image"), std::string::npos) << detect.err;
  EXPECT_FALSE(fs::exists(out));

  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun calibrate = Calibrate(empty, camera);
  EXPECT_EQ(calibrate.exit_code, kExitBadInput) << calibrate.all();
  EXPECT_NE(calibrate.err.find(empty.string()), std::string::npos)
      << calibrate.err;
  EXPECT_FALSE(fs::exists(camera));
}

// Text files, a text file named .png and a JPEG name holding random bytes:
// nothing is an image, so the run fails as bad input and names them.
TEST_F(BadInputTest, FolderOfNonImages) {
  const fs::path folder = case_dir_ / "non_images";
  fs::create_directories(folder);
  WriteFile(folder / "notes.txt", "not an image\n");
  WriteFile(folder / "fake.png", "this is text, not a PNG\n");
  std::string noise(4096, '\0');
  for (size_t k = 0; k < noise.size(); ++k) noise[k] = char((k * 7919) >> 3);
  WriteFile(folder / "random.jpg", noise);
  const fs::path out = case_dir_ / "detections.yaml";
  const ProgramRun detect = Detect(folder, out);
  EXPECT_EQ(detect.exit_code, kExitBadInput) << detect.all();
  EXPECT_NE(detect.err.find("fake.png"), std::string::npos) << detect.err;
  EXPECT_NE(detect.err.find("random.jpg"), std::string::npos) << detect.err;
  EXPECT_NE(detect.err.find("not a readable image"), std::string::npos)
      << detect.err;
  EXPECT_FALSE(fs::exists(out)) << "nothing readable: no detections file";

  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun calibrate = Calibrate(folder, camera);
  EXPECT_EQ(calibrate.exit_code, kExitBadInput) << calibrate.all();
  EXPECT_NE(calibrate.all().find("fake.png"), std::string::npos)
      << calibrate.all();
  EXPECT_NE(calibrate.err.find("none of the 2 image and video files in"),
            std::string::npos)
      << calibrate.err;
  EXPECT_FALSE(fs::exists(camera));

  // One file: said as one.
  fs::remove(folder / "random.jpg");
  const ProgramRun one = Calibrate(folder, camera);
  EXPECT_EQ(one.exit_code, kExitBadInput) << one.all();
  EXPECT_NE(one.err.find("the one image or video file in"), std::string::npos)
      << one.err;
  EXPECT_NE(one.err.find("could not be read"), std::string::npos) << one.err;
}

// A folder of camera folders given to calibrate (calibrate-rig's input)
// and a folder of HEIC photos: the message says where the images are and
// what to do; HEIC photos beside PNGs are counted in one line, not skipped
// silently.
TEST_F(BadInputTest, FolderOfFoldersAndPhotosInFormatsNotRead) {
  const fs::path rig = case_dir_ / "rig";
  for (const char* camera : {"cam0", "cam1"}) {
    fs::create_directories(rig / camera);
    fs::copy_file(*root_ / "good" / "view0.png", rig / camera / "01.png");
  }
  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun folders = Calibrate(rig, camera);
  EXPECT_EQ(folders.exit_code, kExitBadInput) << folders.all();
  EXPECT_NE(folders.err.find(rig.string() + ": the folder holds no image"),
            std::string::npos)
      << folders.err;
  EXPECT_NE(folders.err.find("its sub-folders cam0 and cam1 hold 2 image "
                             "files"),
            std::string::npos)
      << folders.err;
  EXPECT_NE(folders.err.find("calibrate-rig"), std::string::npos)
      << folders.err;

  const fs::path heic = case_dir_ / "heic";
  fs::create_directories(heic);
  WriteFile(heic / "IMG_0001.HEIC", "not decoded");
  WriteFile(heic / "IMG_0002.HEIC", "not decoded");
  const ProgramRun only_heic = Calibrate(heic, camera);
  EXPECT_EQ(only_heic.exit_code, kExitBadInput) << only_heic.all();
  EXPECT_NE(only_heic.err.find("it holds 2 HEIC files"), std::string::npos)
      << only_heic.err;
  EXPECT_NE(only_heic.err.find("convert them to JPEG or PNG"),
            std::string::npos)
      << only_heic.err;
  EXPECT_FALSE(fs::exists(camera));

  const fs::path mixed = ImagesWithGoodViews("mixed", 5);
  WriteFile(mixed / "IMG_0001.HEIC", "not decoded");
  WriteFile(mixed / "IMG_0002.HEIC", "not decoded");
  const ProgramRun run = Calibrate(mixed, camera);
  EXPECT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_EQ(
      CountOf(run.err, "note: " + mixed.string() + ": skipped 2 HEIC files"), 1)
      << run.err;
  EXPECT_TRUE(fs::exists(camera));
}

// `detect --board` on a good view beside a broken file: the broken file is
// named with its reason, and every labelled corner of the good view carries
// the truth id of the printed corner under it (absolute ids, decoded).
// Without --board the same corners come with relative labels that differ from
// the truth ids by one lattice transform per component.
TEST_F(BadInputTest, DetectWritesTruthIdsOfAGoodView) {
  const fs::path folder = case_dir_ / "detect";
  fs::create_directories(folder);
  RenderTruth truth;
  WriteFile(folder / "view.png",
            EncodeImage(Render(GoodPoses()[1], &truth), ".png"));
  WriteFile(folder / "zero.png", "");
  const fs::path out = case_dir_ / "detections.yaml";

  // Truth id of the visible corner within 1 px of (x, y), or (-1, -1).
  auto truth_id = [&](double x, double y) {
    for (const TruthCorner& corner : truth.corners) {
      if (corner.visible && (corner.xy - Eigen::Vector2d(x, y)).norm() < 1.0) {
        return corner.id;
      }
    }
    return Eigen::Vector2i(-1, -1);
  };
  int visible = 0;
  for (const TruthCorner& corner : truth.corners) visible += corner.visible;
  ASSERT_GT(visible, 40);

  for (const bool with_board : {true, false}) {
    SCOPED_TRACE(with_board ? "with --board" : "without --board");
    const ProgramRun detect =
        Run("detect --images " + Quote(folder.string()) + " --out " +
            Quote(out.string()) +
            (with_board ? " --board " + Quote(BoardFile().string()) : ""));
    ASSERT_EQ(detect.exit_code, kExitOk) << detect.all();
    EXPECT_NE(detect.err.find("zero.png"), std::string::npos) << detect.err;
    const YAML::Node root = YAML::LoadFile(out.string());
    ASSERT_EQ(root["images"].size(), 2u);
    const YAML::Node broken = root["images"][1];
    EXPECT_EQ(fs::path(broken["file"].as<std::string>()).filename(),
              "zero.png");
    EXPECT_FALSE(broken["reason"].as<std::string>().empty());
    EXPECT_EQ(broken["corners"].size(), 0u);

    const YAML::Node view = root["images"][0];
    EXPECT_EQ(view["width"].as<int>(), truth.camera.width);
    EXPECT_EQ(view["decoded"].as<bool>(), with_board)
        << view["reason"].as<std::string>();
    // Per component: the offset truth id - label, which must be one value per
    // component when decoded (identity map) and, without a board, one per
    // component under the component's own rotation/reflection, checked
    // through the label differences of corner pairs.
    std::map<int, std::vector<std::pair<Eigen::Vector2i, Eigen::Vector2i>>>
        labels_by_component;  // component -> (label, truth id)
    int labelled = 0;
    for (const YAML::Node& row : view["corners"]) {
      ASSERT_EQ(row.size(), 5u);
      const int component = row[4].as<int>();
      if (component < 0) continue;
      const Eigen::Vector2i label(row[2].as<int>(), row[3].as<int>());
      const Eigen::Vector2i id =
          truth_id(row[0].as<double>(), row[1].as<double>());
      ASSERT_GE(id.x(), 0) << "labelled corner off the board at "
                           << row[0].as<double>() << ", "
                           << row[1].as<double>();
      if (with_board) {
        EXPECT_EQ(label, id) << "component " << component;
      }
      labels_by_component[component].push_back({label, id});
      ++labelled;
    }
    EXPECT_GE(labelled, 0.95 * visible);
    for (const auto& [component, pairs] : labels_by_component) {
      // Relative labels: the lattice transform taking label differences to
      // id differences is fixed by the first pair of non-collinear steps;
      // every other pair must follow it.
      const auto& [label0, id0] = pairs.front();
      std::vector<Eigen::Vector2i> dl, di;
      for (const auto& [label, id] : pairs) {
        dl.push_back(label - label0);
        di.push_back(id - id0);
      }
      Eigen::Matrix2i m = Eigen::Matrix2i::Zero();
      bool found = false;
      for (size_t a = 0; a < dl.size() && !found; ++a) {
        for (size_t b = a + 1; b < dl.size() && !found; ++b) {
          Eigen::Matrix2i l;
          l << dl[a], dl[b];
          const int det = l.determinant();
          if (det != 1 && det != -1) continue;
          Eigen::Matrix2i d;
          d << di[a], di[b];
          // m * l = d, l unimodular: m = d * l^-1 (integer).
          Eigen::Matrix2i l_inverse;
          l_inverse << l(1, 1), -l(0, 1), -l(1, 0), l(0, 0);
          m = d * l_inverse * det;
          found = true;
        }
      }
      ASSERT_TRUE(found) << "component " << component;
      EXPECT_EQ(std::abs(m.determinant()), 1) << m;
      for (size_t k = 0; k < dl.size(); ++k) {
        EXPECT_EQ(m * dl[k], di[k]) << "component " << component;
      }
    }
  }
}

// Broken files among good views: each is named with its reason, the good
// views are still processed, and the calibration is written.
TEST_F(BadInputTest, BrokenFilesAmongGoodViews) {
  const fs::path folder = ImagesWithGoodViews("mixed", 5);
  const cv::Mat view = Render(GoodPoses()[0]);
  const std::string png = EncodeImage(view, ".png");
  const std::string jpeg = EncodeImage(view, ".jpg");
  WriteFile(folder / "truncated.png", png.substr(0, png.size() / 2));
  WriteFile(folder / "truncated.jpg", jpeg.substr(0, jpeg.size() / 2));
  WriteFile(folder / "zero.png", "");
  WriteFile(folder / "one_pixel.png",
            EncodeImage(cv::Mat(1, 1, CV_8UC1, cv::Scalar(128)), ".png"));
  cv::Mat noise(480, 640, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  WriteFile(folder / "noise.png", EncodeImage(noise, ".png"));

  const fs::path out = case_dir_ / "detections.yaml";
  const ProgramRun detect = Detect(folder, out);
  EXPECT_EQ(detect.exit_code, kExitOk) << detect.all();
  EXPECT_NE(detect.err.find("truncated.png: truncated PNG"), std::string::npos)
      << detect.err;
  EXPECT_NE(detect.err.find("truncated.jpg: truncated JPEG"), std::string::npos)
      << detect.err;
  EXPECT_NE(detect.err.find("zero.png: empty file"), std::string::npos)
      << detect.err;
  ASSERT_TRUE(fs::exists(out));
  const auto detections = ReadDetections(out);
  ASSERT_EQ(detections.size(), 10u);
  for (int k = 0; k < 5; ++k) {
    const auto& good = detections.at("view" + std::to_string(k) + ".png");
    // 88 inner corners, most visible in every view.
    EXPECT_GT(good.corners, 60) << "view" << k;
  }
  EXPECT_EQ(detections.at("one_pixel.png").corners, 0);
  EXPECT_FALSE(detections.at("one_pixel.png").reason.empty());
  EXPECT_EQ(detections.at("zero.png").corners, 0);
  EXPECT_NE(detections.at("zero.png").reason.find("empty"), std::string::npos);

  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun calibrate = Calibrate(folder, camera);
  EXPECT_EQ(calibrate.exit_code, kExitOk) << calibrate.all();
  const std::string all = calibrate.all();
  for (const char* name : {"truncated.png", "truncated.jpg", "zero.png",
                           "one_pixel.png", "noise.png"}) {
    // Named on one line, with its reason.
    EXPECT_EQ(CountOf(all, std::string(name) + ": "), 1) << name << "\n" << all;
  }
  EXPECT_FALSE(HasLogPrefix(all)) << all;
  EXPECT_TRUE(fs::exists(camera)) << all;
}

// A photo copied under another name is one view, not two: the copy (the
// later name) is named with the photo it repeats, and the summary line
// counts it.
TEST_F(BadInputTest, CopyOfAPhotoIsUsedOnce) {
  const fs::path folder = ImagesWithGoodViews("copies", 5);
  fs::copy_file(folder / "view1.png", folder / "view1_copy.png");
  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun run = Calibrate(folder, camera);
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_NE(run.err.find("view1_copy.png: repeated photo (not used: the same "
                         "photo as view1.png)"),
            std::string::npos)
      << run.err;
  EXPECT_NE(run.out.find("views used: 5 of 6 images (1 the same photo as an "
                         "earlier one, not used)"),
            std::string::npos)
      << run.out;
  const YAML::Node root = YAML::LoadFile(camera.string());
  EXPECT_EQ(root["views_used"].as<int>(), 5);
  for (const YAML::Node& view : root["views"]) {
    EXPECT_NE(fs::path(view["file"].as<std::string>()).filename(),
              "view1_copy.png");
  }
}

// The program starts without OpenCV's image codecs (Debian's bring about
// 140 libraries, 90 ms of every start); they are loaded when an image needs
// them (see the next test). The dynamic loader lists what it would load.
TEST_F(BadInputTest, ProgramStartsWithoutOpenCvImageCodecs) {
  const fs::path listing = case_dir_ / "loaded.txt";
  const std::string command = "LD_TRACE_LOADED_OBJECTS=1 " +
                              Quote(program_.string()) + " >" +
                              Quote(listing.string()) + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const std::string loaded = ReadFile(listing);
  EXPECT_NE(loaded.find("libopencv_core"), std::string::npos) << loaded;
  EXPECT_EQ(loaded.find("libopencv_imgcodecs"), std::string::npos) << loaded;
  EXPECT_EQ(loaded.find("libgdal"), std::string::npos) << loaded;
}

// 16-bit, RGBA and JPEG files (decoded by OpenCV, loaded on first use) are
// converted and used like the 8-bit grey PNG views.
TEST_F(BadInputTest, SixteenBitRgbaAndJpegImages) {
  const fs::path folder = case_dir_ / "depths";
  fs::create_directories(folder);
  for (size_t k = 0; k < GoodPoses().size(); ++k) {
    const cv::Mat view = Render(GoodPoses()[k]);
    cv::Mat converted;
    if (k % 2 == 0) {
      view.convertTo(converted, CV_16U, 257.0);
    } else {
      cv::cvtColor(view, converted, cv::COLOR_GRAY2BGRA);
    }
    WriteFile(folder / ("view" + std::to_string(k) + ".png"),
              EncodeImage(converted, ".png"));
  }
  cv::Mat colour;
  cv::cvtColor(Render(GoodPoses()[0]), colour, cv::COLOR_GRAY2BGR);
  WriteFile(folder / "colour.jpg", EncodeImage(colour, ".jpg"));
  const fs::path out = case_dir_ / "detections.yaml";
  const ProgramRun detect = Detect(folder, out);
  EXPECT_EQ(detect.exit_code, kExitOk) << detect.all();
  const auto detections = ReadDetections(out);
  ASSERT_EQ(detections.size(), GoodPoses().size() + 1);
  for (const auto& [file, detected] : detections) {
    EXPECT_GT(detected.corners, 60) << file;
  }

  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun calibrate = Calibrate(folder, camera);
  EXPECT_EQ(calibrate.exit_code, kExitOk) << calibrate.all();
  EXPECT_TRUE(fs::exists(camera));
}

// Two copies of the board in one image: the same ids twice. The program
// must not crash or report either copy with ids from the other; the other
// views are still used.
TEST_F(BadInputTest, TwoBoardsInOneImage) {
  const fs::path folder = ImagesWithGoodViews("two_boards", 5);
  const Board board = PuzzleBoard11x8();
  const cv::Mat left =
      Render(LookAtBoard(board, 2.4, 0.1, 0.2, Eigen::Vector3d(-0.36, 0.0, 0)));
  const cv::Mat right = Render(
      LookAtBoard(board, 2.4, -0.1, -0.2, Eigen::Vector3d(0.36, 0.0, 0)));
  cv::Mat both = left.clone();
  right.colRange(320, 640).copyTo(both.colRange(320, 640));
  WriteFile(folder / "two_boards.png", EncodeImage(both, ".png"));

  const fs::path out = case_dir_ / "detections.yaml";
  const ProgramRun detect = Detect(folder, out);
  EXPECT_EQ(detect.exit_code, kExitOk) << detect.all();
  const auto detections = ReadDetections(out);
  EXPECT_GT(detections.at("two_boards.png").corners, 60);

  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun calibrate = Calibrate(folder, camera);
  EXPECT_EQ(calibrate.exit_code, kExitOk) << calibrate.all();
  EXPECT_NE(calibrate.all().find("two_boards.png"), std::string::npos)
      << calibrate.all();
  EXPECT_TRUE(fs::exists(camera));
}

// A 50-megapixel image (mostly constant, so the PNG is small): refused or
// downscaled with a message, never exhausting memory; the other views go on.
TEST_F(BadInputTest, FiftyMegapixelImage) {
  const fs::path folder = ImagesWithGoodViews("huge", 1);
  cv::Mat huge(5800, 8700, CV_8UC1, cv::Scalar(140));
  Render(GoodPoses()[0]).copyTo(huge(cv::Rect(100, 100, 640, 480)));
  WriteFile(folder / "huge.png", EncodeImage(huge, ".png"));
  huge.release();

  const fs::path out = case_dir_ / "detections.yaml";
  const ProgramRun detect = Detect(folder, out);
  EXPECT_EQ(detect.exit_code, kExitOk) << detect.all();
  const auto detections = ReadDetections(out);
  EXPECT_GT(detections.at("view0.png").corners, 60);
  EXPECT_NE(detect.all().find("huge.png"), std::string::npos) << detect.all();
}

TEST_F(BadInputTest, UnreadablePermissions) {
  if (geteuid() == 0) {
    GTEST_SKIP() << "running as root, which reads any file regardless of its "
                    "permissions";
  }
  const fs::path folder = ImagesWithGoodViews("locked", 2);
  fs::copy_file(folder / "view0.png", folder / "locked.png");
  fs::permissions(folder / "locked.png", fs::perms::none);
  const fs::path out = case_dir_ / "detections.yaml";
  const ProgramRun detect = Detect(folder, out);
  fs::permissions(folder / "locked.png", fs::perms::owner_all);
  EXPECT_EQ(detect.exit_code, kExitOk) << detect.all();
  EXPECT_NE(detect.err.find("locked.png: cannot open"), std::string::npos)
      << detect.err;
  const auto detections = ReadDetections(out);
  EXPECT_GT(detections.at("view1.png").corners, 60);

  const fs::path locked_folder = case_dir_ / "locked_folder";
  fs::create_directories(locked_folder);
  fs::permissions(locked_folder, fs::perms::none);
  const ProgramRun folder_run = Detect(locked_folder, out);
  fs::permissions(locked_folder, fs::perms::owner_all);
  EXPECT_EQ(folder_run.exit_code, kExitBadInput) << folder_run.all();
  EXPECT_NE(folder_run.err.find(locked_folder.string()), std::string::npos);
}

// Board files with a missing field, a wrong type, a bad value, unknown type
// name, not YAML at all, and a missing file: bad input naming the board file.
TEST_F(BadInputTest, BadBoardFiles) {
  const fs::path folder = ImagesWithGoodViews("views", 5);
  const std::vector<std::pair<std::string, std::string>> boards = {
      {"missing_cols",
       "type: puzzleboard\nrows: 8\norigin: [0, 0]\n"
       "tile_size_m: 0.06\n"},
      {"text_cols",
       "type: puzzleboard\ncols: eleven\nrows: 8\n"
       "origin: [0, 0]\ntile_size_m: 0.06\n"},
      {"negative_tile",
       "type: puzzleboard\ncols: 11\nrows: 8\n"
       "origin: [0, 0]\ntile_size_m: -0.06\n"},
      {"unknown_type",
       "type: chessboard\ncols: 11\nrows: 8\n"
       "tile_size_m: 0.06\n"},
      {"not_yaml", "{{{ this: is: [not yaml\n"},
  };
  for (const auto& [name, text] : boards) {
    const fs::path board = case_dir_ / (name + ".yaml");
    WriteFile(board, text);
    const fs::path camera = case_dir_ / (name + "_camera.yaml");
    const ProgramRun run =
        Run("calibrate --images " + Quote(folder.string()) + " --board " +
            Quote(board.string()) + " --model pinhole-radtan --out " +
            Quote(camera.string()));
    EXPECT_EQ(run.exit_code, kExitBadInput) << name << "\n" << run.all();
    EXPECT_NE(run.err.find(board.string()), std::string::npos) << name << "\n"
                                                               << run.err;
    EXPECT_FALSE(fs::exists(camera)) << name;
  }
  const fs::path missing = case_dir_ / "no_board.yaml";
  const ProgramRun run =
      Run("calibrate --images " + Quote(folder.string()) + " --board " +
          Quote(missing.string()) + " --model pinhole-radtan --out " +
          Quote((case_dir_ / "camera.yaml").string()));
  EXPECT_EQ(run.exit_code, kExitBadInput) << run.all();
  EXPECT_NE(run.err.find(missing.string()), std::string::npos) << run.err;
}

TEST_F(BadInputTest, UnknownModelName) {
  const fs::path folder = ImagesWithGoodViews("views", 5);
  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun run = Calibrate(folder, camera, "--model fisheye-magic");
  EXPECT_EQ(run.exit_code, kExitUsage) << run.all();
  EXPECT_NE(run.err.find("fisheye-magic"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(camera));
}

// --format kalibr: pinhole-radtan calibrates Kalibr's 4-coefficient radtan
// (k3 held at 0) and writes a camchain with the rostopic Kalibr's reader
// requires; pinhole-rational, which the camchain cannot hold, is refused
// before any image is read.
TEST_F(BadInputTest, KalibrFormatFixesK3OrRefusesAtOnce) {
  const fs::path folder = ImagesWithGoodViews("views", 5);
  const fs::path camchain = case_dir_ / "camchain.yaml";
  const ProgramRun run =
      Calibrate(folder, camchain, "--format kalibr --rostopic /left/image_raw");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  const YAML::Node cam0 = YAML::LoadFile(camchain.string())["cam0"];
  EXPECT_EQ(cam0["rostopic"].as<std::string>(), "/left/image_raw");
  EXPECT_EQ(cam0["distortion_model"].as<std::string>(), "radtan");
  const auto coeffs = cam0["distortion_coeffs"].as<std::vector<double>>();
  ASSERT_EQ(coeffs.size(), 4u);
  // The render's k1 = -0.08, k2 = 0.03: a 4-coefficient fit recovers them.
  EXPECT_NEAR(coeffs[0], -0.08, 0.02);
  const auto intrinsics = cam0["intrinsics"].as<std::vector<double>>();
  EXPECT_NEAR(intrinsics[0], 560.0, 5.0);

  const fs::path rational = case_dir_ / "rational.yaml";
  const ProgramRun refused =
      Run("calibrate --images " + Quote(folder.string()) + " --board " +
          Quote(BoardFile().string()) +
          " --model pinhole-rational --format "
          "kalibr --verbose --out " +
          Quote(rational.string()));
  EXPECT_EQ(refused.exit_code, kExitUsage) << refused.all();
  EXPECT_NE(refused.err.find("kalibr"), std::string::npos) << refused.err;
  EXPECT_EQ(refused.all().find("view0"), std::string::npos)
      << "images were read before the refusal:\n"
      << refused.all();
  EXPECT_FALSE(fs::exists(rational));
}

// `calibrate --format opencv|ros|kalibr` writes the verdict line it prints
// as the file's first comment (after OpenCV's "%YAML:1.0"), and the file
// still loads: cv::FileStorage for opencv, a YAML reader for ros and kalibr.
TEST_F(BadInputTest, OtherFormatsCarryThePrintedVerdict) {
  const fs::path folder = ImagesWithGoodViews("views", 5);
  for (const std::string format : {"opencv", "ros", "kalibr"}) {
    SCOPED_TRACE(format);
    const fs::path camera = case_dir_ / (format + ".yaml");
    const ProgramRun run =
        Calibrate(folder, camera, "--format " + format + " --quiet");
    ASSERT_EQ(run.exit_code, kExitOk) << run.all();
    const size_t at = run.out.find("verdict: ");
    ASSERT_NE(at, std::string::npos) << run.out;
    const std::string verdict = run.out.substr(at, run.out.find('\n', at) - at);
    const std::string text = ReadFile(camera);
    const std::string top =
        (format == "opencv" ? "%YAML:1.0\n# " : "# ") + verdict + "\n";
    EXPECT_EQ(text.substr(0, top.size()), top) << text;
    if (format == "opencv") {
      cv::FileStorage storage(camera.string(), cv::FileStorage::READ);
      ASSERT_TRUE(storage.isOpened());
      cv::Mat k;
      storage["camera_matrix"] >> k;
      ASSERT_EQ(k.rows, 3);
      EXPECT_NEAR(k.at<double>(0, 0), 560.0, 5.0);
    } else {
      const YAML::Node root = YAML::LoadFile(camera.string());
      EXPECT_NEAR(format == "ros"
                      ? root["camera_matrix"]["data"][0].as<double>()
                      : root["cam0"]["intrinsics"][0].as<double>(),
                  560.0, 5.0);
    }
  }
}

// A camera file whose format cannot hold the model (a splined camera in
// OpenCV's YAML) says so on the terminal after the verdict: the verdict's
// "ready to use" is about the calibration, the note about the file, and a
// note printed before the summary scrolled out of sight.
TEST_F(BadInputTest, LossyFormatNoteComesAfterTheVerdict) {
  const fs::path folder = ImagesWithGoodViews("views", 5);
  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun run = Calibrate(
      folder, camera, "--model kannala-brandt-splined --format opencv");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  const std::string note = "note: " + camera.string() +
                           ": the opencv format has no kannala-brandt-splined "
                           "model";
  const size_t at_note = run.out.find(note);
  const size_t at_verdict = run.out.find("verdict: ");
  ASSERT_NE(at_note, std::string::npos) << run.out;
  ASSERT_NE(at_verdict, std::string::npos) << run.out;
  EXPECT_GT(at_note, at_verdict) << run.out;
  EXPECT_EQ(run.out.find(note, at_note + 1), std::string::npos)
      << "said twice:\n"
      << run.out;
}

// A board file that does not fit the photos (another board, another origin,
// cols and rows swapped) ends with a message about the board file, not with
// one about image sizes or the number of views.
TEST_F(BadInputTest, WrongBoardFileNamesTheBoard) {
  const fs::path folder = ImagesWithGoodViews("views", 5);
  struct Case {
    const char* name;
    const char* yaml;
  };
  for (const Case& c : std::vector<Case>{
           {"other_board.yaml",
            "type: puzzleboard\ncols: 23\nrows: 16\norigin: [50, 100]\n"
            "tile_size_m: 0.030\n"},
           {"other_origin.yaml",
            "type: puzzleboard\ncols: 11\nrows: 8\norigin: [40, 40]\n"
            "tile_size_m: 0.060\n"},
           {"swapped.yaml",
            "type: puzzleboard\ncols: 8\nrows: 11\norigin: [0, 0]\n"
            "tile_size_m: 0.060\n"},
       }) {
    const fs::path board = case_dir_ / c.name;
    WriteFile(board, c.yaml);
    const fs::path camera = case_dir_ / "camera.yaml";
    const ProgramRun run =
        Run("calibrate --images " + Quote(folder.string()) + " --board " +
            Quote(board.string()) + " --out " + Quote(camera.string()) +
            " --report " + Quote((case_dir_ / "report").string()));
    EXPECT_EQ(run.exit_code, kExitNoResult) << c.name << "\n" << run.all();
    EXPECT_NE(run.err.find("5 of 5 images show many corners but none matches "
                           "the code of " +
                           board.string() +
                           " at any position: check cols, rows and origin"),
              std::string::npos)
        << c.name << "\n"
        << run.err;
    EXPECT_EQ(run.all().find("must be positive"), std::string::npos)
        << run.all();
    EXPECT_EQ(run.all().find("add more views"), std::string::npos) << run.all();
    EXPECT_FALSE(fs::exists(camera));
  }
}

// Images of two sizes: the size most images have is used; the others are
// named with theirs.
TEST_F(BadInputTest, ImagesOfAnotherSizeAreNamed) {
  const fs::path folder = ImagesWithGoodViews("sizes", 5);
  // Sorted first, so "the first image's size" would be the wrong choice.
  cv::Mat wider;
  cv::copyMakeBorder(Render(GoodPoses()[1]), wider, 0, 20, 0, 60,
                     cv::BORDER_REPLICATE);
  WriteFile(folder / "a_wider.png", EncodeImage(wider, ".png"));
  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun run = Calibrate(folder, camera);
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_NE(run.err.find("a_wider.png"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("700x500 differs from the 640x480 most images have"),
            std::string::npos)
      << run.err;
  const YAML::Node file = YAML::LoadFile(camera.string());
  EXPECT_EQ(file["image_width"].as<int>(), 640);
  EXPECT_EQ(file["views"].size(), 5u);
}

// The camera file is written before the report; the report folder is
// replaced as a whole (old overlays go); a report folder holding other files
// and an unwritable camera path are refused before any image is read.
TEST_F(BadInputTest, OutputsCheckedFirstAndReportReplaced) {
  const fs::path folder = ImagesWithGoodViews("views", 5);
  const fs::path camera = case_dir_ / "camera.yaml";
  const fs::path report = case_dir_ / "report";
  fs::create_directories(report);
  WriteFile(report / "overlay_from_an_old_run.png", "old");
  WriteFile(report / "summary.md", "old summary");
  ProgramRun run =
      Calibrate(folder, camera, "--report " + Quote(report.string()));
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_TRUE(fs::exists(camera));
  EXPECT_FALSE(fs::exists(report / "overlay_from_an_old_run.png"));
  EXPECT_NE(ReadFile(report / "summary.md"), "old summary");
  for (const auto& entry : fs::directory_iterator(case_dir_)) {
    EXPECT_EQ(entry.path().filename().string().find(".report"),
              std::string::npos)
        << entry.path();
  }

  const fs::path notes = case_dir_ / "notes";
  fs::create_directories(notes);
  WriteFile(notes / "my_notes.txt", "keep me");
  const fs::path camera2 = case_dir_ / "camera2.yaml";
  run =
      Calibrate(folder, camera2, "--verbose --report " + Quote(notes.string()));
  EXPECT_EQ(run.exit_code, kExitOutputError) << run.all();
  EXPECT_NE(run.err.find("my_notes.txt"), std::string::npos) << run.err;
  EXPECT_EQ(run.all().find("view0.png"), std::string::npos)
      << "images were read before the refusal:\n"
      << run.all();
  EXPECT_EQ(ReadFile(notes / "my_notes.txt"), "keep me");
  EXPECT_FALSE(fs::exists(camera2));
}

// Ctrl-C while the images are processed: "interrupted", exit 130, nothing
// half-written.
TEST_F(BadInputTest, InterruptSaysSoAndLeavesNothingHalfWritten) {
  const fs::path folder = ImagesWithGoodViews("views", 5);
  const fs::path camera = case_dir_ / "camera.yaml";
  int err_pipe[2];
  ASSERT_EQ(pipe(err_pipe), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    dup2(err_pipe[1], STDERR_FILENO);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    close(err_pipe[0]);
    const std::string program = program_.string();
    const std::string images = folder.string(), out = camera.string(),
                      board = BoardFile().string();
    execl(program.c_str(), program.c_str(), "calibrate", "--images",
          images.c_str(), "--board", board.c_str(), "--out", out.c_str(),
          "--threads", "1", "--verbose", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(err_pipe[1]);
  // The first image line: the run is under way, four images and the
  // calibration still to go.
  std::string err;
  char buffer[256];
  while (err.find("[1/") == std::string::npos) {
    const ssize_t n = read(err_pipe[0], buffer, sizeof(buffer));
    if (n <= 0) break;
    err.append(buffer, n);
  }
  kill(child, SIGINT);
  for (ssize_t n; (n = read(err_pipe[0], buffer, sizeof(buffer))) > 0;) {
    err.append(buffer, n);
  }
  close(err_pipe[0]);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << err;
  EXPECT_EQ(WEXITSTATUS(status), 130) << err;
  EXPECT_NE(err.find("interrupted"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(camera));
  for (const std::string& file : FilesUnder(case_dir_)) {
    EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
  }
}

// The console: --version, `help SUBCOMMAND`, required flags marked, --quiet.
TEST_F(BadInputTest, ConsoleVersionHelpAndQuiet) {
  ProgramRun run = Run("--version");
  EXPECT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_EQ(run.out.rfind("puzzlecal ", 0), 0u) << run.out;
  run = Run("help calibrate");
  EXPECT_EQ(run.exit_code, kExitOk) << run.all();
  for (const char* line :
       {"--images (required)", "--board (required)", "--out (required)",
        "--model (default: pinhole-radtan)", "--format (default: puzzlecal)",
        "--rostopic (default: /cam0/image_raw)",
        "--camera-name (default: camera)", "--quiet", "--verbose"}) {
    EXPECT_NE(run.out.find(line), std::string::npos) << line << "\n" << run.out;
  }
  EXPECT_NE(run.out.find("the camera file"), std::string::npos) << run.out;
  EXPECT_EQ(Run("help calibrate").out, Run("calibrate --help").out);
  EXPECT_EQ(Run("help no-such-thing").exit_code, kExitUsage);
  // The program's own help lists every subcommand, the longest name too.
  for (const char* arguments : {"--help", "help"}) {
    run = Run(arguments);
    EXPECT_EQ(run.exit_code, kExitOk) << arguments << "\n" << run.all();
    for (const char* name : {"calibrate ", "calibrate-rig ", "detect ",
                             "options ", "undistort "}) {
      EXPECT_NE(run.out.find(std::string("  ") + name), std::string::npos)
          << name << "\n"
          << run.out;
    }
  }

  const fs::path folder = ImagesWithGoodViews("views", 5);
  WriteFile(folder / "zero.png", "");
  const fs::path camera = case_dir_ / "camera.yaml";
  run = Calibrate(folder, camera, "--quiet --camera-name left");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_EQ(run.err, "");
  // --quiet keeps two lines: the verdict and what was written.
  EXPECT_EQ(run.out.rfind("verdict: ", 0), 0u) << run.out;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 2) << run.out;
  EXPECT_NE(run.out.find("\nwrote " + camera.string() + "\n"),
            std::string::npos)
      << run.out;
  // With --model auto too: the model-selection table is not printed.
  run = Calibrate(folder, camera, "--quiet --model auto");
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_EQ(run.out.rfind("verdict: ", 0), 0u) << run.out;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 2) << run.out;
  run = Calibrate(folder, camera, "--quiet --verbose");
  EXPECT_EQ(run.exit_code, kExitUsage) << run.all();
}

// Command-line mistakes: exit 2 with a message naming the flag or argument,
// and nothing written.
TEST_F(BadInputTest, BadFlagsExitTwoAndNameTheFlag) {
  const fs::path out = case_dir_ / "detections.yaml";
  const std::string images = Quote((*root_ / "good").string());
  struct Case {
    std::string arguments;
    std::string named;  // must appear in the message
  };
  for (const Case& c : std::vector<Case>{
           {"detect --images " + images + " --out " + Quote(out.string()) +
                " --nosuchflag=1",
            "--nosuchflag"},
           {"detect --images " + images + " --out " + Quote(out.string()) +
                " --threads=abc",
            "abc"},
           {"detect --images " + images + " --out " + Quote(out.string()) +
                " --dpi 300",
            "--dpi"},
           {"detect --images " + images + " --out " + Quote(out.string()) +
                " stray",
            "stray"},
           {"detect --images " + images + " --out", "--out"},
       }) {
    const ProgramRun run = Run(c.arguments);
    EXPECT_EQ(run.exit_code, kExitUsage) << c.arguments << "\n" << run.all();
    EXPECT_NE(run.err.find(c.named), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(out)) << c.arguments;
  }
}

// A knot spacing out of range is a usage error that names the flag and the
// range, before any photo is read.
TEST_F(BadInputTest, KnotSpacingOutOfRangeIsAUsageError) {
  const fs::path out = case_dir_ / "camera.yaml";
  for (const char* spacing : {"0.5", "60"}) {
    const ProgramRun run = Calibrate(
        *root_ / "good", out, std::string("--knot-spacing-deg ") + spacing);
    EXPECT_EQ(run.exit_code, kExitUsage) << run.all();
    EXPECT_NE(run.err.find("--knot-spacing-deg"), std::string::npos) << run.err;
    EXPECT_NE(run.err.find("[1, 51.4]"), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// The output goes to a missing folder, below a regular file, or (when not
// root) into a read-only folder: output error, nothing half-written.
TEST_F(BadInputTest, UnwritableOutput) {
  const fs::path folder = ImagesWithGoodViews("views", 5);
  std::vector<fs::path> outputs = {case_dir_ / "missing" / "out.yaml"};
  WriteFile(case_dir_ / "a_file", "x");
  outputs.push_back(case_dir_ / "a_file" / "out.yaml");
  const fs::path read_only = case_dir_ / "read_only";
  fs::create_directories(read_only);
  if (geteuid() != 0) {
    fs::permissions(read_only, fs::perms::owner_read | fs::perms::owner_exec);
    outputs.push_back(read_only / "out.yaml");
  }
  for (const fs::path& out : outputs) {
    const ProgramRun detect = Detect(folder, out);
    EXPECT_EQ(detect.exit_code, kExitOutputError) << out << "\n"
                                                  << detect.all();
    EXPECT_NE(detect.err.find(out.string()), std::string::npos) << detect.err;
    const ProgramRun calibrate = Calibrate(folder, out);
    EXPECT_EQ(calibrate.exit_code, kExitOutputError) << out << "\n"
                                                     << calibrate.all();
    EXPECT_NE(calibrate.err.find(out.string()), std::string::npos)
        << calibrate.err;
  }
  fs::permissions(read_only, fs::perms::owner_all);
  // No partial output anywhere in the case folder (no temporary files left).
  for (const std::string& file : FilesUnder(case_dir_)) {
    EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
    EXPECT_EQ(file.find("out.yaml"), std::string::npos) << file;
  }
}

// Too few usable views: no result, and no camera file written.
TEST_F(BadInputTest, TooFewViewsWritesNothing) {
  const fs::path folder = ImagesWithGoodViews("one_view", 1);
  const fs::path camera = case_dir_ / "camera.yaml";
  const ProgramRun run = Calibrate(folder, camera);
  EXPECT_EQ(run.exit_code, kExitNoResult) << run.all();
  EXPECT_FALSE(fs::exists(camera));
  for (const std::string& file : FilesUnder(case_dir_)) {
    EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
  }

  // With --report the failure is still exit 4, and the report says why.
  const fs::path report = case_dir_ / "report";
  const ProgramRun reported =
      Calibrate(folder, camera, "--report " + Quote(report.string()));
  EXPECT_EQ(reported.exit_code, kExitNoResult) << reported.all();
  EXPECT_FALSE(fs::exists(camera));
  const std::string summary = ReadFile(report / "summary.md");
  EXPECT_NE(summary.find("usable view"), std::string::npos) << summary;
}

}  // namespace
}  // namespace puzzlecal
