#include "grid/grid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <sstream>

#include "grid/edge_intensity.h"
#include "grid/label_table.h"
#include "grid/lattice_cleanup.h"
#include "grid/lattice_forest.h"
#include "grid/nearest_neighbors.h"
#include "util/enum_names.h"
#include "util/failure.h"
#include "util/timer.h"

namespace puzzlecal {
constexpr EnumName<GridEdgeDecision> kGridEdgeDecisionNames[] = {
    {GridEdgeDecision::kMerged, "merged"},
    {GridEdgeDecision::kSameTree, "same tree"},
    {GridEdgeDecision::kNeighborWeight, "neighbor weight"},
    {GridEdgeDecision::kTreeMeanWeight, "tree mean weight"},
    {GridEdgeDecision::kAmbiguousAxis, "ambiguous axis"},
    {GridEdgeDecision::kLabelCollision, "label collision"},
    {GridEdgeDecision::kNeighborContradiction, "neighbor contradiction"},
    {GridEdgeDecision::kCollinearity, "collinearity"},
    {GridEdgeDecision::kSidesFlip, "sides flip"},
    {GridEdgeDecision::kPenalised, "penalised"},
};

const char* GridEdgeDecisionName(GridEdgeDecision decision) {
  return NameOf(kGridEdgeDecisionNames, decision, "unknown");
}

bool GridCandidateOptions::Check(std::string* why) const {
  if (num_neighbors < 1 || num_neighbors > 64)
    return Fail("candidates.num_neighbors must be in [1, 64]", why);
  if (!(min_orientation_difference_deg >= 0 &&
        min_orientation_difference_deg < 90))
    return Fail("candidates.min_orientation_difference_deg must be in [0, 90)",
                why);
  if (!(min_edge_length_px >= 0 && std::isfinite(min_edge_length_px)))
    return Fail("candidates.min_edge_length_px must be finite and >= 0", why);
  if (!(max_abs_coordinate_px > 0 && max_abs_coordinate_px <= 1e9))
    return Fail("candidates.max_abs_coordinate_px must be in (0, 1e9]", why);
  return true;
}

bool GridEdgeImageOptions::Check(std::string* why) const {
  if (intensity_samples < 3 || intensity_samples > 1000)
    return Fail("image_tests.intensity_samples must be in [3, 1000]", why);
  if (!(intensity_difference_fraction > 0 &&
        std::isfinite(intensity_difference_fraction)))
    return Fail(
        "image_tests.intensity_difference_fraction must be finite and "
        "> 0",
        why);
  if (!(penalty_factor >= 1 && std::isfinite(penalty_factor)))
    return Fail("image_tests.penalty_factor must be finite and >= 1", why);
  if (!(side_offset_fraction > 0 && side_offset_fraction <= 0.5))
    return Fail("image_tests.side_offset_fraction must be in (0, 0.5]", why);
  if (!(side_min_contrast >= 0 && std::isfinite(side_min_contrast)))
    return Fail("image_tests.side_min_contrast must be finite and >= 0", why);
  return true;
}

bool GridMergeOptions::Check(std::string* why) const {
  if (!(neighbor_weight_ratio > 1 && std::isfinite(neighbor_weight_ratio)))
    return Fail("merge.neighbor_weight_ratio must be finite and > 1", why);
  if (!(tree_mean_weight_ratio_min > 0 && tree_mean_weight_ratio_min < 1 &&
        tree_mean_weight_ratio_max > 1 &&
        std::isfinite(tree_mean_weight_ratio_max)))
    return Fail(
        "merge.tree_mean_weight_ratio_min must be in (0, 1) and "
        "merge.tree_mean_weight_ratio_max finite and > 1",
        why);
  if (!(max_collinearity_sin > 0 && max_collinearity_sin <= 1))
    return Fail("merge.max_collinearity_sin must be in (0, 1]", why);
  if (!(max_line_spacing_ratio >= 1 && std::isfinite(max_line_spacing_ratio)))
    return Fail("merge.max_line_spacing_ratio must be finite and >= 1", why);
  if (!(max_axis_deviation_deg > 0 && max_axis_deviation_deg <= 45))
    return Fail("merge.max_axis_deviation_deg must be in (0, 45]", why);
  if (!(max_axis_deviation_with_image_deg > 0 &&
        max_axis_deviation_with_image_deg <= 45))
    return Fail("merge.max_axis_deviation_with_image_deg must be in (0, 45]",
                why);
  if (!(max_adjacency_deviation_with_image_deg > 0 &&
        max_adjacency_deviation_with_image_deg < 90))
    return Fail(
        "merge.max_adjacency_deviation_with_image_deg must be in (0, 90)", why);
  if (!(max_adjacency_length_ratio >= 1 &&
        std::isfinite(max_adjacency_length_ratio)))
    return Fail("merge.max_adjacency_length_ratio must be finite and >= 1",
                why);
  if (!(max_axis_aspect_ratio >= 1 && std::isfinite(max_axis_aspect_ratio)))
    return Fail("merge.max_axis_aspect_ratio must be finite and >= 1", why);
  if (kruskal_passes < 1 || kruskal_passes > 10)
    return Fail("merge.kruskal_passes must be in [1, 10]", why);
  return true;
}

bool GridCleanupOptions::Check(std::string* why) const {
  if (!(saddle_sample_fraction > 0 && saddle_sample_fraction <= 0.5))
    return Fail("cleanup.saddle_sample_fraction must be in (0, 0.5]", why);
  if (!(line_prediction_tolerance > 0 &&
        std::isfinite(line_prediction_tolerance)))
    return Fail("cleanup.line_prediction_tolerance must be finite and > 0",
                why);
  if (min_component_size < 1)
    return Fail("cleanup.min_component_size must be >= 1", why);
  return true;
}

bool GridAttachOptions::Check(std::string* why) const {
  if (rounds < 0 || rounds > 100)
    return Fail("attach.rounds must be in [0, 100]", why);
  if (!(tolerance > 0 && tolerance < 1))
    return Fail("attach.tolerance must be in (0, 1)", why);
  if (!(contradiction_tolerance >= tolerance && contradiction_tolerance < 1))
    return Fail(
        "attach.contradiction_tolerance must be in [attach.tolerance, "
        "1)",
        why);
  if (min_support < 1 || min_support > 8)
    return Fail("attach.min_support must be in [1, 8]", why);
  if (!(saddle_sample_fraction > 0 && saddle_sample_fraction <= 0.5))
    return Fail("attach.saddle_sample_fraction must be in (0, 0.5]", why);
  if (!(max_join_direction_deviation_deg > 0 &&
        max_join_direction_deviation_deg < 90))
    return Fail("attach.max_join_direction_deviation_deg must be in (0, 90)",
                why);
  if (max_component_joins < 0 || max_component_joins > 1000)
    return Fail("attach.max_component_joins must be in [0, 1000]", why);
  return true;
}

bool GridOffLatticeOptions::Check(std::string* why) const {
  if (!(tolerance > 0 && tolerance < 1))
    return Fail("off_lattice.tolerance must be in (0, 1)", why);
  if (!(agreement > 0 && agreement <= tolerance))
    return Fail("off_lattice.agreement must be in (0, off_lattice.tolerance]",
                why);
  if (min_agreeing < 2 || min_agreeing > 10)
    return Fail("off_lattice.min_agreeing must be in [2, 10]", why);
  if (max_rounds < 1 || max_rounds > 10)
    return Fail("off_lattice.max_rounds must be in [1, 10]", why);
  return true;
}

bool GridOptions::Check(std::string* why) const {
  return candidates.Check(why) && image_tests.Check(why) && merge.Check(why) &&
         cleanup.Check(why) && attach.Check(why) && off_lattice.Check(why);
}

namespace {

// Options, image type and corner count that BuildGrid can work with; false
// with the reason in `summary->message`.
bool CheckGridInputs(int num_corners, const cv::Mat& image,
                     const GridOptions& options, GridSummary* summary) {
  std::string why;
  if (!options.Check(&why)) {
    summary->message = "invalid GridOptions: " + why;
    return false;
  }
  if (!image.empty() && !IsSupportedGridImage(image)) {
    summary->message =
        "unsupported image type " + std::to_string(image.type()) +
        " (expected CV_8UC1, CV_16UC1 or CV_32FC1, or an empty image)";
    return false;
  }
  // Labels and tree ids must fit the label table's keys.
  if (num_corners > LabelTable::kMaxLabel) {
    summary->message = "too many corners (" + std::to_string(num_corners) +
                       " > " + std::to_string(LabelTable::kMaxLabel) + ")";
    return false;
  }
  return true;
}

// The corners as the forest reads them, with the doubled orientation angle
// per corner (for the orientation filter) and the valid corners' indices and
// positions (for the neighbour search). Invalid corners stay out of every
// edge and tree.
struct GridNodes {
  LatticeNodes lattice;
  std::vector<Eigen::Vector2d> doubled;
  std::vector<int> valid_index;
  std::vector<Eigen::Vector2d> valid_xy;
};

GridNodes MakeGridNodes(const std::vector<Corner>& corners,
                        const GridOptions& options, GridSummary* summary) {
  const int n = static_cast<int>(corners.size());
  GridNodes nodes;
  nodes.lattice.xy.resize(n);
  nodes.lattice.axis.resize(n);
  nodes.lattice.valid.assign(n, 0);
  nodes.doubled.assign(n, Eigen::Vector2d::Zero());
  nodes.valid_index.reserve(n);
  nodes.valid_xy.reserve(n);
  for (int i = 0; i < n; ++i) {
    const Corner& c = corners[i];
    nodes.lattice.xy[i] = c.xy;
    const bool ok =
        std::isfinite(c.xy.x()) && std::isfinite(c.xy.y()) &&
        std::abs(c.xy.x()) <= options.candidates.max_abs_coordinate_px &&
        std::abs(c.xy.y()) <= options.candidates.max_abs_coordinate_px &&
        std::isfinite(c.orientation);
    if (!ok) {
      ++summary->num_invalid_corners;
      nodes.lattice.xy[i].setZero();
      continue;
    }
    nodes.lattice.valid[i] = 1;
    const double co = std::cos(c.orientation), so = std::sin(c.orientation);
    // Orientation + 45 degrees; the doubled angle for the orientation filter.
    nodes.lattice.axis[i] = Eigen::Vector2d(co - so, co + so) * M_SQRT1_2;
    nodes.doubled[i] = Eigen::Vector2d(co * co - so * so, 2 * co * so);
    nodes.valid_index.push_back(i);
    nodes.valid_xy.push_back(c.xy);
  }
  if (summary->num_invalid_corners > 0) {
    summary->message =
        std::to_string(summary->num_invalid_corners) +
        " corners ignored (non-finite or beyond " +
        std::to_string(options.candidates.max_abs_coordinate_px) + " px)";
  }
  return nodes;
}

// The k nearest neighbours of every valid corner as unique (smaller, larger)
// corner index pairs.
std::vector<std::pair<int, int>> CandidatePairs(const GridNodes& nodes, int k) {
  std::vector<int> knn;
  FindNearestNeighbors(nodes.valid_xy, k, &knn);
  // Each unordered pair once, without sorting: from the smaller index, or
  // from the larger one when the smaller does not list it.
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(knn.size());
  for (size_t v = 0; v < nodes.valid_xy.size(); ++v) {
    for (int m = 0; m < k; ++m) {
      const int w = knn[v * k + m];
      if (w < 0) break;
      if (w < static_cast<int>(v)) {
        const int* list = &knn[static_cast<size_t>(w) * k];
        if (std::find(list, list + k, static_cast<int>(v)) != list + k)
          continue;
      }
      const int a = nodes.valid_index[v], b = nodes.valid_index[w];
      pairs.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  return pairs;
}

// The pairs that pass the orientation filter and are long enough, as edges
// of weight = length (unsorted).
std::vector<GridEdge> FilterPairs(const std::vector<std::pair<int, int>>& pairs,
                                  const GridNodes& nodes,
                                  const GridOptions& options,
                                  GridSummary* summary) {
  // Orientations are compared through their doubled angles:
  // sin^2(d) = (1 - cos(2 d)) / 2.
  const double min_abs_sin =
      std::sin(options.candidates.min_orientation_difference_deg * M_PI / 180);
  const double max_cos_double = 1 - 2 * min_abs_sin * min_abs_sin;
  std::vector<GridEdge> edges;
  edges.reserve(pairs.size());
  for (const auto& [a, b] : pairs) {
    const double cos_double = nodes.doubled[a].dot(nodes.doubled[b]);
    if (!(cos_double < max_cos_double)) {
      ++summary->num_edges_orientation_filtered;
      continue;
    }
    const double length = (nodes.lattice.xy[b] - nodes.lattice.xy[a]).norm();
    if (!(length >= options.candidates.min_edge_length_px) || length <= 0) {
      ++summary->num_edges_too_short;
      continue;
    }
    GridEdge edge;
    edge.a = a;
    edge.b = b;
    edge.length = length;
    edge.weight = length;
    edges.push_back(edge);
  }
  return edges;
}

// Sorts edges of weight = length by GridEdgeLess, through 16-byte keys
// (length, then the pair), cheaper to move than the edges.
void SortEdgesByLength(std::vector<GridEdge>* edges) {
  struct Key {
    double length;
    uint64_t pair;
    bool operator<(const Key& o) const {
      return length != o.length ? length < o.length : pair < o.pair;
    }
  };
  std::vector<Key> keys(edges->size());
  for (size_t e = 0; e < edges->size(); ++e) {
    const GridEdge& edge = (*edges)[e];
    keys[e] = {edge.length, (static_cast<uint64_t>(edge.a) << 32) |
                                static_cast<uint32_t>(edge.b)};
  }
  std::sort(keys.begin(), keys.end());
  for (size_t e = 0; e < edges->size(); ++e) {
    GridEdge& edge = (*edges)[e];
    edge.a = static_cast<int>(keys[e].pair >> 32);
    edge.b = static_cast<int>(keys[e].pair & 0xffffffffu);
    edge.length = edge.weight = keys[e].length;
  }
}

// Kruskal over the sorted edges; with an image, the intensity penalty and
// the sides test are sampled when an edge's turn comes.
LatticeForest RunKruskal(const LatticeNodes& nodes,
                         const std::vector<GridEdge>& edges,
                         const cv::Mat& image, const GridOptions& options,
                         GridSummary* summary,
                         std::vector<GridEdgeTrace>* trace) {
  std::function<bool(const GridEdge&)> crosses_tile, sides_flip;
  if (!image.empty()) {
    crosses_tile = [&](const GridEdge& edge) {
      return EdgeCrossesTile(image, nodes.xy[edge.a], nodes.xy[edge.b],
                             options.image_tests.intensity_samples,
                             options.image_tests.intensity_difference_fraction);
    };
    if (options.image_tests.side_min_contrast > 0) {
      sides_flip = [&](const GridEdge& edge) {
        return EdgeSidesFlip(image, nodes.xy[edge.a], nodes.xy[edge.b],
                             options.image_tests.side_offset_fraction,
                             options.image_tests.side_min_contrast);
      };
    }
  }
  LatticeForest forest;
  BuildLatticeForest(nodes, edges, crosses_tile, sides_flip, options, summary,
                     &forest, trace);
  return forest;
}

// Component counts of the result.
void SummarizeComponents(const std::vector<GridComponent>& components,
                         GridSummary* summary) {
  summary->num_components = static_cast<int>(components.size());
  for (const GridComponent& c : components)
    summary->num_labelled_corners += static_cast<int>(c.corner.size());
  summary->largest_component =
      components.empty() ? 0 : static_cast<int>(components[0].corner.size());
}

}  // namespace

std::vector<GridComponent> BuildGrid(const std::vector<Corner>& corners,
                                     const cv::Mat& image,
                                     const GridOptions& options,
                                     GridSummary* summary_out,
                                     std::vector<GridEdgeTrace>* trace) {
  if (trace != nullptr) trace->clear();
  const Timer timer;
  GridSummary local_summary;
  GridSummary& summary = summary_out ? *summary_out : local_summary;
  summary = GridSummary();
  summary.num_input_corners = static_cast<int>(corners.size());
  if (!CheckGridInputs(summary.num_input_corners, image, options, &summary))
    return {};
  summary.image_used = !image.empty();
  const GridNodes nodes = MakeGridNodes(corners, options, &summary);

  Timer phase;
  const std::vector<std::pair<int, int>> pairs =
      CandidatePairs(nodes, options.candidates.num_neighbors);
  summary.num_candidate_edges = static_cast<int>(pairs.size());
  summary.neighbors_ms = phase.Milliseconds();

  phase.Restart();
  std::vector<GridEdge> edges = FilterPairs(pairs, nodes, options, &summary);
  SortEdgesByLength(&edges);
  summary.num_edges_considered = static_cast<int>(edges.size());
  summary.weights_ms = phase.Milliseconds();

  phase.Restart();
  const LatticeForest forest =
      RunKruskal(nodes.lattice, edges, image, options, &summary, trace);
  summary.kruskal_ms = phase.Milliseconds();

  phase.Restart();
  std::vector<GridComponent> components = ExtractComponents(
      nodes.lattice.xy, image, forest, edges, options, &summary);
  summary.cleanup_ms = phase.Milliseconds();

  SummarizeComponents(components, &summary);
  summary.ok = true;
  summary.total_ms = timer.Milliseconds();
  return components;
}

}  // namespace puzzlecal
