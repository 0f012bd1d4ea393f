#include "decode/position_search.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "target/puzzleboard.h"

namespace puzzlecal {
namespace {

constexpr int kRows = kPuzzleBoardCodeRows;   // 3
constexpr int kLen = kPuzzleBoardCodeLength;  // 167

// The codes as +-1, each row stored twice so a cyclic shift needs no modulo.
struct SignedCodes {
  std::array<std::array<int, 2 * kLen>, kRows> a, b;
  SignedCodes() {
    for (int r = 0; r < kRows; ++r) {
      for (int c = 0; c < 2 * kLen; ++c) {
        a[r][c] = 2 * PuzzleBoardCodeABit(r, c % kLen) - 1;
        b[r][c] = 2 * PuzzleBoardCodeBBit(r, c % kLen) - 1;
      }
    }
  }
};

const SignedCodes& Codes() {
  static const SignedCodes codes;
  return codes;
}

using Table = std::array<std::array<int, kLen>, kRows>;

struct Bin {
  int row, col, vote;
};

// Correlation of the voted bins with a code: out[a][b] = sum over bins of
// vote * code[(row + a) mod 3][(col + b) mod 167].
void Correlate(const std::vector<Bin>& bins,
               const std::array<std::array<int, 2 * kLen>, kRows>& code,
               Table* out) {
  for (auto& row : *out) row.fill(0);
  for (const Bin& bin : bins) {
    if (bin.vote == 0) continue;
    for (int a = 0; a < kRows; ++a) {
      const int* code_row = code[(bin.row + a) % kRows].data() + bin.col;
      int* out_row = (*out)[a].data();
      for (int b = 0; b < kLen; ++b) out_row[b] += bin.vote * code_row[b];
    }
  }
}

Eigen::Vector2i AxisVector(int axis) {
  return axis == 0 ? Eigen::Vector2i(1, 0) : Eigen::Vector2i(0, 1);
}

// Board edge of the label edge under rotation m (offset 0): its min corner
// and whether it is horizontal.
void BoardEdge(const Eigen::Matrix2i& m, const Eigen::Vector2i& from, int axis,
               Eigen::Vector2i* lo, bool* horizontal) {
  const Eigen::Vector2i a = m * from;
  const Eigen::Vector2i d = m * AxisVector(axis);
  *lo = a.cwiseMin(a + d);
  *horizontal = d.x() != 0;
}

using BinGrid = std::array<std::array<int, kLen>, kRows>;

// Sums the votes into the code bins they fall on under rotation m and
// offset t: vertical edges into vbin[y mod 3][x mod 167], horizontal ones
// into hbin[x mod 3][y mod 167]; `sign` -1 for inverted contrast.
void VoteIntoBins(const std::vector<LabelEdgeVote>& votes,
                  const Eigen::Matrix2i& m, const Eigen::Vector2i& t, int sign,
                  BinGrid* vbin, BinGrid* hbin) {
  for (auto& row : *vbin) row.fill(0);
  for (auto& row : *hbin) row.fill(0);
  for (const LabelEdgeVote& vote : votes) {
    Eigen::Vector2i lo;
    bool horizontal;
    BoardEdge(m, vote.from, vote.axis, &lo, &horizontal);
    const int v = sign * (vote.bit ? 1 : -1);
    lo += t;
    if (horizontal) {
      (*hbin)[PositiveMod(lo.x(), kRows)][PositiveMod(lo.y(), kLen)] += v;
    } else {
      (*vbin)[PositiveMod(lo.y(), kRows)][PositiveMod(lo.x(), kLen)] += v;
    }
  }
}

// The bins that received votes, in row-major order.
std::vector<Bin> VotedBins(const BinGrid& bin) {
  std::vector<Bin> bins;
  for (int row = 0; row < kRows; ++row) {
    for (int col = 0; col < kLen; ++col) {
      if (bin[row][col] != 0) bins.push_back({row, col, bin[row][col]});
    }
  }
  return bins;
}

// The best score over the whole torus of positions.
int TorusBestScore(const Table& sv, const Table& sh) {
  int max_v = std::numeric_limits<int>::min();
  int max_h = std::numeric_limits<int>::min();
  for (int a = 0; a < kRows; ++a) {
    max_v = std::max(max_v, *std::max_element(sv[a].begin(), sv[a].end()));
    max_h = std::max(max_h, *std::max_element(sh[a].begin(), sh[a].end()));
  }
  return max_v + max_h;
}

// Best and second-best score of the in-board positions seen so far.
struct Ranking {
  int best = std::numeric_limits<int>::min();
  int second = std::numeric_limits<int>::min();
  int best_rotation = -1;
};

// Scores every offset of rotation m (index r) that keeps the component's
// labels on the printed board and whose tile colour matches
// `dark_tile_parity` (when >= 0).
void ScoreInBoardOffsets(const Table& sv, const Table& sh,
                         const Eigen::Matrix2i& m, int r,
                         const Eigen::Vector2i& label_min,
                         const Eigen::Vector2i& label_max, int dark_tile_parity,
                         const Board& board, bool inverted, int overhang,
                         Ranking* ranking, PositionSearchResult* result) {
  // Offsets that keep every label of the component on the printed board,
  // give or take `overhang` rows and columns on each side.
  Eigen::Vector2i lo = (m * label_min).cwiseMin(m * label_max);
  Eigen::Vector2i hi = (m * label_min).cwiseMax(m * label_max);
  const Eigen::Vector2i t_min =
      board.origin - lo - Eigen::Vector2i::Constant(overhang);
  const Eigen::Vector2i t_max =
      board.origin + Eigen::Vector2i(board.cols - 1, board.rows - 1) - hi +
      Eigen::Vector2i::Constant(overhang);
  // Colour: label tile (0, 0) maps to the board tile whose min corner is
  // tile_lo + t; it is black when that corner's x + y is even.
  Eigen::Vector2i tile_lo = Eigen::Vector2i::Zero();
  for (const Eigen::Vector2i& c :
       {Eigen::Vector2i(1, 0), Eigen::Vector2i(0, 1), Eigen::Vector2i(1, 1)}) {
    tile_lo = tile_lo.cwiseMin(m * c);
  }
  for (int ty = t_min.y(); ty <= t_max.y(); ++ty) {
    const int ty3 = PositiveMod(ty, kRows);
    const int ty167 = PositiveMod(ty, kLen);
    for (int tx = t_min.x(); tx <= t_max.x(); ++tx) {
      if (dark_tile_parity >= 0) {
        const bool black =
            PositiveMod(tile_lo.x() + tile_lo.y() + tx + ty, 2) == 0;
        const bool dark = black != inverted;
        if (dark != (dark_tile_parity == 0)) continue;
      }
      ++result->hypotheses;
      const int score =
          sv[ty3][PositiveMod(tx, kLen)] + sh[PositiveMod(tx, kRows)][ty167];
      if (score > ranking->best) {
        ranking->second = ranking->best;
        ranking->best = score;
        result->best.rotation = m;
        result->best.offset = Eigen::Vector2i(tx, ty);
        ranking->best_rotation = r;
      } else if (score > ranking->second) {
        ranking->second = score;
      }
    }
  }
}

// Distinct code bits read at the best position, and how many agree.
void CountBinsAtBest(const std::vector<LabelEdgeVote>& votes, int sign,
                     PositionSearchResult* result) {
  BinGrid vbin, hbin;
  VoteIntoBins(votes, result->best.rotation, result->best.offset, sign, &vbin,
               &hbin);
  for (int row = 0; row < kRows; ++row) {
    for (int col = 0; col < kLen; ++col) {
      if (vbin[row][col] != 0) {
        ++result->bins_read;
        if ((vbin[row][col] > 0) == (PuzzleBoardCodeABit(row, col) == 1)) {
          ++result->bins_agreeing;
        }
      }
      if (hbin[row][col] != 0) {
        ++result->bins_read;
        if ((hbin[row][col] > 0) == (PuzzleBoardCodeBBit(row, col) == 1)) {
          ++result->bins_agreeing;
        }
      }
    }
  }
}

}  // namespace

std::vector<Eigen::Matrix2i> LabelRotations(int handedness) {
  Eigen::Matrix2i quarter;
  quarter << 0, -1, 1, 0;
  Eigen::Matrix2i m = Eigen::Matrix2i::Identity();
  if (handedness < 0) m(1, 1) = -1;
  std::vector<Eigen::Matrix2i> rotations;
  for (int turn = 0; turn < 4; ++turn) {
    rotations.push_back(m);
    m = quarter * m;
  }
  return rotations;
}

int BoardBitOfLabelEdge(const LabelToBoard& map, const Eigen::Vector2i& from,
                        int axis) {
  Eigen::Vector2i lo;
  bool horizontal;
  BoardEdge(map.rotation, from, axis, &lo, &horizontal);
  lo += map.offset;
  return horizontal ? PuzzleBoardHorizontalEdgeBit(lo.x(), lo.y())
                    : PuzzleBoardVerticalEdgeBit(lo.x(), lo.y());
}

double Log10BinomialTailHalf(int n, int k) {
  if (k <= 0) return 0.0;
  if (k > n) return -std::numeric_limits<double>::infinity();
  // log-sum-exp of log C(n, i) for i = k..n.
  std::vector<double> terms;
  terms.reserve(n - k + 1);
  double top = -std::numeric_limits<double>::infinity();
  for (int i = k; i <= n; ++i) {
    const double t =
        std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0);
    terms.push_back(t);
    top = std::max(top, t);
  }
  double sum = 0.0;
  for (double t : terms) sum += std::exp(t - top);
  return (top + std::log(sum) - n * std::log(2.0)) / std::log(10.0);
}

