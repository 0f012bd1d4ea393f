// The rig report's rectification: RectifyImage resamples like OpenCV's
// initUndistortRectifyMap (pinhole) and fisheye::initUndistortRectifyMap
// (kannala-brandt) for the same rotation and intrinsics, and the viewing
// rectification puts every point on the same row in both views. The
// summary: a section per camera with its verdict, the rig's figures for it
// and its evidence charts.

#include "report/rig_report.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <string>
#include <vector>

#include "calib/rig_calibration.h"
#include "evidence/evidence.h"
#include "evidence/verdict.h"
#include "sim/rig_scenes.h"
#include "tests/support/files.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

// An image whose value is its x (or y) coordinate: bilinear resampling of
// it returns the sampled position (to the 1/32 pixel of cv::remap's
// interpolation table).
cv::Mat Ramp(int width, int height, bool along_y) {
  cv::Mat ramp(height, width, CV_32FC1);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) ramp.at<float>(y, x) = along_y ? y : x;
  }
  return ramp;
}

void ExpectSameResampling(const Camera& camera, const Eigen::Matrix3d& r,
                          const Eigen::Matrix3d& k) {
  const cv::Mat ours_x =
      RectifyImage(Ramp(camera.width, camera.height, false), camera, r, k,
                   camera.width, camera.height);
  const cv::Mat ours_y =
      RectifyImage(Ramp(camera.width, camera.height, true), camera, r, k,
                   camera.width, camera.height);
  cv::Mat cv_k, cv_r, cv_p;
  const std::vector<double>& p = camera.params;
  cv::eigen2cv(Eigen::Matrix3d(Eigen::Matrix3d::Identity()), cv_k);
  cv_k.at<double>(0, 0) = p[0];
  cv_k.at<double>(1, 1) = p[1];
  cv_k.at<double>(0, 2) = p[2];
  cv_k.at<double>(1, 2) = p[3];
  cv::eigen2cv(r, cv_r);
  cv::eigen2cv(k, cv_p);
  const std::vector<double> d(p.begin() + 4, p.end());
  cv::Mat map_x, map_y;
  const cv::Size size(camera.width, camera.height);
  if (camera.model == CameraModelId::kKannalaBrandt) {
    cv::fisheye::initUndistortRectifyMap(cv_k, d, cv_r, cv_p, size, CV_32FC1,
                                         map_x, map_y);
  } else {
    cv::initUndistortRectifyMap(cv_k, d, cv_r, cv_p, size, CV_32FC1, map_x,
                                map_y);
  }
  const cv::Mat valid =
      RectifyImage(cv::Mat(camera.height, camera.width, CV_32FC1, 1.0f), camera,
                   r, k, camera.width, camera.height);
  int compared = 0, folded = 0;
  for (int y = 0; y < camera.height; y += 7) {
    for (int x = 0; x < camera.width; x += 7) {
      const float mx = map_x.at<float>(y, x), my = map_y.at<float>(y, x);
      if (!(mx > 1 && my > 1 && mx < camera.width - 2 &&
            my < camera.height - 2)) {
        continue;
      }
      // Beyond the fold of the pinhole's distortion RectifyImage draws
      // black where OpenCV's map still points into the image.
      if (valid.at<float>(y, x) < 1) {
        ++folded;
        continue;
      }
      EXPECT_NEAR(ours_x.at<float>(y, x), mx, 0.04) << "at " << x << ", " << y;
      EXPECT_NEAR(ours_y.at<float>(y, x), my, 0.04) << "at " << x << ", " << y;
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000);
  EXPECT_LT(folded, compared / 50);
}

TEST(RigReportTest, RectifyImageResamplesLikeOpenCv) {
  const RigSceneSpec scene = FisheyePinholeRig();
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, 1, 0.1).normalized())
          .toRotationMatrix();
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = k(1, 1) = 300;
  k(0, 2) = 330;
  k(1, 2) = 235;
  ExpectSameResampling(scene.cameras[1].camera, r, k);  // pinhole-radtan
  k(0, 0) = k(1, 1) = 120;
  ExpectSameResampling(scene.cameras[0].camera, r, k);  // kannala-brandt
}

