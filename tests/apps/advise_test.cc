// `puzzlecal advise` and calibrate's advice end to end on renders with
// known truth: a deficient start (6 near-frontal views of the board in the
// middle of the sample lens's image), the advice printed and written
// (pictures, advice.yaml) and its poses checked against the truth camera;
// the same with the intrinsics given (--camera); calibrate's report with a
// "Next photos" section when the verdict is not good; bad input refused.
// The program is the one built beside this test (<build>/apps/puzzlecal).

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "formats/camera_yaml.h"
#include "formats/png_writer.h"
#include "sim/render.h"
#include "sim/scenes.h"
#include "sim/synthetic_views.h"
#include "tests/support/files.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace advise_test {
namespace {

namespace fs = std::filesystem;
using testing_program::ProgramRun;
using testing_program::Quote;

fs::path Scratch() {
  return fs::temp_directory_path() /
         ("puzzlecal_advise_test_" + std::to_string(getpid()));
}

[[maybe_unused]] const ::testing::Environment* const kCleanup =
    ::testing::AddGlobalTestEnvironment(
        new testing_program::RemoveAtEnd(Scratch()));

ProgramRun RunPuzzlecal(const std::string& arguments) {
  const ProgramRun run = testing_program::RunProgram(arguments, Scratch());
  std::cout << "$ puzzlecal " << arguments << "\n" << run.all();
  return run;
}

// The deficient start of the sample lens, rendered once: photos/,
// board.yaml and truth.yaml (the truth camera) under Scratch()/start.
struct Start {
  SceneSpec scene = SampleScene();
  fs::path root = Scratch() / "start";
  fs::path photos = root / "photos";
  fs::path board_file = root / "board.yaml";
  fs::path truth_file = root / "truth.yaml";
};

const Start& RenderedStart() {
  static const Start* start = [] {
    auto* s = new Start;
    fs::create_directories(s->photos);
    const std::vector<Eigen::Isometry3d> poses =
        sim::CentredFrontalPoses(s->scene.camera, s->scene.board, 6, 3);
    std::string error;
    for (size_t k = 0; k < poses.size(); ++k) {
      RenderOptions render = s->scene.render;
      render.seed = 100 + k;
      const cv::Mat image =
          RenderBoard(s->scene.board, s->scene.camera, poses[k], render);
      EXPECT_TRUE(WritePngFile(
          (s->photos / ("view_" + std::to_string(k) + ".png")).string(), image,
          &error))
          << error;
    }
    const Board& board = s->scene.board;
    std::ofstream(s->board_file)
        << "type: puzzleboard\ncols: " << board.cols << "\nrows: " << board.rows
        << "\norigin: [" << board.origin.x() << ", " << board.origin.y()
        << "]\ntile_size_m: " << board.tile_size_m << "\n";
    EXPECT_TRUE(WriteCameraFile(s->truth_file.string(),
                                CameraFileFormat::kPuzzlecal, s->scene.camera,
                                CameraFileStats(), &error))
        << error;
    return s;
  }();
  return *start;
}

// advice.yaml's views: each pose a rotation with the board in front, and
// the board's centre projected by the truth camera where the advice says
// it appears (the start's intrinsics are close to the truth).
void ExpectPosesMatchTheTruth(const fs::path& advice_file, const Start& start,
                              size_t count) {
  const YAML::Node advice = YAML::LoadFile(advice_file.string());
  ASSERT_TRUE(advice["views"].IsSequence());
  ASSERT_EQ(advice["views"].size(), count);
  const Board& board = start.scene.board;
  const Eigen::Vector3d centre =
      0.5 * (board.Point(board.origin) +
             board.Point(board.origin +
                         Eigen::Vector2i(board.cols - 1, board.rows - 1)));
  for (const YAML::Node& view : advice["views"]) {
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        r(i, j) = view["cam_from_board"]["R"][i][j].as<double>();
      }
    }
    EXPECT_LT((r * r.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-9);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-9);
    const Eigen::Vector3d t(view["cam_from_board"]["t"][0].as<double>(),
                            view["cam_from_board"]["t"][1].as<double>(),
                            view["cam_from_board"]["t"][2].as<double>());
    Eigen::Vector2d pixel;
    ASSERT_TRUE(start.scene.camera.Project(r * centre + t, &pixel));
    const Eigen::Vector2d said(view["centre_px"][0].as<double>(),
                               view["centre_px"][1].as<double>());
    EXPECT_LT((pixel - said).norm(), 3.0) << view["words"].as<std::string>();
    EXPECT_GT(view["expected_after"]["worst_px"].as<double>(), 0.0);
    EXPECT_TRUE(fs::exists(advice_file.parent_path() /
                           view["picture"].as<std::string>()));
  }
  EXPECT_LT(
      advice["views"][count - 1]["expected_after"]["worst_px"].as<double>(),
      advice["uncertainty_now"]["worst_px"].as<double>());
}

