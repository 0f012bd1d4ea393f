#include "formats/camera_yaml.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <string>

#include "sim/synthetic_views.h"
#include "tests/support/files.h"
#include "util/atomic_file.h"

namespace puzzlecal {
namespace {

Camera MakeCamera(CameraModelId id) {
  Camera camera;
  camera.model = id;
  camera.width = 1280;
  camera.height = 960;
  switch (id) {
    case CameraModelId::kPinholeRadtan:
      camera.params = {820.125, 818.5, 642.3, 477.1, -0.28,
                       0.09,    6e-4,  -4e-4, -0.012};
      break;
    case CameraModelId::kPinholeRational:
      camera.params = {760.0, 761.2, 637.8, 482.6, 0.3,  0.02,
                       4e-4,  7e-4,  5e-4,  0.52,  0.06, 0.001};
      break;
    case CameraModelId::kKannalaBrandt:
      camera.params = {495.0, 494.2, 801.7, 598.4, 0.02, -0.005, 0.001, -2e-4};
      break;
    case CameraModelId::kKannalaBrandtNoncentral:
      camera.params = {495.0,  494.2, 801.7, 598.4,   0.02,
                       -0.005, 0.001, -2e-4, 0.95e-3, 0.31e-3};
      break;
    case CameraModelId::kKannalaBrandtSplined:
    case CameraModelId::kKannalaBrandtSplinedNoncentral:
      // The bumpy fisheye's parameters (sim), at this test's image size.
      camera.params = sim::TruthBumpyFisheye().params;
      if (id == CameraModelId::kKannalaBrandtSplinedNoncentral) {
        camera.params.insert(camera.params.end(), {0.95e-3, 0.31e-3});
      }
      break;
  }
  return camera;
}

// A fresh scratch folder per test, removed at the end.
class CameraYamlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "camera_yaml_test_XXXXXX";
    const std::string base = std::string(::testing::TempDir()) + "/" + pattern;
    std::vector<char> name(base.begin(), base.end());
    name.push_back('\0');
    ASSERT_NE(mkdtemp(name.data()), nullptr);
    dir_ = name.data();
  }
  void TearDown() override {
    for (const std::string& file : files_) std::remove(file.c_str());
    rmdir(dir_.c_str());
  }
  std::string Path(const std::string& name) {
    files_.push_back(dir_ + "/" + name);
    return files_.back();
  }
  std::string dir_;
  std::vector<std::string> files_;
};

// (A non-central camera comes back from opencv, ros and kalibr as its
// far-field part; see NoncentralCameraIntoOtherFormatsSaysWhatIsLeftOut.)
TEST_F(CameraYamlTest, RoundTripsEveryModelThroughEveryLosslessFormat) {
  for (CameraModelId id : kAllCameraModels) {
    for (CameraFileFormat format :
         {CameraFileFormat::kPuzzlecal, CameraFileFormat::kOpenCv,
          CameraFileFormat::kRos, CameraFileFormat::kKalibr}) {
      Camera camera = MakeCamera(id);
      if (format == CameraFileFormat::kKalibr &&
          id == CameraModelId::kPinholeRadtan) {
        camera.params[8] = 0;  // kalibr's radtan has no k3
      }
      if (format == CameraFileFormat::kKalibr &&
          id == CameraModelId::kPinholeRational) {
        continue;  // refused, see below
      }
      SCOPED_TRACE(std::string(CameraModelName(id)) + " as " +
                   CameraFileFormatName(format));
      const std::string path = Path(std::string(CameraModelName(id)) + "." +
                                    CameraFileFormatName(format) + ".yaml");
      std::string error;
      ASSERT_TRUE(
          WriteCameraFile(path, format, camera, CameraFileStats(), &error))
          << error;
      Camera read;
      ASSERT_TRUE(ReadCameraFile(path, &read, &error)) << error;
      // What the format holds: the far-field part of a non-central camera,
      // the best-fitting kannala-brandt of a splined one.
      camera = CameraForFormat(camera, format, CameraFileStats());
      EXPECT_EQ(read.model, camera.model);
      EXPECT_EQ(read.width, camera.width);
      EXPECT_EQ(read.height, camera.height);
      ASSERT_EQ(read.params.size(), camera.params.size());
      for (size_t k = 0; k < camera.params.size(); ++k) {
        EXPECT_EQ(read.params[k], camera.params[k]) << k;
      }
    }
  }
}

