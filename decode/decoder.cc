#include "decode/decoder.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "decode/position_search.h"
#include "util/failure.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

// Relative labels of a component: right-handed, smallest label at (0, 0).
void AppendRelativeLabels(const LabelLattice& lattice, int handedness,
                          int component, DecodeResult* result) {
  Eigen::Matrix2i flip = Eigen::Matrix2i::Identity();
  if (handedness < 0) flip(1, 1) = -1;
  Eigen::Vector2i lo = (flip * lattice.label.front());
  for (const Eigen::Vector2i& ij : lattice.label) lo = lo.cwiseMin(flip * ij);
  for (size_t k = 0; k < lattice.label.size(); ++k) {
    result->observation.id.push_back(flip * lattice.label[k] - lo);
    result->observation.xy.push_back(lattice.xy[k]);
    result->corner_index.push_back(lattice.corner_index[k]);
    result->component.push_back(component);
  }
}

// Image direction of the label step `step`, averaged over the lattice.
Eigen::Vector2d ImageDirection(const LabelLattice& lattice,
                               const Eigen::Vector2i& step) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < lattice.label.size(); ++k) {
    const int next = lattice.At(lattice.label[k] + step);
    if (next >= 0) sum += (lattice.xy[next] - lattice.xy[k]).normalized();
  }
  return sum;
}

// A checkerboard component whose label extent is the whole board: the map to
// board ids, or false.
bool FullCheckerboardMap(const LabelLattice& lattice, int handedness,
                         const Board& board, LabelToBoard* map) {
  const Eigen::Vector2i span(lattice.width - 1, lattice.height - 1);
  double best_x = -1e300;
  bool found = false;
  for (const Eigen::Matrix2i& m : LabelRotations(handedness >= 0 ? 1 : -1)) {
    const Eigen::Vector2i a = m * lattice.min_label;
    const Eigen::Vector2i b = m * (lattice.min_label + span);
    const Eigen::Vector2i lo = a.cwiseMin(b), hi = a.cwiseMax(b);
    if (hi.x() - lo.x() != board.cols - 1 ||
        hi.y() - lo.y() != board.rows - 1) {
      continue;
    }
    // Board +col axis in label steps: m^T (1, 0).
    const Eigen::Vector2i step = m.transpose() * Eigen::Vector2i(1, 0);
    const double x = ImageDirection(lattice, step).x();
    if (!found || x > best_x) {
      found = true;
      best_x = x;
      map->rotation = m;
      map->offset = board.origin - lo;
    }
  }
  return found;
}

// Rule 3 of the acceptance rule (decoder.h).
int RequiredMargin(double agreement, const DecodeOptions& options) {
  const double q = std::max(1.0 - agreement, 0.02);
  if (q >= 0.5) return std::numeric_limits<int>::max();
  const double per_edge = 2.0 * std::log10((1.0 - q) / q);
  const int needed =
      static_cast<int>(std::ceil(options.min_log10_odds / per_edge));
  return std::max(options.min_margin, needed);
}

struct AcceptedComponent {
  int component = -1;
  const LabelLattice* lattice = nullptr;
  LabelToBoard map;
  std::vector<char> keep;  // per lattice point
};

}  // namespace

