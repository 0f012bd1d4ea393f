#include "grid/lattice_forest.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <utility>

#include "grid/dihedral.h"
#include "grid/label_table.h"

namespace puzzlecal {

namespace {

// Why a merge was refused (kMerged: it was not).
using Refusal = GridEdgeDecision;

// Direction index of an image vector in a corner's own axes: k = 0..3 for the
// axis estimate rotated by k * 90 degrees; `cosine` of the angle between them.
struct AxisStep {
  int k = 0;
  double cosine = 0;
};

class Forest {
 public:
  // `image_check` (may be null): true when the image shows a tile edge
  // between two corners (not tile-crossing, no flip of sides).
  Forest(const LatticeNodes& nodes, const GridOptions& options,
         double max_axis_deviation_deg,
         const std::function<bool(const GridEdge&)>* image_check)
      : nodes_(nodes),
        options_(options),
        min_axis_cosine_(std::cos(max_axis_deviation_deg * M_PI / 180)),
        adjacency_cosine_(std::cos(
            options.max_adjacency_deviation_with_image_deg * M_PI / 180)),
        image_check_(image_check),
        table_(static_cast<int>(nodes.xy.size())) {
    const int n = static_cast<int>(nodes.xy.size());
    parent_.resize(n);
    size_.assign(n, 1);
    next_.assign(n, -1);
    tail_.resize(n);
    weight_sum_.assign(n, {0.0, 0.0});
    edge_count_.assign(n, {0, 0});
    label_.assign(n, Eigen::Vector2i::Zero());
    box_low_.assign(n, Eigen::Vector2i::Zero());
    box_high_.assign(n, Eigen::Vector2i::Zero());
    frame_.assign(n, Dihedral());
    neighbor_.assign(n, {-1, -1, -1, -1});
    neighbor_weight_.assign(n, {0, 0, 0, 0});
    neighbor_length_.assign(n, {0, 0, 0, 0});
    for (int i = 0; i < n; ++i) {
      parent_[i] = i;
      tail_[i] = i;
      // Single-corner trees stay out of the table (see Lookup).
    }
  }

  int Find(int x) {
    int root = x;
    while (parent_[root] != root) root = parent_[root];
    while (parent_[x] != root) {  // path compression
      const int next = parent_[x];
      parent_[x] = root;
      x = next;
    }
    return root;
  }

  // The corner at `label` in the tree with root `root`, or -1. Trees of one
  // corner are not in the table (most trees are, until Kruskal joins them):
  // the root is their only corner.
  int Lookup(int root, const Eigen::Vector2i& label) const {
    if (size_[root] == 1) return label == label_[root] ? root : -1;
    return table_.Find(root, label);
  }

  // Tries to join the trees of the edge's ends; returns why not.
  Refusal TryMerge(const GridEdge& edge);

  void Export(LatticeForest* forest) {
    const int n = static_cast<int>(nodes_.xy.size());
    forest->tree.assign(n, -1);
    forest->label = std::move(label_);
    for (int i = 0; i < n; ++i)
      if (nodes_.valid[i]) forest->tree[i] = Find(i);
    forest->table = std::move(table_);
  }

 private:
  Eigen::Vector2d Direction(int node, int k) const {
    const Eigen::Vector2d& a = nodes_.axis[node];
    switch (Mod4(k)) {
      case 0:
        return a;
      case 1:
        return Eigen::Vector2d(-a.y(), a.x());
      case 2:
        return -a;
      default:
        return Eigen::Vector2d(a.y(), -a.x());
    }
  }

  AxisStep Classify(int node, const Eigen::Vector2d& v) const {
    const Eigen::Vector2d& a = nodes_.axis[node];
    const double along = a.dot(v);
    const double across = a.x() * v.y() - a.y() * v.x();
    const double norm = v.norm();
    AxisStep step;
    if (std::abs(along) >= std::abs(across)) {
      step.k = along >= 0 ? 0 : 2;
      step.cosine = norm > 0 ? std::abs(along) / norm : 0;
    } else {
      step.k = across >= 0 ? 1 : 3;
      step.cosine = norm > 0 ? std::abs(across) / norm : 0;
    }
    return step;
  }

