// DecodeBoard against sim/ renders with exact truth. Components are built from
// the truth corners and relabelled by a rotation/reflection and offset, as
// grid/ would label them; decoded ids must equal the truth ids.

#include "decode/decoder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>

#include "target/puzzleboard.h"
#include "tests/decode/truth_components.h"

namespace puzzlecal {
namespace {

using decode_testing::FisheyeCamera;
using decode_testing::LookAt;
using decode_testing::MakePuzzleBoard;
using decode_testing::OneComponentFromTruth;
using decode_testing::PinholeCamera;
using decode_testing::RandomSignedPermutation;
using decode_testing::TruthGrid;

struct Render {
  cv::Mat image;
  RenderTruth truth;
};

Render RenderView(const Board& board, const Camera& camera,
                  const Eigen::Isometry3d& cam_from_board,
                  const PatternVariant& variant = PatternVariant(),
                  double noise = 0.02) {
  RenderOptions options;
  options.noise_sigma = noise;
  options.variant = variant;
  Render render;
  render.image =
      RenderBoard(board, camera, cam_from_board, options, &render.truth);
  return render;
}

Board Board23x16() { return MakePuzzleBoard(23, 16, 50, 100, 0.03); }

Render FrontView23x16(const PatternVariant& variant) {
  const Board board = Board23x16();
  return RenderView(board, PinholeCamera(1280, 960, 800),
                    LookAt(board, {61, 107.5}, 1.0, 20, 10), variant);
}

// The true pattern's view, rendered once for all tests.
const Render& FrontView23x16() {
  static const Render render = FrontView23x16(PatternVariant());
  return render;
}

// Number of observation points whose id differs from the truth id.
int WrongIds(const DecodeResult& result, const TruthGrid& grid) {
  int wrong = 0;
  for (size_t k = 0; k < result.observation.id.size(); ++k) {
    if (result.observation.id[k] != grid.truth_id[result.corner_index[k]])
      ++wrong;
  }
  return wrong;
}

std::vector<Eigen::Matrix2i> AllLabelTransforms() {
  std::vector<Eigen::Matrix2i> all = LabelRotations(1);
  for (const Eigen::Matrix2i& m : LabelRotations(-1)) all.push_back(m);
  return all;
}

TEST(DecodeOptions, CheckNamesTheBadField) {
  DecodeOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.min_agreement = 0.3;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("min_agreement"), std::string::npos);
  options = DecodeOptions();
  options.bits.min_confidence = 0.0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("min_confidence"), std::string::npos);
  options = DecodeOptions();
  options.max_log10_nfa = 1.0;
  EXPECT_FALSE(options.Check(&why));
  options = DecodeOptions();
  options.min_margin = 0;
  EXPECT_FALSE(options.Check(&why));
}

TEST(DecodeBoard, FullViewDecodesUnderEveryLabelTransform) {
  const Board board = Board23x16();
  const Render render = FrontView23x16();
  for (const Eigen::Matrix2i& label_from_id : AllLabelTransforms()) {
    const TruthGrid grid = OneComponentFromTruth(render.truth, label_from_id,
                                                 Eigen::Vector2i(-7, 31));
    ASSERT_EQ(grid.corners.size(), 368u);
    const DecodeResult result =
        DecodeBoard(board, grid.corners, grid.components, render.image);
    ASSERT_TRUE(result.decoded) << result.reason;
    EXPECT_TRUE(result.absolute_ids);
    EXPECT_EQ(result.observation.id.size(), 368u);
    EXPECT_EQ(WrongIds(result, grid), 0);
    const ComponentDecoding& c = result.components[0];
    EXPECT_EQ(c.handedness, label_from_id.determinant());
    EXPECT_EQ(c.bits_read, c.edges);
    EXPECT_EQ(c.edges, 22 * 16 + 23 * 15);
    EXPECT_DOUBLE_EQ(c.agreement, 1.0);
    EXPECT_LT(c.log10_nfa, -30.0);
    // The map is the inverse of the relabelling.
    EXPECT_EQ(c.rotation * label_from_id, Eigen::Matrix2i::Identity());
    for (size_t k = 0; k < result.observation.id.size(); ++k) {
      EXPECT_TRUE(board.Contains(result.observation.id[k]));
    }
  }
}

