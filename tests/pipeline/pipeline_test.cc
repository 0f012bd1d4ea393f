// The per-image pipeline on rendered files: outcomes, ids against truth, and
// results that do not depend on the number of threads.

#include "pipeline/pipeline.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "sim/render.h"
#include "tests/decode/truth_components.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using decode_testing::LookAt;
using decode_testing::MakePuzzleBoard;
using decode_testing::PinholeCamera;

class PipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("puzzlecal_pipeline_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Renders a view to dir_/name and returns its truth.
  RenderTruth Render(const std::string& name, const Board& render_board,
                     const Eigen::Isometry3d& cam_from_board,
                     const RenderOptions& options = RenderOptions()) {
    RenderTruth truth;
    const cv::Mat image =
        RenderBoard(render_board, PinholeCamera(640, 480, 520), cam_from_board,
                    options, &truth);
    cv::imwrite((dir_ / name).string(), image);
    files_.push_back((dir_ / name).string());
    return truth;
  }

  fs::path dir_;
  std::vector<std::string> files_;
};

// Truth id of the visible corner nearest to `xy` (within 3 px), or (-1, -1).
Eigen::Vector2i TruthIdAt(const RenderTruth& truth, const Eigen::Vector2d& xy) {
  for (const TruthCorner& corner : truth.corners) {
    if (corner.visible && (corner.xy - xy).norm() < 3.0) return corner.id;
  }
  return Eigen::Vector2i(-1, -1);
}

TEST_F(PipelineTest, PuzzleBoardViewsGetTruthIdsAndBadFilesAReason) {
  const Board board = MakePuzzleBoard(23, 16, 50, 100, 0.03);
  std::map<std::string, RenderTruth> truth;
  truth["a.png"] =
      Render("a.png", board, LookAt(board, {61, 107.5}, 0.9, 20, 5));
  truth["b.png"] =
      Render("b.png", board, LookAt(board, {55, 104}, 0.5, 35, -20));
  std::ofstream((dir_ / "c.png").string()) << "not a png";
  files_.push_back((dir_ / "c.png").string());
  // A blank image: no corners.
  cv::imwrite((dir_ / "d.png").string(),
              cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)));
  files_.push_back((dir_ / "d.png").string());

  PipelineOptions options;
  const std::vector<ImageResult> results =
      ProcessImageFiles(files_, board, options, 2);
  ASSERT_EQ(results.size(), 4u);
  for (const char* name : {"a.png", "b.png"}) {
    const ImageResult& result = results[name[0] - 'a'];
    EXPECT_EQ(result.outcome, ImageOutcome::kUsable) << name << result.reason;
    EXPECT_TRUE(result.decode.absolute_ids) << name;
    EXPECT_GT(result.decode.observation.id.size(), 100u) << name;
    for (size_t k = 0; k < result.decode.observation.id.size(); ++k) {
      EXPECT_EQ(result.decode.observation.id[k],
                TruthIdAt(truth[name], result.decode.observation.xy[k]))
          << name << " point " << k;
    }
  }
  EXPECT_EQ(results[2].outcome, ImageOutcome::kUnreadable);
  EXPECT_NE(results[2].reason.find("c.png"), std::string::npos)
      << results[2].reason;
  EXPECT_EQ(results[3].outcome, ImageOutcome::kNoCorners);
}

TEST_F(PipelineTest, ResultsDoNotDependOnTheThreadCount) {
  const Board board = MakePuzzleBoard(11, 8, 0, 0, 0.06);
  for (int v = 0; v < 5; ++v) {
    Render("v" + std::to_string(v) + ".png", board,
           LookAt(board, {5, 3.5}, 1.0 + 0.1 * v, 10.0 * v, 15.0 * v));
  }
  const PipelineOptions options;
  const std::vector<ImageResult> one =
      ProcessImageFiles(files_, board, options, 1);
  const std::vector<ImageResult> three =
      ProcessImageFiles(files_, board, options, 3);
  ASSERT_EQ(one.size(), three.size());
  for (size_t i = 0; i < one.size(); ++i) {
    // Every view is decoded (an unusable view would compare nothing).
    EXPECT_EQ(one[i].outcome, ImageOutcome::kUsable) << one[i].file;
    EXPECT_GE(one[i].decode.observation.id.size(), 44u) << one[i].file;
    EXPECT_EQ(one[i].file, three[i].file);
    EXPECT_EQ(one[i].outcome, three[i].outcome);
    ASSERT_EQ(one[i].decode.observation.id.size(),
              three[i].decode.observation.id.size());
    for (size_t k = 0; k < one[i].decode.observation.id.size(); ++k) {
      EXPECT_EQ(one[i].decode.observation.id[k],
                three[i].decode.observation.id[k]);
      EXPECT_EQ(one[i].decode.observation.xy[k],
                three[i].decode.observation.xy[k]);
    }
  }
}

