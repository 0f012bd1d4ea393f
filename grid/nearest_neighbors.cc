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

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The points bucketed into a grid of square-ish cells over their central
// 98 % (points beyond it go to the border cells), with coordinates copied in
// cell order so that a cell's points are contiguous in memory.
struct CellGrid {
  double x_lo = 0, y_lo = 0;
  double cell_x = 1, cell_y = 1;
  int nx = 1, ny = 1;
  std::vector<int> cell_index;  // per point
  std::vector<int> cell_start;  // per cell, + 1 at the end
  std::vector<int> sorted_id;   // point index, in cell order
  std::vector<double> sorted_x, sorted_y;

  // Lower and upper coordinate of cell column cx / row cy (border cells
  // reach out to infinity: they hold the points beyond).
  double ColumnLow(int cx) const {
    return cx > 0 ? x_lo + cx * cell_x : -kInfinity;
  }
  double ColumnHigh(int cx) const {
    return cx < nx - 1 ? x_lo + (cx + 1) * cell_x : kInfinity;
  }
  double RowLow(int cy) const {
    return cy > 0 ? y_lo + cy * cell_y : -kInfinity;
  }
  double RowHigh(int cy) const {
    return cy < ny - 1 ? y_lo + (cy + 1) * cell_y : kInfinity;
  }
};

CellGrid MakeCellGrid(const std::vector<Eigen::Vector2d>& points) {
  const int n = static_cast<int>(points.size());
  CellGrid g;
  std::vector<double> coords(n);
  for (int i = 0; i < n; ++i) coords[i] = points[i].x();
  g.x_lo = Quantile(&coords, 0.01);
  const double x_hi = Quantile(&coords, 0.99);
  for (int i = 0; i < n; ++i) coords[i] = points[i].y();
  g.y_lo = Quantile(&coords, 0.01);
  const double y_hi = Quantile(&coords, 0.99);
  const double width = std::max(x_hi - g.x_lo, 1e-9);
  const double height = std::max(y_hi - g.y_lo, 1e-9);
  // About one point per cell: few candidates per cell, and the per-cell
  // pruning against the current k-th distance skips most of the second
  // ring.
  double cell = std::sqrt(width * height / n);
  if (!(cell > 0)) cell = std::max(width, height);
  constexpr int kMaxCellsPerAxis = 4096;
  g.nx = static_cast<int>(
      std::clamp(std::ceil(width / cell), 1.0, double(kMaxCellsPerAxis)));
  g.ny = static_cast<int>(
      std::clamp(std::ceil(height / cell), 1.0, double(kMaxCellsPerAxis)));
  g.cell_x = width / g.nx;
  g.cell_y = height / g.ny;
  // Counting sort of the points into cells.
  g.cell_index.resize(n);
  g.cell_start.assign(static_cast<size_t>(g.nx) * g.ny + 1, 0);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = points[i];
    const int cx = static_cast<int>(
        std::clamp(std::floor((p.x() - g.x_lo) / g.cell_x), 0.0, g.nx - 1.0));
    const int cy = static_cast<int>(
        std::clamp(std::floor((p.y() - g.y_lo) / g.cell_y), 0.0, g.ny - 1.0));
    g.cell_index[i] = cy * g.nx + cx;
    ++g.cell_start[g.cell_index[i] + 1];
  }
  for (size_t c = 1; c < g.cell_start.size(); ++c)
    g.cell_start[c] += g.cell_start[c - 1];
  g.sorted_id.resize(n);
  g.sorted_x.resize(n);
  g.sorted_y.resize(n);
  std::vector<int> fill(g.cell_start.begin(), g.cell_start.end() - 1);
  for (int i = 0; i < n; ++i) {
    const int s = fill[g.cell_index[i]]++;
    g.sorted_id[s] = i;
    g.sorted_x[s] = points[i].x();
    g.sorted_y[s] = points[i].y();
  }
  return g;
}

// Offers the points of cells [first, last] (one run in cell order) to `top`,
// except the query itself (sorted position qs).
inline void OfferCells(const CellGrid& g, int first, int last, int qs,
                       double px, double py, TopK* top) {
  const int end = g.cell_start[last + 1];
  for (int s = g.cell_start[first]; s < end; ++s) {
    if (s == qs) continue;
    const double dx = g.sorted_x[s] - px, dy = g.sorted_y[s] - py;
    top->Offer(dx * dx + dy * dy, g.sorted_id[s]);
  }
}