namespace {

// The read edges as votes on the labels shifted to start at (0, 0).
std::vector<LabelEdgeVote> EdgeVotes(const LabelLattice& lattice,
                                     const EdgeBitReading& reading) {
  std::vector<LabelEdgeVote> votes;
  votes.reserve(reading.num_read);
  for (const EdgeBit& edge : reading.edges) {
    if (!edge.read) continue;
    votes.push_back({edge.from - lattice.min_label, edge.axis,
                     edge.confidence > 0 ? 1 : 0});
  }
  return votes;
}

// The figures of the acceptance rule at the search's best position.
void RecordSearchFigures(const PositionSearchResult& search,
                         ComponentDecoding* decoding) {
  decoding->bits_agreeing = search.edges_agreeing;
  decoding->agreement = static_cast<double>(search.edges_agreeing) /
                        std::max(1, search.num_edges);
  decoding->bins_read = search.bins_read;
  decoding->bins_agreeing = search.bins_agreeing;
  decoding->margin = (search.best_score - search.second_score) / 2;
  decoding->hypotheses = search.hypotheses;
  decoding->log10_nfa =
      std::log10(static_cast<double>(search.hypotheses)) +
      Log10BinomialTailHalf(search.bins_read, search.bins_agreeing);
}

// Rules 2-5 of the acceptance rule (decoder.h): empty when they hold, else
// why not.
std::string RefusalReason(const PositionSearchResult& search,
                          const ComponentDecoding& decoding,
                          const DecodeOptions& options) {
  if (decoding.agreement < options.min_agreement) {
    return StringPrintf(
        "best position agrees with %.1f %% of %d bits (need %.1f %%)",
        100.0 * decoding.agreement, decoding.bits_read,
        100.0 * options.min_agreement);
  }
  if (decoding.margin < RequiredMargin(decoding.agreement, options)) {
    return StringPrintf(
        "ambiguous: best position leads the second by %d bits "
        "(need %d at %.1f %% agreement)",
        decoding.margin, RequiredMargin(decoding.agreement, options),
        100.0 * decoding.agreement);
  }
  if (decoding.log10_nfa > options.max_log10_nfa) {
    return StringPrintf(
        "too little evidence: a random pattern would match this well "
        "10^%.1f times (allowed 10^%.1f)",
        decoding.log10_nfa, options.max_log10_nfa);
  }
  if (options.refuse_better_off_board &&
      search.torus_best_score > search.best_score) {
    return StringPrintf(
        "a position outside the printed board matches better (%d vs "
        "%d agreeing bits): wrong board file or print?",
        (search.torus_best_score + search.num_edges) / 2,
        search.edges_agreeing);
  }
  return std::string();
}

// For a refused component: the agreement of mirrored and inverted prints,
// and a note on `why` when one of them explains the bits better.
void NameMirroredOrInverted(const std::vector<LabelEdgeVote>& votes,
                            const Eigen::Vector2i& label_max, int handedness,
                            int parity, const Board& board,
                            const PositionSearchResult& search,
                            const DecodeOptions& options,
                            ComponentDecoding* decoding, std::string* why) {
  const PositionSearchResult mirrored = SearchPuzzleBoardPosition(
      votes, Eigen::Vector2i::Zero(), label_max, -handedness,
      parity < 0 ? -1 : parity, board, /*inverted=*/false,
      options.max_label_overhang);
  const PositionSearchResult inverted = SearchPuzzleBoardPosition(
      votes, Eigen::Vector2i::Zero(), label_max, handedness, parity, board,
      /*inverted=*/true, options.max_label_overhang);
  const auto agreement = [](const PositionSearchResult& r) {
    return r.found ? static_cast<double>(r.edges_agreeing) /
                         std::max(1, r.num_edges)
                   : 0.0;
  };
  decoding->mirrored_agreement = agreement(mirrored);
  decoding->inverted_agreement = agreement(inverted);
  if (decoding->mirrored_agreement >= options.min_agreement &&
      mirrored.edges_agreeing > search.edges_agreeing) {
    *why += StringPrintf(
        "; the bits match a mirrored PuzzleBoard (%.1f %%): mirrored "
        "image or print",
        100.0 * decoding->mirrored_agreement);
  } else if (decoding->inverted_agreement >= options.min_agreement &&
             inverted.edges_agreeing > search.edges_agreeing) {
    *why += StringPrintf(
        "; the bits match a contrast-inverted PuzzleBoard (%.1f %%)",
        100.0 * decoding->inverted_agreement);
  }
}

// Per lattice point: 0 when at least drop_corner_min_disagreeing_edges of
// its read edges contradict the code at `map` (a mislabelled corner).
std::vector<char> CornersAgreeingWithCode(const LabelLattice& lattice,
                                          const EdgeBitReading& reading,
                                          const LabelToBoard& map,
                                          const DecodeOptions& options,
                                          int* dropped) {
  std::vector<int> disagreeing(lattice.xy.size(), 0);
  for (const EdgeBit& edge : reading.edges) {
    if (!edge.read) continue;
    const int bit = edge.confidence > 0 ? 1 : 0;
    if (bit == BoardBitOfLabelEdge(map, edge.from, edge.axis)) continue;
    const Eigen::Vector2i to =
        edge.from +
        (edge.axis == 0 ? Eigen::Vector2i(1, 0) : Eigen::Vector2i(0, 1));
    ++disagreeing[lattice.At(edge.from)];
    ++disagreeing[lattice.At(to)];
  }
  std::vector<char> keep(lattice.xy.size(), 1);
  for (size_t k = 0; k < lattice.xy.size(); ++k) {
    if (disagreeing[k] >= options.drop_corner_min_disagreeing_edges) {
      keep[k] = 0;
      ++*dropped;
    }
  }
  return keep;
}

// Labels the accepted position puts beyond the printed board
// (max_label_overhang) are not board corners. They come from a row joined
// askew, and at the board's border the grid can also join a false corner
// beside it (bench_advise's steep fisheye view: one 25 px from the corner
// whose id it got): the corners on the board's outermost row or column
// next to an off-board label (one label step away, diagonals included) are
// dropped as well.
void DropOffBoardLabels(const LabelLattice& lattice, const Board& board,
                        const LabelToBoard& map, std::vector<char>* keep,
                        int* dropped) {
  const Eigen::Vector2i lo = board.origin;
  const Eigen::Vector2i hi =
      board.origin + Eigen::Vector2i(board.cols - 1, board.rows - 1);
  const auto off_board = [&](const Eigen::Vector2i& id) {
    return (id.array() < lo.array()).any() || (id.array() > hi.array()).any();
  };
  const auto on_edge = [&](const Eigen::Vector2i& id) {
    return (id.array() == lo.array()).any() || (id.array() == hi.array()).any();
  };
  std::vector<char> off(lattice.xy.size(), 0);
  bool any_off = false;
  for (size_t k = 0; k < lattice.xy.size(); ++k) {
    off[k] = off_board(map.Apply(lattice.label[k])) ? 1 : 0;
    any_off |= off[k] != 0;
  }
  if (!any_off) return;
  for (size_t k = 0; k < lattice.xy.size(); ++k) {
    bool drop = off[k] != 0;
    if (!drop && on_edge(map.Apply(lattice.label[k]))) {
      for (int dj = -1; dj <= 1 && !drop; ++dj) {
        for (int di = -1; di <= 1 && !drop; ++di) {
          const int n = lattice.At(lattice.label[k] + Eigen::Vector2i(di, dj));
          drop = n >= 0 && off[n] != 0;
        }
      }
    }
    if (drop && (*keep)[k]) {
      (*keep)[k] = 0;
      ++*dropped;
    }
  }
}

}  // namespace