TEST_F(CameraYamlTest, PuzzlecalFormatCarriesTheStatistics) {
  CalibrationResult result;
  result.camera = MakeCamera(CameraModelId::kKannalaBrandt);
  result.param_stddev = {0.1, 0.2, 0.3, 0.4, 1e-4, 2e-4, 3e-4, 4e-5};
  result.rms_px = 0.0961;
  result.num_views_used = 20;
  result.num_corners_used = 1598;
  result.num_outliers = 3;
  const std::string path = Path("camera.yaml");
  std::string error;
  ASSERT_TRUE(
      WriteCameraFile(path, CameraFileFormat::kPuzzlecal, result, &error))
      << error;
  // Read back with a plain YAML reader: the fields are where they belong.
  const YAML::Node root = YAML::LoadFile(path);
  EXPECT_EQ(root["model"].as<std::string>(), "kannala-brandt");
  EXPECT_EQ(root["image_width"].as<int>(), 1280);
  EXPECT_EQ(root["image_height"].as<int>(), 960);
  EXPECT_EQ(root["parameters"]["k2"].as<double>(), -0.005);
  EXPECT_EQ(root["parameter_stddev"]["cx"].as<double>(), 0.3);
  EXPECT_EQ(root["rms_px"].as<double>(), 0.0961);
  EXPECT_EQ(root["views_used"].as<int>(), 20);
  EXPECT_EQ(root["corners_used"].as<int>(), 1598);
  EXPECT_EQ(root["outliers"].as<int>(), 3);
}

// A puzzlecal file without parameter_covariance (trimmed or hand-written)
// reads as a camera whose uncertainty is unknown: the covariance empty, the
// other statistics as written. Without parameter_stddev too, the sigmas
// are empty as well. (A missing covariance list was read as a list of 0
// rows: "field 'parameter_covariance': expected 8 rows ..., got 0".)
TEST_F(CameraYamlTest, PuzzlecalFileWithoutCovarianceHasNoUncertainty) {
  CalibrationResult result;
  result.camera = MakeCamera(CameraModelId::kKannalaBrandt);
  result.param_stddev = {0.1, 0.2, 0.3, 0.4, 1e-4, 2e-4, 3e-4, 4e-5};
  result.covariance = Eigen::MatrixXd::Identity(8, 8) * 1e-4;
  result.covariance_ok = true;
  result.rms_px = 0.0961;
  result.num_views_used = 20;
  std::string text, error;
  CameraFileStats written = CameraFileStatsOfResult(
      result, std::vector<std::string>(), Eigen::Vector3d::Zero());
  ASSERT_TRUE(FormatCameraFile(result.camera, written,
                               CameraFileFormat::kPuzzlecal, &text, &error))
      << error;
  YAML::Node root = YAML::Load(text);
  ASSERT_TRUE(root["parameter_covariance"]);
  root.remove("parameter_covariance");
  Camera camera;
  CameraFileStats stats;
  ASSERT_TRUE(ParseCameraFile(YAML::Dump(root), "trimmed.yaml", &camera,
                              nullptr, &error, &stats))
      << error;
  EXPECT_EQ(camera.params, result.camera.params);
  EXPECT_TRUE(stats.has_stats);
  EXPECT_EQ(stats.covariance.size(), 0);
  EXPECT_EQ(stats.param_stddev, result.param_stddev);
  EXPECT_EQ(stats.rms_px, 0.0961);
  EXPECT_EQ(stats.num_views_used, 20);
  root.remove("parameter_stddev");
  ASSERT_TRUE(ParseCameraFile(YAML::Dump(root), "trimmed.yaml", &camera,
                              nullptr, &error, &stats))
      << error;
  EXPECT_EQ(stats.covariance.size(), 0);
  EXPECT_TRUE(stats.param_stddev.empty());
  EXPECT_EQ(stats.rms_px, 0.0961);
}