  // Mean length of the tree edges at `node` in own-axis slots k and k + 2
  // (one lattice line), or in the other two slots; 0 when there are none.
  double LineEdgeLength(int node, int k) const {
    double sum = 0;
    int count = 0;
    for (int slot : {Mod4(k), Mod4(k + 2)}) {
      if (neighbor_[node][slot] >= 0) {
        sum += neighbor_length_[node][slot];
        ++count;
      }
    }
    return count > 0 ? sum / count : 0.0;
  }

  // The distance of a new lattice neighbour in own-axis direction k of `node`
  // fits the tree edges there: within max_adjacency_length_ratio of those on
  // the same line, else within max_axis_aspect_ratio of those across, else
  // within max_adjacency_length_ratio of `fallback`.
  bool LengthFits(int node, int k, double dist, double fallback) const {
    double ref = LineEdgeLength(node, k);
    double r = options_.max_adjacency_length_ratio;
    if (ref == 0) {
      ref = LineEdgeLength(node, k + 1);
      if (ref > 0) {
        r = options_.max_axis_aspect_ratio;
      } else {
        ref = fallback;
      }
    }
    return dist <= r * ref && dist * r >= ref;
  }

  // Three consecutive corners p0, p1, p2 on one lattice line: the line turns
  // by less than the collinearity limit and the spacing changes slowly.
  bool Collinear(int p0, int p1, int p2) const {
    const Eigen::Vector2d v1 = nodes_.xy[p1] - nodes_.xy[p0];
    const Eigen::Vector2d v2 = nodes_.xy[p2] - nodes_.xy[p1];
    const double n1 = v1.norm(), n2 = v2.norm();
    if (!(n1 > 0 && n2 > 0)) return false;
    const double cross = v1.x() * v2.y() - v1.y() * v2.x();
    if (v1.dot(v2) <= 0) return false;
    if (std::abs(cross) > options_.max_collinearity_sin * n1 * n2) return false;
    const double ratio = n2 / n1;
    return ratio <= options_.max_line_spacing_ratio &&
           ratio * options_.max_line_spacing_ratio >= 1.0;
  }

  // n (in the tree being moved, new frame `frame_n`) and m (in the kept tree)
  // would become lattice neighbours with m at step d from n.
  bool AdjacencyAgrees(int n, const Dihedral& frame_n, int m, int d,
                       double fallback_length) const {
    const Eigen::Vector2d v = nodes_.xy[m] - nodes_.xy[n];
    const AxisStep at_n = Classify(n, v);
    const AxisStep at_m = Classify(m, -v);
    if (at_n.cosine < min_axis_cosine_ || at_m.cosine < min_axis_cosine_)
      return AmbiguousAdjacencyAgrees(n, frame_n, m, d, fallback_length);
    // Parity of the two own directions, as for the joining edge (TryMerge).
    if ((at_n.k - at_m.k) % 2 == 0) return false;
    if (frame_n.Apply(at_n.k) != d) return false;
    if (frame_[m].Apply(at_m.k) != Mod4(d + 2)) return false;
    const double dist = v.norm();
    return LengthFits(n, at_n.k, dist, fallback_length) &&
           LengthFits(m, at_m.k, dist, fallback_length);
  }