bool DecodeComponentBits(const LabelLattice& lattice,
                         const EdgeBitReading& reading, const Board& board,
                         const DecodeOptions& options,
                         ComponentDecoding* decoding, LabelToBoard* map,
                         std::vector<char>* keep) {
  const int handedness = decoding->handedness;
  if (handedness == 0) {
    decoding->reason = "labels do not span two lattice directions";
    return false;
  }
  decoding->edges = static_cast<int>(reading.edges.size());
  decoding->bits_read = reading.num_read;
  if (reading.num_read < options.min_bits_read) {
    decoding->reason = StringPrintf(
        "only %d of %d edge bits readable (need %d): no discs "
        "(plain checkerboard?), blur or tiles too small",
        reading.num_read, decoding->edges, options.min_bits_read);
    return false;
  }
  const std::vector<LabelEdgeVote> votes = EdgeVotes(lattice, reading);
  // Dark-tile parity relative to the shifted labels.
  int parity = reading.dark_tile_parity;
  if (parity >= 0) {
    parity = (parity + lattice.min_label.x() + lattice.min_label.y()) & 1;
  }
  const Eigen::Vector2i label_max(lattice.width - 1, lattice.height - 1);
  const PositionSearchResult search = SearchPuzzleBoardPosition(
      votes, Eigen::Vector2i::Zero(), label_max, handedness, parity, board,
      /*inverted=*/false, options.max_label_overhang);
  if (!search.found) {
    decoding->reason = StringPrintf(
        "labels spanning %d x %d corners fit on the %d x %d-corner board "
        "in no rotation (%d row(s) beyond it allowed)",
        lattice.width, lattice.height, board.cols, board.rows,
        options.max_label_overhang);
    return false;
  }
  RecordSearchFigures(search, decoding);
  std::string why = RefusalReason(search, *decoding, options);
  if (!why.empty()) {
    NameMirroredOrInverted(votes, label_max, handedness, parity, board, search,
                           options, decoding, &why);
    decoding->reason = why;
    return false;
  }
  // Accepted: label -> board map for the original labels.
  map->rotation = search.best.rotation;
  map->offset = search.best.offset - search.best.rotation * lattice.min_label;
  decoding->rotation = map->rotation;
  decoding->offset = map->offset;
  decoding->decoded = true;
  *keep = CornersAgreeingWithCode(lattice, reading, *map, options,
                                  &decoding->corners_dropped);
  DropOffBoardLabels(lattice, board, *map, keep, &decoding->corners_dropped);
  return true;
}

