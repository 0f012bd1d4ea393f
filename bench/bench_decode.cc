// Decoding figures, printed as JSON: time per image for a 23x16-corner view,
// decoding success by window size and tile size, error correction with
// flipped bits, refusal of other codes / mirrored / inverted / plain prints,
// and the agreement statistics behind DecodeOptions' acceptance rule.
// Components come from the render truth, relabelled by a random rotation /
// reflection and offset (as grid/ would label them).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "decode/decoder.h"
#include "target/puzzleboard.h"
#include "tests/decode/truth_components.h"

namespace puzzlecal {
namespace {

using decode_testing::FisheyeCamera;
using decode_testing::LookAt;
using decode_testing::MakePuzzleBoard;
using decode_testing::OneComponentFromTruth;
using decode_testing::PinholeCamera;
using decode_testing::RandomSignedPermutation;
using decode_testing::TruthGrid;

struct Tally {
  int trials = 0, decoded = 0, wrong_components = 0, wrong_ids = 0, ids = 0;
  // Flipped-bit trials: how often the best-scoring in-board position is the
  // true one and strictly better than every other (the maximum-likelihood
  // decision for independent flips; no decoder can be right more often).
  int ml_trials = 0, ml_unique_correct = 0;
  std::vector<double> agreement, log10_nfa;
  std::vector<int> margin;
};

bool SameIdMod501(const Eigen::Vector2i& a, const Eigen::Vector2i& b) {
  return PuzzleBoardWrap(a.x()) == PuzzleBoardWrap(b.x()) &&
         PuzzleBoardWrap(a.y()) == PuzzleBoardWrap(b.y());
}

// Decodes `grid` in `image` (optionally flipping read bits at `flip_rate`),
// adds the outcome to `tally`. Truth ids are compared mod 501.
void DecodeAndCount(const Board& board, const cv::Mat& image,
                    const TruthGrid& grid, double flip_rate, std::mt19937* rng,
                    Tally* tally, bool truth_known = true) {
  ++tally->trials;
  const DecodeOptions options;
  if (flip_rate <= 0.0) {
    const DecodeResult result =
        DecodeBoard(board, grid.corners, grid.components, image);
    const ComponentDecoding& c = result.components[0];
    tally->agreement.push_back(c.agreement);
    tally->log10_nfa.push_back(c.log10_nfa);
    tally->margin.push_back(c.margin);
    if (!result.decoded) return;
    ++tally->decoded;
    if (!truth_known) return;
    int wrong = 0;
    for (size_t k = 0; k < result.observation.id.size(); ++k) {
      if (!SameIdMod501(result.observation.id[k],
                        grid.truth_id[result.corner_index[k]])) {
        ++wrong;
      }
    }
    tally->ids += static_cast<int>(result.observation.id.size());
    tally->wrong_ids += wrong;
    if (wrong > 0) ++tally->wrong_components;
    return;
  }
  LabelLattice lattice;
  std::string why;
  if (!BuildLabelLattice(grid.corners, grid.components[0],
                         options.max_label_extent, &lattice, &why)) {
    return;
  }
  EdgeBitReading reading = ReadEdgeBits(lattice, image, options.bits);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (EdgeBit& edge : reading.edges) {
    if (uniform(*rng) < flip_rate) edge.confidence = -edge.confidence;
  }
  ComponentDecoding decoding;
  decoding.handedness = LabelHandedness(lattice);
  {
    std::vector<LabelEdgeVote> votes;
    for (const EdgeBit& edge : reading.edges) {
      if (edge.read) {
        votes.push_back({edge.from - lattice.min_label, edge.axis,
                         edge.confidence > 0 ? 1 : 0});
      }
    }
    int parity = reading.dark_tile_parity;
    if (parity >= 0) {
      parity = (parity + lattice.min_label.x() + lattice.min_label.y()) & 1;
    }
    const PositionSearchResult search = SearchPuzzleBoardPosition(
        votes, Eigen::Vector2i::Zero(),
        Eigen::Vector2i(lattice.width - 1, lattice.height - 1),
        decoding.handedness, parity, board, /*inverted=*/false,
        options.max_label_overhang);
    ++tally->ml_trials;
    bool correct = search.found && search.best_score > search.second_score;
    for (size_t k = 0; correct && k < lattice.xy.size(); ++k) {
      correct =
          SameIdMod501(search.best.Apply(lattice.label[k] - lattice.min_label),
                       grid.truth_id[lattice.corner_index[k]]);
    }
    tally->ml_unique_correct += correct;
  }
  LabelToBoard map;
  std::vector<char> keep;
  const bool ok = DecodeComponentBits(lattice, reading, board, options,
                                      &decoding, &map, &keep);
  tally->agreement.push_back(decoding.agreement);
  tally->log10_nfa.push_back(decoding.log10_nfa);
  tally->margin.push_back(decoding.margin);
  if (!ok) return;
  ++tally->decoded;
  int wrong = 0;
  for (size_t k = 0; k < lattice.xy.size(); ++k) {
    if (!keep[k]) continue;
    ++tally->ids;
    const int corner = lattice.corner_index[k];
    if (!SameIdMod501(map.Apply(lattice.label[k]), grid.truth_id[corner]))
      ++wrong;
  }
  tally->wrong_ids += wrong;
  if (wrong > 0) ++tally->wrong_components;
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * (v.size() - 1))];
}