  // AdjacencyAgrees for a step near 45 degrees to an axis estimate: with the
  // image, the frames say which own direction to expect at either end; the
  // step must lie within max_adjacency_deviation_with_image_deg of both, the
  // parities must differ, the lengths fit, and the image must show a tile
  // edge between the two corners (which keeps out tile diagonals and
  // "knight" steps). Without the image such a step is refused.
  bool AmbiguousAdjacencyAgrees(int n, const Dihedral& frame_n, int m, int d,
                                double fallback_length) const {
    if (image_check_ == nullptr) return false;
    const Eigen::Vector2d v = nodes_.xy[m] - nodes_.xy[n];
    const double dist = v.norm();
    const int k_n = frame_n.Inverse().Apply(d);
    const int k_m = frame_[m].Inverse().Apply(d + 2);
    if ((k_n - k_m) % 2 == 0) return false;
    if (!(Direction(n, k_n).dot(v) >= adjacency_cosine_ * dist &&
          -Direction(m, k_m).dot(v) >= adjacency_cosine_ * dist))
      return false;
    if (!LengthFits(n, k_n, dist, fallback_length) ||
        !LengthFits(m, k_m, dist, fallback_length))
      return false;
    GridEdge edge;
    edge.a = std::min(n, m);
    edge.b = std::max(n, m);
    edge.length = edge.weight = dist;
    return (*image_check_)(edge);
  }

  const LatticeNodes& nodes_;
  const GridOptions& options_;
  const double min_axis_cosine_;
  const double adjacency_cosine_;
  const std::function<bool(const GridEdge&)>* image_check_;
  LabelTable table_;

  // Union-find and member lists (a root's list starts at the root).
  std::vector<int> parent_;
  std::vector<int> size_;
  std::vector<int> next_;
  std::vector<int> tail_;
  // Per root and lattice axis (0 = i, 1 = j): sum and count of edge weights.
  std::vector<std::array<double, 2>> weight_sum_;
  std::vector<std::array<int, 2>> edge_count_;
  // Per root: bounding box of its labels. A moved corner whose new label lies
  // more than one step outside the kept tree's box can neither collide with
  // nor neighbour any of its corners.
  std::vector<Eigen::Vector2i> box_low_;
  std::vector<Eigen::Vector2i> box_high_;