TEST(DecodeBoard, StrongFisheyeAndSteepTiltDecodeWithoutWrongIds) {
  const Board board = Board23x16();
  std::mt19937 rng(5);
  struct Case {
    Camera camera;
    Eigen::Isometry3d pose;
  };
  const Case cases[] = {
      // Equidistant fisheye, board close and near the image edge (curved).
      {FisheyeCamera(1280, 960, 330, -0.02),
       LookAt(board, {61, 107.5}, 0.55, 50, 30, {0.16, -0.1})},
      // Viewing angle 20 degrees (tilt 70).
      {PinholeCamera(1280, 960, 900), LookAt(board, {61, 107.5}, 1.1, 70, 20)},
  };
  for (const Case& c : cases) {
    const Render render = RenderView(board, c.camera, c.pose);
    const TruthGrid grid = OneComponentFromTruth(
        render.truth, RandomSignedPermutation(&rng), Eigen::Vector2i(3, 3));
    ASSERT_GT(grid.corners.size(), 100u);
    const DecodeResult result =
        DecodeBoard(board, grid.corners, grid.components, render.image);
    ASSERT_TRUE(result.decoded) << result.reason;
    EXPECT_EQ(WrongIds(result, grid), 0);
    EXPECT_GT(result.observation.id.size(), 0.95 * grid.corners.size());
  }
}

// Every (k+1)x(k+1)-corner window of the render that is fully visible.
TruthGrid WindowGrid(const RenderTruth& truth, int x0, int y0, int k,
                     std::mt19937* rng) {
  return OneComponentFromTruth(truth, RandomSignedPermutation(rng),
                               Eigen::Vector2i(11, -4),
                               [=](const Eigen::Vector2i& id) {
                                 return id.x() >= x0 && id.x() <= x0 + k &&
                                        id.y() >= y0 && id.y() <= y0 + k;
                               });
}

TEST(DecodeBoard, SmallWindowsOfSixPixelTilesDecodeWithoutWrongIds) {
  // 72 x 52 board, tiles of about 6 px, tilted 15 degrees.
  const Board board = MakePuzzleBoard(72, 52, 100, 200, 0.01);
  const double tile_px = 6.0;
  const Render render = RenderView(
      board, PinholeCamera(1280, 960, 800),
      LookAt(board, {135.5, 225.5}, 800 * board.tile_size_m / tile_px, 15, 5),
      {}, 0.03);
  std::mt19937 rng(7);
  for (int k : {3, 4}) {
    int trials = 0, decoded = 0;
    for (int x0 = 102; x0 < 165; x0 += 9) {
      for (int y0 = 203; y0 < 245; y0 += 9) {
        const TruthGrid grid = WindowGrid(render.truth, x0, y0, k, &rng);
        ASSERT_EQ(static_cast<int>(grid.corners.size()), (k + 1) * (k + 1));
        const DecodeResult result =
            DecodeBoard(board, grid.corners, grid.components, render.image);
        ++trials;
        if (!result.decoded) continue;
        ++decoded;
        EXPECT_EQ(WrongIds(result, grid), 0) << k << " " << x0 << " " << y0;
      }
    }
    // Measured by bench_decode: 98 % of 3x3 and 100 % of 4x4 windows; 3x3
    // windows whose nearest other window differs in one bit are refused.
    EXPECT_GE(decoded, (k == 3 ? 0.85 : 1.0) * trials) << k;
  }
}