TEST(RigReportTest, ViewingRectificationPutsPointsOnOneRow) {
  const RigSceneSpec scene = FisheyePinholeRig();
  const Eigen::Isometry3d& second_from_first = scene.cameras[1].cam_from_rig;
  const StereoRectification rect = ViewingRectification(
      scene.cameras[0].camera, scene.cameras[1].camera, second_from_first);
  for (const Eigen::Vector3d& x :
       {Eigen::Vector3d(0.3, -0.1, 0.6), Eigen::Vector3d(0.5, 0.2, 0.9),
        Eigen::Vector3d(0.2, 0.05, 1.2)}) {
    const Eigen::Vector2d a =
        (rect.p1.leftCols<3>() * rect.r1 * x).hnormalized();
    const Eigen::Vector2d b =
        (rect.p2.leftCols<3>() * rect.r2 * (second_from_first * x))
            .hnormalized();
    EXPECT_NEAR(a.y(), b.y(), 1e-9);
    EXPECT_GT(a.x(), b.x());  // positive disparity in front of the rig
  }
  EXPECT_TRUE((rect.r1 * rect.r1.transpose()).isIdentity(1e-12));
}

namespace fs = std::filesystem;
using testing_files::ReadFile;

// The text of summary.md from "## Camera <name>" to the next "## " heading.
std::string CameraSection(const std::string& summary, const std::string& name) {
  const std::string heading = "\n## Camera " + name + "\n";
  const size_t begin = summary.find(heading);
  if (begin == std::string::npos) return "";
  const size_t end = summary.find("\n## ", begin + heading.size());
  return summary.substr(
      begin, end == std::string::npos ? std::string::npos : end - begin);
}

// The targets of the markdown links and images in `text`.
std::vector<std::string> LinkedFiles(const std::string& text) {
  std::vector<std::string> files;
  const std::regex link("\\]\\(([^)]+)\\)");
  for (std::sregex_iterator it(text.begin(), text.end(), link), end; it != end;
       ++it) {
    files.push_back((*it)[1].str());
  }
  return files;
}

// A two-camera rig's exact correspondences (0.05 px noise), calibrated and
// judged camera by camera as the program does.
struct JudgedRig {
  RigCalibrationResult result;
  std::vector<Evidence> evidence;
  std::vector<Verdict> verdicts;
};

JudgedRig CalibrateAndJudge(const RigSceneSpec& scene) {
  JudgedRig rig;
  const std::vector<RigCameraInput> inputs = RigCorrespondences(scene, 0.05);
  RigCalibrationOptions options;
  std::string error;
  EXPECT_TRUE(CalibrateRig(inputs, options, &rig.result, &error)) << error;
  for (size_t c = 0; c < rig.result.cameras.size(); ++c) {
    const CalibrationResult& single = rig.result.cameras[c].single;
    rig.evidence.push_back(ComputeEvidence(inputs[c].frames, single,
                                           options.camera, EvidenceOptions()));
    rig.verdicts.push_back(MakeVerdict(single, rig.evidence.back(),
                                       EvidenceOptions(), VerdictOptions()));
  }
  return rig;
}

RigReportInput MakeInput(const JudgedRig& rig) {
  RigReportInput input;
  input.result = &rig.result;
  input.calibration_ok = true;
  for (size_t c = 0; c < rig.evidence.size(); ++c) {
    input.evidence.push_back(&rig.evidence[c]);
    input.verdicts.push_back(&rig.verdicts[c]);
  }
  return input;
}