TEST_F(CameraYamlTest, OpenCvFormatIsReadableByFileStorage) {
  for (CameraModelId id : kAllCameraModels) {
    // What the file holds (the far-field part of a non-central camera, the
    // best-fitting kannala-brandt of a splined one).
    const Camera camera = CameraForFormat(
        MakeCamera(id), CameraFileFormat::kOpenCv, CameraFileStats());
    const std::string path =
        Path(std::string("opencv_") + CameraModelName(id) + ".yaml");
    std::string error;
    ASSERT_TRUE(WriteCameraFile(path, CameraFileFormat::kOpenCv, MakeCamera(id),
                                CameraFileStats(), &error))
        << error;
    cv::FileStorage fs(path, cv::FileStorage::READ);
    ASSERT_TRUE(fs.isOpened());
    cv::Mat k, d;
    fs["camera_matrix"] >> k;
    // A fisheye keeps its k1..k4 (cv::fisheye's D) under its own key, so
    // that pinhole readers cannot take them for k1 k2 p1 p2.
    const bool fisheye = CameraModelIsFisheye(id);
    fs[fisheye ? "fisheye_distortion_coefficients"
               : "distortion_coefficients"] >>
        d;
    EXPECT_EQ(fs["distortion_coefficients"].empty(), fisheye);
    if (fisheye) {
      EXPECT_EQ(static_cast<std::string>(fs["distortion_model"]), "fisheye");
    }
    ASSERT_EQ(k.rows, 3);
    ASSERT_EQ(k.cols, 3);
    EXPECT_EQ(k.at<double>(0, 0), camera.params[0]);
    EXPECT_EQ(k.at<double>(1, 1), camera.params[1]);
    EXPECT_EQ(k.at<double>(0, 2), camera.params[2]);
    EXPECT_EQ(k.at<double>(1, 2), camera.params[3]);
    EXPECT_EQ(k.at<double>(2, 2), 1.0);
    ASSERT_EQ(static_cast<int>(d.total()),
              CameraModelNumParams(camera.model) - kDistortionBegin);
    for (int i = 0; i < static_cast<int>(d.total()); ++i) {
      EXPECT_EQ(d.at<double>(i), camera.params[kDistortionBegin + i]);
    }
    EXPECT_EQ(static_cast<int>(fs["image_width"]), camera.width);
    EXPECT_EQ(static_cast<int>(fs["image_height"]), camera.height);
    EXPECT_EQ(static_cast<std::string>(fs["model"]),
              CameraModelName(camera.model));
  }
}

TEST_F(CameraYamlTest, NoncentralCameraIntoOtherFormatsSaysWhatIsLeftOut) {
  const Camera camera = MakeCamera(CameraModelId::kKannalaBrandtNoncentral);
  CameraFileStats stats;
  stats.closest_board_distance_m = 0.1;
  // The puzzlecal format holds it all.
  EXPECT_FALSE(
      DescribeCameraFileOmission(camera, CameraFileFormat::kPuzzlecal, stats)
          .lossy);
  EXPECT_FALSE(
      DescribeCameraFileOmission(MakeCamera(CameraModelId::kKannalaBrandt),
                                 CameraFileFormat::kOpenCv, stats)
          .lossy);
  // The largest difference between the camera and its far-field part for
  // points 10 cm away that the camera images, by a sweep over directions.
  const Camera far = FarFieldCamera(camera);
  double expected = 0;
  for (double deg = 0; deg <= 130; deg += 0.05) {
    for (double azimuth_deg = 0; azimuth_deg < 360; azimuth_deg += 5) {
      const double t = deg * M_PI / 180, a = azimuth_deg * M_PI / 180;
      const Eigen::Vector3d point =
          0.1 * Eigen::Vector3d(std::sin(t) * std::cos(a),
                                std::sin(t) * std::sin(a), std::cos(t));
      Eigen::Vector2d p, q;
      if (!camera.Project(point, &p) || !far.Project(point, &q)) continue;
      if (p.x() < 0 || p.y() < 0 || p.x() > camera.width - 1 ||
          p.y() > camera.height - 1) {
        continue;
      }
      expected = std::max(expected, (p - q).norm());
    }
  }
  ASSERT_GT(expected, 1.0);  // a real effect at this distance
  for (CameraFileFormat format :
       {CameraFileFormat::kOpenCv, CameraFileFormat::kRos,
        CameraFileFormat::kKalibr}) {
    SCOPED_TRACE(CameraFileFormatName(format));
    const CameraFileOmission omission =
        DescribeCameraFileOmission(camera, format, stats);
    EXPECT_TRUE(omission.lossy);
    EXPECT_NEAR(omission.max_error_px, expected, 0.02 * expected);
    EXPECT_NE(omission.left_out.find("e1 = 0.00095 m"), std::string::npos)
        << omission.left_out;
    EXPECT_NE(omission.left_out.find("e2 = 0.00031 m"), std::string::npos);
    EXPECT_NE(omission.note.find("0.1 m away"), std::string::npos)
        << omission.note;
    const std::string path =
        Path(std::string("noncentral.") + CameraFileFormatName(format));
    std::string error, note;
    ASSERT_TRUE(WriteCameraFile(path, format, camera, stats, &error, &note))
        << error;
    EXPECT_EQ(note, omission.note);
    // The file says so, and reads back as the far-field kannala-brandt.
    std::ifstream in(path);
    const std::string text((std::istreambuf_iterator<char>(in)),
                           std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("# " + omission.note), std::string::npos) << text;
    Camera read;
    ASSERT_TRUE(ReadCameraFile(path, &read, &error)) << error;
    EXPECT_EQ(read.model, CameraModelId::kKannalaBrandt);
    EXPECT_EQ(read.params, far.params);
    if (format == CameraFileFormat::kOpenCv) {
      cv::FileStorage fs(path, cv::FileStorage::READ);
      ASSERT_TRUE(fs.isOpened());
      cv::Mat d;
      fs["fisheye_distortion_coefficients"] >> d;
      EXPECT_EQ(d.total(), 4u);
    }
  }
  // Without a distance no figure, but still the note.
  const CameraFileOmission bare = DescribeCameraFileOmission(
      camera, CameraFileFormat::kRos, CameraFileStats());
  EXPECT_TRUE(bare.lossy);
  EXPECT_EQ(bare.max_error_px, 0);
  EXPECT_NE(bare.note.find("far-field"), std::string::npos);
}

