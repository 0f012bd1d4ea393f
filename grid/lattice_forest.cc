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
            options.merge.max_adjacency_deviation_with_image_deg * M_PI / 180)),
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
  // A merge under consideration: the joining edge (a in the kept tree with
  // root ra, b in the moved one with root rb), its steps in both corners'
  // own axes and the map of the moved tree's labels.
  struct MergePlan {
    int a = 0, b = 0, ra = 0, rb = 0;
    double weight = 0;
    double length = 0;
    AxisStep at_a, at_b;
    Dihedral rotation, rotation_inverse;
    Eigen::Vector2i offset = Eigen::Vector2i::Zero();
    Eigen::Vector2i moved_low = Eigen::Vector2i::Zero();
    Eigen::Vector2i moved_high = Eigen::Vector2i::Zero();
  };
  Refusal ClassifyJoiningEdge(MergePlan* plan) const;
  bool NeighborWeightsFit(const MergePlan& plan) const;
  void PlanRelabelling(MergePlan* plan) const;
  bool TreeMeanWeightsFit(const MergePlan& plan) const;
  Refusal VerifySeam(const MergePlan& plan) const;
  void Commit(const MergePlan& plan);

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
  // fits the tree edges there: within merge.max_adjacency_length_ratio of those
  // on the same line, else within merge.max_axis_aspect_ratio of those across,
  // else within merge.max_adjacency_length_ratio of `fallback`.
  bool LengthFits(int node, int k, double dist, double fallback) const {
    double ref = LineEdgeLength(node, k);
    double r = options_.merge.max_adjacency_length_ratio;
    if (ref == 0) {
      ref = LineEdgeLength(node, k + 1);
      if (ref > 0) {
        r = options_.merge.max_axis_aspect_ratio;
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
    if (std::abs(cross) > options_.merge.max_collinearity_sin * n1 * n2)
      return false;
    const double ratio = n2 / n1;
    return ratio <= options_.merge.max_line_spacing_ratio &&
           ratio * options_.merge.max_line_spacing_ratio >= 1.0;
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
  // step must lie within merge.max_adjacency_deviation_with_image_deg of both,
  // the parities must differ, the lengths fit, and the image must show a tile
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
  MergePlan plan;
  plan.a = edge.a;
  plan.b = edge.b;
  plan.ra = Find(plan.a);
  plan.rb = Find(plan.b);
  // The larger tree (ties: smaller root index) keeps its labels.
  if (size_[plan.ra] < size_[plan.rb] ||
      (size_[plan.ra] == size_[plan.rb] && plan.ra > plan.rb)) {
    std::swap(plan.a, plan.b);
    std::swap(plan.ra, plan.rb);
  }
  plan.weight = edge.weight;
  plan.length = edge.length;
  Refusal refusal = ClassifyJoiningEdge(&plan);
  if (refusal != Refusal::kMerged) return refusal;
  if (!NeighborWeightsFit(plan)) return Refusal::kNeighborWeight;
  PlanRelabelling(&plan);
  if (!TreeMeanWeightsFit(plan)) return Refusal::kTreeMeanWeight;
  refusal = VerifySeam(plan);
  if (refusal != Refusal::kMerged) return refusal;
  Commit(plan);
  return Refusal::kMerged;
}

// The step a -> b in a's own axes and b -> a in b's; kAmbiguousAxis when
// either lies near 45 degrees to the axes or their parities agree.
Refusal Forest::ClassifyJoiningEdge(MergePlan* plan) const {
  const Eigen::Vector2d e = nodes_.xy[plan->b] - nodes_.xy[plan->a];
  plan->at_a = Classify(plan->a, e);
  plan->at_b = Classify(plan->b, -e);
  if (plan->at_a.cosine < min_axis_cosine_ ||
      plan->at_b.cosine < min_axis_cosine_)
    return Refusal::kAmbiguousAxis;
  // Lattice neighbours have Hessian axes 90 degrees apart (their dark and
  // light tiles swap; the orientation filter keeps only such pairs), so the
  // step and its reverse fall on own directions of different parity: equal
  // parity means one end classified it into the wrong quadrant.
  if ((plan->at_a.k - plan->at_b.k) % 2 == 0) return Refusal::kAmbiguousAxis;
  return Refusal::kMerged;
}

// Thesis eq. 4.2 at both ends, against the tree edges on the same lattice
// line only: steep views legitimately foreshorten one axis by more than
// the ratio, so edges of the other axis are not compared.
bool Forest::NeighborWeightsFit(const MergePlan& plan) const {
  const double wr = options_.merge.neighbor_weight_ratio;
  const double w = plan.weight;
  for (const auto& [x, k] :
       {std::pair{plan.a, plan.at_a.k}, std::pair{plan.b, plan.at_b.k}}) {
    for (int slot : {Mod4(k), Mod4(k + 2)}) {
      if (neighbor_[x][slot] < 0) continue;
      const double other = neighbor_weight_[x][slot];
      if (!(other * wr > w && other < w * wr)) return false;
    }
  }
  return true;
}

// The map of b's tree labels into a's tree labels and the moved tree's box
// there.
void Forest::PlanRelabelling(MergePlan* plan) const {
  const int a = plan->a, b = plan->b;
  const AxisStep& at_a = plan->at_a;
  const AxisStep& at_b = plan->at_b;
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
  plan->rotation =
      frame_[a].Compose(b_axes_to_a_axes).Compose(frame_[b].Inverse());
  plan->offset = label_[a] + LatticeStep(frame_[a].Apply(at_a.k)) -
                 plan->rotation.Apply(label_[b]);
  plan->rotation_inverse = plan->rotation.Inverse();
  const Eigen::Vector2i c0 =
      plan->rotation.Apply(box_low_[plan->rb]) + plan->offset;
  const Eigen::Vector2i c1 =
      plan->rotation.Apply(box_high_[plan->rb]) + plan->offset;
  plan->moved_low = c0.cwiseMin(c1);
  plan->moved_high = c0.cwiseMax(c1);
}

// Thesis eq. 4.3, per lattice axis (for the same reason as eq. 4.2): the
// mean edge weights of the two trees along one axis, where both have edges
// on it.
bool Forest::TreeMeanWeightsFit(const MergePlan& plan) const {
  const int ra = plan.ra, rb = plan.rb;
  for (int axis = 0; axis < 2; ++axis) {
    const int moved_axis = plan.rotation_inverse.Apply(axis) % 2;
    if (edge_count_[ra][axis] == 0 || edge_count_[rb][moved_axis] == 0)
      continue;
    const double ratio =
        (weight_sum_[ra][axis] / edge_count_[ra][axis]) /
        (weight_sum_[rb][moved_axis] / edge_count_[rb][moved_axis]);
    if (!(ratio > options_.merge.tree_mean_weight_ratio_min &&
          ratio < options_.merge.tree_mean_weight_ratio_max))
      return false;
  }
  return true;
}

// Verifies every corner of the moved tree that lands next to the kept one:
// free label, agreeing new neighbours, collinear lines through them.
Refusal Forest::VerifySeam(const MergePlan& plan) const {
  if (plan.moved_low.minCoeff() < -LabelTable::kMaxLabel ||
      plan.moved_high.maxCoeff() > LabelTable::kMaxLabel)
    return Refusal::kLabelCollision;
  const int ra = plan.ra, rb = plan.rb;
  const Eigen::Vector2i near_low = box_low_[ra] - Eigen::Vector2i::Ones();
  const Eigen::Vector2i near_high = box_high_[ra] + Eigen::Vector2i::Ones();
  for (int n = rb; n >= 0; n = next_[n]) {
    const Eigen::Vector2i new_label =
        plan.rotation.Apply(label_[n]) + plan.offset;
    if ((new_label.array() < near_low.array()).any() ||
        (new_label.array() > near_high.array()).any())
      continue;
    if (Lookup(ra, new_label) >= 0) return Refusal::kLabelCollision;
    const Dihedral new_frame = plan.rotation.Compose(frame_[n]);
    for (int d = 0; d < 4; ++d) {
      const Eigen::Vector2i step = LatticeStep(d);
      const int m = Lookup(ra, new_label + step);
      if (m < 0) continue;
      if (!AdjacencyAgrees(n, new_frame, m, d, plan.length))
        return Refusal::kNeighborContradiction;
      // The lattice line through n and m, continued on both sides.
      const int before =
          Lookup(rb, label_[n] - plan.rotation_inverse.Apply(step));
      if (before >= 0 && !Collinear(before, n, m))
        return Refusal::kCollinearity;
      const int after = Lookup(ra, new_label + 2 * step);
      if (after >= 0 && !Collinear(n, m, after)) return Refusal::kCollinearity;
    }
  }
  return Refusal::kMerged;
}

// Relabels the smaller tree into the larger one and records the new edge.
void Forest::Commit(const MergePlan& plan) {
  const int a = plan.a, b = plan.b, ra = plan.ra, rb = plan.rb;
  if (size_[ra] == 1) table_.Insert(ra, label_[ra], ra);
  const bool moved_in_table = size_[rb] > 1;
  for (int n = rb; n >= 0; n = next_[n]) {
    if (moved_in_table) table_.Erase(rb, label_[n]);
    label_[n] = plan.rotation.Apply(label_[n]) + plan.offset;
    frame_[n] = plan.rotation.Compose(frame_[n]);
    table_.Insert(ra, label_[n], n);
  }
  box_low_[ra] = box_low_[ra].cwiseMin(plan.moved_low);
  box_high_[ra] = box_high_[ra].cwiseMax(plan.moved_high);
  parent_[rb] = ra;
  size_[ra] += size_[rb];
  next_[tail_[ra]] = rb;
  tail_[ra] = tail_[rb];
  for (int axis = 0; axis < 2; ++axis) {
    const int moved_axis = plan.rotation_inverse.Apply(axis) % 2;
    weight_sum_[ra][axis] += weight_sum_[rb][moved_axis];
    edge_count_[ra][axis] += edge_count_[rb][moved_axis];
  }
  const int edge_axis = frame_[a].Apply(plan.at_a.k) % 2;
  weight_sum_[ra][edge_axis] += plan.weight;
  edge_count_[ra][edge_axis] += 1;
  neighbor_[a][plan.at_a.k] = b;
  neighbor_weight_[a][plan.at_a.k] = plan.weight;
  neighbor_length_[a][plan.at_a.k] = plan.length;
  neighbor_[b][plan.at_b.k] = a;
  neighbor_weight_[b][plan.at_b.k] = plan.weight;
  neighbor_length_[b][plan.at_b.k] = plan.length;
}

// Adds one decision to the summary's counts.
void CountDecision(Refusal refusal, GridSummary* summary) {
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
}

// Appends an edge and its decision to `trace` (when not null); returns its
// entry, or -1.
int RecordDecision(const GridEdge& edge, Refusal decision,
                   std::vector<GridEdgeTrace>* trace) {
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
}

// Edges refused by a merge check, in the order they were refused, with
// their trace entries.
struct RefusedEdges {
  std::vector<GridEdge> edges;
  std::vector<int> trace;
};

// Kruskal's passes over the edges with the image tests of BuildLatticeForest.
class KruskalPasses {
 public:
  KruskalPasses(const std::function<bool(const GridEdge&)>& crosses_tile,
                const std::function<bool(const GridEdge&)>& sides_flip,
                const GridOptions& options, Forest* forest,
                GridSummary* summary, std::vector<GridEdgeTrace>* trace)
      : crosses_tile_(crosses_tile),
        sides_flip_(sides_flip),
        options_(options),
        forest_(*forest),
        summary_(summary),
        trace_(trace) {}

  RefusedEdges FirstPass(const std::vector<GridEdge>& sorted_edges);
  void Retry(RefusedEdges refused);

 private:
  void Decide(const GridEdge& edge, RefusedEdges* refused);

  const std::function<bool(const GridEdge&)>& crosses_tile_;
  const std::function<bool(const GridEdge&)>& sides_flip_;
  const GridOptions& options_;
  Forest& forest_;
  GridSummary* summary_;
  std::vector<GridEdgeTrace>* trace_;
  // Penalised edges waiting for their turn at the higher weight.
  std::vector<GridEdge> heap_;
};

// First pass in weight order: the edges sorted by length, merged with a
// heap of the penalised ones (weight = length x penalty). An edge is
// sampled for the penalty only when it is reached and joins two trees.
RefusedEdges KruskalPasses::FirstPass(
    const std::vector<GridEdge>& sorted_edges) {
  auto heap_after = [](const GridEdge& x, const GridEdge& y) {
    return GridEdgeLess(y, x);
  };
  RefusedEdges refused;
  size_t next = 0;
  while (next < sorted_edges.size() || !heap_.empty()) {
    const bool from_heap =
        !heap_.empty() && (next == sorted_edges.size() ||
                           GridEdgeLess(heap_.front(), sorted_edges[next]));
    GridEdge edge;
    if (from_heap) {
      std::pop_heap(heap_.begin(), heap_.end(), heap_after);
      edge = heap_.back();
      heap_.pop_back();
    } else {
      edge = sorted_edges[next++];
    }
    if (forest_.Find(edge.a) == forest_.Find(edge.b)) {
      CountDecision(Refusal::kSameTree, summary_);
      RecordDecision(edge, Refusal::kSameTree, trace_);
      continue;
    }
    if (!from_heap && crosses_tile_ && crosses_tile_(edge)) {
      edge.weight *= options_.image_tests.penalty_factor;
      edge.penalised = true;
      ++summary_->num_edges_penalised;
      if (options_.image_tests.refuse_penalised_edges) {
        CountDecision(Refusal::kPenalised, summary_);
        RecordDecision(edge, Refusal::kPenalised, trace_);
        continue;
      }
      heap_.push_back(edge);
      std::push_heap(heap_.begin(), heap_.end(), heap_after);
      continue;
    }
    Decide(edge, &refused);
  }
  return refused;
}

// An edge between two trees: refused when it runs through an undetected
// corner (never retried), else the merge is tried (refusals kept for the
// later passes).
void KruskalPasses::Decide(const GridEdge& edge, RefusedEdges* refused) {
  if (sides_flip_ && sides_flip_(edge)) {
    CountDecision(Refusal::kSidesFlip, summary_);
    RecordDecision(edge, Refusal::kSidesFlip, trace_);
    return;
  }
  const Refusal refusal = forest_.TryMerge(edge);
  CountDecision(refusal, summary_);
  const int t = RecordDecision(edge, refusal, trace_);
  if (refusal != Refusal::kMerged) {
    refused->edges.push_back(edge);
    refused->trace.push_back(t);
  }
}

// Later passes retry the refused edges (the trees have grown since), while
// any merges.
void KruskalPasses::Retry(RefusedEdges refused) {
  for (int pass = 1;
       pass < options_.merge.kruskal_passes && !refused.edges.empty(); ++pass) {
    RefusedEdges still_refused;
    int merges_this_pass = 0;
    for (size_t e = 0; e < refused.edges.size(); ++e) {
      const GridEdge& edge = refused.edges[e];
      if (forest_.Find(edge.a) == forest_.Find(edge.b)) continue;
      const Refusal refusal = forest_.TryMerge(edge);
      CountDecision(refusal, summary_);
      if (trace_ != nullptr) (*trace_)[refused.trace[e]].decision = refusal;
      if (refusal == Refusal::kMerged) {
        ++merges_this_pass;
      } else {
        still_refused.edges.push_back(edge);
        still_refused.trace.push_back(refused.trace[e]);
      }
    }
    if (merges_this_pass == 0) break;
    refused = std::move(still_refused);
  }
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
  const bool image_guard =
      crosses_tile && options.image_tests.refuse_penalised_edges;
  std::function<bool(const GridEdge&)> image_check;
  if (image_guard) {
    image_check = [&](const GridEdge& edge) {
      return !crosses_tile(edge) && !(sides_flip && sides_flip(edge));
    };
  }
  Forest state(nodes, options,
               image_guard ? options.merge.max_axis_deviation_with_image_deg
                           : options.merge.max_axis_deviation_deg,
               image_guard ? &image_check : nullptr);
  if (trace != nullptr) trace->clear();
  KruskalPasses passes(crosses_tile, sides_flip, options, &state, summary,
                       trace);
  passes.Retry(passes.FirstPass(sorted_edges));
  state.Export(forest);
}

}  // namespace puzzlecal
