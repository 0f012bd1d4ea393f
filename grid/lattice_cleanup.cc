#include "grid/lattice_cleanup.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "grid/dihedral.h"
#include "grid/label_table.h"

namespace puzzlecal {
namespace {

// How well corner n's lattice lines predict it: each of its 4 directions with
// at least two more corners gives one verdict. With three corners, a
// quadratic extrapolation (it follows the changing spacing and curvature of
// steep and fisheye views) must land within the tolerance; with two, the
// three corners must pass the merge's collinearity test.
void ScoreCorner(const std::vector<Eigen::Vector2d>& xy,
                 const LabelTable& table, int tree, int n,
                 const Eigen::Vector2i& label, const GridOptions& options,
                 int* supported, int* contradicted) {
  *supported = 0;
  *contradicted = 0;
  for (int d = 0; d < 4; ++d) {
    const Eigen::Vector2i step = LatticeStep(d);
    const int p1 = table.Find(tree, label + step);
    if (p1 < 0) continue;
    const int p2 = table.Find(tree, label + 2 * step);
    if (p2 < 0) continue;
    const int p3 = table.Find(tree, label + 3 * step);
    bool ok;
    if (p3 >= 0) {
      const Eigen::Vector2d predicted = 3 * xy[p1] - 3 * xy[p2] + xy[p3];
      const double spacing = (xy[p1] - xy[p2]).norm();
      ok = (xy[n] - predicted).norm() <=
           options.line_prediction_tolerance * spacing;
    } else {
      const Eigen::Vector2d v1 = xy[n] - xy[p1];
      const Eigen::Vector2d v2 = xy[p1] - xy[p2];
      const double n1 = v1.norm(), n2 = v2.norm();
      const double cross = v1.x() * v2.y() - v1.y() * v2.x();
      const double r = options.max_line_spacing_ratio;
      ok = n1 > 0 && n2 > 0 && v1.dot(v2) > 0 &&
           std::abs(cross) <= options.max_collinearity_sin * n1 * n2 &&
           n1 <= r * n2 && n1 * r >= n2;
    }
    if (ok) {
      ++*supported;
    } else {
      ++*contradicted;
    }
  }
}

// Grey level at (x, y), bilinear, clamped to the image.
double Grey(const cv::Mat& image, const Eigen::Vector2d& p) {
  const double x = std::clamp(p.x(), 0.0, image.cols - 1.0);
  const double y = std::clamp(p.y(), 0.0, image.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), image.cols - 1);
  const int y0 = std::min(static_cast<int>(y), image.rows - 1);
  const int x1 = std::min(x0 + 1, image.cols - 1);
  const int y1 = std::min(y0 + 1, image.rows - 1);
  auto at = [&](int xx, int yy) -> double {
    switch (image.type()) {
      case CV_8UC1:
        return image.at<uint8_t>(yy, xx);
      case CV_16UC1:
        return image.at<uint16_t>(yy, xx);
      default:
        return image.at<float>(yy, xx);
    }
  };
  const double fx = x - x0, fy = y - y0;
  const double top = at(x0, y0) + fx * (at(x1, y0) - at(x0, y0));
  const double bottom = at(x0, y1) + fx * (at(x1, y1) - at(x0, y1));
  return top + fy * (bottom - top);
}

// False when the four tiles around corner n (sampled inside them, towards
// the lattice diagonals) do not alternate dark/light like a checkerboard
// saddle: an L-junction at the board's border or a clutter corner. True when
// n lacks the neighbours to place the samples.
bool LooksLikeSaddle(const std::vector<Eigen::Vector2d>& xy,
                     const cv::Mat& image, const LabelTable& table, int tree,
                     int n, const Eigen::Vector2i& label, double fraction) {
  // Each lattice axis from n's own neighbours along it, else from those of a
  // neighbour across it.
  Eigen::Vector2d axis[2];
  for (int a = 0; a < 2; ++a) {
    bool found = false;
    const Eigen::Vector2i across = LatticeStep(a + 1);
    for (const Eigen::Vector2i& base :
         {Eigen::Vector2i(label), Eigen::Vector2i(label + across),
          Eigen::Vector2i(label - across)}) {
      const int at = base == label ? n : table.Find(tree, base);
      if (at < 0) continue;
      const int forward = table.Find(tree, base + LatticeStep(a));
      const int backward = table.Find(tree, base - LatticeStep(a));
      if (forward >= 0) {
        axis[a] = xy[forward] - xy[at];
      } else if (backward >= 0) {
        axis[a] = xy[at] - xy[backward];
      } else {
        continue;
      }
      found = true;
      break;
    }
    if (!found) return true;
  }
  const double v_pp = Grey(image, xy[n] + fraction * (axis[0] + axis[1]));
  const double v_mm = Grey(image, xy[n] - fraction * (axis[0] + axis[1]));
  const double v_pm = Grey(image, xy[n] + fraction * (axis[0] - axis[1]));
  const double v_mp = Grey(image, xy[n] - fraction * (axis[0] - axis[1]));
  const double contrast = std::abs((v_pp + v_mm) - (v_pm + v_mp)) / 2;
  const double spread = std::max(std::abs(v_pp - v_mm), std::abs(v_pm - v_mp));
  return spread < contrast;
}

}  // namespace