std::string TallyJson(const Tally& t) {
  std::vector<double> margin(t.margin.begin(), t.margin.end());
  std::string ml;
  if (t.ml_trials > 0) {
    char text[96];
    std::snprintf(text, sizeof(text), ", \"ml_unique_correct_fraction\": %.3f",
                  double(t.ml_unique_correct) / t.ml_trials);
    ml = text;
  }
  char buffer[640];
  std::snprintf(
      buffer, sizeof(buffer),
      "{\"trials\": %d, \"decoded\": %d, \"decoded_fraction\": %.3f, "
      "\"wrong_components\": %d, \"wrong_ids\": %d, \"ids\": %d, "
      "\"agreement_p05_p50_p95\": [%.3f, %.3f, %.3f], "
      "\"margin_p05_p50\": [%.0f, %.0f], \"log10_nfa_p50_p95\": [%.1f, "
      "%.1f]%s}",
      t.trials, t.decoded, t.trials ? double(t.decoded) / t.trials : 0.0,
      t.wrong_components, t.wrong_ids, t.ids, Quantile(t.agreement, 0.05),
      Quantile(t.agreement, 0.5), Quantile(t.agreement, 0.95),
      Quantile(margin, 0.05), Quantile(margin, 0.5), Quantile(t.log10_nfa, 0.5),
      Quantile(t.log10_nfa, 0.95), ml.c_str());
  return buffer;
}

// A k x k-tile window of ids starting at (x0, y0).
std::function<bool(const Eigen::Vector2i&)> Window(int x0, int y0, int k) {
  return [=](const Eigen::Vector2i& id) {
    return id.x() >= x0 && id.x() <= x0 + k && id.y() >= y0 && id.y() <= y0 + k;
  };
}

// Random windows of a render: every window fully visible.
void WindowTrials(const Board& board, const cv::Mat& image,
                  const RenderTruth& truth, int k, int trials, double flip_rate,
                  std::mt19937* rng, Tally* tally, bool truth_known = true) {
  std::uniform_int_distribution<int> px(board.origin.x(),
                                        board.origin.x() + board.cols - 1 - k);
  std::uniform_int_distribution<int> py(board.origin.y(),
                                        board.origin.y() + board.rows - 1 - k);
  int done = 0;
  for (int attempt = 0; done < trials && attempt < 20 * trials; ++attempt) {
    const int x0 = px(*rng), y0 = py(*rng);
    const Eigen::Matrix2i l = RandomSignedPermutation(rng);
    TruthGrid grid = OneComponentFromTruth(
        truth, l,
        [rng] {
          // One draw per statement (y first): as two arguments of one call
          // they come in an order each compiler picks.
          const int y = static_cast<int>((*rng)() % 50);
          return Eigen::Vector2i(static_cast<int>((*rng)() % 50), y);
        }(),
        Window(x0, y0, k));
    if (static_cast<int>(grid.corners.size()) != (k + 1) * (k + 1)) continue;
    DecodeAndCount(board, image, grid, flip_rate, rng, tally, truth_known);
    ++done;
  }
}