TEST(DecodeBoard, FlippedBitsAreCorrectedOrRefusedNeverWrong) {
  const Board board = MakePuzzleBoard(72, 52, 100, 200, 0.01);
  const Render render =
      RenderView(board, PinholeCamera(1280, 960, 800),
                 LookAt(board, {135.5, 225.5}, 0.8, 10, 0), {}, 0.0);
  const DecodeOptions options;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (double flip_rate : {0.1, 0.2}) {
    int decoded = 0, trials = 0;
    for (int trial = 0; trial < 60; ++trial) {
      const int k = 7;
      const TruthGrid grid = WindowGrid(render.truth, 101 + (trial * 7) % 60,
                                        201 + (trial * 5) % 40, k, &rng);
      LabelLattice lattice;
      std::string why;
      ASSERT_TRUE(BuildLabelLattice(grid.corners, grid.components[0],
                                    options.max_label_extent, &lattice, &why));
      EdgeBitReading reading =
          ReadEdgeBits(lattice, render.image, options.bits);
      ASSERT_EQ(reading.num_read, 2 * k * (k + 1));
      for (EdgeBit& edge : reading.edges) {
        if (uniform(rng) < flip_rate) edge.confidence = -edge.confidence;
      }
      ComponentDecoding decoding;
      decoding.handedness = LabelHandedness(lattice);
      LabelToBoard map;
      std::vector<char> keep;
      ++trials;
      if (!DecodeComponentBits(lattice, reading, board, options, &decoding,
                               &map, &keep)) {
        EXPECT_FALSE(decoding.reason.empty());
        continue;
      }
      ++decoded;
      for (size_t p = 0; p < lattice.xy.size(); ++p) {
        EXPECT_EQ(map.Apply(lattice.label[p]),
                  grid.truth_id[lattice.corner_index[p]]);
      }
    }
    // bench_decode: 7x7 windows decode 100 % at 10 % and ~65 % at 20 %.
    EXPECT_GE(decoded, (flip_rate < 0.15 ? 0.95 : 0.4) * trials) << flip_rate;
  }
}

TEST(DecodeBoard, OtherCodesMirroredInvertedAndPlainPrintsAreRefused) {
  const Board board = Board23x16();
  std::mt19937 rng(13);
  std::vector<PatternVariant> variants(5);
  variants[0].random_code_seed = 77;
  variants[1].random_code_seed = 12345;
  variants[2].mirrored = true;
  variants[3].inverted = true;
  variants[4].mirrored = true;
  variants[4].inverted = true;
  for (size_t v = 0; v < variants.size(); ++v) {
    const Render render = FrontView23x16(variants[v]);
    for (int trial = 0; trial < 2; ++trial) {
      const TruthGrid grid = OneComponentFromTruth(
          render.truth, RandomSignedPermutation(&rng), Eigen::Vector2i(0, 0));
      ASSERT_GT(grid.corners.size(), 300u);
      const DecodeResult result =
          DecodeBoard(board, grid.corners, grid.components, render.image);
      EXPECT_FALSE(result.decoded) << "variant " << v;
      EXPECT_FALSE(result.absolute_ids);
      EXPECT_FALSE(result.reason.empty());
      // Not decoded: relative labels of every corner are still there.
      EXPECT_EQ(result.observation.id.size(), grid.corners.size());
      if (v == 2) {
        EXPECT_NE(result.reason.find("mirrored"), std::string::npos)
            << result.reason;
        EXPECT_GT(result.components[0].mirrored_agreement, 0.95);
      }
      if (v == 3) {
        EXPECT_GT(result.components[0].inverted_agreement, 0.95);
      }
    }
  }
  // A plain checkerboard decoded as a PuzzleBoard: no bits to read.
  Board plain = board;
  plain.type = BoardType::kCheckerboard;
  plain.origin = Eigen::Vector2i::Zero();
  const Render render = RenderView(plain, PinholeCamera(1280, 960, 800),
                                   LookAt(plain, {11, 7.5}, 1.0, 20, 10));
  TruthGrid grid = OneComponentFromTruth(
      render.truth, Eigen::Matrix2i::Identity(), Eigen::Vector2i(0, 0));
  const DecodeResult result =
      DecodeBoard(board, grid.corners, grid.components, render.image);
  EXPECT_FALSE(result.decoded);
  EXPECT_NE(result.reason.find("readable"), std::string::npos) << result.reason;
  EXPECT_LT(result.components[0].bits_read, 0.05 * result.components[0].edges);
}