std::vector<GridComponent> ExtractComponents(
    const std::vector<Eigen::Vector2d>& xy, const cv::Mat& image,
    const LatticeForest& forest, const GridOptions& options,
    GridSummary* summary) {
  const int n = static_cast<int>(xy.size());
  // Members of each tree, trees in order of their smallest corner.
  std::vector<int> order;
  order.reserve(n);
  for (int i = 0; i < n; ++i)
    if (forest.tree[i] >= 0) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) {
    return forest.tree[x] < forest.tree[y];
  });

  LabelTable table(n);
  std::vector<char> alive(n, 0);
  for (int i : order) {
    table.Insert(forest.tree[i], forest.label[i], i);
    alive[i] = 1;
  }

  // Remove corners that are no saddles of the lattice's checkerboard.
  if (!image.empty() && options.check_saddle_pattern) {
    std::vector<int> not_saddle;
    for (int i : order) {
      if (!LooksLikeSaddle(xy, image, table, forest.tree[i], i, forest.label[i],
                           options.saddle_sample_fraction))
        not_saddle.push_back(i);
    }
    for (int i : not_saddle) {
      table.Erase(forest.tree[i], forest.label[i]);
      alive[i] = 0;
      ++summary->num_removed_not_saddle;
    }
  }

  // Remove unpredicted corners, a few rounds (a removal changes the lines).
  constexpr int kMaxRounds = 4;
  std::vector<int> removals;
  for (int round = 0; round < kMaxRounds; ++round) {
    removals.clear();
    for (int i : order) {
      if (!alive[i]) continue;
      int supported, contradicted;
      ScoreCorner(xy, table, forest.tree[i], i, forest.label[i], options,
                  &supported, &contradicted);
      if (contradicted > supported) removals.push_back(i);
    }
    if (removals.empty()) break;
    for (int i : removals) {
      table.Erase(forest.tree[i], forest.label[i]);
      alive[i] = 0;
      ++summary->num_removed_by_prediction;
    }
  }

  // Split into 4-connected label sets.
  std::vector<GridComponent> components;
  std::vector<char> visited(n, 0);
  std::vector<int> queue;
  queue.reserve(n);
  for (int seed : order) {
    if (!alive[seed] || visited[seed]) continue;
    const int tree = forest.tree[seed];
    queue.clear();
    queue.push_back(seed);
    visited[seed] = 1;
    for (size_t q = 0; q < queue.size(); ++q) {
      const int c = queue[q];
      for (int d = 0; d < 4; ++d) {
        const int m = table.Find(tree, forest.label[c] + LatticeStep(d));
        if (m >= 0 && !visited[m]) {
          visited[m] = 1;
          queue.push_back(m);
        }
      }
    }
    if (static_cast<int>(queue.size()) < options.min_component_size) {
      ++summary->num_components_dropped;
      continue;
    }
    std::sort(queue.begin(), queue.end());
    Eigen::Vector2i low = forest.label[queue[0]];
    for (int c : queue) low = low.cwiseMin(forest.label[c]);
    GridComponent component;
    component.corner = queue;
    component.ij.reserve(queue.size());
    for (int c : queue) component.ij.push_back(forest.label[c] - low);
    components.push_back(std::move(component));
  }
  std::sort(components.begin(), components.end(),
            [](const GridComponent& x, const GridComponent& y) {
              if (x.corner.size() != y.corner.size())
                return x.corner.size() > y.corner.size();
              return x.corner.front() < y.corner.front();
            });
  return components;
}

}  // namespace puzzlecal