TEST(RigReportTest, EachCameraHasItsVerdictFiguresAndEvidenceCharts) {
  const JudgedRig rig = CalibrateAndJudge(StereoPinholeRig());
  ASSERT_EQ(rig.result.cameras.size(), 2u);
  const fs::path dir = fs::temp_directory_path() /
                       ("puzzlecal_rig_report_" + std::to_string(getpid()));
  fs::remove_all(dir);
  std::string error;
  ASSERT_TRUE(
      WriteRigReport(dir.string(), MakeInput(rig), RigReportOptions(), &error))
      << error;
  const std::string summary = ReadFile(dir / "summary.md");
  ASSERT_FALSE(summary.empty());
  std::vector<std::string> all_charts;
  for (size_t c = 0; c < rig.result.cameras.size(); ++c) {
    const RigCameraResult& cam = rig.result.cameras[c];
    const Verdict& verdict = rig.verdicts[c];
    SCOPED_TRACE("camera " + cam.name);
    const std::string line = cam.name + ": " + verdict.Line();
    EXPECT_EQ(RigVerdictLine(cam.name, verdict), line);
    // At the top, before the first section.
    const size_t top = summary.find("- " + line + "\n");
    EXPECT_LT(top, summary.find("\n## ")) << summary;
    const std::string section = CameraSection(summary, cam.name);
    ASSERT_FALSE(section.empty()) << summary;
    EXPECT_NE(section.find("**" + line + "**"), std::string::npos) << section;
    EXPECT_NE(section.find("Verdict **" +
                           std::string(VerdictKindName(verdict.kind)) + "**"),
              std::string::npos)
        << section;
    EXPECT_NE(section.find(StringPrintf(
                  "| RMS reprojection error (px per coordinate) | %.4f | "
                  "%.4f |",
                  cam.rms_px, cam.single_rms_px)),
              std::string::npos)
        << section;
    EXPECT_NE(section.find(StringPrintf("| corners used | %d | %d |",
                                        cam.num_corners_used,
                                        cam.single.num_corners_used)),
              std::string::npos)
        << section;
    EXPECT_NE(
        section.find(StringPrintf("| outliers | %d | %d |", cam.num_outliers,
                                  cam.single.num_outliers)),
        std::string::npos)
        << section;
    EXPECT_NE(section.find(StringPrintf("| %d | %d |\n", cam.num_frames_used,
                                        cam.single_views_used)),
              std::string::npos)
        << section;
    // The single-camera report's evidence tables, one level down.
    EXPECT_NE(section.find("### Evidence\n"), std::string::npos);
    EXPECT_NE(section.find("#### Cross-validation"), std::string::npos);
    EXPECT_NE(section.find("#### Systematic residuals"), std::string::npos);
    // Every evidence chart, named after the camera, linked and drawn.
    ASSERT_TRUE(rig.evidence[c].cross_validation.ok);
    ASSERT_TRUE(rig.evidence[c].uncertainty.ok);
    const std::vector<std::string> charts = LinkedFiles(section);
    EXPECT_EQ(charts,
              (std::vector<std::string>{cam.name + "_cross_validation.png",
                                        cam.name + "_uncertainty.png",
                                        cam.name + "_residual_bins.png"}));
    for (const std::string& chart : charts) {
      const cv::Mat image = cv::imread((dir / chart).string());
      ASSERT_FALSE(image.empty()) << chart;
      cv::Scalar mean, stddev;
      cv::meanStdDev(image, mean, stddev);
      EXPECT_GT(stddev[0], 5) << chart << " is blank";
      all_charts.push_back(chart);
    }
  }
  // Two cameras, six different files.
  std::sort(all_charts.begin(), all_charts.end());
  EXPECT_EQ(std::unique(all_charts.begin(), all_charts.end()),
            all_charts.end());
  EXPECT_EQ(all_charts.size(), 6u);
  fs::remove_all(dir);
}

TEST(RigReportTest, RefusesEvidenceThatDoesNotMatchTheCameras) {
  const JudgedRig rig = CalibrateAndJudge(StereoPinholeRig());
  RigReportInput input = MakeInput(rig);
  input.verdicts.pop_back();
  const fs::path dir = fs::temp_directory_path() /
                       ("puzzlecal_rig_report_bad_" + std::to_string(getpid()));
  std::string error;
  EXPECT_FALSE(WriteRigReport(dir.string(), input, RigReportOptions(), &error));
  EXPECT_NE(error.find("one of each per camera"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir / "summary.md"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace puzzlecal
