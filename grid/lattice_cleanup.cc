#include "grid/lattice_cleanup.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>

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
           options.cleanup.line_prediction_tolerance * spacing;
    } else {
      const Eigen::Vector2d v1 = xy[n] - xy[p1];
      const Eigen::Vector2d v2 = xy[p1] - xy[p2];
      const double n1 = v1.norm(), n2 = v2.norm();
      const double cross = v1.x() * v2.y() - v1.y() * v2.x();
      const double r = options.merge.max_line_spacing_ratio;
      ok = n1 > 0 && n2 > 0 && v1.dot(v2) > 0 &&
           std::abs(cross) <= options.merge.max_collinearity_sin * n1 * n2 &&
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

// One prediction of a corner's position from its lattice neighbours, with
// the local spacing its error is measured in.
struct Prediction {
  Eigen::Vector2d xy;
  double spacing;
};

// The predictions of corner n from its lattice neighbours (n itself not
// used): per lattice line, interpolation between the neighbours on both
// sides (cubic or quadratic through a third or fourth corner when there is
// one) and quadratic extrapolation from each side with three corners; per
// tile at n, the parallelogram of its three other corners.
int PredictFromNeighbors(const std::vector<Eigen::Vector2d>& xy,
                         const Links& links, int n, Prediction out[12]) {
  int count = 0;
  auto add = [&](const Eigen::Vector2d& p, double spacing) {
    if (spacing > 0) out[count++] = {p, spacing};
  };
  for (int d = 0; d < 4; ++d) {
    const int p1 = links[n][d];
    if (p1 < 0) continue;
    const int p2 = links[p1][d];
    const int p3 = p2 >= 0 ? links[p2][d] : -1;
    if (p3 >= 0)
      add(3 * xy[p1] - 3 * xy[p2] + xy[p3], (xy[p1] - xy[p2]).norm());
    const int q1 = links[n][Mod4(d + 2)];
    if (d < 2 && q1 >= 0) {
      // Lagrange interpolation at t = 0 through t = -2, -1, 1, 2 (as many as
      // exist on the line).
      const int q2 = links[q1][Mod4(d + 2)];
      const double spacing = 0.5 * (xy[p1] - xy[q1]).norm();
      if (p2 >= 0 && q2 >= 0) {
        add((4 * (xy[p1] + xy[q1]) - xy[p2] - xy[q2]) / 6, spacing);
      } else if (p2 >= 0) {
        add(xy[q1] / 3 + xy[p1] - xy[p2] / 3, spacing);
      } else if (q2 >= 0) {
        add(xy[p1] / 3 + xy[q1] - xy[q2] / 3, spacing);
      } else {
        add(0.5 * (xy[p1] + xy[q1]), spacing);
      }
    }
    const int b = links[n][Mod4(d + 1)];
    if (b < 0) continue;
    const int m = links[p1][Mod4(d + 1)];
    if (m < 0 || links[b][d] != m) continue;
    add(xy[p1] + xy[b] - xy[m],
        std::min((xy[p1] - xy[m]).norm(), (xy[b] - xy[m]).norm()));
  }
  return count;
}

// Corner n sits off the lattice its neighbours predict: at least
// off_lattice.min_agreeing of its predictions, and more than half of them,
// agree with one another (within off_lattice.agreement of their spacing),
// and n lies farther than off_lattice.tolerance of their mean spacing from
// their mean. `error` gets that distance over the spacing (0 when too few
// agree).
bool OffLattice(const std::vector<Eigen::Vector2d>& xy, const Links& links,
                int n, const GridOffLatticeOptions& options, double* error) {
  *error = 0;
  Prediction predictions[12];
  const int count = PredictFromNeighbors(xy, links, n, predictions);
  if (count < options.min_agreeing) return false;
  // Any group's mean lies within agreement * s_i of its centre P_i and its
  // mean spacing is at least the smallest spacing: a corner within
  // tolerance * s_min - agreement * s_i of every P_i stays (the common case,
  // without the grouping below).
  double min_spacing = predictions[0].spacing;
  for (int i = 1; i < count; ++i)
    min_spacing = std::min(min_spacing, predictions[i].spacing);
  bool near_all = true;
  for (int i = 0; i < count && near_all; ++i) {
    near_all = (xy[n] - predictions[i].xy).norm() +
                   options.agreement * predictions[i].spacing <=
               options.tolerance * min_spacing;
  }
  if (near_all) return false;
  // The largest group of predictions agreeing with one of them.
  int best_size = 0;
  Eigen::Vector2d best_mean = Eigen::Vector2d::Zero();
  double best_spacing = 0;
  for (int i = 0; i < count; ++i) {
    int size = 0;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    double spacing = 0;
    for (int j = 0; j < count; ++j) {
      const double s = std::min(predictions[i].spacing, predictions[j].spacing);
      if ((predictions[i].xy - predictions[j].xy).norm() >
          options.agreement * s)
        continue;
      ++size;
      sum += predictions[j].xy;
      spacing += predictions[j].spacing;
    }
    if (size > best_size) {
      best_size = size;
      best_mean = sum / size;
      best_spacing = spacing / size;
    }
  }
  if (best_size < options.min_agreeing || 2 * best_size <= count) return false;
  *error = (xy[n] - best_mean).norm() / best_spacing;
  return *error > options.tolerance;
}

// Removes corners off the lattice their neighbours predict (OffLattice), in
// rounds (all judged on the links before a round's removals): a false
// corner next to a lattice position whose corner was not detected, which
// passed the merge and line checks where only few predictions exist.
// Returns how many were removed.
int RemoveOffLatticeCorners(const std::vector<Eigen::Vector2d>& xy,
                            const std::vector<int>& members,
                            const GridOffLatticeOptions& options, Links* links,
                            std::vector<int>* component_of,
                            GridSummary* summary) {
  int removed = 0;
  std::vector<int> removals;
  for (int round = 0; round < options.max_rounds; ++round) {
    removals.clear();
    for (int i : members) {
      if ((*component_of)[i] < 0) continue;
      double error;
      if (OffLattice(xy, *links, i, options, &error)) removals.push_back(i);
    }
    if (removals.empty()) break;
    for (int i : removals) {
      Unlink(links, i);
      (*component_of)[i] = -1;
    }
    removed += static_cast<int>(removals.size());
  }
  summary->num_removed_off_lattice += removed;
  return removed;
}

// Lattice position lookup of one component during the attach pass: the
// forest's table for corners still at their tree's labels, a hash map for
// attached and moved ones.
class ComponentLookup {
 public:
  ComponentLookup(const LatticeForest& forest,
                  const std::vector<int>& component_of,
                  const std::vector<Eigen::Vector2i>& label)
      : forest_(forest), component_of_(component_of), label_(label) {}

  // The corner of component `c` (tree `tree`) at `label`, or -1.
  int Find(int c, int tree, const Eigen::Vector2i& label) const {
    const int m = forest_.table.Find(tree, label);
    if (m >= 0 && component_of_[m] == c && label_[m] == label) return m;
    if (moved_.empty()) return -1;
    const auto it = moved_.find(Key(c, label));
    if (it == moved_.end()) return -1;
    const int a = it->second;
    return component_of_[a] == c && label_[a] == label ? a : -1;
  }
  // `corner` is now in component_of[corner] at label[corner].
  void Attach(int corner) {
    moved_[Key(component_of_[corner], label_[corner])] = corner;
  }

 private:
  static uint64_t Key(int c, const Eigen::Vector2i& label) {
    constexpr int64_t kOffset = int64_t{1} << 21;
    return (static_cast<uint64_t>(c) << 44) |
           (static_cast<uint64_t>(label.x() + kOffset) << 22) |
           static_cast<uint64_t>(label.y() + kOffset);
  }

  const LatticeForest& forest_;
  const std::vector<int>& component_of_;
  const std::vector<Eigen::Vector2i>& label_;
  std::unordered_map<uint64_t, int> moved_;
};

// How well the lattice of component c (tree `tree`) around the free label L
// predicts a corner at p: quadratic extrapolation along each of the 4 lines
// through L with three corners, and the parallelogram of each tile at L
// with its three other corners; an error up to `support` of the local
// spacing supports, above `contradict` contradicts (in between: neither).
// Returns the largest relative error of the supporting verdicts.
double PredictAt(const std::vector<Eigen::Vector2d>& xy,
                 const ComponentLookup& lookup, int c, int tree,
                 const Eigen::Vector2i& L, const Eigen::Vector2d& p,
                 double support, double contradict, int* supported,
                 int* contradicted) {
  *supported = 0;
  *contradicted = 0;
  double worst = 0;
  auto verdict = [&](const Eigen::Vector2d& predicted, double spacing) {
    if (!(spacing > 0)) return;
    const double error = (p - predicted).norm() / spacing;
    if (error <= support) {
      ++*supported;
      worst = std::max(worst, error);
    } else if (error > contradict) {
      ++*contradicted;
    }
  };
  int near[4];
  for (int d = 0; d < 4; ++d)
    near[d] = lookup.Find(c, tree, L + LatticeStep(d));
  for (int d = 0; d < 4; ++d) {
    if (near[d] < 0) continue;
    const int q2 = lookup.Find(c, tree, L + 2 * LatticeStep(d));
    if (q2 < 0) continue;
    const int q3 = lookup.Find(c, tree, L + 3 * LatticeStep(d));
    if (q3 < 0) continue;
    verdict(3 * xy[near[d]] - 3 * xy[q2] + xy[q3],
            (xy[near[d]] - xy[q2]).norm());
  }
  for (int d = 0; d < 4; ++d) {
    const int a = near[d], b = near[Mod4(d + 1)];
    if (a < 0 || b < 0) continue;
    const int m = lookup.Find(c, tree, L + LatticeStep(d) + LatticeStep(d + 1));
    if (m < 0) continue;
    verdict(xy[a] + xy[b] - xy[m],
            std::min((xy[a] - xy[m]).norm(), (xy[b] - xy[m]).norm()));
  }
  return worst;
}

// A free label `at` of component c (tree `tree`) where the component's
// lattice predicts corner u, with the largest relative error of the
// supporting predictions (see PredictAt).
struct Placement {
  double error;
  int u;
  int c;
  int tree;
  Eigen::Vector2i at;
};

// Best prediction first; ties by corner, component and label.
bool PlacementLess(const Placement& x, const Placement& y) {
  if (x.error != y.error) return x.error < y.error;
  if (x.u != y.u) return x.u < y.u;
  if (x.c != y.c) return x.c < y.c;
  if (x.at.x() != y.at.x()) return x.at.x() < y.at.x();
  return x.at.y() < y.at.y();
}

// The attach pass: corners outside every component (never joined, removed,
// or in a dropped tree) join a component at a free label next to it when
// the component's lattice around that label predicts them there (see
// PredictAt) and the four tiles around them alternate. Candidates are the
// candidate edges between such a corner and a component corner. Rounds
// repeat while corners join (a joined corner predicts the next one).
// Then components join one another (see JoinOneComponent), and corners are
// attached again, up to options.attach.max_component_joins times.
class AttachPass {
 public:
  AttachPass(const std::vector<Eigen::Vector2d>& xy, const cv::Mat& image,
             const LatticeForest& forest, const std::vector<GridEdge>& edges,
             const GridOptions& options, int num_components, Links* links,
             std::vector<int>* component_of, GridSummary* summary)
      : xy_(xy),
        image_(image),
        forest_(forest),
        edges_(edges),
        options_(options),
        num_components_(num_components),
        links_(*links),
        component_of_(*component_of),
        summary_(summary),
        labels_(forest.label),
        lookup_(forest, component_of_, labels_),
        refused_(xy.size(), 0) {}

  // Runs the pass; true when any corner moved (then see labels()).
  bool Run();
  std::vector<Eigen::Vector2i>& labels() { return labels_; }

 private:
  bool Outside(int i) const {
    return component_of_[i] < 0 && forest_.tree[i] >= 0;
  }
  void AddPlacements(int u, int m, std::vector<Placement>* out) const;

  bool AttachOutsideCorners();
  int AttachRound(std::vector<Placement>* proposals);
  std::vector<char> CrowdedPlaces(
      const std::vector<Placement>& proposals) const;
  void RefuseAmbiguousCorners(const std::vector<Placement>& proposals);
  bool TryAttach(const Placement& p);

  bool JoinOneComponent();
  std::vector<Placement> JoinPlaces() const;
  bool JoinSymmetry(const Placement& place, Dihedral* symmetry) const;
  bool JoiningStep(int c, int tree, const Eigen::Vector2i& at,
                   const Eigen::Vector2d& p, int k, Eigen::Vector2d* v) const;
  bool MovingStep(int base, int k, Eigen::Vector2d* v) const;
  bool TargetLabels(const Placement& place, const Dihedral& symmetry,
                    const std::vector<int>& members,
                    std::vector<Eigen::Vector2i>* target) const;
  bool SeamHolds(const Placement& place, const std::vector<int>& members,
                 const std::vector<Eigen::Vector2i>& target) const;
  void MoveComponent(int c, int tree, const std::vector<int>& members,
                     const std::vector<Eigen::Vector2i>& target);

  const std::vector<Eigen::Vector2d>& xy_;
  const cv::Mat& image_;
  const LatticeForest& forest_;
  const std::vector<GridEdge>& edges_;
  const GridOptions& options_;
  const int num_components_;
  Links& links_;
  std::vector<int>& component_of_;
  GridSummary* summary_;
  std::vector<Eigen::Vector2i> labels_;
  ComponentLookup lookup_;
  // Corners that fit two places or failed the saddle test: never attached.
  std::vector<char> refused_;
  // (outside corner, component corner) pairs of the candidate edges.
  std::vector<std::pair<int, int>> pairs_;
};

bool AttachPass::Run() {
  for (const GridEdge& e : edges_) {
    if (Outside(e.a) && component_of_[e.b] >= 0) pairs_.emplace_back(e.a, e.b);
    if (Outside(e.b) && component_of_[e.a] >= 0) pairs_.emplace_back(e.b, e.a);
  }
  if (pairs_.empty() && num_components_ < 2) return false;
  bool any = false;
  for (int joins = 0; joins <= options_.attach.max_component_joins; ++joins) {
    if (AttachOutsideCorners()) any = true;
    if (joins == options_.attach.max_component_joins || !JoinOneComponent())
      break;
    ++summary_->num_components_joined;
    any = true;
  }
  return any;
}

// Appends the placements of corner u at the free labels next to corner m in
// m's component where at least attach.min_support predictions hold and none
// contradicts.
void AttachPass::AddPlacements(int u, int m,
                               std::vector<Placement>* out) const {
  const int c = component_of_[m];
  const int tree = forest_.tree[m];
  for (int d = 0; d < 4; ++d) {
    if (links_[m][d] >= 0) continue;
    const Eigen::Vector2i at = labels_[m] + LatticeStep(d);
    if (lookup_.Find(c, tree, at) >= 0) continue;
    int supported, contradicted;
    const double error = PredictAt(
        xy_, lookup_, c, tree, at, xy_[u], options_.attach.tolerance,
        options_.attach.contradiction_tolerance, &supported, &contradicted);
    if (supported >= options_.attach.min_support && contradicted == 0)
      out->push_back({error, u, c, tree, at});
  }
}

// Rounds of attaching outside corners while any join; true when any joined.
bool AttachPass::AttachOutsideCorners() {
  std::vector<Placement> proposals;
  bool any = false;
  for (int round = 0; round < options_.attach.rounds; ++round) {
    const int joined = AttachRound(&proposals);
    if (joined == 0) break;
    summary_->num_attached += joined;
    any = true;
  }
  return any;
}

// One round: every outside corner that fits exactly one free place, alone,
// joins there in order of prediction error. Returns how many joined.
int AttachPass::AttachRound(std::vector<Placement>* proposals) {
  proposals->clear();
  for (const auto& [u, m] : pairs_) {
    if (!Outside(u) || refused_[u] || component_of_[m] < 0) continue;
    AddPlacements(u, m, proposals);
  }
  if (proposals->empty()) return 0;
  std::sort(proposals->begin(), proposals->end(), PlacementLess);
  const std::vector<char> crowded = CrowdedPlaces(*proposals);
  RefuseAmbiguousCorners(*proposals);
  int joined = 0;
  for (size_t k = 0; k < proposals->size(); ++k) {
    const Placement& p = (*proposals)[k];
    if (crowded[k] || refused_[p.u] || !Outside(p.u)) continue;
    if (lookup_.Find(p.c, p.tree, p.at) >= 0) continue;  // taken this round
    if (TryAttach(p)) ++joined;
  }
  return joined;
}

// Per proposal: 1 when two different corners fit its place (duplicate
// detections, clutter); such places stay free.
std::vector<char> AttachPass::CrowdedPlaces(
    const std::vector<Placement>& proposals) const {
  std::vector<int> by_place(proposals.size());
  for (size_t k = 0; k < proposals.size(); ++k)
    by_place[k] = static_cast<int>(k);
  auto place_less = [&](int x, int y) {
    const Placement& a = proposals[x];
    const Placement& b = proposals[y];
    if (a.c != b.c) return a.c < b.c;
    if (a.at.x() != b.at.x()) return a.at.x() < b.at.x();
    if (a.at.y() != b.at.y()) return a.at.y() < b.at.y();
    return a.u < b.u;
  };
  std::sort(by_place.begin(), by_place.end(), place_less);
  std::vector<char> crowded(proposals.size(), 0);
  for (size_t k = 0; k < by_place.size();) {
    size_t end = k + 1;
    bool two = false;
    const Placement& a = proposals[by_place[k]];
    while (end < by_place.size() && proposals[by_place[end]].c == a.c &&
           proposals[by_place[end]].at == a.at) {
      two = two || proposals[by_place[end]].u != a.u;
      ++end;
    }
    if (two)
      for (size_t j = k; j < end; ++j) crowded[by_place[j]] = 1;
    k = end;
  }
  return crowded;
}

// A corner that fits two places is ambiguous and is refused for good.
void AttachPass::RefuseAmbiguousCorners(
    const std::vector<Placement>& proposals) {
  std::vector<int> first(xy_.size(), -1);
  for (size_t k = 0; k < proposals.size(); ++k) {
    const Placement& p = proposals[k];
    if (first[p.u] == -1) {
      first[p.u] = static_cast<int>(k);
    } else {
      const Placement& q = proposals[first[p.u]];
      if (q.c != p.c || q.at != p.at) refused_[p.u] = 1;
    }
  }
}

// Puts p.u at its place when its four tiles alternate there (at either
// sample fraction); else refuses it for good. True when it joined.
bool AttachPass::TryAttach(const Placement& p) {
  const int previous = component_of_[p.u];
  component_of_[p.u] = p.c;
  labels_[p.u] = p.at;
  for (int d = 0; d < 4; ++d)
    links_[p.u][d] = lookup_.Find(p.c, p.tree, p.at + LatticeStep(d));
  if (!LooksLikeSaddle(xy_, image_, links_, p.u,
                       options_.cleanup.saddle_sample_fraction) &&
      !LooksLikeSaddle(xy_, image_, links_, p.u,
                       options_.attach.saddle_sample_fraction)) {
    for (int d = 0; d < 4; ++d) links_[p.u][d] = -1;
    component_of_[p.u] = previous;
    labels_[p.u] = forest_.label[p.u];
    refused_[p.u] = 1;
    return false;
  }
  for (int d = 0; d < 4; ++d) {
    const int m = links_[p.u][d];
    if (m >= 0) links_[m][Mod4(d + 2)] = p.u;
  }
  lookup_.Attach(p.u);
  return true;
}

// The places where a corner of one component could take a free label of a
// larger one (ties: of the one with the smaller number), sorted.
std::vector<Placement> AttachPass::JoinPlaces() const {
  std::vector<int> size(num_components_, 0);
  for (int c : component_of_)
    if (c >= 0) ++size[c];
  std::vector<Placement> places;
  for (const GridEdge& e : edges_) {
    for (const auto& [u, m] :
         {std::make_pair(e.a, e.b), std::make_pair(e.b, e.a)}) {
      const int cu = component_of_[u], cm = component_of_[m];
      if (cu < 0 || cm < 0 || cu == cm) continue;
      if (size[cu] > size[cm] || (size[cu] == size[cm] && cu < cm)) continue;
      AddPlacements(u, m, &places);
    }
  }
  std::sort(places.begin(), places.end(), PlacementLess);
  return places;
}

// One component joins another at the first place (in order of prediction
// error) where the other's lattice predicts one of its corners, when the
// lattice directions of both at that corner agree on both axes under one
// symmetry (JoinSymmetry), no two corners meet on one label and the seam
// holds (SeamHolds). The smaller component joins the larger. False when none
// joins.
bool AttachPass::JoinOneComponent() {
  if (num_components_ < 2) return false;
  std::vector<int> members;
  std::vector<Eigen::Vector2i> target;
  for (const Placement& place : JoinPlaces()) {
    Dihedral symmetry;
    if (!JoinSymmetry(place, &symmetry)) continue;
    const int moving = component_of_[place.u];
    members.clear();
    for (int i = 0; i < static_cast<int>(xy_.size()); ++i)
      if (component_of_[i] == moving) members.push_back(i);
    if (!TargetLabels(place, symmetry, members, &target)) continue;
    if (!SeamHolds(place, members, target)) continue;
    MoveComponent(place.c, place.tree, members, target);
    return true;
  }
  return false;
}

// The image vector of lattice step k of component c (tree `tree`) at label
// `at` (image position p): to its neighbour there, else from the opposite
// one; false when neither exists.
bool AttachPass::JoiningStep(int c, int tree, const Eigen::Vector2i& at,
                             const Eigen::Vector2d& p, int k,
                             Eigen::Vector2d* v) const {
  const int a = lookup_.Find(c, tree, at + LatticeStep(k));
  if (a >= 0) {
    *v = xy_[a] - p;
    return true;
  }
  const int b = lookup_.Find(c, tree, at - LatticeStep(k));
  if (b >= 0) {
    *v = p - xy_[b];
    return true;
  }
  return false;
}

// The image vector of lattice step k of corner `base` in its own component;
// false when it has no neighbour on that line (or base < 0).
bool AttachPass::MovingStep(int base, int k, Eigen::Vector2d* v) const {
  if (base < 0) return false;
  const int a = links_[base][k], b = links_[base][Mod4(k + 2)];
  if (a >= 0) {
    *v = xy_[a] - xy_[base];
    return true;
  }
  if (b >= 0) {
    *v = xy_[base] - xy_[b];
    return true;
  }
  return false;
}

// The one lattice symmetry under which the image directions of the joining
// component at the place (r) and of the moving one at the corner (w) agree
// within attach.max_join_direction_deviation_deg on both axes (directions from
// the place's own neighbours, else from a neighbour across). False when none or
// several do.
bool AttachPass::JoinSymmetry(const Placement& place,
                              Dihedral* symmetry) const {
  const int u = place.u, c = place.c, tree = place.tree;
  Eigen::Vector2d r[4], w[4];
  bool has_r[4], has_w[4];
  for (int k = 0; k < 4; ++k) {
    has_r[k] = JoiningStep(c, tree, place.at, xy_[u], k, &r[k]);
    for (int j : {k + 1, k + 3}) {
      if (has_r[k]) break;
      const int a = lookup_.Find(c, tree, place.at + LatticeStep(j));
      has_r[k] = a >= 0 && JoiningStep(c, tree, labels_[a], xy_[a], k, &r[k]);
    }
    has_w[k] = MovingStep(u, k, &w[k]) ||
               MovingStep(links_[u][Mod4(k + 1)], k, &w[k]) ||
               MovingStep(links_[u][Mod4(k + 3)], k, &w[k]);
  }
  const double min_cosine =
      std::cos(options_.attach.max_join_direction_deviation_deg * M_PI / 180);
  int found = 0;
  for (int sign : {1, -1}) {
    for (int shift = 0; shift < 4; ++shift) {
      const Dihedral t{sign, shift};
      bool axis_agrees[2] = {false, false}, bad = false;
      for (int d = 0; d < 4; ++d) {
        const int k = t.Apply(d);
        if (!has_w[d] || !has_r[k]) continue;
        const double cosine =
            r[k].dot(w[d]) / (r[k].norm() * w[d].norm() + 1e-300);
        if (cosine >= min_cosine) {
          axis_agrees[k % 2] = true;
        } else {
          bad = true;
        }
      }
      if (!bad && axis_agrees[0] && axis_agrees[1]) {
        ++found;
        *symmetry = t;
      }
    }
  }
  return found == 1;
}

// The labels of the moving component's members in the joining component;
// false when one of them is taken.
bool AttachPass::TargetLabels(const Placement& place, const Dihedral& symmetry,
                              const std::vector<int>& members,
                              std::vector<Eigen::Vector2i>* target) const {
  target->clear();
  for (int p : members) {
    const Eigen::Vector2i at =
        place.at +
        symmetry.Apply(Eigen::Vector2i(labels_[p] - labels_[place.u]));
    if (lookup_.Find(place.c, place.tree, at) >= 0) return false;
    target->push_back(at);
  }
  return true;
}

// At every moved label next to the joining component, no prediction fails
// or more hold than fail.
bool AttachPass::SeamHolds(const Placement& place,
                           const std::vector<int>& members,
                           const std::vector<Eigen::Vector2i>& target) const {
  for (size_t q = 0; q < members.size(); ++q) {
    bool seam = false;
    for (int k = 0; k < 4 && !seam; ++k)
      seam = lookup_.Find(place.c, place.tree, target[q] + LatticeStep(k)) >= 0;
    if (!seam) continue;
    int supported, contradicted;
    PredictAt(xy_, lookup_, place.c, place.tree, target[q], xy_[members[q]],
              options_.attach.tolerance,
              options_.attach.contradiction_tolerance, &supported,
              &contradicted);
    if (!(contradicted == 0 || supported > contradicted)) return false;
  }
  return true;
}

// Moves the members to their target labels in component c and links them.
void AttachPass::MoveComponent(int c, int tree, const std::vector<int>& members,
                               const std::vector<Eigen::Vector2i>& target) {
  for (size_t q = 0; q < members.size(); ++q) {
    component_of_[members[q]] = c;
    labels_[members[q]] = target[q];
    lookup_.Attach(members[q]);
  }
  for (int p : members) {
    for (int k = 0; k < 4; ++k) {
      const int m = lookup_.Find(c, tree, labels_[p] + LatticeStep(k));
      links_[p][k] = m;
      if (m >= 0) links_[m][Mod4(k + 2)] = p;
    }
  }
}

// Removes corners that are no saddles of the lattice's checkerboard (all
// judged on the links before any removal).
void RemoveNonSaddles(const std::vector<Eigen::Vector2d>& xy,
                      const cv::Mat& image, const std::vector<int>& members,
                      const GridOptions& options, Links* links,
                      std::vector<char>* alive, GridSummary* summary) {
  std::vector<int> not_saddle;
  for (int i : members) {
    if (!LooksLikeSaddle(xy, image, *links, i,
                         options.cleanup.saddle_sample_fraction))
      not_saddle.push_back(i);
  }
  for (int i : not_saddle) {
    Unlink(links, i);
    (*alive)[i] = 0;
    ++summary->num_removed_not_saddle;
  }
}

// Removes corners their lattice lines contradict more often than they
// support them (ScoreCorner), a few rounds (a removal changes the lines).
void RemoveUnpredicted(const std::vector<Eigen::Vector2d>& xy,
                       const std::vector<int>& members,
                       const GridOptions& options, Links* links,
                       std::vector<char>* alive, GridSummary* summary) {
  constexpr int kMaxRounds = 4;
  std::vector<int> removals;
  for (int round = 0; round < kMaxRounds; ++round) {
    removals.clear();
    for (int i : members) {
      if (!(*alive)[i]) continue;
      int supported, contradicted;
      ScoreCorner(xy, *links, i, options, &supported, &contradicted);
      if (contradicted > supported) removals.push_back(i);
    }
    if (removals.empty()) break;
    for (int i : removals) {
      Unlink(links, i);
      (*alive)[i] = 0;
      ++summary->num_removed_by_prediction;
    }
  }
}

// Splits the live corners into 4-connected label sets: `component_of` gets a
// component number per corner (-1: not alive, -3: in a set below
// options.cleanup.min_component_size, dropped); returns that many empty
// components.
std::vector<GridComponent> SplitComponents(const std::vector<int>& members,
                                           const Links& links,
                                           const std::vector<char>& alive,
                                           const GridOptions& options,
                                           std::vector<int>* component_of,
                                           GridSummary* summary) {
  std::vector<GridComponent> components;
  component_of->assign(links.size(), -1);
  std::vector<int> queue;
  queue.reserve(links.size());
  for (int seed : members) {
    if (!alive[seed] || (*component_of)[seed] != -1) continue;
    queue.clear();
    queue.push_back(seed);
    (*component_of)[seed] = -2;
    for (size_t q = 0; q < queue.size(); ++q) {
      for (int m : links[queue[q]]) {
        if (m >= 0 && alive[m] && (*component_of)[m] == -1) {
          (*component_of)[m] = -2;
          queue.push_back(m);
        }
      }
    }
    int id = -3;  // dropped
    if (static_cast<int>(queue.size()) < options.cleanup.min_component_size) {
      ++summary->num_components_dropped;
    } else {
      id = static_cast<int>(components.size());
      components.emplace_back();
      components.back().corner.reserve(queue.size());
    }
    for (int c : queue) (*component_of)[c] = id;
  }
  return components;
}

// Fills the components with their members (in index order) and labels
// shifted to start at (0, 0), drops empty ones and sorts them (largest
// first, ties by smallest corner index).
void FinishComponents(const std::vector<int>& members,
                      const std::vector<int>& component_of,
                      const std::vector<Eigen::Vector2i>& label,
                      std::vector<GridComponent>* components) {
  for (int i : members)
    if (component_of[i] >= 0)
      (*components)[component_of[i]].corner.push_back(i);
  components->erase(std::remove_if(components->begin(), components->end(),
                                   [](const GridComponent& component) {
                                     return component.corner.empty();
                                   }),
                    components->end());
  for (GridComponent& component : *components) {
    Eigen::Vector2i low = label[component.corner[0]];
    for (int c : component.corner) low = low.cwiseMin(label[c]);
    component.ij.reserve(component.corner.size());
    for (int c : component.corner) component.ij.push_back(label[c] - low);
  }
  std::sort(components->begin(), components->end(),
            [](const GridComponent& x, const GridComponent& y) {
              if (x.corner.size() != y.corner.size())
                return x.corner.size() > y.corner.size();
              return x.corner.front() < y.corner.front();
            });
}

}  // namespace

