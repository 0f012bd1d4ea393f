#include "grid/lattice_cleanup.h"

#include <algorithm>

#include "grid/dihedral.h"
#include "grid/label_table.h"

namespace puzzlecal {
namespace {

// How well corner n's lattice lines predict it: each of its 4 directions with
// at least two more corners gives one prediction (quadratic extrapolation
// from three corners, linear from two).
void ScoreCorner(const std::vector<Eigen::Vector2d>& xy,
                 const LabelTable& table, int tree, int n,
                 const Eigen::Vector2i& label, double tolerance, int* supported,
                 int* contradicted) {
  *supported = 0;
  *contradicted = 0;
  for (int d = 0; d < 4; ++d) {
    const Eigen::Vector2i step = LatticeStep(d);
    const int p1 = table.Find(tree, label + step);
    if (p1 < 0) continue;
    const int p2 = table.Find(tree, label + 2 * step);
    if (p2 < 0) continue;
    const int p3 = table.Find(tree, label + 3 * step);
    const Eigen::Vector2d predicted =
        p3 >= 0 ? Eigen::Vector2d(3 * xy[p1] - 3 * xy[p2] + xy[p3])
                : Eigen::Vector2d(2 * xy[p1] - xy[p2]);
    const double spacing = (xy[p1] - xy[p2]).norm();
    if ((xy[n] - predicted).norm() <= tolerance * spacing) {
      ++*supported;
    } else {
      ++*contradicted;
    }
  }
}

}  // namespace

std::vector<GridComponent> ExtractComponents(
    const std::vector<Eigen::Vector2d>& xy, const LatticeForest& forest,
    const GridOptions& options, GridSummary* summary) {
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

  // Remove unpredicted corners, a few rounds (a removal changes the lines).
  constexpr int kMaxRounds = 4;
  std::vector<int> removals;
  for (int round = 0; round < kMaxRounds; ++round) {
    removals.clear();
    for (int i : order) {
      if (!alive[i]) continue;
      int supported, contradicted;
      ScoreCorner(xy, table, forest.tree[i], i, forest.label[i],
                  options.line_prediction_tolerance, &supported, &contradicted);
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