TEST(Advise, AdvisesPosesThatTheTruthCameraSeesWhereSaid) {
  const Start& start = RenderedStart();
  const fs::path out = Scratch() / "advice";
  const ProgramRun run = RunPuzzlecal(
      "advise --images " + Quote(start.photos.string()) + " --board " +
      Quote(start.board_file.string()) + " --out " + Quote(out.string()) +
      " --model pinhole-radtan --count 3 --threads 2");
  ASSERT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("next 1: board about"), std::string::npos);
  EXPECT_NE(run.out.find("next 3: board about"), std::string::npos);
  EXPECT_EQ(run.out.find("next 4:"), std::string::npos);
  ExpectPosesMatchTheTruth(out / "advice.yaml", start, 3);
  for (int k = 1; k <= 3; ++k) {
    const cv::Mat picture =
        cv::imread((out / ("next_" + std::to_string(k) + ".png")).string());
    ASSERT_FALSE(picture.empty()) << k;
    EXPECT_EQ(picture.cols, 1200);
  }
}

TEST(Advise, StartsFromKnownIntrinsics) {
  const Start& start = RenderedStart();
  const fs::path out = Scratch() / "advice_known";
  const ProgramRun run = RunPuzzlecal(
      "advise --images " + Quote(start.photos.string()) + " --board " +
      Quote(start.board_file.string()) + " --out " + Quote(out.string()) +
      " --camera " + Quote(start.truth_file.string()) + " --count 2");
  ASSERT_EQ(run.exit_code, 0);
  ExpectPosesMatchTheTruth(out / "advice.yaml", start, 2);
}

TEST(Advise, CalibrateReportCarriesTheAdviceWhenTheVerdictIsNotGood) {
  const Start& start = RenderedStart();
  const fs::path report = Scratch() / "report";
  const ProgramRun run =
      RunPuzzlecal("calibrate --images " + Quote(start.photos.string()) +
                   " --board " + Quote(start.board_file.string()) + " --out " +
                   Quote((Scratch() / "camera.yaml").string()) + " --report " +
                   Quote(report.string()) + " --model pinhole-radtan");
  ASSERT_EQ(run.exit_code, 0) << run.all();
  // Six views are fewer than the verdict asks for.
  EXPECT_NE(run.out.find("verdict: insufficient-data"), std::string::npos);
  EXPECT_NE(run.out.find("next photo ("), std::string::npos);
  const std::string summary = testing_files::ReadFile(report / "summary.md");
  EXPECT_NE(summary.find("## Next photos"), std::string::npos);
  EXPECT_NE(summary.find("![next photo 1](next_1.png)"), std::string::npos);
  ExpectPosesMatchTheTruth(report / "advice.yaml", start, 4);
}

TEST(Advise, RefusesBadInput) {
  const Start& start = RenderedStart();
  const fs::path empty = Scratch() / "empty";
  fs::create_directories(empty);
  ProgramRun run =
      RunPuzzlecal("advise --images " + Quote(empty.string()) + " --board " +
                   Quote(start.board_file.string()) + " --out " +
                   Quote((Scratch() / "no_advice").string()));
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_NE(run.err.find(empty.string()), std::string::npos);
  run =
      RunPuzzlecal("advise --images " + Quote(start.photos.string()) +
                   " --board " + Quote(start.board_file.string()) + " --out " +
                   Quote((Scratch() / "no_advice").string()) + " --count 0");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("count must be >= 1"), std::string::npos);
  run = RunPuzzlecal("advise --images " + Quote(start.photos.string()) +
                     " --board " + Quote(start.board_file.string()));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--out"), std::string::npos);
}

}  // namespace
}  // namespace advise_test
}  // namespace puzzlecal