  // Per corner: label in its tree, the map from its own axis directions
  // (k = 0..3) to lattice steps, and its tree edges by own axis direction.
  std::vector<Eigen::Vector2i> label_;
  std::vector<Dihedral> frame_;
  std::vector<std::array<int, 4>> neighbor_;
  std::vector<std::array<double, 4>> neighbor_weight_;
  std::vector<std::array<double, 4>> neighbor_length_;
};

Refusal Forest::TryMerge(const GridEdge& edge) {
  int a = edge.a, b = edge.b;
  int ra = Find(a), rb = Find(b);
  // The larger tree (ties: smaller root index) keeps its labels.
  if (size_[ra] < size_[rb] || (size_[ra] == size_[rb] && ra > rb)) {
    std::swap(a, b);
    std::swap(ra, rb);
  }
  const double w = edge.weight;

  // The step a -> b in a's own axes and b -> a in b's.
  const Eigen::Vector2d e = nodes_.xy[b] - nodes_.xy[a];
  const AxisStep at_a = Classify(a, e);
  const AxisStep at_b = Classify(b, -e);
  if (at_a.cosine < min_axis_cosine_ || at_b.cosine < min_axis_cosine_)
    return Refusal::kAmbiguousAxis;
  // Lattice neighbours have Hessian axes 90 degrees apart (their dark and
  // light tiles swap; the orientation filter keeps only such pairs), so the
  // step and its reverse fall on own directions of different parity: equal
  // parity means one end classified it into the wrong quadrant.
  if ((at_a.k - at_b.k) % 2 == 0) return Refusal::kAmbiguousAxis;

  // Thesis eq. 4.2 at both ends, against the tree edges on the same lattice
  // line only: steep views legitimately foreshorten one axis by more than
  // the ratio, so edges of the other axis are not compared.
  const double wr = options_.neighbor_weight_ratio;
  for (const auto& [x, k] : {std::pair{a, at_a.k}, std::pair{b, at_b.k}}) {
    for (int slot : {Mod4(k), Mod4(k + 2)}) {
      if (neighbor_[x][slot] < 0) continue;
      const double other = neighbor_weight_[x][slot];
      if (!(other * wr > w && other < w * wr)) return Refusal::kNeighborWeight;
    }
  }

  // b's direction kb points where a's ka + 2 points; b's kb + 1 runs along
  // a's ka + 1 or against it (then a reflection of the own axes).
  // The reflection branch (sigma = -1) cannot be taken: both frames turn
  // like the image (direction k + 1 is direction k turned by +90 degrees),
  // so the dot product below equals Direction(b, kb) . Direction(a, ka),
  // and Classify put those within 45 degrees of -e and e (e: the step a ->
  // b), i.e. more than 90 degrees apart: it is negative. Trees therefore
  // merge by rotations only and every label turns like the image
  // (GridTest.AllComponentsTurnLikeTheImage); the general form is kept so
  // that the merge stays correct for any frame convention.
  const int sigma =
      Direction(b, at_b.k + 1).dot(Direction(a, at_a.k + 1)) < 0 ? 1 : -1;
  const Dihedral b_axes_to_a_axes{sigma, Mod4(at_a.k + 2 - sigma * at_b.k)};
  // Labels of b's tree -> labels of a's tree.
  const Dihedral rotation =
      frame_[a].Compose(b_axes_to_a_axes).Compose(frame_[b].Inverse());
  const Eigen::Vector2i offset = label_[a] +
                                 LatticeStep(frame_[a].Apply(at_a.k)) -
                                 rotation.Apply(label_[b]);
  const Dihedral rotation_inverse = rotation.Inverse();

  // Thesis eq. 4.3, per lattice axis (for the same reason): the mean edge
  // weights of the two trees along one axis, where both have edges on it.
  for (int axis = 0; axis < 2; ++axis) {
    const int moved_axis = rotation_inverse.Apply(axis) % 2;
    if (edge_count_[ra][axis] == 0 || edge_count_[rb][moved_axis] == 0)
      continue;
    const double ratio =
        (weight_sum_[ra][axis] / edge_count_[ra][axis]) /
        (weight_sum_[rb][moved_axis] / edge_count_[rb][moved_axis]);
    if (!(ratio > options_.tree_mean_weight_ratio_min &&
          ratio < options_.tree_mean_weight_ratio_max))
      return Refusal::kTreeMeanWeight;
  }

  // The moved tree's box in the kept tree's labels.
  const Eigen::Vector2i c0 = rotation.Apply(box_low_[rb]) + offset;
  const Eigen::Vector2i c1 = rotation.Apply(box_high_[rb]) + offset;
  const Eigen::Vector2i moved_low = c0.cwiseMin(c1);
  const Eigen::Vector2i moved_high = c0.cwiseMax(c1);
  if (moved_low.minCoeff() < -LabelTable::kMaxLabel ||
      moved_high.maxCoeff() > LabelTable::kMaxLabel)
    return Refusal::kLabelCollision;
  const Eigen::Vector2i near_low = box_low_[ra] - Eigen::Vector2i::Ones();
  const Eigen::Vector2i near_high = box_high_[ra] + Eigen::Vector2i::Ones();

  // Verify every corner of the moved tree that lands next to the kept one.
  for (int n = rb; n >= 0; n = next_[n]) {
    const Eigen::Vector2i new_label = rotation.Apply(label_[n]) + offset;
    if ((new_label.array() < near_low.array()).any() ||
        (new_label.array() > near_high.array()).any())
      continue;
    if (Lookup(ra, new_label) >= 0) return Refusal::kLabelCollision;
    const Dihedral new_frame = rotation.Compose(frame_[n]);
    for (int d = 0; d < 4; ++d) {
      const Eigen::Vector2i step = LatticeStep(d);
      const int m = Lookup(ra, new_label + step);
      if (m < 0) continue;
      if (!AdjacencyAgrees(n, new_frame, m, d, edge.length))
        return Refusal::kNeighborContradiction;
      // The lattice line through n and m, continued on both sides.
      const int before = Lookup(rb, label_[n] - rotation_inverse.Apply(step));
      if (before >= 0 && !Collinear(before, n, m))
        return Refusal::kCollinearity;
      const int after = Lookup(ra, new_label + 2 * step);
      if (after >= 0 && !Collinear(n, m, after)) return Refusal::kCollinearity;
    }
  }

  // Commit: relabel the smaller tree into the larger one.
  if (size_[ra] == 1) table_.Insert(ra, label_[ra], ra);
  const bool moved_in_table = size_[rb] > 1;
  for (int n = rb; n >= 0; n = next_[n]) {
    if (moved_in_table) table_.Erase(rb, label_[n]);
    label_[n] = rotation.Apply(label_[n]) + offset;
    frame_[n] = rotation.Compose(frame_[n]);
    table_.Insert(ra, label_[n], n);
  }
  box_low_[ra] = box_low_[ra].cwiseMin(moved_low);
  box_high_[ra] = box_high_[ra].cwiseMax(moved_high);
  parent_[rb] = ra;
  size_[ra] += size_[rb];
  next_[tail_[ra]] = rb;
  tail_[ra] = tail_[rb];
  for (int axis = 0; axis < 2; ++axis) {
    const int moved_axis = rotation_inverse.Apply(axis) % 2;
    weight_sum_[ra][axis] += weight_sum_[rb][moved_axis];
    edge_count_[ra][axis] += edge_count_[rb][moved_axis];
  }
  const int edge_axis = frame_[a].Apply(at_a.k) % 2;
  weight_sum_[ra][edge_axis] += w;
  edge_count_[ra][edge_axis] += 1;
  neighbor_[a][at_a.k] = b;
  neighbor_weight_[a][at_a.k] = w;
  neighbor_length_[a][at_a.k] = edge.length;
  neighbor_[b][at_b.k] = a;
  neighbor_weight_[b][at_b.k] = w;
  neighbor_length_[b][at_b.k] = edge.length;
  return Refusal::kMerged;
}

}  // namespace

void BuildLatticeForest(
    const LatticeNodes& nodes, const std::vector<GridEdge>& sorted_edges,
    const std::function<bool(const GridEdge&)>& crosses_tile,
    const std::function<bool(const GridEdge&)>& sides_flip,
    const GridOptions& options, GridSummary* summary, LatticeForest* forest,
    std::vector<GridEdgeTrace>* trace) {
  // With the intensity test refusing tile-crossing edges, the ambiguity band
  // around 45 degrees can be narrower (GridOptions).
  const bool image_guard = crosses_tile && options.refuse_penalised_edges;
  std::function<bool(const GridEdge&)> image_check;
  if (image_guard) {
    image_check = [&](const GridEdge& edge) {
      return !crosses_tile(edge) && !(sides_flip && sides_flip(edge));
    };
  }
  Forest state(nodes, options,
               image_guard ? options.max_axis_deviation_with_image_deg
                           : options.max_axis_deviation_deg,
               image_guard ? &image_check : nullptr);
  if (trace != nullptr) trace->clear();
  auto record = [&](const GridEdge& edge, Refusal decision) -> int {
    if (trace == nullptr) return -1;
    GridEdgeTrace t;
    t.a = edge.a;
    t.b = edge.b;
    t.length = edge.length;
    t.weight = edge.weight;
    t.penalised = edge.penalised;
    t.decision = decision;
    trace->push_back(t);
    return static_cast<int>(trace->size()) - 1;
  };
  auto count = [&](Refusal refusal) {
    switch (refusal) {
      case Refusal::kSameTree:
        ++summary->num_edges_same_tree;
        break;
      case Refusal::kMerged:
        ++summary->num_merges;
        break;
      case Refusal::kNeighborWeight:
        ++summary->num_rejected_neighbor_weight;
        break;
      case Refusal::kTreeMeanWeight:
        ++summary->num_rejected_tree_mean_weight;
        break;
      case Refusal::kAmbiguousAxis:
        ++summary->num_rejected_ambiguous_axis;
        break;
      case Refusal::kLabelCollision:
        ++summary->num_rejected_label_collision;
        break;
      case Refusal::kNeighborContradiction:
        ++summary->num_rejected_neighbor_contradiction;
        break;
      case Refusal::kCollinearity:
        ++summary->num_rejected_collinearity;
        break;
      case Refusal::kSidesFlip:
        ++summary->num_rejected_sides_flip;
        break;
      case Refusal::kPenalised:
        break;  // counted in num_edges_penalised
    }
  };

  // First pass in weight order: the edges sorted by length, merged with a
  // heap of the penalised ones (weight = length x penalty). An edge is
  // sampled for the penalty only when it is reached and joins two trees.
  auto heap_after = [](const GridEdge& x, const GridEdge& y) {
    return GridEdgeLess(y, x);
  };
  std::vector<GridEdge> heap;
  std::vector<GridEdge> refused;   // in the order they were refused
  std::vector<int> refused_trace;  // their trace entries
  size_t next = 0;
  while (next < sorted_edges.size() || !heap.empty()) {
    const bool from_heap =
        !heap.empty() && (next == sorted_edges.size() ||
                          GridEdgeLess(heap.front(), sorted_edges[next]));
    GridEdge edge;
    if (from_heap) {
      std::pop_heap(heap.begin(), heap.end(), heap_after);
      edge = heap.back();
      heap.pop_back();
    } else {
      edge = sorted_edges[next++];
    }
    if (state.Find(edge.a) == state.Find(edge.b)) {
      count(Refusal::kSameTree);
      record(edge, Refusal::kSameTree);
      continue;
    }
    if (!from_heap && crosses_tile && crosses_tile(edge)) {
      edge.weight *= options.penalty_factor;
      edge.penalised = true;
      ++summary->num_edges_penalised;
      if (options.refuse_penalised_edges) {
        count(Refusal::kPenalised);
        record(edge, Refusal::kPenalised);
        continue;
      }
      heap.push_back(edge);
      std::push_heap(heap.begin(), heap.end(), heap_after);
      continue;
    }
    if (sides_flip && sides_flip(edge)) {
      count(Refusal::kSidesFlip);
      record(edge, Refusal::kSidesFlip);
      continue;  // never retried
    }
    const Refusal refusal = state.TryMerge(edge);
    count(refusal);
    const int t = record(edge, refusal);
    if (refusal != Refusal::kMerged) {
      refused.push_back(edge);
      refused_trace.push_back(t);
    }
  }

  // Later passes retry the refused edges (the trees have grown since).
  for (int pass = 1; pass < options.kruskal_passes && !refused.empty();
       ++pass) {
    std::vector<GridEdge> still_refused;
    std::vector<int> still_refused_trace;
    int merges_this_pass = 0;
    for (size_t e = 0; e < refused.size(); ++e) {
      const GridEdge& edge = refused[e];
      if (state.Find(edge.a) == state.Find(edge.b)) continue;
      const Refusal refusal = state.TryMerge(edge);
      count(refusal);
      if (trace != nullptr) (*trace)[refused_trace[e]].decision = refusal;
      if (refusal == Refusal::kMerged) {
        ++merges_this_pass;
      } else {
        still_refused.push_back(edge);
        still_refused_trace.push_back(refused_trace[e]);
      }
    }
    if (merges_this_pass == 0) break;
    refused.swap(still_refused);
    refused_trace.swap(still_refused_trace);
  }
  state.Export(forest);
}

}  // namespace puzzlecal
