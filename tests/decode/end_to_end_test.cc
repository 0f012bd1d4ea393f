// DetectCorners -> BuildGrid -> DecodeBoard on sim/ renders: every decoded id
// must be the truth id of the corner at that position.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "decode/decoder.h"
#include "detection/detector.h"
#include "grid/grid.h"
#include "sim/scenes.h"
#include "sim/synthetic_views.h"
#include "tests/decode/truth_components.h"

namespace puzzlecal {
namespace {

using decode_testing::FisheyeCamera;
using decode_testing::LookAt;
using decode_testing::MakePuzzleBoard;
using decode_testing::PinholeCamera;

struct Outcome {
  int decoded_ids = 0;
  int wrong_ids = 0;  // id differs from the nearest truth corner's
  int unmatched = 0;  // no truth corner within `match_px` (a spurious corner)
  int visible = 0;    // visible truth corners
  std::string reason;
};

// `match_px`: radius within which a detected corner is that truth corner
// (less than half a tile, so the match is unambiguous).
Outcome RunPipeline(const Board& board, const Camera& camera,
                    const Eigen::Isometry3d& cam_from_board,
                    const RenderOptions& render_options, double match_px,
                    const DecodeOptions& decode_options = DecodeOptions()) {
  RenderTruth truth;
  const cv::Mat image =
      RenderBoard(board, camera, cam_from_board, render_options, &truth);
  const std::vector<Corner> corners = DetectCorners(image);
  const std::vector<GridComponent> components = BuildGrid(corners, image);
  const DecodeResult result =
      DecodeBoard(board, corners, components, image, decode_options);
  Outcome outcome;
  outcome.reason = result.reason;
  for (const TruthCorner& c : truth.corners)
    outcome.visible += c.visible ? 1 : 0;
  if (!result.decoded) return outcome;
  for (size_t k = 0; k < result.observation.id.size(); ++k) {
    ++outcome.decoded_ids;
    const TruthCorner* nearest = nullptr;
    double best = match_px;
    for (const TruthCorner& c : truth.corners) {
      if (!c.xy.allFinite()) continue;
      const double d = (c.xy - result.observation.xy[k]).norm();
      if (d < best) {
        best = d;
        nearest = &c;
      }
    }
    if (nearest == nullptr) {
      ++outcome.unmatched;
    } else if (nearest->id != result.observation.id[k]) {
      ++outcome.wrong_ids;
    }
  }
  return outcome;
}

TEST(EndToEnd, PinholeViewWithOccluderDecodesCorrectly) {
  const Board board = MakePuzzleBoard(23, 16, 50, 100, 0.03);
  RenderOptions options;
  options.noise_sigma = 0.02;
  Occluder occluder;
  occluder.center_px = Eigen::Vector2d(640, 480);
  occluder.radius_px = 70;
  options.occluders.push_back(occluder);
  const Outcome outcome =
      RunPipeline(board, PinholeCamera(1280, 960, 800),
                  LookAt(board, {61, 107.5}, 1.0, 25, 10), options, 8.0);
  EXPECT_EQ(outcome.wrong_ids, 0);
  EXPECT_EQ(outcome.unmatched, 0);
  EXPECT_GT(outcome.decoded_ids, 0.9 * outcome.visible) << outcome.reason;
}

TEST(EndToEnd, FisheyeViewDecodesCorrectly) {
  const Board board = MakePuzzleBoard(23, 16, 50, 100, 0.03);
  RenderOptions options;
  options.noise_sigma = 0.02;
  const Outcome outcome = RunPipeline(
      board, FisheyeCamera(1280, 960, 330, -0.02),
      LookAt(board, {61, 107.5}, 0.55, 40, 30, {0.12, -0.08}), options, 6.0);
  EXPECT_EQ(outcome.wrong_ids, 0);
  EXPECT_EQ(outcome.unmatched, 0);
  EXPECT_GT(outcome.decoded_ids, 0.8 * outcome.visible) << outcome.reason;
}

TEST(EndToEnd, SmallTilesDecodeCorrectly) {
  const Board board = MakePuzzleBoard(72, 52, 100, 200, 0.01);
  RenderOptions options;
  options.noise_sigma = 0.02;
  // About 10 px per tile.
  const Outcome outcome =
      RunPipeline(board, PinholeCamera(1280, 960, 800),
                  LookAt(board, {135.5, 225.5}, 0.8, 20, 5), options, 4.0);
  EXPECT_EQ(outcome.wrong_ids, 0);
  EXPECT_EQ(outcome.unmatched, 0);
  EXPECT_GT(outcome.decoded_ids, 0.8 * outcome.visible) << outcome.reason;
}

// A steep view through a lens that distorts strongly and unevenly
// (sim::TruthBumpyFisheye; the pose is the fourth view the capture advice
// gives for it in bench_advise): the grid splits the board into three
// components, and the largest joins a row of 11 corners one step askew
// (their labels shifted by a diagonal), which widens its labels one row
// past the board. Its bits agree 277 of 281 at the true position; with
// every label held on the board (max_label_overhang 0) that position is
// not searched and the component is refused, losing 166 of the 359
// corners. Now the overhanging labels and the board's outermost row on
// that side are dropped and the rest decodes.
TEST(EndToEnd, AskewRowOfLabelsDoesNotHideTheTruePosition) {
  // The sample scene's board and rendering, as bench_advise renders it.
  const SceneSpec scene = SampleScene();
  const Board& board = scene.board;
  RenderOptions options = scene.render;
  options.seed = 203;
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d angle_axis(-0.41862897639958113, 0.11402208123296614,
                                   -0.12435524421527568);
  cam_from_board.linear() =
      Eigen::AngleAxisd(angle_axis.norm(), angle_axis.normalized())
          .toRotationMatrix();
  cam_from_board.translation() =
      Eigen::Vector3d(-2.268181469128256, -2.7282497571653872,
                      1.6753430373048488);
  const Camera camera = sim::TruthBumpyFisheye();
  const Outcome outcome =
      RunPipeline(board, camera, cam_from_board, options, 6.0);
  DecodeOptions on_board;
  on_board.max_label_overhang = 0;
  const Outcome held =
      RunPipeline(board, camera, cam_from_board, options, 6.0, on_board);
  // Measured: 336 of 368 visible corners decoded, none wrong; 192 with the
  // labels held on the board. The askew row's corners and a false corner
  // the grid joined beside it (25 px from the corner whose id it would
  // get) are dropped, not given ids.
  EXPECT_EQ(outcome.unmatched, 0);
  EXPECT_EQ(outcome.wrong_ids, 0) << outcome.reason;
  EXPECT_GT(outcome.decoded_ids, 0.85 * outcome.visible) << outcome.reason;
  EXPECT_LT(held.decoded_ids, 0.6 * outcome.visible) << held.reason;
}

TEST(EndToEnd, MirroredPrintIsRefused) {
  const Board board = MakePuzzleBoard(23, 16, 50, 100, 0.03);
  RenderOptions options;
  options.noise_sigma = 0.02;
  options.variant.mirrored = true;
  const Outcome outcome =
      RunPipeline(board, PinholeCamera(1280, 960, 800),
                  LookAt(board, {61, 107.5}, 1.0, 25, 10), options, 8.0);
  EXPECT_EQ(outcome.decoded_ids, 0) << "mirrored print accepted";
  EXPECT_FALSE(outcome.reason.empty());
}

}  // namespace
}  // namespace puzzlecal