TEST(DecodeBoard, ComponentsSplitByAnOccluderAreJoined) {
  const Board board = Board23x16();
  const Render render = FrontView23x16();
  // Columns 60 and 61 hidden: components left and right, labelled differently.
  const TruthGrid left = OneComponentFromTruth(
      render.truth, LabelRotations(1)[1], Eigen::Vector2i(4, 4),
      [](const Eigen::Vector2i& id) { return id.x() < 60; });
  const TruthGrid right = OneComponentFromTruth(
      render.truth, LabelRotations(-1)[2], Eigen::Vector2i(-9, 2),
      [](const Eigen::Vector2i& id) { return id.x() > 61; });
  TruthGrid both = left;
  for (size_t k = 0; k < right.corners.size(); ++k) {
    both.corners.push_back(right.corners[k]);
    both.truth_id.push_back(right.truth_id[k]);
  }
  both.components.push_back(right.components[0]);
  for (int& index : both.components[1].corner)
    index += static_cast<int>(left.corners.size());
  const DecodeResult result =
      DecodeBoard(board, both.corners, both.components, render.image);
  ASSERT_TRUE(result.decoded) << result.reason;
  ASSERT_TRUE(result.components[0].decoded) << result.components[0].reason;
  ASSERT_TRUE(result.components[1].decoded) << result.components[1].reason;
  EXPECT_EQ(result.observation.id.size(), both.corners.size());
  EXPECT_EQ(WrongIds(result, both), 0);
  std::set<int> components(result.component.begin(), result.component.end());
  EXPECT_EQ(components, (std::set<int>{0, 1}));
}

TEST(DecodeBoard, IdsClaimedTwiceAreDropped) {
  const Board board = Board23x16();
  const Render render = FrontView23x16();
  // Two overlapping components: columns <= 62 and >= 58 share 5 columns.
  TruthGrid a = OneComponentFromTruth(
      render.truth, Eigen::Matrix2i::Identity(), {0, 0},
      [](const Eigen::Vector2i& id) { return id.x() <= 62; });
  const TruthGrid b = OneComponentFromTruth(
      render.truth, Eigen::Matrix2i::Identity(), {0, 0},
      [](const Eigen::Vector2i& id) { return id.x() >= 58; });
  const int offset = static_cast<int>(a.corners.size());
  a.corners.insert(a.corners.end(), b.corners.begin(), b.corners.end());
  a.truth_id.insert(a.truth_id.end(), b.truth_id.begin(), b.truth_id.end());
  a.components.push_back(b.components[0]);
  for (int& index : a.components[1].corner) index += offset;
  const DecodeResult result =
      DecodeBoard(board, a.corners, a.components, render.image);
  ASSERT_TRUE(result.decoded) << result.reason;
  std::set<std::pair<int, int>> ids;
  for (const Eigen::Vector2i& id : result.observation.id) {
    EXPECT_TRUE(ids.insert({id.x(), id.y()}).second) << "duplicate id";
    EXPECT_TRUE(id.x() < 58 || id.x() > 62) << "shared id kept";
  }
  EXPECT_EQ(WrongIds(result, a), 0);
  EXPECT_EQ(static_cast<int>(result.observation.id.size()), 23 * 16 - 5 * 16);
}

