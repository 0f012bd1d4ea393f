#include "grid/nearest_neighbors.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace puzzlecal {
namespace {

// The value at quantile q (in [0, 1]) of `values` (reordered in place).
double Quantile(std::vector<double>* values, double q) {
  const size_t index = static_cast<size_t>(q * (values->size() - 1));
  std::nth_element(values->begin(), values->begin() + index, values->end());
  return (*values)[index];
}

// Keeps the k best (distance, index) pairs in ascending order.
struct TopK {
  int k;
  int count = 0;
  double* dist;
  int* index;

  void Offer(double d, int i) {
    if (count == k &&
        (d > dist[k - 1] || (d == dist[k - 1] && i > index[k - 1])))
      return;
    int pos = count < k ? count++ : k - 1;
    while (pos > 0 &&
           (dist[pos - 1] > d || (dist[pos - 1] == d && index[pos - 1] > i))) {
      dist[pos] = dist[pos - 1];
      index[pos] = index[pos - 1];
      --pos;
    }
    dist[pos] = d;
    index[pos] = i;
  }
};

}  // namespace

void FindNearestNeighbors(const std::vector<Eigen::Vector2d>& points, int k,
                          std::vector<int>* neighbors) {
  const int n = static_cast<int>(points.size());
  neighbors->assign(static_cast<size_t>(n) * std::max(k, 0), -1);
  if (n < 2 || k <= 0) return;

  std::vector<double> coords(n);
  for (int i = 0; i < n; ++i) coords[i] = points[i].x();
  const double x_lo = Quantile(&coords, 0.01);
  const double x_hi = Quantile(&coords, 0.99);
  for (int i = 0; i < n; ++i) coords[i] = points[i].y();
  const double y_lo = Quantile(&coords, 0.01);
  const double y_hi = Quantile(&coords, 0.99);
  const double width = std::max(x_hi - x_lo, 1e-9);
  const double height = std::max(y_hi - y_lo, 1e-9);
  // About one point per cell (measured fastest on 3204- and 3744-corner
  // boards against 0.5, 0.7, 2, 3.3 and 4.5 points): few candidates per
  // cell, and the per-cell pruning against the current k-th distance skips
  // most of the second ring.
  double cell = std::sqrt(width * height / n);
  if (!(cell > 0)) cell = std::max(width, height);
  constexpr int kMaxCellsPerAxis = 4096;
  const int nx = static_cast<int>(
      std::clamp(std::ceil(width / cell), 1.0, double(kMaxCellsPerAxis)));
  const int ny = static_cast<int>(
      std::clamp(std::ceil(height / cell), 1.0, double(kMaxCellsPerAxis)));
  const double cell_x = width / nx;
  const double cell_y = height / ny;

  auto cell_of = [&](const Eigen::Vector2d& p, int* cx, int* cy) {
    *cx = static_cast<int>(
        std::clamp(std::floor((p.x() - x_lo) / cell_x), 0.0, nx - 1.0));
    *cy = static_cast<int>(
        std::clamp(std::floor((p.y() - y_lo) / cell_y), 0.0, ny - 1.0));
  };

  // Counting sort of the points into cells; coordinates copied in cell
  // order so that a cell's points are contiguous in memory.
  std::vector<int> cell_index(n);
  std::vector<int> cell_start(static_cast<size_t>(nx) * ny + 1, 0);
  for (int i = 0; i < n; ++i) {
    int cx, cy;
    cell_of(points[i], &cx, &cy);
    cell_index[i] = cy * nx + cx;
    ++cell_start[cell_index[i] + 1];
  }
  for (size_t c = 1; c < cell_start.size(); ++c)
    cell_start[c] += cell_start[c - 1];
  std::vector<int> sorted_id(n);
  std::vector<double> sorted_x(n), sorted_y(n);
  {
    std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
    for (int i = 0; i < n; ++i) {
      const int s = fill[cell_index[i]]++;
      sorted_id[s] = i;
      sorted_x[s] = points[i].x();
      sorted_y[s] = points[i].y();
    }
  }

  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  std::vector<double> best_dist(k);
  std::vector<int> best_index(k);
  for (int qs = 0; qs < n; ++qs) {  // queries in cell order
    const int i = sorted_id[qs];
    TopK top{k, 0, best_dist.data(), best_index.data()};
    const int qcell = cell_index[i];
    const int qx = qcell % nx, qy = qcell / nx;
    const double px = sorted_x[qs], py = sorted_y[qs];
    // The 3 x 3 block first, one contiguous run of points per row.
    for (int cy = std::max(qy - 1, 0); cy <= std::min(qy + 1, ny - 1); ++cy) {
      const int end = cell_start[cy * nx + std::min(qx + 1, nx - 1) + 1];
      for (int s = cell_start[cy * nx + std::max(qx - 1, 0)]; s < end; ++s) {
        if (s == qs) continue;
        const double dx = sorted_x[s] - px, dy = sorted_y[s] - py;
        top.Offer(dx * dx + dy * dy, sorted_id[s]);
      }
    }
    for (int ring = 1;; ++ring) {
      const int y0 = qy - ring, y1 = qy + ring;
      const int x0 = qx - ring, x1 = qx + ring;
      for (int cy = std::max(y0, 0); cy <= std::min(y1, ny - 1) && ring > 1;
           ++cy) {
        const bool full_row = (cy == y0 || cy == y1);
        const int step = full_row ? 1 : std::max(x1 - x0, 1);
        // Vertical distance from the query to this row of cells (border
        // cells reach out to infinity: they hold the points beyond).
        const double row_low = cy > 0 ? y_lo + cy * cell_y : -kInfinity;
        const double row_high =
            cy < ny - 1 ? y_lo + (cy + 1) * cell_y : kInfinity;
        const double gap_y = std::max({0.0, row_low - py, py - row_high});
        for (int cx = x0; cx <= x1; cx += step) {
          if (cx < 0 || cx >= nx) continue;
          if (top.count == k) {  // skip cells beyond the current k-th
            const double col_low = cx > 0 ? x_lo + cx * cell_x : -kInfinity;
            const double col_high =
                cx < nx - 1 ? x_lo + (cx + 1) * cell_x : kInfinity;
            const double gap_x = std::max({0.0, col_low - px, px - col_high});
            if (gap_x * gap_x + gap_y * gap_y > top.dist[k - 1]) continue;
          }
          const int c = cy * nx + cx;
          for (int s = cell_start[c]; s < cell_start[c + 1]; ++s) {
            if (s == qs) continue;
            const double dx = sorted_x[s] - px, dy = sorted_y[s] - py;
            top.Offer(dx * dx + dy * dy, sorted_id[s]);
          }
        }
      }
      // Every point not yet seen lies in a cell outside the searched block
      // (points beyond the grid were put in its border cells, which only
      // moves them farther out): at least the distance to the block's
      // nearest side that has cells beyond it.
      const double left = x0 > 0 ? px - (x_lo + x0 * cell_x) : kInfinity;
      const double right =
          x1 < nx - 1 ? (x_lo + (x1 + 1) * cell_x) - px : kInfinity;
      const double top_side = y0 > 0 ? py - (y_lo + y0 * cell_y) : kInfinity;
      const double bottom =
          y1 < ny - 1 ? (y_lo + (y1 + 1) * cell_y) - py : kInfinity;
      const double bound = std::min({left, right, top_side, bottom});
      if (bound == kInfinity) break;  // the block covers the grid
      if (top.count == k && bound > 0 && top.dist[k - 1] <= bound * bound)
        break;
    }
    std::copy(best_index.begin(), best_index.begin() + top.count,
              neighbors->begin() + static_cast<size_t>(i) * k);
  }
}

}  // namespace puzzlecal