double MedianMs(const std::function<void()>& fn, int runs) {
  std::vector<double> ms;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    ms.push_back(std::chrono::duration<double, std::milli>(
                     std::chrono::steady_clock::now() - t0)
                     .count());
  }
  return Quantile(ms, 0.5);
}

}  // namespace
}  // namespace puzzlecal

int main() {
  using namespace puzzlecal;
  std::mt19937 rng(2024);
  std::printf("{\n");

  // --- Timing: full 23x16 view (368 corners, 697 edges). ---
  {
    const Board board = MakePuzzleBoard(23, 16, 50, 100, 0.03);
    const Camera camera = PinholeCamera(1280, 960, 800);
    RenderOptions ro;
    ro.noise_sigma = 0.02;
    RenderTruth truth;
    const cv::Mat image = RenderBoard(
        board, camera, LookAt(board, {61, 107.5}, 1.0, 20, 10), ro, &truth);
    const TruthGrid grid =
        OneComponentFromTruth(truth, RandomSignedPermutation(&rng), {3, 4});
    DecodeResult result;
    const double ms = MedianMs(
        [&] {
          result = DecodeBoard(board, grid.corners, grid.components, image);
        },
        200);
    const double best =
        MedianMs(
            [&] {
              for (int i = 0; i < 20; ++i)
                DecodeBoard(board, grid.corners, grid.components, image);
            },
            5) /
        20.0;
    std::printf(
        "  \"time_23x16_view\": {\"corners\": %zu, \"decoded\": %s, "
        "\"median_ms\": %.3f, \"median_of_batches_ms\": %.3f},\n",
        grid.corners.size(), result.decoded ? "true" : "false", ms, best);
  }

  // --- Bit confidence (|disc - mid level| / half contrast) by tile size, and
  // on a plain checkerboard (no discs), behind EdgeBitOptions::min_confidence.
  {
    std::printf("  \"bit_confidence\": {");
    const int sizes[] = {4, 5, 6, 8, 12, 0};  // 0: plain checkerboard, 12 px
    for (int si = 0; si < 6; ++si) {
      const bool plain = sizes[si] == 0;
      const int tile_px = plain ? 12 : sizes[si];
      Board board = MakePuzzleBoard(72, 52, 100, 200, 0.01);
      if (plain) {
        board.type = BoardType::kCheckerboard;
        board.origin = Eigen::Vector2i::Zero();
      }
      RenderOptions ro;
      ro.noise_sigma = 0.03;
      RenderTruth truth;
      const Eigen::Vector2d centre(board.origin.x() + 35.5,
                                   board.origin.y() + 25.5);
      const cv::Mat image =
          RenderBoard(board, PinholeCamera(1280, 960, 800),
                      LookAt(board, centre, 8.0 / tile_px, 15, 5), ro, &truth);
      const TruthGrid grid =
          OneComponentFromTruth(truth, Eigen::Matrix2i::Identity(), {0, 0});
      LabelLattice lattice;
      std::string why;
      std::vector<double> magnitude, signed_correct;
      if (BuildLabelLattice(grid.corners, grid.components[0], 4096, &lattice,
                            &why)) {
        const EdgeBitReading reading =
            ReadEdgeBits(lattice, image, EdgeBitOptions());
        for (const EdgeBit& e : reading.edges) {
          magnitude.push_back(std::abs(e.confidence));
          if (plain) continue;
          const int bit =
              e.axis == 0 ? PuzzleBoardHorizontalEdgeBit(e.from.x(), e.from.y())
                          : PuzzleBoardVerticalEdgeBit(e.from.x(), e.from.y());
          signed_correct.push_back(bit ? e.confidence : -e.confidence);
        }
      }
      std::printf(
          "%s\"%s\": {\"edges\": %zu, \"abs_p05_p50_p95\": [%.2f, %.2f, %.2f]",
          si == 0 ? "" : ", ",
          plain ? "plain_checkerboard_12px"
                : (std::to_string(tile_px) + "px").c_str(),
          magnitude.size(), Quantile(magnitude, 0.05), Quantile(magnitude, 0.5),
          Quantile(magnitude, 0.95));
      if (!plain) {
        std::printf(", \"toward_true_bit_p01_p05_p50\": [%.2f, %.2f, %.2f]",
                    Quantile(signed_correct, 0.01),
                    Quantile(signed_correct, 0.05),
                    Quantile(signed_correct, 0.5));
      }
      std::printf("}");
    }
    std::printf("},\n");
  }

  // --- Windows x tile sizes (72x52 board, 10 mm tiles, 15 deg tilt, noise).
  // ---
  std::printf("  \"windows_by_tile_px\": {\n");
  const int tile_sizes[] = {4, 5, 6, 8, 12};
  for (int ti = 0; ti < 5; ++ti) {
    const int tile_px = tile_sizes[ti];
    const Board board = MakePuzzleBoard(72, 52, 100, 200, 0.01);
    const double f = 800;
    const double distance = f * board.tile_size_m / tile_px;
    const Camera camera = PinholeCamera(1280, 960, f);
    RenderOptions ro;
    ro.noise_sigma = 0.03;
    RenderTruth truth;
    const cv::Mat image =
        RenderBoard(board, camera,
                    LookAt(board, {135.5, 225.5}, distance, 15, 5), ro, &truth);
    std::printf("    \"%d\": {", tile_px);
    for (int k = 2; k <= 6; ++k) {
      Tally tally;
      WindowTrials(board, image, truth, k, 60, 0.0, &rng, &tally);
      std::printf("%s\"%dx%d\": %s", k == 2 ? "" : ", ", k, k,
                  TallyJson(tally).c_str());
    }
    std::printf("}%s\n", ti == 4 ? "" : ",");
  }
  std::printf("  },\n");

  // --- Flipped bits (clean 12 px render, read bits flipped at random). ---
  {
    const Board board = MakePuzzleBoard(72, 52, 100, 200, 0.01);
    const Camera camera = PinholeCamera(1280, 960, 800);
    RenderOptions ro;
    RenderTruth truth;
    const cv::Mat image = RenderBoard(
        board, camera, LookAt(board, {135.5, 225.5}, 800 * 0.01 / 12, 10, 0),
        ro, &truth);
    std::printf("  \"flipped_bits\": {\n");
    const double rates[] = {0.1, 0.2};
    for (int ri = 0; ri < 2; ++ri) {
      std::printf("    \"%.0f%%\": {", 100 * rates[ri]);
      for (int k = 3; k <= 8; ++k) {
        Tally tally;
        WindowTrials(board, image, truth, k, 300, rates[ri], &rng, &tally);
        std::printf("%s\"%dx%d\": %s", k == 3 ? "" : ", ", k, k,
                    TallyJson(tally).c_str());
      }
      std::printf("}%s\n", ri == 1 ? "" : ",");
    }
    std::printf("  },\n");
  }

  // --- What the code itself allows: every k x k-tile window of the 72x52
  // board read without error, searched like a component (any rotation of
  // the labels' handedness, tile colour known). margin 0: another in-board
  // position matches every bit (no decoder can tell them apart); margin 1:
  // one misread bit away from ambiguity (DecodeOptions::min_margin refuses
  // these). ---
  {
    const Board board = MakePuzzleBoard(72, 52, 100, 200, 0.01);
    std::printf("  \"code_limit_72x52\": {");
    for (int k = 3; k <= 4; ++k) {
      int windows = 0, margin0 = 0, margin1 = 0, wrong_best = 0;
      for (int y0 = board.origin.y(); y0 + k < board.origin.y() + board.rows;
           ++y0) {
        for (int x0 = board.origin.x(); x0 + k < board.origin.x() + board.cols;
             ++x0) {
          LabelToBoard truth;
          truth.offset = Eigen::Vector2i(x0, y0);
          std::vector<LabelEdgeVote> votes;
          for (int j = 0; j <= k; ++j) {
            for (int i = 0; i <= k; ++i) {
              const Eigen::Vector2i from(i, j);
              if (i < k)
                votes.push_back({from, 0, BoardBitOfLabelEdge(truth, from, 0)});
              if (j < k)
                votes.push_back({from, 1, BoardBitOfLabelEdge(truth, from, 1)});
            }
          }
          const PositionSearchResult search = SearchPuzzleBoardPosition(
              votes, Eigen::Vector2i::Zero(), Eigen::Vector2i(k, k), +1,
              (x0 + y0) & 1, board, /*inverted=*/false,
              DecodeOptions().max_label_overhang);
          ++windows;
          const int margin = (search.best_score - search.second_score) / 2;
          if (margin <= 0) {
            ++margin0;
          } else if (margin == 1) {
            ++margin1;
          }
          if (margin > 0 && (search.best.rotation != truth.rotation ||
                             !SameIdMod501(search.best.offset, truth.offset))) {
            ++wrong_best;
          }
        }
      }
      std::printf(
          "%s\"%dx%d\": {\"windows\": %d, \"margin_0_fraction\": %.4f, "
          "\"margin_1_fraction\": %.4f, \"margin_ge_2_fraction\": %.4f, "
          "\"unique_best_not_true\": %d}",
          k == 3 ? "" : ", ", k, k, windows, double(margin0) / windows,
          double(margin1) / windows,
          double(windows - margin0 - margin1) / windows, wrong_best);
    }
    std::printf("},\n");
  }

  // --- Refusal: other codes, mirrored, inverted, plain checkerboard. ---
  {
    const Board board = MakePuzzleBoard(23, 16, 50, 100, 0.03);
    const Camera camera = PinholeCamera(1280, 960, 800);
    struct Variant {
      const char* name;
      PatternVariant variant;
      bool checkerboard;
    };
    std::vector<Variant> variants;
    for (uint64_t seed = 1; seed <= 8; ++seed) {
      PatternVariant v;
      v.random_code_seed = seed;
      variants.push_back({"random_code", v, false});
    }
    PatternVariant mirrored;
    mirrored.mirrored = true;
    PatternVariant inverted;
    inverted.inverted = true;
    PatternVariant both;
    both.mirrored = true;
    both.inverted = true;
    variants.push_back({"mirrored", mirrored, false});
    variants.push_back({"inverted", inverted, false});
    variants.push_back({"mirrored_inverted", both, false});
    variants.push_back({"plain_checkerboard", PatternVariant(), true});
    std::printf("  \"refusal\": {\n");
    std::string last;
    Tally full, windows[7];
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      const Variant& v = variants[vi];
      RenderOptions ro;
      ro.noise_sigma = 0.02;
      ro.variant = v.variant;
      Board render_board = board;
      if (v.checkerboard) {
        render_board.type = BoardType::kCheckerboard;
        render_board.origin = Eigen::Vector2i::Zero();
      }
      RenderTruth truth;
      const cv::Mat image =
          RenderBoard(render_board, camera,
                      LookAt(render_board,
                             Eigen::Vector2d(render_board.origin.x() + 11,
                                             render_board.origin.y() + 7.5),
                             1.0, 15, 5),
                      ro, &truth);
      // Ids of the rendered board, shifted onto the PuzzleBoard's range.
      for (TruthCorner& c : truth.corners)
        c.id += board.origin - render_board.origin;
      for (int trial = 0; trial < 4; ++trial) {
        DecodeAndCount(
            board, image,
            OneComponentFromTruth(truth, RandomSignedPermutation(&rng), {1, 2}),
            0.0, &rng, &full, false);
      }
      for (int k = 3; k <= 6; ++k) {
        WindowTrials(board, image, truth, k, 25, 0.0, &rng, &windows[k], false);
      }
      if (vi + 1 == variants.size() ||
          variants[vi + 1].name != std::string(v.name)) {
        std::printf("    \"%s\": {\"full_view\": %s", v.name,
                    TallyJson(full).c_str());
        for (int k = 3; k <= 6; ++k) {
          std::printf(", \"%dx%d\": %s", k, k, TallyJson(windows[k]).c_str());
          windows[k] = Tally();
        }
        std::printf("}%s\n", vi + 1 == variants.size() ? "" : ",");
        full = Tally();
      }
    }
    std::printf("  },\n");
  }

  // --- Scenes: tilt series, fisheye, occluders. ---
  {
    std::printf("  \"scenes\": {\n");
    const Board board = MakePuzzleBoard(23, 16, 50, 100, 0.03);
    // Tilt series: viewing angle 90..20 deg (tilt 0..70 deg).
    for (int angle = 90; angle >= 20; angle -= 10) {
      const Camera camera = PinholeCamera(1280, 960, 900);
      RenderOptions ro;
      ro.noise_sigma = 0.02;
      RenderTruth truth;
      const cv::Mat image = RenderBoard(
          board, camera, LookAt(board, {61, 107.5}, 1.1, 90 - angle, 20), ro,
          &truth);
      Tally tally;
      for (int trial = 0; trial < 4; ++trial) {
        DecodeAndCount(
            board, image,
            OneComponentFromTruth(truth, RandomSignedPermutation(&rng), {5, 5}),
            0.0, &rng, &tally);
      }
      std::printf("    \"tilt_view_angle_%d\": %s,\n", angle,
                  TallyJson(tally).c_str());
    }
    // Strong fisheye (equidistant, ~190 deg over the image diagonal), board
    // close and off-centre.
    for (int placement = 0; placement < 3; ++placement) {
      const Camera camera = FisheyeCamera(1280, 960, 330, -0.02);
      RenderOptions ro;
      ro.noise_sigma = 0.02;
      RenderTruth truth;
      const cv::Mat image = RenderBoard(
          board, camera,
          LookAt(board, {61, 107.5}, 0.35 + 0.1 * placement, 25.0 * placement,
                 30, Eigen::Vector2d(0.08 * placement, -0.05 * placement)),
          ro, &truth);
      Tally tally;
      for (int trial = 0; trial < 4; ++trial) {
        DecodeAndCount(
            board, image,
            OneComponentFromTruth(truth, RandomSignedPermutation(&rng), {5, 5}),
            0.0, &rng, &tally);
      }
      std::printf("    \"fisheye_%d\": %s,\n", placement,
                  TallyJson(tally).c_str());
    }
    // Wide pinhole, board cut by the image border and by an occluder.
    {
      const Camera camera = PinholeCamera(1280, 960, 600);
      RenderOptions ro;
      ro.noise_sigma = 0.02;
      Occluder occluder;
      occluder.center_px = Eigen::Vector2d(700, 500);
      occluder.radius_px = 90;
      occluder.grey = 0.3;
      ro.occluders.push_back(occluder);
      RenderTruth truth;
      const cv::Mat image = RenderBoard(
          board, camera, LookAt(board, {61, 107.5}, 0.8, 30, -15, {0.25, 0.1}),
          ro, &truth);
      Tally tally;
      for (int trial = 0; trial < 4; ++trial) {
        DecodeAndCount(
            board, image,
            OneComponentFromTruth(truth, RandomSignedPermutation(&rng), {5, 5}),
            0.0, &rng, &tally);
      }
      std::printf("    \"wide_occluded\": %s\n", TallyJson(tally).c_str());
    }
    std::printf("  }\n");
  }
  std::printf("}\n");
  return 0;
}