std::vector<GridComponent> ExtractComponents(
    const std::vector<Eigen::Vector2d>& xy, const cv::Mat& image,
    const LatticeForest& forest, const std::vector<GridEdge>& edges,
    const GridOptions& options, GridSummary* summary) {
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
  if (!image.empty() && options.cleanup.check_saddle_pattern)
    RemoveNonSaddles(xy, image, members, options, &links, &alive, summary);
  RemoveUnpredicted(xy, members, options, &links, &alive, summary);

  std::vector<int> component_of;
  std::vector<GridComponent> components =
      SplitComponents(members, links, alive, options, &component_of, summary);
  std::vector<Eigen::Vector2i> attached_label;
  if (!image.empty() && options.attach.rounds > 0 && !components.empty()) {
    AttachPass pass(xy, image, forest, edges, options,
                    static_cast<int>(components.size()), &links, &component_of,
                    summary);
    if (pass.Run()) attached_label = std::move(pass.labels());
  }
  if (options.off_lattice.enabled &&
      RemoveOffLatticeCorners(xy, members, options.off_lattice, &links,
                              &component_of, summary) > 0) {
    // Components may have fallen apart.
    std::vector<char> kept(n, 0);
    for (int i : members) kept[i] = component_of[i] >= 0;
    components =
        SplitComponents(members, links, kept, options, &component_of, summary);
  }
  FinishComponents(members, component_of,
                   attached_label.empty() ? forest.label : attached_label,
                   &components);
  return components;
}

}  // namespace puzzlecal
