// The building blocks of BuildGrid against simple references: k nearest
// neighbours against brute force, the label table against std::map, the
// lattice symmetries against their matrices, the intensity-thirds test on a
// drawn checkerboard.

#include <gtest/gtest.h>

#include <map>
#include <opencv2/imgproc.hpp>
#include <random>
#include <tuple>

#include "grid/dihedral.h"
#include "grid/edge_intensity.h"
#include "grid/label_table.h"
#include "grid/nearest_neighbors.h"
#include "tests/support/draws.h"

namespace puzzlecal {
namespace {

std::vector<int> BruteForceNeighbors(const std::vector<Eigen::Vector2d>& p,
                                     int k) {
  const int n = static_cast<int>(p.size());
  std::vector<int> out(static_cast<size_t>(n) * k, -1);
  for (int i = 0; i < n; ++i) {
    std::vector<std::pair<double, int>> d;
    for (int j = 0; j < n; ++j)
      if (j != i) d.emplace_back((p[j] - p[i]).squaredNorm(), j);
    std::sort(d.begin(), d.end());
    for (int m = 0; m < k && m < static_cast<int>(d.size()); ++m)
      out[static_cast<size_t>(i) * k + m] = d[m].second;
  }
  return out;
}

TEST(NearestNeighborsTest, MatchesBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 500);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<Eigen::Vector2d> points;
    for (int i = 0; i < 300; ++i) {
      const Eigen::Vector2d p =
          testing_draws::DrawVector2d([&] { return u(rng); });
      points.emplace_back(p.x(), p.y() * 0.3);
    }
    if (trial == 1) points.emplace_back(9e5, -9e5);  // one far outlier
    if (trial == 2)  // a lattice with exact ties
      for (int i = 0; i < 100; ++i) points.emplace_back(i % 10, i / 10);
    if (trial == 3) points.resize(5);  // fewer points than k + 1
    std::vector<int> fast;
    FindNearestNeighbors(points, 8, &fast);
    EXPECT_EQ(fast, BruteForceNeighbors(points, 8)) << trial;
  }
}

TEST(LabelTableTest, MatchesMap) {
  LabelTable table(2000);
  std::map<std::tuple<int, int, int>, int> reference;
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> tree(0, 5), coord(-20, 20), op(0, 2);
  for (int step = 0; step < 20000; ++step) {
    const int t = tree(rng);
    const Eigen::Vector2i label =
        testing_draws::DrawVector2d([&] { return coord(rng); }).cast<int>();
    const auto key = std::make_tuple(t, label.x(), label.y());
    const int o = op(rng);
    if (o == 0 && reference.size() < 1900) {
      table.Insert(t, label, step);
      reference[key] = step;
    } else if (o == 1) {
      table.Erase(t, label);
      reference.erase(key);
    }
    const auto it = reference.find(key);
    ASSERT_EQ(table.Find(t, label), it == reference.end() ? -1 : it->second);
  }
  for (const auto& [key, value] : reference) {
    EXPECT_EQ(table.Find(std::get<0>(key),
                         Eigen::Vector2i(std::get<1>(key), std::get<2>(key))),
              value);
  }
}

TEST(DihedralTest, GroupLaws) {
  std::vector<Dihedral> all;
  for (int sign : {1, -1})
    for (int shift = 0; shift < 4; ++shift) all.push_back({sign, shift});
  const Eigen::Vector2i v(2, -3);
  for (const Dihedral& g : all) {
    // Orthogonal integer map that sends step k to step g(k).
    for (int k = 0; k < 4; ++k)
      EXPECT_EQ(g.Apply(LatticeStep(k)), LatticeStep(g.Apply(k)));
    EXPECT_EQ(g.Inverse().Apply(g.Apply(v)), v);
    EXPECT_EQ(g.Apply(v).squaredNorm(), v.squaredNorm());
    for (const Dihedral& h : all)
      EXPECT_EQ(g.Compose(h).Apply(v), g.Apply(h.Apply(v)));
  }
  // Reflections reverse the turning sense of the steps, rotations keep it.
  EXPECT_EQ(Dihedral({-1, 0}).Apply(Eigen::Vector2i(0, 1)),
            Eigen::Vector2i(0, -1));
  EXPECT_EQ(Dihedral({1, 1}).Apply(Eigen::Vector2i(1, 0)),
            Eigen::Vector2i(0, 1));
}

TEST(EdgeIntensityTest, TileEdgesAreNotPenalisedDiagonalsAre) {
  // 40 px tiles; corners at multiples of 40.
  cv::Mat image(200, 200, CV_8UC1);
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x)
      image.at<uint8_t>(y, x) = ((x / 40 + y / 40) % 2) ? 220 : 30;
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.0);
  for (int type : {CV_8UC1, CV_16UC1, CV_32FC1}) {
    cv::Mat typed;
    image.convertTo(typed, type, type == CV_16UC1 ? 256.0 : 1.0);
    ASSERT_TRUE(IsSupportedGridImage(typed));
    // Along a tile edge: half dark, half light on both thirds.
    EXPECT_FALSE(EdgeCrossesTile(typed, {40, 40}, {80, 40}, 15, 0.5));
    EXPECT_FALSE(EdgeCrossesTile(typed, {80, 80}, {80, 120}, 15, 0.5));
    // From a corner across a light tile into a dark one (a wrong edge that
    // skips a corner diagonally): the thirds differ.
    EXPECT_TRUE(EdgeCrossesTile(typed, {40, 40}, {100, 70}, 15, 0.5));
  }
  EXPECT_FALSE(IsSupportedGridImage(cv::Mat()));
  EXPECT_FALSE(IsSupportedGridImage(cv::Mat(4, 4, CV_8UC3)));
}

}  // namespace
}  // namespace puzzlecal
