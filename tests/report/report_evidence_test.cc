// The evidence sections of the calibration report: the verdict heads
// summary.md, the evidence tables follow, and the evidence plots are written.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/verdict.h"
#include "report/report.h"
#include "sim/synthetic_views.h"
#include "tests/evidence/judge.h"
#include "tests/support/files.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using testing_files::ReadFile;

TEST(ReportEvidence, VerdictHeadsTheSummaryAndPlotsAreWritten) {
  sim::SyntheticScene scene;
  scene.camera = sim::TruthFisheye190();
  scene.num_views = 16;
  scene.noise_px = 0.2;
  scene.max_direction_deg = 45;
  scene.min_visible_fraction = 0.6;
  const sim::SyntheticData data = sim::MakeSyntheticData(scene);
  CalibrationResult result;
  std::string error;
  ASSERT_TRUE(Calibrate(data.views, scene.camera.model, scene.camera.width,
                        scene.camera.height, CalibrationOptions(), &result,
                        &error))
      << error;
  const EvidenceOptions evidence_options;
  const Evidence evidence = ComputeEvidence(
      data.views, result, CalibrationOptions(), evidence_options);
  const Verdict verdict =
      MakeVerdict(result, evidence, evidence_options, VerdictOptions());

  ReportInput input;
  input.board.cols = scene.board_cols;
  input.board.rows = scene.board_rows;
  input.board.tile_size_m = scene.tile;
  input.result = &result;
  input.views = &data.views;
  input.evidence = &evidence;
  input.verdict = &verdict;
  for (size_t v = 0; v < data.views.size(); ++v) {
    ReportImage image;
    image.file = data.views[v].name + ".png";  // not on disk: no overlays
    image.outcome = ImageOutcome::kUsable;
    image.use = ViewUse::kUsed;
    image.view_index = static_cast<int>(v);
    input.images.push_back(image);
  }
  ReportOptions options;
  options.num_overlays = 0;
  const fs::path dir =
      fs::path(::testing::TempDir()) / "puzzlecal_report_evidence_test";
  fs::remove_all(dir);
  ReportSummary summary;
  ASSERT_TRUE(WriteReport(dir.string(), input, options, &error, &summary))
      << error;
  for (const char* name :
       {"cross_validation.png", "uncertainty.png", "residual_bins.png"}) {
    EXPECT_NE(std::find(summary.files.begin(), summary.files.end(), name),
              summary.files.end())
        << name;
    const cv::Mat image = cv::imread((dir / name).string());
    EXPECT_FALSE(image.empty()) << name;
  }
  const std::string markdown = ReadFile(dir / "summary.md");
  EXPECT_EQ(
      markdown.rfind("# Calibration report\n\n**" + verdict.Line() + "**", 0),
      0u)
      << markdown.substr(0, 300);
  EXPECT_NE(markdown.find("## Evidence"), std::string::npos);
  EXPECT_NE(markdown.find("### Cross-validation"), std::string::npos);
  EXPECT_NE(markdown.find("### Projection uncertainty"), std::string::npos);
  EXPECT_NE(markdown.find("### Systematic residuals"), std::string::npos);
  // One table row per residual bin by field angle.
  const std::string first_bin =
      "| 0-10 deg | " + std::to_string(evidence.residuals.by_angle[0].count) +
      " |";
  EXPECT_NE(markdown.find(first_bin), std::string::npos) << first_bin;
  fs::remove_all(dir);
}

// One rule names views: a view whose inliers fit but a third of whose
// corners were rejected stands out in the verdict, and the report's table
// of worst views puts it first with the verdict's reason, although views of
// higher inlier RMS exist.
TEST(ReportEvidence, WorstViewsFollowTheVerdictsRule) {
  const Camera truth = sim::TruthRadtan();
  sim::SyntheticData data =
      sim::MakeSyntheticData(testing_judge::TiltedScene(truth, 24, 0.1, 29));
  CalibrationView& view = data.views[7];
  for (size_t i = 0; i < view.image_points.size(); i += 3) {
    const double sign = i % 2 == 0 ? 1.0 : -1.0;
    view.image_points[i] += sign * Eigen::Vector2d(6, 4);
  }
  const testing_judge::Judged judged =
      testing_judge::Judge(data.views, truth.model, truth.width, truth.height);
  ASSERT_TRUE(judged.calibrated) << judged.error;
  ASSERT_EQ(judged.verdict.views[7].standing, ViewStanding::kStandsOut);
  int higher_rms = 0;
  for (size_t v = 0; v < data.views.size(); ++v) {
    higher_rms += judged.result.view_rms_px[v] > judged.result.view_rms_px[7];
  }
  ASSERT_GT(higher_rms, 0) << "the view should not lead by its RMS alone";

  ReportInput input;
  input.result = &judged.result;
  input.views = &data.views;
  input.evidence = &judged.evidence;
  input.verdict = &judged.verdict;
  for (size_t v = 0; v < data.views.size(); ++v) {
    ReportImage image;
    image.file = data.views[v].name + ".png";
    image.outcome = ImageOutcome::kUsable;
    image.use = ViewUse::kUsed;
    image.view_index = static_cast<int>(v);
    input.images.push_back(image);
  }
  const std::string markdown = ReportMarkdown(input, ReportOptions(), {});
  const size_t table = markdown.find("|---:|", markdown.find("## Worst views"));
  ASSERT_NE(table, std::string::npos) << markdown;
  const size_t first_row = markdown.find('\n', table) + 1;
  const std::string row =
      markdown.substr(first_row, markdown.find('\n', first_row) - first_row);
  EXPECT_NE(row.find(view.name + ".png"), std::string::npos) << row;
  EXPECT_NE(row.find("bad detections: " + judged.verdict.views[7].why),
            std::string::npos)
      << row;
}

}  // namespace
}  // namespace puzzlecal