bool DecodeOptions::Check(std::string* why) const {
  if (!bits.Check(why)) return false;
  if (min_corners < 1) return Fail("min_corners must be >= 1", why);
  if (max_label_extent < 2) return Fail("max_label_extent must be >= 2", why);
  if (max_label_overhang < 0 || max_label_overhang > 3) {
    return Fail("max_label_overhang must lie in [0, 3]", why);
  }
  if (!(max_lattice_deviation > 0.0))
    return Fail("max_lattice_deviation must be > 0", why);
  if (min_bits_read < 1) return Fail("min_bits_read must be >= 1", why);
  if (!(min_agreement >= 0.5 && min_agreement <= 1.0)) {
    return Fail("min_agreement must be in [0.5, 1]", why);
  }
  if (min_margin < 1) return Fail("min_margin must be >= 1", why);
  if (!(min_log10_odds >= 0.0)) return Fail("min_log10_odds must be >= 0", why);
  if (!(max_log10_nfa <= 0.0)) return Fail("max_log10_nfa must be <= 0", why);
  if (drop_corner_min_disagreeing_edges < 1) {
    return Fail("drop_corner_min_disagreeing_edges must be >= 1", why);
  }
  return true;
}

namespace {

// Board, options and components DecodeBoard can work with; false with the
// reason in `result->reason`.
bool CheckDecodeInputs(const Board& board, const DecodeOptions& options,
                       const std::vector<GridComponent>& components,
                       DecodeResult* result) {
  std::string why;
  if (!board.Check(&why)) {
    result->reason = "invalid board: " + why;
    return false;
  }
  if (!options.Check(&why)) {
    result->reason = "invalid decode options: " + why;
    return false;
  }
  if (components.empty()) {
    result->reason = "no grid components";
    return false;
  }
  return true;
}

// The single-channel image the edge bits are read from, or an empty image
// with the reason in `*reason`.
cv::Mat GreyForEdgeBits(const cv::Mat& image, std::string* reason) {
  cv::Mat grey;
  if (image.empty()) {
    *reason = "empty image: edge bits cannot be read";
  } else if (image.channels() == 1) {
    grey = image;
  } else if (image.channels() == 3 || image.channels() == 4) {
    cv::cvtColor(
        image, grey,
        image.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
  } else {
    *reason = "image has an unsupported number of channels";
  }
  if (!grey.empty() && grey.depth() != CV_8U && grey.depth() != CV_16U &&
      grey.depth() != CV_32F && grey.depth() != CV_64F) {
    grey = cv::Mat();
    *reason = "image depth not supported (8-bit, 16-bit or float)";
  }
  return grey;
}

// The lattice of one component without its invalid, duplicate and
// off-lattice corners; fills the corner counts and the handedness of
// `decoding`. False with the reason in `decoding` when the component is not
// usable.
bool UsableLattice(const std::vector<Corner>& corners,
                   const GridComponent& component, const DecodeOptions& options,
                   LabelLattice* lattice, ComponentDecoding* decoding) {
  std::string why;
  if (!BuildLabelLattice(corners, component, options.max_label_extent, lattice,
                         &why)) {
    decoding->reason = why;
    return false;
  }
  int dropped = lattice->dropped_duplicates + lattice->dropped_invalid;
  const std::vector<int> outliers =
      LatticeOutliers(*lattice, options.max_lattice_deviation);
  if (!outliers.empty()) {
    // Rebuild without the mislabelled corners.
    GridComponent kept;
    std::vector<char> is_outlier(lattice->xy.size(), 0);
    for (int k : outliers) is_outlier[k] = 1;
    for (size_t k = 0; k < lattice->xy.size(); ++k) {
      if (is_outlier[k]) continue;
      kept.corner.push_back(lattice->corner_index[k]);
      kept.ij.push_back(lattice->label[k]);
    }
    dropped += static_cast<int>(outliers.size());
    if (!BuildLabelLattice(corners, kept, options.max_label_extent, lattice,
                           &why)) {
      decoding->reason = why;
      return false;
    }
  }
  decoding->num_corners = static_cast<int>(lattice->xy.size());
  decoding->corners_dropped = dropped;
  decoding->handedness = LabelHandedness(*lattice);
  if (decoding->num_corners < options.min_corners) {
    decoding->reason = StringPrintf("only %d usable corners (need %d)",
                                    decoding->num_corners, options.min_corners);
    return false;
  }
  return true;
}

// Appends the points of one lattice with board ids through `map`.
void AppendBoardIds(const LabelLattice& lattice, const LabelToBoard& map,
                    int component, DecodeResult* result) {
  for (size_t k = 0; k < lattice.xy.size(); ++k) {
    result->observation.id.push_back(map.Apply(lattice.label[k]));
    result->observation.xy.push_back(lattice.xy[k]);
    result->corner_index.push_back(lattice.corner_index[k]);
    result->component.push_back(component);
  }
}

// Plain checkerboard: the largest usable component spanning the whole board
// gets board ids; else every usable component keeps relative labels.
void DecodeCheckerboard(const Board& board,
                        const std::vector<LabelLattice>& lattices,
                        const std::vector<char>& usable, DecodeResult* result) {
  const size_t num_components = lattices.size();
  int best = -1;
  LabelToBoard best_map;
  for (size_t c = 0; c < num_components; ++c) {
    LabelToBoard map;
    if (!usable[c] ||
        !FullCheckerboardMap(lattices[c], result->components[c].handedness,
                             board, &map)) {
      continue;
    }
    if (best < 0 || lattices[c].xy.size() > lattices[best].xy.size()) {
      best = static_cast<int>(c);
      best_map = map;
    }
  }
  if (best >= 0) {
    ComponentDecoding& decoding = result->components[best];
    decoding.decoded = true;
    decoding.rotation = best_map.rotation;
    decoding.offset = best_map.offset;
    AppendBoardIds(lattices[best], best_map, best, result);
    result->decoded = true;
    result->absolute_ids = true;
    for (size_t c = 0; c < num_components; ++c) {
      if (static_cast<int>(c) != best && result->components[c].reason.empty()) {
        result->components[c].reason =
            "another component spans the whole board";
      }
    }
    return;
  }
  for (size_t c = 0; c < num_components; ++c) {
    if (!usable[c]) continue;
    result->components[c].reason =
        "component does not span the whole checkerboard: relative labels";
    AppendRelativeLabels(lattices[c], result->components[c].handedness,
                         static_cast<int>(c), result);
  }
  result->reason =
      "no component spans the whole checkerboard: labels are relative";
}

// PuzzleBoard without any accepted component: relative labels for the
// usable ones and a reason naming the first refusals.
void ReportNoneDecoded(const std::vector<LabelLattice>& lattices,
                       const std::vector<char>& usable, DecodeResult* result) {
  for (size_t c = 0; c < lattices.size(); ++c) {
    if (usable[c]) {
      AppendRelativeLabels(lattices[c], result->components[c].handedness,
                           static_cast<int>(c), result);
    }
  }
  if (!result->reason.empty()) return;
  result->reason = "no component decoded";
  int listed = 0;
  for (const ComponentDecoding& decoding : result->components) {
    if (decoding.reason.empty() || listed == 3) continue;
    result->reason += (listed == 0 ? ": component " : "; component ") +
                      std::to_string(decoding.component) + ": " +
                      decoding.reason;
    ++listed;
  }
}

// Joins the accepted components into one observation; ids claimed twice are
// dropped.
void JoinAccepted(const std::vector<AcceptedComponent>& accepted,
                  DecodeResult* result) {
  std::map<std::pair<int, int>, int> claims;
  for (const AcceptedComponent& a : accepted) {
    for (size_t k = 0; k < a.lattice->xy.size(); ++k) {
      if (!a.keep[k]) continue;
      const Eigen::Vector2i id = a.map.Apply(a.lattice->label[k]);
      ++claims[{id.x(), id.y()}];
    }
  }
  for (const AcceptedComponent& a : accepted) {
    ComponentDecoding& decoding = result->components[a.component];
    for (size_t k = 0; k < a.lattice->xy.size(); ++k) {
      if (!a.keep[k]) continue;
      const Eigen::Vector2i id = a.map.Apply(a.lattice->label[k]);
      if (claims[{id.x(), id.y()}] > 1) {
        ++decoding.corners_dropped;
        continue;
      }
      result->observation.id.push_back(id);
      result->observation.xy.push_back(a.lattice->xy[k]);
      result->corner_index.push_back(a.lattice->corner_index[k]);
      result->component.push_back(a.component);
    }
  }
  result->decoded = !result->observation.id.empty();
  result->absolute_ids = result->decoded;
  if (!result->decoded) {
    result->reason = "every decoded corner collided with another";
  }
}

}  // namespace

DecodeResult DecodeBoard(const Board& board, const std::vector<Corner>& corners,
                         const std::vector<GridComponent>& components,
                         const cv::Mat& image, const DecodeOptions& options) {
  DecodeResult result;
  result.components.resize(components.size());
  for (size_t c = 0; c < components.size(); ++c) {
    result.components[c].component = static_cast<int>(c);
  }
  if (!CheckDecodeInputs(board, options, components, &result)) return result;
  const bool puzzle = board.Traits().absolute_ids;
  const cv::Mat grey =
      puzzle ? GreyForEdgeBits(image, &result.reason) : cv::Mat();

  std::vector<LabelLattice> lattices(components.size());
  std::vector<char> usable(components.size(), 0);
  std::vector<AcceptedComponent> accepted;
  for (size_t c = 0; c < components.size(); ++c) {
    ComponentDecoding& decoding = result.components[c];
    LabelLattice& lattice = lattices[c];
    if (!UsableLattice(corners, components[c], options, &lattice, &decoding)) {
      continue;
    }
    usable[c] = 1;
    if (!puzzle) continue;
    if (grey.empty()) {
      decoding.reason = result.reason;
      continue;
    }
    AcceptedComponent candidate;
    candidate.component = static_cast<int>(c);
    candidate.lattice = &lattice;
    const EdgeBitReading reading = ReadEdgeBits(lattice, grey, options.bits);
    if (DecodeComponentBits(lattice, reading, board, options, &decoding,
                            &candidate.map, &candidate.keep)) {
      accepted.push_back(std::move(candidate));
    }
  }
  if (!puzzle) {
    DecodeCheckerboard(board, lattices, usable, &result);
  } else if (accepted.empty()) {
    ReportNoneDecoded(lattices, usable, &result);
  } else {
    JoinAccepted(accepted, &result);
  }
  return result;
}

}  // namespace puzzlecal
