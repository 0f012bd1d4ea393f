#include "grid/lattice_cleanup.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "grid/dihedral.h"
#include "grid/label_table.h"

namespace puzzlecal {
namespace {

// Per corner: its lattice neighbour in each of the 4 label directions
// (LatticeStep order) inside its tree, or -1.
using Links = std::vector<std::array<int, 4>>;

// How well corner n's lattice lines predict it: each of its 4 directions with
// at least two more corners gives one verdict. With three corners, a
// quadratic extrapolation (it follows the changing spacing and curvature of
// steep and fisheye views) must land within the tolerance; with two, the
// three corners must pass the merge's collinearity test.
void ScoreCorner(const std::vector<Eigen::Vector2d>& xy, const Links& links,
                 int n, const GridOptions& options, int* supported,
                 int* contradicted) {
  *supported = 0;
  *contradicted = 0;
  for (int d = 0; d < 4; ++d) {
    const int p1 = links[n][d];
    if (p1 < 0) continue;
    const int p2 = links[p1][d];
    if (p2 < 0) continue;
    const int p3 = links[p2][d];
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

// Grey level at p, bilinear, clamped to the image.
template <typename T>
double GreyAt(const cv::Mat& image, const Eigen::Vector2d& p) {
  const double x = std::clamp(p.x(), 0.0, image.cols - 1.0);
  const double y = std::clamp(p.y(), 0.0, image.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), image.cols - 1);
  const int y0 = std::min(static_cast<int>(y), image.rows - 1);
  const int x1 = std::min(x0 + 1, image.cols - 1);
  const int y1 = std::min(y0 + 1, image.rows - 1);
  const T* row0 = image.ptr<T>(y0);
  const T* row1 = image.ptr<T>(y1);
  const double fx = x - x0, fy = y - y0;
  const double top = row0[x0] + fx * (double(row0[x1]) - row0[x0]);
  const double bottom = row1[x0] + fx * (double(row1[x1]) - row1[x0]);
  return top + fy * (bottom - top);
}

double Grey(const cv::Mat& image, const Eigen::Vector2d& p) {
  switch (image.type()) {
    case CV_8UC1:
      return GreyAt<uint8_t>(image, p);
    case CV_16UC1:
      return GreyAt<uint16_t>(image, p);
    default:
      return GreyAt<float>(image, p);
  }
}

// The image vector of one lattice step from corner n in direction d: to its
// neighbour there, else the reversed step to the opposite neighbour, else
// the same from a neighbour across; false when none of them exists.
bool StepVector(const std::vector<Eigen::Vector2d>& xy, const Links& links,
                int n, int d, Eigen::Vector2d* v) {
  for (int base : {n, links[n][Mod4(d + 1)], links[n][Mod4(d + 3)]}) {
    if (base < 0) continue;
    if (links[base][d] >= 0) {
      *v = xy[links[base][d]] - xy[base];
      return true;
    }
    if (links[base][Mod4(d + 2)] >= 0) {
      *v = xy[base] - xy[links[base][Mod4(d + 2)]];
      return true;
    }
  }
  return false;
}

// False when the four tiles around corner n (sampled inside them, towards
// the lattice diagonals) do not alternate dark/light like a checkerboard
// saddle: an L-junction at the board's border or a clutter corner. True when
// n lacks the neighbours to place the samples. Each tile is sampled along
// its own two edges from n, so tiles of different sizes (fisheye rim, steep
// views) are each hit near their middle.
bool LooksLikeSaddle(const std::vector<Eigen::Vector2d>& xy,
                     const cv::Mat& image, const Links& links, int n,
                     double fraction) {
  Eigen::Vector2d step[4];
  for (int d = 0; d < 4; ++d)
    if (!StepVector(xy, links, n, d, &step[d])) return true;
  // Tile between directions d and d + 1.
  double v[4];
  for (int d = 0; d < 4; ++d)
    v[d] = Grey(image, xy[n] + fraction * (step[d] + step[Mod4(d + 1)]));
  // v[0], v[2] are opposite tiles, as are v[1], v[3].
  const double contrast = std::abs((v[0] + v[2]) - (v[1] + v[3])) / 2;
  const double spread = std::max(std::abs(v[0] - v[2]), std::abs(v[1] - v[3]));
  return spread < contrast;
}

// Removes corner i: unlinks it from its neighbours.
void Unlink(Links* links, int i) {
  for (int d = 0; d < 4; ++d) {
    const int m = (*links)[i][d];
    if (m >= 0) (*links)[m][Mod4(d + 2)] = -1;
    (*links)[i][d] = -1;
  }
}

}  // namespace

std::vector<GridComponent> ExtractComponents(
    const std::vector<Eigen::Vector2d>& xy, const cv::Mat& image,
    const LatticeForest& forest, const GridOptions& options,
    GridSummary* summary) {
  const int n = static_cast<int>(xy.size());
  std::vector<int> members;
  members.reserve(n);
  for (int i = 0; i < n; ++i)
    if (forest.tree[i] >= 0) members.push_back(i);

  // Lattice neighbours, looked up once.
  Links links(n, {-1, -1, -1, -1});
  std::vector<char> alive(n, 0);
  for (int i : members) {
    alive[i] = 1;
    for (int d = 0; d < 4; ++d)
      links[i][d] =
          forest.table.Find(forest.tree[i], forest.label[i] + LatticeStep(d));
  }

  // Remove corners that are no saddles of the lattice's checkerboard (all
  // judged on the links before any removal).
  if (!image.empty() && options.check_saddle_pattern) {
    std::vector<int> not_saddle;
    for (int i : members) {
      if (!LooksLikeSaddle(xy, image, links, i, options.saddle_sample_fraction))
        not_saddle.push_back(i);
    }
    for (int i : not_saddle) {
      Unlink(&links, i);
      alive[i] = 0;
      ++summary->num_removed_not_saddle;
    }
  }

  // Remove unpredicted corners, a few rounds (a removal changes the lines).
  constexpr int kMaxRounds = 4;
  std::vector<int> removals;
  for (int round = 0; round < kMaxRounds; ++round) {
    removals.clear();
    for (int i : members) {
      if (!alive[i]) continue;
      int supported, contradicted;
      ScoreCorner(xy, links, i, options, &supported, &contradicted);
      if (contradicted > supported) removals.push_back(i);
    }
    if (removals.empty()) break;
    for (int i : removals) {
      Unlink(&links, i);
      alive[i] = 0;
      ++summary->num_removed_by_prediction;
    }
  }

  // Split into 4-connected label sets: a component number per corner, then
  // the members in index order.
  std::vector<GridComponent> components;
  std::vector<int> component_of(n, -1);
  std::vector<int> queue;
  queue.reserve(n);
  for (int seed : members) {
    if (!alive[seed] || component_of[seed] != -1) continue;
    queue.clear();
    queue.push_back(seed);
    component_of[seed] = -2;
    for (size_t q = 0; q < queue.size(); ++q) {
      for (int m : links[queue[q]]) {
        if (m >= 0 && component_of[m] == -1) {
          component_of[m] = -2;
          queue.push_back(m);
        }
      }
    }
    int id = -3;  // dropped
    if (static_cast<int>(queue.size()) < options.min_component_size) {
      ++summary->num_components_dropped;
    } else {
      id = static_cast<int>(components.size());
      components.emplace_back();
      components.back().corner.reserve(queue.size());
    }
    for (int c : queue) component_of[c] = id;
  }
  for (int i : members)
    if (component_of[i] >= 0) components[component_of[i]].corner.push_back(i);
  for (GridComponent& component : components) {
    Eigen::Vector2i low = forest.label[component.corner[0]];
    for (int c : component.corner) low = low.cwiseMin(forest.label[c]);
    component.ij.reserve(component.corner.size());
    for (int c : component.corner)
      component.ij.push_back(forest.label[c] - low);
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