TEST_F(PipelineTest, CheckerboardViewKeepsOneConsistentComponent) {
  Board board =
      MakeBoard(BoardType::kCheckerboard, 11, 8, Eigen::Vector2i::Zero(), 0.02);
  // Cut by the image border: a partial view, labels stay relative.
  RenderOptions render_options;
  const RenderTruth truth =
      Render("partial.png", board, LookAt(board, {1.5, 3.5}, 0.25, 20, 10),
             render_options);
  int visible = 0;
  for (const TruthCorner& c : truth.corners) visible += c.visible;
  ASSERT_LT(visible, board.NumCorners());
  const std::vector<ImageResult> results =
      ProcessImageFiles(files_, board, PipelineOptions(), 1);
  ASSERT_EQ(results.size(), 1u);
  const ImageResult& result = results[0];
  ASSERT_EQ(result.outcome, ImageOutcome::kUsable) << result.reason;
  const BoardObservation& obs = result.decode.observation;
  ASSERT_GE(obs.id.size(), 0.9 * visible);
  // One component only, and its labels are a lattice motion of the truth:
  // label differences between points equal truth id differences up to one
  // fixed rotation/reflection.
  for (int component : result.decode.component) {
    EXPECT_EQ(component, result.decode.component[0]);
  }
  const Eigen::Vector2i truth0 = TruthIdAt(truth, obs.xy[0]);
  const Eigen::Vector2i truth1 = TruthIdAt(truth, obs.xy[1]);
  ASSERT_NE(truth0.x(), -1);
  ASSERT_NE(truth1.x(), -1);
  int consistent_transforms = 0;
  for (int a = -1; a <= 1; ++a) {
    for (int b = -1; b <= 1; ++b) {
      for (int swap = 0; swap < 2; ++swap) {
        if (a == 0 || b == 0) continue;
        Eigen::Matrix2i m = Eigen::Matrix2i::Zero();
        if (swap) {
          m(0, 1) = a;
          m(1, 0) = b;
        } else {
          m(0, 0) = a;
          m(1, 1) = b;
        }
        bool all = true;
        for (size_t k = 0; k < obs.id.size() && all; ++k) {
          const Eigen::Vector2i t = TruthIdAt(truth, obs.xy[k]);
          all = (m * (obs.id[k] - obs.id[0])) == (t - truth0);
        }
        consistent_transforms += all;
      }
    }
  }
  EXPECT_EQ(consistent_transforms, 1);
}