TEST(DecodeBoard, MislabelledCornerIsDropped) {
  const Board board = Board23x16();
  const Render& render = FrontView23x16();
  // Corner (57, 108) removed; corner (56, 109) wrongly labelled as (57, 108),
  // a diagonal slip as grid/ can make.
  TruthGrid grid = OneComponentFromTruth(
      render.truth, Eigen::Matrix2i::Identity(), {0, 0},
      [](const Eigen::Vector2i& id) { return id != Eigen::Vector2i(57, 108); });
  int slipped = -1;
  for (size_t k = 0; k < grid.corners.size(); ++k) {
    if (grid.truth_id[k] == Eigen::Vector2i(56, 109))
      slipped = static_cast<int>(k);
  }
  ASSERT_GE(slipped, 0);
  grid.components[0].ij[slipped] = Eigen::Vector2i(57, 108);
  const DecodeResult result =
      DecodeBoard(board, grid.corners, grid.components, render.image);
  ASSERT_TRUE(result.decoded) << result.reason;
  for (size_t k = 0; k < result.observation.id.size(); ++k) {
    EXPECT_NE(result.corner_index[k], slipped) << "mislabelled corner kept";
  }
  EXPECT_EQ(WrongIds(result, grid), 0);
  EXPECT_GE(result.components[0].corners_dropped, 1);
  EXPECT_GE(result.observation.id.size(), grid.corners.size() - 3);
}

TEST(DecodeBoard, CheckerboardSpanningTheBoardGetsBoardIdsUpToSymmetry) {
  Board board =
      MakeBoard(BoardType::kCheckerboard, 11, 8, Eigen::Vector2i::Zero(), 0.02);
  const Render render = RenderView(board, PinholeCamera(1280, 960, 800),
                                   LookAt(board, {5, 3.5}, 0.5, 25, 100));
  std::mt19937 rng(17);
  for (const Eigen::Matrix2i& label_from_id : AllLabelTransforms()) {
    const TruthGrid grid =
        OneComponentFromTruth(render.truth, label_from_id, {40, -3});
    ASSERT_EQ(grid.corners.size(), 88u);
    const DecodeResult result =
        DecodeBoard(board, grid.corners, grid.components, cv::Mat());
    ASSERT_TRUE(result.decoded) << result.reason;
    EXPECT_TRUE(result.absolute_ids);
    // Either every id is the truth id or every id is its 180-degree twin.
    int same = 0, twin = 0;
    for (size_t k = 0; k < result.observation.id.size(); ++k) {
      const Eigen::Vector2i truth = grid.truth_id[result.corner_index[k]];
      const Eigen::Vector2i id = result.observation.id[k];
      if (id == truth) ++same;
      if (id == Eigen::Vector2i(10, 7) - truth) ++twin;
      EXPECT_TRUE(board.Contains(id));
    }
    EXPECT_TRUE(same == 88 || twin == 88) << same << " " << twin;
  }
  // A partial view keeps right-handed relative labels starting at (0, 0).
  const TruthGrid partial = OneComponentFromTruth(
      render.truth, LabelRotations(-1)[3], {5, 5},
      [](const Eigen::Vector2i& id) { return id.x() >= 2 && id.y() >= 1; });
  const DecodeResult result =
      DecodeBoard(board, partial.corners, partial.components, cv::Mat());
  EXPECT_FALSE(result.decoded);
  EXPECT_FALSE(result.absolute_ids);
  ASSERT_EQ(result.observation.id.size(), partial.corners.size());
  // Relative label = R * truth + t with a proper rotation R.
  const Eigen::Vector2i t0 = result.observation.id[0];
  const Eigen::Vector2i truth0 = partial.truth_id[result.corner_index[0]];
  Eigen::Vector2i lo(1 << 20, 1 << 20);
  bool consistent_with_some_rotation = false;
  for (const Eigen::Matrix2i& r : LabelRotations(1)) {
    bool all = true;
    for (size_t k = 0; k < result.observation.id.size(); ++k) {
      const Eigen::Vector2i truth = partial.truth_id[result.corner_index[k]];
      all = all && (result.observation.id[k] - t0 == r * (truth - truth0));
    }
    consistent_with_some_rotation = consistent_with_some_rotation || all;
  }
  EXPECT_TRUE(consistent_with_some_rotation);
  for (const Eigen::Vector2i& id : result.observation.id) lo = lo.cwiseMin(id);
  EXPECT_EQ(lo, Eigen::Vector2i(0, 0));
}

