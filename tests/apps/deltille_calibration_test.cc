// Regression on real photos: the deltille fisheye set (64 photos, 1600x1200,
// an 11x8-inner-corner checkerboard with 20 mm tiles; corners reach about
// 114 degrees off the optical axis). Skips when the data is absent.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/verdict.h"
#include "formats/board_file.h"
#include "formats/camera_yaml.h"
#include "formats/image_io.h"
#include "pipeline/pipeline.h"
#include "tests/support/deltille_data.h"
#include "tests/support/shared_data.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

struct DeltilleRun {
  bool ok = false;
  std::string error;
  int images = 0;
  std::vector<CalibrationView> views;
  CalibrationResult result;
};

DeltilleRun CalibrateFiles(
    const std::vector<std::string>& files,
    CameraModelId model = CameraModelId::kKannalaBrandt) {
  DeltilleRun run;
  Board board;
  EXPECT_TRUE(
      LoadBoardFile("configs/boards/deltille_checkerboard_11x8_20mm.yaml",
                    &board, &run.error))
      << run.error;
  std::vector<ImageResult> images =
      ProcessImageFiles(files, board, PipelineOptions(), 0);
  run.images = static_cast<int>(images.size());
  int width = 0, height = 0;
  run.views = MakeCalibrationViews(board, &images, &width, &height);
  run.ok = Calibrate(run.views, model, width, height, CalibrationOptions(),
                     &run.result, &run.error);
  return run;
}

class DeltilleCalibrationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = testing_data::DeltilleFolder();
    if (folder_.empty()) {
      PUZZLECAL_SKIP_WITHOUT_DATA("deltille fisheye photos not found: "
                                  << testing_data::DeltilleHowToGet());
    }
    ImageListing listing;
    std::string error;
    ASSERT_TRUE(ListImages(folder_, &listing, &error)) << error;
    files_ = listing.images;
  }
  std::string folder_;
  std::vector<std::string> files_;
};