// Views come from the image size most usable images have, whichever comes
// first; the others are marked with both sizes.
TEST(MakeCalibrationViewsTest, UsesTheSizeMostImagesHave) {
  const Board board =
      MakeBoard(BoardType::kPuzzleBoard, 11, 8, Eigen::Vector2i(0, 0), 0.02);
  std::vector<ImageResult> images(5);
  const int sizes[5][2] = {
      {800, 600}, {640, 480}, {640, 480}, {1024, 768}, {640, 480}};
  for (int i = 0; i < 5; ++i) {
    images[i].file = "view" + std::to_string(i) + ".png";
    images[i].outcome = ImageOutcome::kUsable;
    images[i].width = sizes[i][0];
    images[i].height = sizes[i][1];
    for (int k = 0; k < 6; ++k) {
      images[i].decode.observation.id.emplace_back(k, 0);
      images[i].decode.observation.xy.emplace_back(10.0 * k, 5.0);
    }
  }
  images[3].outcome = ImageOutcome::kNoGrid;  // not usable: not counted
  int width = 0, height = 0;
  const std::vector<CalibrationView> views =
      MakeCalibrationViews(board, &images, &width, &height);
  EXPECT_EQ(width, 640);
  EXPECT_EQ(height, 480);
  ASSERT_EQ(views.size(), 3u);
  std::vector<int> view_index;
  for (const ImageResult& image : images)
    view_index.push_back(image.view_index);
  EXPECT_EQ(view_index, (std::vector<int>{-1, 0, 1, -1, 2}));
  EXPECT_EQ(ViewFiles(images, views.size()),
            (std::vector<std::string>{images[1].file, images[2].file,
                                      images[4].file}));
  EXPECT_EQ(images[0].outcome, ImageOutcome::kSizeMismatch);
  EXPECT_NE(images[0].reason.find("800x600 differs from the 640x480"),
            std::string::npos)
      << images[0].reason;
  EXPECT_EQ(images[3].outcome, ImageOutcome::kNoGrid);
  EXPECT_EQ(views[0].board_points[2], board.Point(Eigen::Vector2i(2, 0)));
}

// A rendered photo and a byte-for-byte copy under another name (sorted
// after it) in one folder: the copy is no second view. It is marked with
// the photo it repeats; a file of the same size with other bytes, and the
// photo itself, stay views.
TEST_F(PipelineTest, CopyOfAnEarlierPhotoIsNoView) {
  const Board board = MakePuzzleBoard(11, 8, 0, 0, 0.06);
  Render("a.png", board, LookAt(board, {5, 3.5}, 1.0, 10.0, 15.0));
  Render("b.png", board, LookAt(board, {5, 3.5}, 1.1, 20.0, 30.0));
  fs::copy_file(dir_ / "a.png", dir_ / "c.png");
  files_.push_back((dir_ / "c.png").string());
  std::vector<ImageResult> images =
      ProcessImageFiles(files_, board, PipelineOptions(), 2);
  ASSERT_EQ(images.size(), 3u);
  for (const ImageResult& image : images) {
    ASSERT_EQ(image.outcome, ImageOutcome::kUsable) << image.reason;
  }
  int width = 0, height = 0;
  const std::vector<CalibrationView> views =
      MakeCalibrationViews(board, &images, &width, &height);
  ASSERT_EQ(views.size(), 2u);
  EXPECT_EQ(views[0].name, "a.png");
  EXPECT_EQ(views[1].name, "b.png");
  EXPECT_EQ(images[2].outcome, ImageOutcome::kRepeatedPhoto);
  EXPECT_EQ(images[2].reason, "not used: the same photo as a.png");
  EXPECT_EQ(images[2].view_index, -1);
  EXPECT_STREQ(ImageOutcomeName(images[2].outcome), "repeated photo");

  // Files of one size: only equal bytes make a copy, whatever the hash.
  std::vector<ImageResult> records(4);
  const std::string contents[4] = {"0123456789", "0123456788", "0123456789",
                                   "0123456788"};
  for (int i = 0; i < 4; ++i) {
    const fs::path file = dir_ / ("same_size_" + std::to_string(i) + ".bin");
    std::ofstream(file, std::ios::binary) << contents[i];
    records[i].file = file.string();
    records[i].outcome = ImageOutcome::kUsable;
  }
  records[1].outcome = ImageOutcome::kNoGrid;  // not a view: not compared
  EXPECT_EQ(MarkRepeatedPhotos(&records), 1);
  EXPECT_EQ(records[0].outcome, ImageOutcome::kUsable);
  EXPECT_EQ(records[1].outcome, ImageOutcome::kNoGrid);
  EXPECT_EQ(records[2].outcome, ImageOutcome::kRepeatedPhoto);
  EXPECT_EQ(records[2].reason, "not used: the same photo as same_size_0.bin");
  EXPECT_EQ(records[3].outcome, ImageOutcome::kUsable);
}

}  // namespace
}  // namespace puzzlecal
