// BuildGrid on synthetic corner sets: board corners projected through camera
// models with exact ids (tests/grid/grid_test_util.h), checked with the
// wrong-label metric.

#include "grid/grid.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <map>
#include <random>

#include "tests/grid/grid_test_util.h"

namespace puzzlecal {
namespace {

using grid_test::CheckLabels;
using grid_test::CountBoardCorners;
using grid_test::LabelCheck;
using grid_test::LookAtBoard;
using grid_test::ProjectBoards;
using grid_test::SyntheticBoard;
using grid_test::SyntheticCorners;
using grid_test::SyntheticOptions;

LabelCheck BuildAndCheck(const SyntheticCorners& scene,
                         GridSummary* summary = nullptr,
                         const GridOptions& options = {}) {
  GridSummary local;
  const std::vector<GridComponent> components =
      BuildGrid(scene.corners, cv::Mat(), options, summary ? summary : &local);
  EXPECT_TRUE((summary ? summary : &local)->ok);
  for (const GridComponent& c : components) {
    EXPECT_EQ(c.corner.size(), c.ij.size());
  }
  return CheckLabels(components, scene.truth);
}

TEST(GridTest, FrontalBoardIsOneComponent) {
  const Camera camera = grid_test::PinholeCamera();
  SyntheticBoard board;
  board.cam_from_board = LookAtBoard(board, 0.35, 90, 0, 10);
  const SyntheticCorners scene = ProjectBoards(camera, {board}, {});
  ASSERT_EQ(scene.corners.size(), 88u);
  GridSummary summary;
  const LabelCheck check = BuildAndCheck(scene, &summary);
  EXPECT_EQ(check.wrong, 0);
  EXPECT_EQ(check.components, 1);
  EXPECT_EQ(check.largest, 88);
  EXPECT_GT(summary.num_edges_orientation_filtered, 0);
  EXPECT_EQ(summary.num_merges, 87);
}

// The thesis's tilt series (its Table 6.1 had 6.8 % wrong at 40 degrees and
// 53 % at 30) over several in-plane rotations and tilt axes.
TEST(GridTest, TiltSeriesHasNoWrongLabels) {
  const Camera camera = grid_test::PinholeCamera();
  std::printf("angle  roll  axis  corners  labelled  largest  wrong\n");
  int seed = 1;
  for (int angle = 90; angle >= 20; angle -= 10) {
    for (double roll : {0.0, 20.0, 45.0, 70.0}) {
      for (double axis : {0.0, 30.0, 90.0}) {
        SyntheticBoard board;
        board.cam_from_board = LookAtBoard(board, 0.3, angle, axis, roll);
        SyntheticOptions options;
        options.seed = seed++;
        const SyntheticCorners scene = ProjectBoards(camera, {board}, options);
        const int total = CountBoardCorners(scene.truth);
        ASSERT_GT(total, 60) << angle << " " << roll << " " << axis;
        const LabelCheck check = BuildAndCheck(scene);
        std::printf("%5d  %4.0f  %4.0f  %7d  %8d  %7d  %5d\n", angle, roll,
                    axis, total, check.labelled, check.largest, check.wrong);
        EXPECT_EQ(check.wrong, 0) << angle << " " << roll << " " << axis;
        EXPECT_EQ(check.foreign, 0);
        if (angle >= 30) {
          EXPECT_GE(check.labelled, 0.95 * total)
              << angle << " " << roll << " " << axis;
          EXPECT_GE(check.largest, 0.95 * total)
              << angle << " " << roll << " " << axis;
        }
      }
    }
  }
}

TEST(GridTest, MirroredCornerSetHasNoWrongLabels) {
  const Camera camera = grid_test::PinholeCamera();
  SyntheticBoard board;
  board.cam_from_board = LookAtBoard(board, 0.3, 35, 20, 30);
  SyntheticCorners scene = ProjectBoards(camera, {board}, {});
  for (Corner& c : scene.corners) {
    c.xy.x() = camera.width - 1 - c.xy.x();
    c.orientation = M_PI - c.orientation;
  }
  const LabelCheck check = BuildAndCheck(scene);
  EXPECT_EQ(check.wrong, 0);
  EXPECT_GE(check.labelled, 0.95 * scene.corners.size());
}

TEST(GridTest, StrongFisheyeHasNoWrongLabels) {
  const Camera camera = grid_test::FisheyeCamera();
  int seed = 100;
  for (double distance : {0.12, 0.2}) {
    for (const Eigen::Vector3d& offset :
         {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.12, 0.05, 0),
          Eigen::Vector3d(-0.15, -0.1, 0)}) {
      for (double angle : {90.0, 50.0}) {
        SyntheticBoard board;
        board.cam_from_board =
            LookAtBoard(board, distance, angle, 15, 25, offset);
        SyntheticOptions options;
        options.seed = seed++;
        const SyntheticCorners scene = ProjectBoards(camera, {board}, options);
        const int total = CountBoardCorners(scene.truth);
        if (total < 20) continue;
        const LabelCheck check = BuildAndCheck(scene);
        EXPECT_EQ(check.wrong, 0) << distance << " " << offset.transpose();
        EXPECT_GE(check.labelled, 0.95 * total)
            << distance << " " << offset.transpose() << " " << angle;
      }
    }
  }
}

TEST(GridTest, LargeBoardUnderFisheyeIsOneComponent) {
  const Camera camera = grid_test::FisheyeCamera();
  SyntheticBoard board;
  board.cols = 23;
  board.rows = 16;
  board.tile_m = 0.015;
  board.cam_from_board = LookAtBoard(board, 0.15, 70, 0, 10);
  const SyntheticCorners scene = ProjectBoards(camera, {board}, {});
  const LabelCheck check = BuildAndCheck(scene);
  EXPECT_EQ(check.wrong, 0);
  EXPECT_GE(check.largest, 0.95 * scene.corners.size());
}

TEST(GridTest, OccluderSplitsIntoConsistentComponents) {
  const Camera camera = grid_test::PinholeCamera();
  SyntheticBoard board;
  board.cam_from_board = LookAtBoard(board, 0.35, 60, 0, 5);
  SyntheticOptions options;
  // A band of discs across the middle of the image hides two columns.
  for (int y = 0; y < 960; y += 40) options.occluders.emplace_back(640, y, 45);
  const SyntheticCorners scene = ProjectBoards(camera, {board}, options);
  const LabelCheck check = BuildAndCheck(scene);
  EXPECT_EQ(check.wrong, 0);
  EXPECT_GE(check.components, 2);
  EXPECT_GE(check.labelled, 0.95 * scene.corners.size());
}

TEST(GridTest, TwoBoardsNeverShareAComponent) {
  const Camera camera = grid_test::PinholeCamera();
  int seed = 7;
  for (double gap : {0.06, 0.1}) {
    for (double angle : {90.0, 50.0}) {
      SyntheticBoard left, right;
      left.cam_from_board = LookAtBoard(left, 0.6, angle, 90, 0,
                                        Eigen::Vector3d(-0.1 - gap / 2, 0, 0));
      right.cam_from_board = LookAtBoard(right, 0.6, angle, 90, 0,
                                         Eigen::Vector3d(0.1 + gap / 2, 0, 0));
      SyntheticOptions options;
      options.seed = seed++;
      const SyntheticCorners scene =
          ProjectBoards(camera, {left, right}, options);
      const LabelCheck check = BuildAndCheck(scene);
      EXPECT_EQ(check.wrong, 0);
      EXPECT_EQ(check.foreign, 0) << gap << " " << angle;
      EXPECT_GE(check.labelled, 0.95 * scene.corners.size());
    }
  }
}

TEST(GridTest, ClutterOffTheBoardDoesNotJoin) {
  const Camera camera = grid_test::PinholeCamera();
  for (unsigned seed = 1; seed <= 5; ++seed) {
    SyntheticBoard board;
    board.cam_from_board = LookAtBoard(board, 0.35, 50 + 5 * seed, 30, 15);
    SyntheticOptions options;
    options.num_clutter = 300;
    options.seed = seed;
    const SyntheticCorners scene = ProjectBoards(camera, {board}, options);
    const LabelCheck check = BuildAndCheck(scene);
    EXPECT_EQ(check.wrong, 0) << seed;
    EXPECT_EQ(check.foreign, 0) << seed;
    EXPECT_GE(check.labelled, 0.95 * CountBoardCorners(scene.truth)) << seed;
  }
}

TEST(GridTest, DeterministicOutput) {
  const Camera camera = grid_test::PinholeCamera();
  SyntheticBoard board;
  board.cam_from_board = LookAtBoard(board, 0.35, 40, 30, 15);
  SyntheticOptions options;
  options.num_clutter = 100;
  const SyntheticCorners scene = ProjectBoards(camera, {board}, options);
  const std::vector<GridComponent> first = BuildGrid(scene.corners, cv::Mat());
  const std::vector<GridComponent> second = BuildGrid(scene.corners, cv::Mat());
  ASSERT_EQ(first.size(), second.size());
  for (size_t c = 0; c < first.size(); ++c) {
    EXPECT_EQ(first[c].corner, second[c].corner);
    EXPECT_EQ(first[c].ij, second[c].ij);
  }
}

// True when one rotation of the lattice (no reflection) plus an offset maps
// the labels `from` onto `to` (same corners, same order).
bool SameUpToRotation(const GridComponent& from, const GridComponent& to) {
  if (from.corner != to.corner || from.ij.empty()) return false;
  static const int kRotation[4][2][2] = {{{1, 0}, {0, 1}},
                                         {{0, -1}, {1, 0}},
                                         {{-1, 0}, {0, -1}},
                                         {{0, 1}, {-1, 0}}};
  for (const auto& r : kRotation) {
    Eigen::Matrix2i m;
    m << r[0][0], r[0][1], r[1][0], r[1][1];
    const Eigen::Vector2i offset = to.ij[0] - m * from.ij[0];
    bool all = true;
    for (size_t k = 0; k < from.ij.size() && all; ++k)
      all = to.ij[k] == m * from.ij[k] + offset;
    if (all) return true;
  }
  return false;
}

// The detector's orientation is an axis, defined modulo pi (it reports it in
// (-pi/2, pi/2]): adding or subtracting pi to any corner's orientation must
// give the same components with the same labels up to a rotation of the
// whole component (a tree's labels start from the axes of its first corner).
TEST(GridTest, OrientationsCountModuloPi) {
  int seed = 1;
  for (const Camera& camera :
       {grid_test::PinholeCamera(), grid_test::FisheyeCamera()}) {
    for (int angle : {90, 40, 25}) {
      SyntheticBoard board;
      board.cam_from_board = LookAtBoard(board, 0.3, angle, 30, 25);
      SyntheticOptions options;
      options.num_clutter = 40;
      options.seed = seed++;
      SyntheticCorners scene = ProjectBoards(camera, {board}, options);
      const std::vector<GridComponent> reference =
          BuildGrid(scene.corners, cv::Mat());
      std::mt19937 rng(seed);
      for (Corner& corner : scene.corners) {
        const int turn = static_cast<int>(rng() % 3) - 1;  // -1, 0, 1
        corner.orientation += turn * M_PI;
      }
      const std::vector<GridComponent> turned =
          BuildGrid(scene.corners, cv::Mat());
      ASSERT_EQ(turned.size(), reference.size()) << angle;
      ASSERT_FALSE(reference.empty());
      for (size_t c = 0; c < reference.size(); ++c)
        EXPECT_TRUE(SameUpToRotation(reference[c], turned[c])) << angle;
      EXPECT_EQ(CheckLabels(turned, scene.truth).wrong, 0) << angle;
    }
  }
}

// Merges never need a reflection: every corner's own axis frame turns like
// the image (its direction k + 1 is direction k turned by +90 degrees), and
// the joining step lies within 45 degrees of an axis at both ends, so the
// two frames always meet as a rotation (BuildLatticeForest's sigma is +1).
// Hence every lattice cell of every component, on any board and through any
// camera, turns the same way in the image: (L + i) - L to (L + j) - L has one
// sign of the cross product everywhere. A mirrored print or a board seen
// through a mirror gives the same labels' handedness; decode/ tells them
// apart by the code.
TEST(GridTest, AllComponentsTurnLikeTheImage) {
  int seed = 100;
  int cells = 0, turned_other_way = 0;
  for (const Camera& camera :
       {grid_test::PinholeCamera(), grid_test::FisheyeCamera()}) {
    for (int angle : {90, 50, 30, 20}) {
      for (double roll : {0.0, 45.0, 160.0}) {
        SyntheticBoard board;
        board.cam_from_board = LookAtBoard(board, 0.3, angle, 60, roll);
        SyntheticBoard mirrored = board;  // the board seen from its back
        mirrored.cam_from_board =
            board.cam_from_board * Eigen::Isometry3d(Eigen::AngleAxisd(
                                       M_PI, Eigen::Vector3d::UnitX()));
        for (const SyntheticBoard& b : {board, mirrored}) {
          SyntheticOptions options;
          options.num_clutter = 20;
          options.seed = seed++;
          const SyntheticCorners scene = ProjectBoards(camera, {b}, options);
          const std::vector<GridComponent> components =
              BuildGrid(scene.corners, cv::Mat());
          for (const GridComponent& component : components) {
            std::map<std::pair<int, int>, Eigen::Vector2d> at;
            for (size_t k = 0; k < component.corner.size(); ++k)
              at[{component.ij[k].x(), component.ij[k].y()}] =
                  scene.corners[component.corner[k]].xy;
            for (const auto& [l, p] : at) {
              const auto pi = at.find({l.first + 1, l.second});
              const auto pj = at.find({l.first, l.second + 1});
              if (pi == at.end() || pj == at.end()) continue;
              const Eigen::Vector2d u = pi->second - p, v = pj->second - p;
              ++cells;
              if (u.x() * v.y() - u.y() * v.x() < 0) ++turned_other_way;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(cells, 1000);
  // The lattice's j step is +90 degrees from its i step in the image
  // (LatticeStep order and right-handed corner frames): all cells positive.
  EXPECT_EQ(turned_other_way, 0);
}

TEST(GridTest, BadCornersAreIgnored) {
  const Camera camera = grid_test::PinholeCamera();
  SyntheticBoard board;
  board.cam_from_board = LookAtBoard(board, 0.35, 70, 0, 10);
  SyntheticCorners scene = ProjectBoards(camera, {board}, {});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<Corner> bad(6);
  bad[0].xy = {nan, 10};
  bad[1].xy = {inf, -inf};
  bad[2].xy = {1e300, -1e300};
  bad[3].xy = {20, 20};
  bad[3].orientation = nan;
  bad[4] = scene.corners[10];  // exact duplicate
  bad[5] = scene.corners[11];
  bad[5].orientation += M_PI / 2;  // duplicate position, rotated orientation
  for (const Corner& c : bad) {
    scene.corners.push_back(c);
    scene.truth.push_back({-1, Eigen::Vector2i::Zero()});
  }
  GridSummary summary;
  const LabelCheck check = BuildAndCheck(scene, &summary);
  EXPECT_EQ(summary.num_invalid_corners, 4);
  EXPECT_GT(summary.num_edges_too_short, 0);
  EXPECT_EQ(check.wrong, 0);
  EXPECT_EQ(check.foreign, 0);
  EXPECT_GE(check.labelled, 86);
}

TEST(GridTest, DegenerateInputsDoNotCrash) {
  GridSummary summary;
  EXPECT_TRUE(BuildGrid({}, cv::Mat(), {}, &summary).empty());
  EXPECT_TRUE(summary.ok);
  std::vector<Corner> one(1);
  EXPECT_TRUE(BuildGrid(one, cv::Mat(), {}, &summary).empty());
  std::vector<Corner> same(500);  // all at the origin
  EXPECT_TRUE(BuildGrid(same, cv::Mat(), {}, &summary).empty());
  std::vector<Corner> line(200);  // collinear, alternating orientations
  for (int i = 0; i < 200; ++i) {
    line[i].xy = {10.0 * i, 5.0};
    line[i].orientation = (i % 2) ? M_PI / 4 : -M_PI / 4;
  }
  const std::vector<GridComponent> components =
      BuildGrid(line, cv::Mat(), {}, &summary);
  ASSERT_EQ(components.size(), 1u);
  EXPECT_EQ(components[0].corner.size(), 200u);
  std::vector<Corner> far(3);  // a far point must not break the buckets
  far[0].xy = {0, 0};
  far[1].xy = {10, 0};
  far[1].orientation = M_PI / 2;
  far[2].xy = {9e5, -9e5};
  BuildGrid(far, cv::Mat(), {}, &summary);
  EXPECT_TRUE(summary.ok);
}

TEST(GridTest, BadOptionsAndImagesAreRefusedWithAReason) {
  std::vector<Corner> corners(4);
  GridOptions options;
  options.candidates.num_neighbors = 0;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("num_neighbors"), std::string::npos);
  GridSummary summary;
  EXPECT_TRUE(BuildGrid(corners, cv::Mat(), options, &summary).empty());
  EXPECT_FALSE(summary.ok);
  EXPECT_NE(summary.message.find("num_neighbors"), std::string::npos);

  const cv::Mat colour(10, 10, CV_8UC3, cv::Scalar::all(0));
  EXPECT_TRUE(BuildGrid(corners, colour, {}, &summary).empty());
  EXPECT_FALSE(summary.ok);
  EXPECT_NE(summary.message.find("image type"), std::string::npos);
  EXPECT_TRUE(GridOptions().Check(&why));
}

// Every option group refuses an out-of-range field and names it with its
// group; the defaults pass.
TEST(GridTest, EachOptionGroupChecksItsFields) {
  std::string why;
  EXPECT_TRUE(GridCandidateOptions().Check(&why)) << why;
  EXPECT_TRUE(GridEdgeImageOptions().Check(&why)) << why;
  EXPECT_TRUE(GridMergeOptions().Check(&why)) << why;
  EXPECT_TRUE(GridCleanupOptions().Check(&why)) << why;
  EXPECT_TRUE(GridAttachOptions().Check(&why)) << why;
  EXPECT_TRUE(GridOffLatticeOptions().Check(&why)) << why;
  struct Case {
    void (*spoil)(GridOptions*);
    const char* name;
  };
  const Case cases[] = {
      {[](GridOptions* o) {
         o->candidates.min_orientation_difference_deg = 90;
       },
       "candidates.min_orientation_difference_deg"},
      {[](GridOptions* o) { o->image_tests.penalty_factor = 0.5; },
       "image_tests.penalty_factor"},
      {[](GridOptions* o) { o->merge.kruskal_passes = 0; },
       "merge.kruskal_passes"},
      {[](GridOptions* o) { o->cleanup.min_component_size = 0; },
       "cleanup.min_component_size"},
      {[](GridOptions* o) { o->attach.contradiction_tolerance = 0.2; },
       "attach.contradiction_tolerance"},
      {[](GridOptions* o) { o->off_lattice.agreement = 0.5; },
       "off_lattice.agreement"},
  };
  for (const Case& c : cases) {
    GridOptions options;
    c.spoil(&options);
    why.clear();
    EXPECT_FALSE(options.Check(&why)) << c.name;
    EXPECT_NE(why.find(c.name), std::string::npos) << why;
  }
}

}  // namespace
}  // namespace puzzlecal