// The same detections through OpenCV's fisheye calibration (the same
// Kannala-Brandt model with four coefficients): cv::fisheye handles rays up
// to about 90 degrees only, so it gets the corners within kCentralRadiusPx of
// the image centre (about 75 degrees off axis here), of views that keep at
// least 20 such corners. On those corners our solver with OpenCV's objective
// must land on OpenCV's minimum; our default run on all corners must agree
// with it to a fraction of a percent.
TEST_F(DeltilleCalibrationTest, UsesAlmostEveryPhotoAndAgreesWithOpenCv) {
  DeltilleRun run = CalibrateFiles(files_);
  ASSERT_TRUE(run.ok) << run.error;
  // The 64-photo subset: every photo shows the whole board.
  EXPECT_GE(run.result.num_views_used, 60) << CalibrationReport(run.result);
  // The board's rim corners at 100-114 degrees are the hardest to locate;
  // 0.41 px per coordinate was measured, the bound is 1.5x that.
  EXPECT_LT(run.result.rms_px, 0.6) << CalibrationReport(run.result);

  constexpr double kCentralRadiusPx = 380.0;
  const Eigen::Vector2d centre(800, 600);
  std::vector<CalibrationView> central;
  std::vector<std::vector<cv::Point3d>> object_points;
  std::vector<std::vector<cv::Point2d>> image_points;
  for (const CalibrationView& view : run.views) {
    CalibrationView kept;
    kept.name = view.name;
    for (size_t i = 0; i < view.image_points.size(); ++i) {
      if ((view.image_points[i] - centre).norm() < kCentralRadiusPx) {
        kept.board_points.push_back(view.board_points[i]);
        kept.image_points.push_back(view.image_points[i]);
      }
    }
    if (kept.image_points.size() < 20) continue;
    object_points.emplace_back();
    image_points.emplace_back();
    for (size_t i = 0; i < kept.image_points.size(); ++i) {
      const Eigen::Vector3d& b = kept.board_points[i];
      object_points.back().emplace_back(b.x(), b.y(), b.z());
      image_points.back().emplace_back(kept.image_points[i].x(),
                                       kept.image_points[i].y());
    }
    central.push_back(std::move(kept));
  }
  ASSERT_GE(central.size(), 30u);

  // OpenCV's own initial guess (f from the image size) fails in
  // InitExtrinsics on this lens, so it starts from a generic one: f = 300 px
  // (a 190-degree lens on a 1600-pixel-wide sensor), centre, no distortion.
  cv::Matx33d k(300, 0, 799.5, 0, 300, 599.5, 0, 0, 1);
  cv::Vec4d d(0, 0, 0, 0);
  std::vector<cv::Mat> rvecs, tvecs;
  try {
    cv::fisheye::calibrate(
        object_points, image_points, cv::Size(1600, 1200), k, d, rvecs, tvecs,
        cv::fisheye::CALIB_USE_INTRINSIC_GUESS |
            cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC |
            cv::fisheye::CALIB_FIX_SKEW,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200,
                         1e-12));
  } catch (const cv::Exception& e) {
    FAIL() << "cv::fisheye::calibrate threw: " << e.what();
  }
  // Our solver on the same objective as OpenCV's (plain least squares, no
  // robust loss, no outlier rejection).
  CalibrationOptions plain;
  plain.loss = RobustLoss::kNone;
  plain.outlier_k = 0;
  CalibrationResult ours_central;
  std::string error;
  ASSERT_TRUE(Calibrate(central, CameraModelId::kKannalaBrandt, 1600, 1200,
                        plain, &ours_central, &error))
      << error;
  const double opencv[4] = {k(0, 0), k(1, 1), k(0, 2), k(1, 2)};
  for (int p = 0; p < 4; ++p) {
    const std::string name =
        CameraModelParamNames(CameraModelId::kKannalaBrandt)[p];
    // Same corners, model and objective: the same minimum (measured equal
    // to 1e-3 px).
    const double same_data = p < 2 ? 2e-4 * opencv[p] : 0.05;
    EXPECT_NEAR(ours_central.camera.params[p], opencv[p], same_data) << name;
    // The default run (all corners to 114 degrees, robust loss, outlier
    // rejection) against OpenCV's central fit: 0.3 %, 1 px (measured
    // 0.04 %, 0.1 px).
    const double all_data = p < 2 ? 3e-3 * opencv[p] : 1.0;
    EXPECT_NEAR(run.result.camera.params[p], opencv[p], all_data) << name;
    std::printf(
        "%s: ours (all, default) %.3f, ours (central, plain) %.3f, "
        "OpenCV (central) %.3f\n",
        name.c_str(), run.result.camera.params[p],
        ours_central.camera.params[p], opencv[p]);
  }
}

TEST_F(DeltilleCalibrationTest, DisjointHalvesAgree) {
  std::vector<std::string> even, odd;
  for (size_t i = 0; i < files_.size(); ++i) {
    (i % 2 == 0 ? even : odd).push_back(files_[i]);
  }
  const DeltilleRun a = CalibrateFiles(even);
  const DeltilleRun b = CalibrateFiles(odd);
  ASSERT_TRUE(a.ok) << a.error;
  ASSERT_TRUE(b.ok) << b.error;
  // Formal 3-sigma agreement holds for fx, fy and cx, but cy of the halves
  // differed by 0.28 px against a formal 3 sigma of 0.24 px when this test
  // was written: the formal sigmas come from the residual variance and miss
  // the systematic rim error of the detections. So the halves are held to
  // fixed bounds instead: 0.1 % in focal length, 0.5 px in principal point.
  for (int p = 0; p < 4; ++p) {
    const double bound = p < 2 ? 1e-3 * a.result.camera.params[p] : 0.5;
    EXPECT_NEAR(a.result.camera.params[p], b.result.camera.params[p], bound)
        << CameraModelParamNames(a.result.camera.model)[p];
  }
}

// The evidence and verdict of a run, as `puzzlecal calibrate` makes them.
struct Judged {
  Evidence evidence;
  Verdict verdict;
};