// The verdict in the opencv, ros and kalibr formats, which have no field
// for it: a comment line at the top ("# verdict: ..."), after OpenCV's
// "%YAML:1.0" line, before a non-central camera's note; the file still
// reads as the same camera through the project's reader, a plain YAML
// reader (ros, kalibr) and cv::FileStorage (opencv). The puzzlecal format
// keeps its `verdict` field and no comment.
TEST_F(CameraYamlTest, OtherFormatsCarryTheVerdictAsACommentLine) {
  CameraFileStats stats;
  stats.has_stats = true;  // the puzzlecal format writes a verdict with them
  stats.verdict =
      "verdict: insufficient-data \u2014 4 views used, at least 8 needed "
      "\u2014 take more photos";
  stats.closest_board_distance_m = 0.3;
  for (CameraModelId id : {CameraModelId::kPinholeRadtan,
                           CameraModelId::kKannalaBrandtNoncentral}) {
    Camera camera = MakeCamera(id);
    if (id == CameraModelId::kPinholeRadtan) {
      camera.params[8] = 0;  // kalibr's radtan has no k3
    }
    for (CameraFileFormat format :
         {CameraFileFormat::kOpenCv, CameraFileFormat::kRos,
          CameraFileFormat::kKalibr, CameraFileFormat::kPuzzlecal}) {
      SCOPED_TRACE(std::string(CameraModelName(id)) + " as " +
                   CameraFileFormatName(format));
      const std::string path =
          Path(std::string("verdict_") + CameraModelName(id) + "." +
               CameraFileFormatName(format) + ".yaml");
      std::string error, note;
      ASSERT_TRUE(WriteCameraFile(path, format, camera, stats, &error, &note))
          << error;
      std::ifstream in(path);
      const std::string text((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
      Camera read;
      ASSERT_TRUE(ReadCameraFile(path, &read, &error)) << error;
      const Camera held = CameraForFormat(camera, format, stats);
      EXPECT_EQ(read.model, held.model);
      EXPECT_EQ(read.params, held.params);
      if (format == CameraFileFormat::kPuzzlecal) {
        EXPECT_EQ(YAML::LoadFile(path)["verdict"].as<std::string>(),
                  stats.verdict);
        EXPECT_EQ(text.find("# verdict"), std::string::npos) << text;
        continue;
      }
      const std::string header =
          format == CameraFileFormat::kOpenCv ? "%YAML:1.0\n" : "";
      const std::string expected_top =
          header + "# " + stats.verdict + "\n" +
          (note.empty() ? std::string() : "# " + note + "\n");
      EXPECT_EQ(text.substr(0, expected_top.size()), expected_top) << text;
      EXPECT_EQ(id == CameraModelId::kKannalaBrandtNoncentral, !note.empty());
      if (format == CameraFileFormat::kOpenCv) {
        cv::FileStorage fs(path, cv::FileStorage::READ);
        ASSERT_TRUE(fs.isOpened());
        cv::Mat k;
        fs["camera_matrix"] >> k;
        ASSERT_EQ(k.rows, 3);
        EXPECT_EQ(k.at<double>(0, 0), held.params[0]);
        EXPECT_EQ(static_cast<int>(fs["image_width"]), held.width);
        EXPECT_EQ(static_cast<std::string>(fs["model"]),
                  CameraModelName(held.model));
      } else {
        const YAML::Node root = YAML::LoadFile(path);
        if (format == CameraFileFormat::kRos) {
          EXPECT_EQ(root["image_width"].as<int>(), held.width);
          EXPECT_EQ(root["camera_matrix"]["data"][0].as<double>(),
                    held.params[0]);
        } else {
          EXPECT_EQ(root["cam0"]["intrinsics"][0].as<double>(), held.params[0]);
        }
      }
    }
  }
  // A verdict of several lines stays a comment, line by line.
  stats.verdict = "verdict: good \u2014 fine\nsecond line \u2014 none";
  std::string text, error;
  ASSERT_TRUE(FormatCameraFile(MakeCamera(CameraModelId::kKannalaBrandt), stats,
                               CameraFileFormat::kRos, &text, &error))
      << error;
  EXPECT_EQ(text.rfind("# verdict: good \u2014 fine\n# second line", 0), 0u)
      << text;
}

// A splined camera in the opencv, ros and kalibr formats: the file holds the
// kannala-brandt that fits it best over the observed field, its comment and
// the note say how far that is off, and that figure is what the camera read
// back shows against the splined one (the truth: a lens with a bump and a
// prism term, sim::TruthBumpyFisheye).
TEST_F(CameraYamlTest,
       SplinedCameraIntoOtherFormatsIsTheBestFittingKannalaBrandt) {
  Camera camera = sim::TruthBumpyFisheye();
  CameraFileStats stats;
  stats.max_field_angle_deg = 80;
  for (CameraFileFormat format :
       {CameraFileFormat::kOpenCv, CameraFileFormat::kRos,
        CameraFileFormat::kKalibr}) {
    SCOPED_TRACE(CameraFileFormatName(format));
    const CameraFileOmission omission =
        DescribeCameraFileOmission(camera, format, stats);
    ASSERT_TRUE(omission.lossy);
    ASSERT_TRUE(omission.fitted);
    EXPECT_NE(omission.note.find("best-fitting kannala-brandt"),
              std::string::npos)
        << omission.note;
    EXPECT_NE(omission.note.find("up to 80 deg"), std::string::npos);
    const std::string path =
        Path(std::string("splined.") + CameraFileFormatName(format) + ".yaml");
    std::string error, note;
    ASSERT_TRUE(WriteCameraFile(path, format, camera, stats, &error, &note))
        << error;
    EXPECT_EQ(note, omission.note);
    const std::string text = testing_files::ReadFile(path);
    EXPECT_NE(text.find(omission.note), std::string::npos);
    Camera read;
    ASSERT_TRUE(ReadCameraFile(path, &read, &error)) << error;
    EXPECT_EQ(read.model, CameraModelId::kKannalaBrandt);
    // The difference the note states, measured on the camera read back.
    double worst = 0;
    for (int y = 0; y < camera.height; y += 8) {
      for (int x = 0; x < camera.width; x += 8) {
        Eigen::Vector3d ray;
        if (!camera.Unproject(Eigen::Vector2d(x, y), &ray).converged) continue;
        if (std::acos(ray.z()) > 80 * M_PI / 180) continue;
        Eigen::Vector2d pixel;
        ASSERT_TRUE(read.Project(ray, &pixel));
        worst = std::max(worst, (pixel - Eigen::Vector2d(x, y)).norm());
      }
    }
    EXPECT_NEAR(worst, omission.fit_max_px, 1e-6);
    // The prism term alone is 3 px at 90 degrees: no kannala-brandt
    // follows it, and the fit is better than kannala-brandt's own part.
    EXPECT_GT(omission.fit_max_px, 0.5);
    EXPECT_LT(omission.fit_rms_px, omission.fit_max_px);
  }
}

// A splined camera file whose grid radius is not a positive number is
// refused, naming the file and the field.
TEST_F(CameraYamlTest, SplinedFileWithoutAGridRadiusIsRefused) {
  Camera camera = sim::TruthBumpyFisheye();
  const std::string path = Path("bad_grid.yaml");
  std::string error;
  ASSERT_TRUE(WriteCameraFile(path, CameraFileFormat::kPuzzlecal, camera,
                              CameraFileStats(), &error))
      << error;
  std::string text = testing_files::ReadFile(path);
  const size_t at = text.find("grid_radius:");
  ASSERT_NE(at, std::string::npos);
  const size_t end = text.find('\n', at);
  text.replace(at, end - at, "grid_radius: 0");
  testing_files::WriteFile(path, text);
  Camera read;
  EXPECT_FALSE(ReadCameraFile(path, &read, &error));
  EXPECT_NE(error.find("bad_grid.yaml"), std::string::npos) << error;
  EXPECT_NE(error.find("grid_radius"), std::string::npos) << error;
}

TEST_F(CameraYamlTest, ReadsFilesWrittenByOpenCv) {
  const std::string path = Path("written_by_opencv.yaml");
  {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    fs << "image_width" << 640 << "image_height" << 480;
    fs << "camera_matrix"
       << (cv::Mat_<double>(3, 3) << 500, 0, 320, 0, 501, 240, 0, 0, 1);
    fs << "distortion_coefficients"
       << (cv::Mat_<double>(1, 8) << 0.1, 0.01, 1e-3, 2e-3, 1e-4, 0.2, 0.02,
           1e-3);
  }
  Camera camera;
  std::string error;
  ASSERT_TRUE(ReadCameraFile(path, &camera, &error)) << error;
  EXPECT_EQ(camera.model, CameraModelId::kPinholeRational);
  EXPECT_EQ(camera.params[1], 501);
  EXPECT_EQ(camera.params[11], 1e-3);
  EXPECT_EQ(camera.width, 640);
}

TEST_F(CameraYamlTest, RosFileHasCameraInfoFields) {
  const Camera camera = MakeCamera(CameraModelId::kPinholeRational);
  std::string text, error;
  ASSERT_TRUE(FormatCameraFile(camera, CameraFileStats(),
                               CameraFileFormat::kRos, &text, &error));
  for (const char* field :
       {"image_width: 1280", "image_height: 960", "camera_name:",
        "camera_matrix:", "distortion_model: rational_polynomial",
        "distortion_coefficients:", "rectification_matrix:",
        "projection_matrix:", "rows: 3", "cols: 4"}) {
    EXPECT_NE(text.find(field), std::string::npos) << field << "\n" << text;
  }
  ASSERT_TRUE(FormatCameraFile(MakeCamera(CameraModelId::kKannalaBrandt),
                               CameraFileStats(), CameraFileFormat::kRos, &text,
                               &error));
  EXPECT_NE(text.find("distortion_model: equidistant"), std::string::npos);
  ASSERT_TRUE(FormatCameraFile(MakeCamera(CameraModelId::kPinholeRadtan),
                               CameraFileStats(), CameraFileFormat::kRos, &text,
                               &error));
  EXPECT_NE(text.find("distortion_model: plumb_bob"), std::string::npos);
}

TEST_F(CameraYamlTest, KalibrRefusesLossyWritesAndKeepsTheOldFile) {
  const std::string path = Path("camchain.yaml");
  std::string error;
  ASSERT_TRUE(WriteFileAtomically(path, "old contents\n", &error)) << error;
  // k3 != 0 has no place in kalibr's radtan.
  EXPECT_FALSE(WriteCameraFile(path, CameraFileFormat::kKalibr,
                               MakeCamera(CameraModelId::kPinholeRadtan),
                               CameraFileStats(), &error));
  EXPECT_NE(error.find("k3"), std::string::npos) << error;
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_FALSE(WriteCameraFile(path, CameraFileFormat::kKalibr,
                               MakeCamera(CameraModelId::kPinholeRational),
                               CameraFileStats(), &error));
  EXPECT_NE(error.find("rational"), std::string::npos) << error;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "old contents");
  // The kalibr fields.
  Camera camera = MakeCamera(CameraModelId::kKannalaBrandt);
  std::string text;
  ASSERT_TRUE(FormatCameraFile(camera, CameraFileStats(),
                               CameraFileFormat::kKalibr, &text, &error));
  for (const char* field :
       {"cam0:", "camera_model: pinhole", "intrinsics: [495",
        "distortion_model: equidistant", "distortion_coeffs: [",
        "resolution: [1280, 960]"}) {
    EXPECT_NE(text.find(field), std::string::npos) << field << "\n" << text;
  }
}

TEST_F(CameraYamlTest, FormatsSayBeforehandWhichParametersMustBeFixed) {
  std::vector<std::string> fixed;
  std::string error;
  ASSERT_TRUE(CameraFormatFixedParams(CameraFileFormat::kKalibr,
                                      CameraModelId::kPinholeRadtan, &fixed,
                                      &error));
  EXPECT_EQ(fixed, std::vector<std::string>{"k3"});
  ASSERT_TRUE(CameraFormatFixedParams(CameraFileFormat::kKalibr,
                                      CameraModelId::kKannalaBrandt, &fixed,
                                      &error));
  EXPECT_TRUE(fixed.empty());
  EXPECT_FALSE(CameraFormatFixedParams(CameraFileFormat::kKalibr,
                                       CameraModelId::kPinholeRational, &fixed,
                                       &error));
  EXPECT_NE(error.find("pinhole-rational"), std::string::npos) << error;
  for (CameraFileFormat format :
       {CameraFileFormat::kPuzzlecal, CameraFileFormat::kOpenCv,
        CameraFileFormat::kRos}) {
    for (CameraModelId model :
         {CameraModelId::kPinholeRadtan, CameraModelId::kPinholeRational,
          CameraModelId::kKannalaBrandt}) {
      EXPECT_TRUE(CameraFormatFixedParams(format, model, &fixed, &error));
      EXPECT_TRUE(fixed.empty());
    }
  }
}

// Read as Kalibr's camchain reader does: cam0 with camera_model, intrinsics,
// distortion_model, distortion_coeffs, resolution and the required rostopic;
// ros camera_info with its camera_name.
TEST_F(CameraYamlTest, KalibrAndRosFilesCarryTopicAndName) {
  Camera camera = MakeCamera(CameraModelId::kPinholeRadtan);
  camera.params[8] = 0;
  CameraFileNames names;
  std::string text, error;
  ASSERT_TRUE(FormatCameraFile(camera, CameraFileStats(),
                               CameraFileFormat::kKalibr, &text, &error));
  YAML::Node cam0 = YAML::Load(text)["cam0"];
  ASSERT_TRUE(cam0.IsMap()) << text;
  EXPECT_EQ(cam0["rostopic"].as<std::string>(), "/cam0/image_raw");
  EXPECT_EQ(cam0["camera_model"].as<std::string>(), "pinhole");
  EXPECT_EQ(cam0["distortion_model"].as<std::string>(), "radtan");
  const auto intrinsics = cam0["intrinsics"].as<std::vector<double>>();
  const auto coeffs = cam0["distortion_coeffs"].as<std::vector<double>>();
  const auto resolution = cam0["resolution"].as<std::vector<int>>();
  ASSERT_EQ(intrinsics.size(), 4u);
  ASSERT_EQ(coeffs.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(intrinsics[k], camera.params[k]);
    EXPECT_EQ(coeffs[k], camera.params[4 + k]);
  }
  EXPECT_EQ(resolution, (std::vector<int>{camera.width, camera.height}));

  names.rostopic = "/left/image_mono";
  names.camera_name = "left_camera";
  ASSERT_TRUE(FormatCameraFile(camera, CameraFileStats(),
                               CameraFileFormat::kKalibr, &text, &error,
                               names));
  EXPECT_EQ(YAML::Load(text)["cam0"]["rostopic"].as<std::string>(),
            "/left/image_mono");
  ASSERT_TRUE(FormatCameraFile(camera, CameraFileStats(),
                               CameraFileFormat::kRos, &text, &error, names));
  EXPECT_EQ(YAML::Load(text)["camera_name"].as<std::string>(), "left_camera");
  ASSERT_TRUE(FormatCameraFile(camera, CameraFileStats(),
                               CameraFileFormat::kRos, &text, &error));
  EXPECT_EQ(YAML::Load(text)["camera_name"].as<std::string>(), "camera");
}

// The puzzlecal format's `views`: poses read back and used the way OpenCV
// uses a pose (cv::projectPoints, cv::fisheye::projectPoints) put the board
// corners, in the board file's frame, onto the observed corners.
TEST_F(CameraYamlTest, ViewPosesReprojectTheBoardWithOpenCv) {
  for (const Camera& truth : {sim::TruthRadtan(), sim::TruthFisheye190()}) {
    sim::SyntheticScene scene;
    scene.camera = truth;
    scene.num_views = 8;
    scene.max_corner_angle_deg = 70;  // cv::fisheye's range
    sim::SyntheticData data = sim::MakeSyntheticData(scene);
    // The calibration's board frame has the first printed corner at
    // `first_corner` (a PuzzleBoard with origin (7, 3)); the file's at 0.
    const Eigen::Vector3d first_corner(7 * scene.tile, 3 * scene.tile, 0);
    std::vector<std::vector<Eigen::Vector3d>> file_points;
    std::vector<std::string> files;
    for (CalibrationView& view : data.views) {
      file_points.push_back(view.board_points);
      for (Eigen::Vector3d& p : view.board_points) p += first_corner;
      files.push_back("view" + std::to_string(files.size()) + ".png");
    }
    CalibrationResult result;
    std::string error;
    ASSERT_TRUE(Calibrate(data.views, truth.model, truth.width, truth.height,
                          CalibrationOptions(), &result, &error))
        << error;
    const std::string path = Path("views.yaml");
    ASSERT_TRUE(WriteCameraFile(
        path, CameraFileFormat::kPuzzlecal, result.camera,
        CameraFileStatsOfResult(result, files, first_corner), &error))
        << error;
    std::vector<CameraFileView> views;
    ASSERT_TRUE(ReadCameraFileViews(path, &views, &error)) << error;
    ASSERT_EQ(views.size(), data.views.size());
    const auto& p = result.camera.params;
    const cv::Matx33d k(p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
    for (size_t v = 0; v < views.size(); ++v) {
      EXPECT_EQ(views[v].file, files[v]);
      EXPECT_EQ(views[v].corners,
                static_cast<int>(data.views[v].board_points.size()));
      EXPECT_GT(views[v].rms_px, 0.0);
      EXPECT_LT(views[v].rms_px, 0.3);
      cv::Matx33d r;
      cv::Vec3d t;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
          r(i, j) = views[v].cam_from_board.linear()(i, j);
        t[i] = views[v].cam_from_board.translation()[i];
      }
      cv::Vec3d rvec;
      cv::Rodrigues(r, rvec);
      std::vector<cv::Point3d> object;
      for (const Eigen::Vector3d& q : file_points[v]) {
        object.emplace_back(q.x(), q.y(), q.z());
      }
      std::vector<cv::Point2d> projected;
      if (truth.model == CameraModelId::kKannalaBrandt) {
        cv::fisheye::projectPoints(object, projected, rvec, t, k,
                                   cv::Vec4d(p[4], p[5], p[6], p[7]));
      } else {
        cv::projectPoints(object, rvec, t, k,
                          std::vector<double>(p.begin() + 4, p.end()),
                          projected);
      }
      double sum = 0;
      for (size_t c = 0; c < object.size(); ++c) {
        const Eigen::Vector2d& seen = data.views[v].image_points[c];
        sum += std::pow(projected[c].x - seen.x(), 2) +
               std::pow(projected[c].y - seen.y(), 2);
      }
      const double rms = std::sqrt(sum / (2.0 * object.size()));
      // The noise is 0.1 px per coordinate; the view's RMS is that of its fit.
      EXPECT_LT(rms, 0.2) << CameraModelName(truth.model) << " view " << v;
      EXPECT_NEAR(rms, views[v].rms_px, 0.02);
    }
  }
}

TEST_F(CameraYamlTest, BadFilesGiveMessagesNamingFileAndField) {
  struct Case {
    const char* text;
    const char* expected;
  };
  const Case cases[] = {
      {"format: puzzlecal-camera\nmodel: pinhole-fancy\nimage_width: 10\n"
       "image_height: 10\nparameters: {}\n",
       "field 'model': unknown model 'pinhole-fancy'"},
      {"format: puzzlecal-camera\nmodel: kannala-brandt\nimage_width: 10\n"
       "image_height: 10\nparameters: {fx: 1, fy: 1, cx: 1, cy: 1, k1: 0, "
       "k2: 0, k3: 0}\n",
       "field 'parameters.k4': missing"},
      {"format: puzzlecal-camera\nmodel: kannala-brandt\nimage_width: ten\n",
       "field 'image_width': must be an integer, got 'ten'"},
      {"image_width: 640\nimage_height: 480\ncamera_name: c\n"
       "camera_matrix: {rows: 3, cols: 3, data: [1, 0, 1, 0, 1, 1]}\n"
       "distortion_model: plumb_bob\n"
       "distortion_coefficients: {rows: 1, cols: 5, data: [0, 0, 0, 0, 0]}\n",
       "field 'camera_matrix.data': must hold 9 numbers, got 6"},
      {"image_width: 640\nimage_height: 480\n"
       "camera_matrix: {rows: 3, cols: 3, data: [1, 0, 1, 0, 1, 1, 0, 0, 1]}\n"
       "distortion_model: kb9\n"
       "distortion_coefficients: {rows: 1, cols: 5, data: [0, 0, 0, 0, 0]}\n",
       "field 'distortion_model': unknown model 'kb9'"},
      {"cam0:\n  camera_model: omni\n",
       "field 'cam0.camera_model': only 'pinhole' is supported"},
      {"cam0:\n  camera_model: pinhole\n  distortion_model: radtan\n"
       "  intrinsics: [1, 1, 1, 1]\n  distortion_coeffs: [0, 0, 0]\n",
       "field 'cam0.distortion_coeffs': must hold 4 numbers, got 3"},
      {"just: a map\n", "not a camera file in any known format"},
      {"[1, 2\n", "not valid YAML"},
  };
  for (const Case& c : cases) {
    Camera camera;
    std::string error;
    EXPECT_FALSE(ParseCameraFile(c.text, "cam.yaml", &camera, nullptr, &error))
        << c.text;
    EXPECT_NE(error.find("cam.yaml"), std::string::npos) << error;
    EXPECT_NE(error.find(c.expected), std::string::npos)
        << "got: " << error << "\nexpected: " << c.expected;
  }
  Camera camera;
  std::string error;
  EXPECT_FALSE(ReadCameraFile(Path("missing.yaml"), &camera, &error));
  EXPECT_NE(error.find("missing.yaml"), std::string::npos);
}

TEST_F(CameraYamlTest, FormatNames) {
  for (CameraFileFormat format :
       {CameraFileFormat::kPuzzlecal, CameraFileFormat::kOpenCv,
        CameraFileFormat::kRos, CameraFileFormat::kKalibr}) {
    CameraFileFormat parsed;
    ASSERT_TRUE(
        CameraFileFormatFromName(CameraFileFormatName(format), &parsed));
    EXPECT_EQ(parsed, format);
  }
  CameraFileFormat parsed;
  EXPECT_FALSE(CameraFileFormatFromName("json", &parsed));
}

}  // namespace
}  // namespace puzzlecal