PositionSearchResult SearchPuzzleBoardPosition(
    const std::vector<LabelEdgeVote>& votes, const Eigen::Vector2i& label_min,
    const Eigen::Vector2i& label_max, int handedness, int dark_tile_parity,
    const Board& board, bool inverted, int overhang) {
  PositionSearchResult result;
  result.num_edges = static_cast<int>(votes.size());
  result.torus_best_score = std::numeric_limits<int>::min();
  const int sign = inverted ? -1 : 1;
  const SignedCodes& codes = Codes();
  Ranking ranking;
  BinGrid vbin, hbin;
  Table sv, sh;
  const std::vector<Eigen::Matrix2i> rotations = LabelRotations(handedness);
  for (int r = 0; r < 4; ++r) {
    const Eigen::Matrix2i& m = rotations[r];
    VoteIntoBins(votes, m, Eigen::Vector2i::Zero(), sign, &vbin, &hbin);
    Correlate(VotedBins(vbin), codes.a, &sv);  // sv[ty mod 3][tx mod 167]
    Correlate(VotedBins(hbin), codes.b, &sh);  // sh[tx mod 3][ty mod 167]
    result.torus_best_score =
        std::max(result.torus_best_score, TorusBestScore(sv, sh));
    ScoreInBoardOffsets(sv, sh, m, r, label_min, label_max, dark_tile_parity,
                        board, inverted, overhang, &ranking, &result);
  }
  if (ranking.best_rotation < 0) return result;
  result.found = true;
  result.best_score = ranking.best;
  result.second_score = ranking.second == std::numeric_limits<int>::min()
                            ? ranking.best - 2 * result.num_edges - 2
                            : ranking.second;
  result.edges_agreeing = (ranking.best + result.num_edges) / 2;
  CountBinsAtBest(votes, sign, &result);
  return result;
}

}  // namespace puzzlecal