TEST(DecodeBoard, BadInputGivesReasonsNotCrashes) {
  const Board board = Board23x16();
  const Render render = FrontView23x16();
  TruthGrid grid =
      OneComponentFromTruth(render.truth, Eigen::Matrix2i::Identity(), {0, 0});
  // Empty image.
  DecodeResult result =
      DecodeBoard(board, grid.corners, grid.components, cv::Mat());
  EXPECT_FALSE(result.decoded);
  EXPECT_NE(result.reason.find("empty image"), std::string::npos)
      << result.reason;
  // No components.
  result = DecodeBoard(board, grid.corners, {}, render.image);
  EXPECT_FALSE(result.decoded);
  EXPECT_FALSE(result.reason.empty());
  // Invalid board.
  Board bad = board;
  bad.cols = 0;
  result = DecodeBoard(bad, grid.corners, grid.components, render.image);
  EXPECT_NE(result.reason.find("invalid board"), std::string::npos);
  // NaN positions, out-of-range indices, mismatched sizes, duplicate labels.
  TruthGrid broken = grid;
  broken.corners[0].xy.x() = std::numeric_limits<double>::quiet_NaN();
  broken.components[0].corner[1] = 100000;
  broken.components[0].corner[2] = -5;
  broken.components[0].ij[4] = broken.components[0].ij[5];
  broken.components[0].ij.pop_back();
  result = DecodeBoard(board, broken.corners, broken.components, render.image);
  ASSERT_TRUE(result.decoded) << result.reason;
  EXPECT_EQ(WrongIds(result, broken), 0);
  EXPECT_LE(result.observation.id.size(), grid.corners.size() - 6);
  // A single row of corners has no second lattice direction.
  TruthGrid row = OneComponentFromTruth(
      render.truth, Eigen::Matrix2i::Identity(), {0, 0},
      [](const Eigen::Vector2i& id) { return id.y() == 104; });
  result = DecodeBoard(board, row.corners, row.components, render.image);
  EXPECT_FALSE(result.decoded);
  EXPECT_FALSE(result.components[0].reason.empty());
  // A huge label extent is refused.
  TruthGrid far = grid;
  far.components[0].ij[0] = Eigen::Vector2i(1 << 22, 0);
  result = DecodeBoard(board, far.corners, far.components, render.image);
  EXPECT_NE(result.components[0].reason.find("extent"), std::string::npos)
      << result.components[0].reason;
}

TEST(DecodeBoard, SameInputSameOutput) {
  const Board board = Board23x16();
  const Render render = FrontView23x16();
  std::mt19937 rng(3);
  const TruthGrid grid = OneComponentFromTruth(
      render.truth, RandomSignedPermutation(&rng), {2, 9});
  const DecodeResult a =
      DecodeBoard(board, grid.corners, grid.components, render.image);
  const DecodeResult b =
      DecodeBoard(board, grid.corners, grid.components, render.image);
  ASSERT_EQ(a.observation.id.size(), b.observation.id.size());
  for (size_t k = 0; k < a.observation.id.size(); ++k) {
    EXPECT_EQ(a.observation.id[k], b.observation.id[k]);
    EXPECT_EQ(a.corner_index[k], b.corner_index[k]);
  }
  EXPECT_EQ(a.components[0].margin, b.components[0].margin);
}

}  // namespace
}  // namespace puzzlecal