Judged Judge(const DeltilleRun& run) {
  Judged judged;
  const EvidenceOptions evidence_options;
  judged.evidence = ComputeEvidence(run.views, run.result, CalibrationOptions(),
                                    evidence_options);
  judged.verdict = MakeVerdict(run.result, judged.evidence, evidence_options,
                               VerdictOptions());
  return judged;
}

// The lens is non-central: its entrance pupil moves along the axis with the
// field angle, by millimetres at 90 degrees, and the board was 2.5-24 cm
// away. The central model leaves errors that grow as the board comes closer
// (12 % of the corners rejected, RMS 0.49 px when this was written); the
// verdict says so and names the non-central model.
TEST_F(DeltilleCalibrationTest, CentralModelVerdictNamesNoncentral) {
  const DeltilleRun run = CalibrateFiles(files_, CameraModelId::kKannalaBrandt);
  ASSERT_TRUE(run.ok) << run.error;
  const Judged judged = Judge(run);
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kModelError)
      << judged.verdict.Line();
  EXPECT_EQ(judged.verdict.suggested_model, "kannala-brandt-noncentral")
      << judged.verdict.Line();
  std::printf("%s\n", judged.verdict.Line().c_str());
}

// The non-central model on the same photos: the noise level of the corners
// with nothing left over. Measured when this was written: RMS 0.153 px per
// coordinate, 3 of 5472 corners (0.05 %) rejected, 64 of 64 photos used,
// halves' far-field difference (median per 10-degree band) at most 0.091 px
// within 100 degrees (0.086 px at 30-40, 0.091 px at 90-100), verdict good.
TEST_F(DeltilleCalibrationTest, NoncentralModelFitsToTheNoiseAndIsGood) {
  const DeltilleRun run =
      CalibrateFiles(files_, CameraModelId::kKannalaBrandtNoncentral);
  ASSERT_TRUE(run.ok) << run.error;
  const CalibrationResult& result = run.result;
  EXPECT_EQ(result.num_views_used, run.images) << CalibrationReport(result);
  EXPECT_EQ(run.images, static_cast<int>(files_.size()));
  EXPECT_LE(result.rms_px, 0.17) << CalibrationReport(result);
  const int corners = result.num_corners_used + result.num_outliers;
  ASSERT_GT(corners, 0);
  EXPECT_LE(result.num_outliers, 0.01 * corners) << CalibrationReport(result);
  // No false corner holds a board id: a non-corner with a label lies 12-25
  // px from where its id projects; every labelled corner of every photo,
  // rejected or not, must be where the model puts its id.
  double worst_px = 0;
  for (const std::vector<Eigen::Vector2d>& view : result.residuals)
    for (const Eigen::Vector2d& r : view)
      worst_px = std::max(worst_px, r.norm());
  EXPECT_LT(worst_px, 3.0) << CalibrationReport(result);

  const Judged judged = Judge(run);
  const CrossValidation& cv = judged.evidence.cross_validation;
  ASSERT_TRUE(cv.ok) << cv.error;
  int judged_bands = 0;
  for (const AngleBand& band : cv.difference_bands) {
    if (band.hi_deg > 100.0 + 1e-9) continue;
    ++judged_bands;
    // The aim within 100 degrees.
    EXPECT_LE(band.median, 0.1) << band.lo_deg << "-" << band.hi_deg << " deg\n"
                                << EvidenceText(judged.evidence);
    std::printf("halves %3.0f-%3.0f deg: median %.3f px, p95 %.3f px\n",
                band.lo_deg, band.hi_deg, band.median, band.p95);
  }
  EXPECT_EQ(judged_bands, 10);
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kGood)
      << judged.verdict.Line() << "\n"
      << EvidenceText(judged.evidence);
  std::printf(
      "rms %.4f px, %d of %d corners rejected (largest residual %.2f px), %d "
      "of %d views\n%s\n",
      result.rms_px, result.num_outliers, corners, worst_px,
      result.num_views_used, run.images, judged.verdict.Line().c_str());
}

}  // namespace
}  // namespace puzzlecal