// Offers the cells of the square ring at Chebyshev distance `ring` (>= 2)
// around cell (qx, qy), skipping cells farther than the current k-th.
void OfferRing(const CellGrid& g, int qx, int qy, int ring, int qs, double px,
               double py, TopK* top) {
  const int y0 = qy - ring, y1 = qy + ring;
  const int x0 = qx - ring, x1 = qx + ring;
  for (int cy = std::max(y0, 0); cy <= std::min(y1, g.ny - 1); ++cy) {
    const bool full_row = (cy == y0 || cy == y1);
    const int step = full_row ? 1 : std::max(x1 - x0, 1);
    // Vertical distance from the query to this row of cells.
    const double gap_y = std::max({0.0, g.RowLow(cy) - py, py - g.RowHigh(cy)});
    for (int cx = x0; cx <= x1; cx += step) {
      if (cx < 0 || cx >= g.nx) continue;
      if (top->count == top->k) {  // skip cells beyond the current k-th
        const double gap_x =
            std::max({0.0, g.ColumnLow(cx) - px, px - g.ColumnHigh(cx)});
        if (gap_x * gap_x + gap_y * gap_y > top->dist[top->k - 1]) continue;
      }
      const int c = cy * g.nx + cx;
      OfferCells(g, c, c, qs, px, py, top);
    }
  }
}

// Every point not yet seen after searching the block of cells within
// `ring` of (qx, qy) lies in a cell outside it (points beyond the grid were
// put in its border cells, which only moves them farther out): at least the
// distance to the block's nearest side that has cells beyond it. Infinity
// when the block covers the grid.
double UnseenDistanceBound(const CellGrid& g, int qx, int qy, int ring,
                           double px, double py) {
  const int y0 = qy - ring, y1 = qy + ring;
  const int x0 = qx - ring, x1 = qx + ring;
  const double left = x0 > 0 ? px - (g.x_lo + x0 * g.cell_x) : kInfinity;
  const double right =
      x1 < g.nx - 1 ? (g.x_lo + (x1 + 1) * g.cell_x) - px : kInfinity;
  const double top_side = y0 > 0 ? py - (g.y_lo + y0 * g.cell_y) : kInfinity;
  const double bottom =
      y1 < g.ny - 1 ? (g.y_lo + (y1 + 1) * g.cell_y) - py : kInfinity;
  return std::min({left, right, top_side, bottom});
}

// The k nearest neighbours of the point at sorted position qs: the 3 x 3
// block of cells first, then rings outwards until no unseen point can be
// nearer than the k-th.
void QueryNearest(const CellGrid& g, int qs, TopK* top) {
  const int qcell = g.cell_index[g.sorted_id[qs]];
  const int qx = qcell % g.nx, qy = qcell / g.nx;
  const double px = g.sorted_x[qs], py = g.sorted_y[qs];
  // One contiguous run of points per row of the 3 x 3 block.
  for (int cy = std::max(qy - 1, 0); cy <= std::min(qy + 1, g.ny - 1); ++cy) {
    OfferCells(g, cy * g.nx + std::max(qx - 1, 0),
               cy * g.nx + std::min(qx + 1, g.nx - 1), qs, px, py, top);
  }
  for (int ring = 1;; ++ring) {
    if (ring > 1) OfferRing(g, qx, qy, ring, qs, px, py, top);
    const double bound = UnseenDistanceBound(g, qx, qy, ring, px, py);
    if (bound == kInfinity) break;  // the block covers the grid
    if (top->count == top->k && bound > 0 &&
        top->dist[top->k - 1] <= bound * bound)
      break;
  }
}

}  // namespace

void FindNearestNeighbors(const std::vector<Eigen::Vector2d>& points, int k,
                          std::vector<int>* neighbors) {
  const int n = static_cast<int>(points.size());
  neighbors->assign(static_cast<size_t>(n) * std::max(k, 0), -1);
  if (n < 2 || k <= 0) return;
  const CellGrid grid = MakeCellGrid(points);
  std::vector<double> best_dist(k);
  std::vector<int> best_index(k);
  for (int qs = 0; qs < n; ++qs) {  // queries in cell order
    TopK top{k, 0, best_dist.data(), best_index.data()};
    QueryNearest(grid, qs, &top);
    std::copy(best_index.begin(), best_index.begin() + top.count,
              neighbors->begin() + static_cast<size_t>(grid.sorted_id[qs]) * k);
  }
}

}  // namespace puzzlecal
