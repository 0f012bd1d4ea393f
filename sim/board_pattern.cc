#include "sim/board_pattern.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "target/puzzleboard.h"

namespace puzzlecal {
namespace {

// Disc radius in tiles: the discs have diameter s/3.
constexpr double kDiscRadius = 1.0 / 6.0;

// Covered fraction of a footprint of extent `width` whose centre lies at
// signed distance `distance` inside a straight boundary.
double Ramp(double distance, double width) {
  if (!(width > 1e-300)) return distance > 0 ? 1.0 : 0.0;
  return std::clamp(0.5 + distance / width, 0.0, 1.0);
}

// Exact covered fraction of a parallelogram footprint (a unit sample square
// mapped linearly) by the half plane {signed distance > 0}, when the signed
// distance at the footprint centre is `distance` and changes by `rate_x`
// and `rate_y` per sample step along the square's two sides: the CDF of the
// sum of two uniform variables (a trapezoid).
double EdgeCoverage(double distance, double rate_x, double rate_y) {
  double a = std::abs(rate_x), b = std::abs(rate_y);
  if (a < b) std::swap(a, b);
  if (!(b > 1e-9 * a)) return Ramp(distance, a);
  const double outer = 0.5 * (a + b), inner = 0.5 * (a - b);
  if (distance <= -outer) return 0.0;
  if (distance >= outer) return 1.0;
  if (distance < -inner) {
    const double e = distance + outer;
    return e * e / (2.0 * a * b);
  }
  if (distance > inner) {
    const double e = outer - distance;
    return 1.0 - e * e / (2.0 * a * b);
  }
  return 0.5 + distance / a;
}

// Covered fraction of the axis-aligned rectangle.
double RectCoverage(double u, double v, const PatternExtent& rect,
                    double width_u, double width_v) {
  return Ramp(u - rect.min_x, width_u) * Ramp(rect.max_x - u, width_u) *
         Ramp(v - rect.min_y, width_v) * Ramp(rect.max_y - v, width_v);
}

}  // namespace

PatternExtent PrintedPatternExtent(const Board& board) {
  const double border = board.Traits().border_tiles;
  PatternExtent extent;
  extent.min_x = board.origin.x() - border;
  extent.min_y = board.origin.y() - border;
  extent.max_x = board.origin.x() + board.cols - 1 + border;
  extent.max_y = board.origin.y() + board.rows - 1 + border;
  return extent;
}

BoardPattern::BoardPattern(const Board& board, const PatternVariant& variant,
                           double paper_margin_tiles)
    : board_(board), variant_(variant), extent_(PrintedPatternExtent(board)) {
  paper_ = extent_;
  paper_.min_x -= paper_margin_tiles;
  paper_.min_y -= paper_margin_tiles;
  paper_.max_x += paper_margin_tiles;
  paper_.max_y += paper_margin_tiles;
  if (variant.random_code_seed != 0) {
    // mt19937_64 is fully specified by the standard: the same seed gives the
    // same code everywhere.
    random_code_ = true;
    std::mt19937_64 rng(variant.random_code_seed);
    for (auto* table : {&code_a_, &code_b_}) {
      for (auto& row : *table) {
        for (auto& bit : row) bit = static_cast<uint8_t>(rng() >> 63);
      }
    }
  }
}

int BoardPattern::VerticalEdgeBit(int x, int y) const {
  if (!random_code_) return PuzzleBoardVerticalEdgeBit(x, y);
  return code_a_[PositiveMod(y, 3)][PositiveMod(x, kPuzzleBoardCodeLength)];
}

int BoardPattern::HorizontalEdgeBit(int x, int y) const {
  if (!random_code_) return PuzzleBoardHorizontalEdgeBit(x, y);
  return code_b_[PositiveMod(x, 3)][PositiveMod(y, kPuzzleBoardCodeLength)];
}

bool BoardPattern::TileIsBlack(int x, int y) const {
  // Checkerboard tiles beyond the printed border tiles are paper.
  if (board_.Traits().pattern_ends_at_border &&
      (x < extent_.min_x || x + 1 > extent_.max_x || y < extent_.min_y ||
       y + 1 > extent_.max_y)) {
    return false;
  }
  return PuzzleBoardTileIsBlack(x, y);
}

InkMix BoardPattern::SampleArea(double u, double v,
                                const Eigen::Matrix2d& footprint) const {
  Eigen::Matrix2d f = footprint;
  if (variant_.mirrored) {
    u = 2.0 * board_.origin.x() + board_.cols - 1 - u;
    f.row(0) = -f.row(0);
  }
  InkMix mix;
  // Far off any board (and safe to round to int below).
  if (!(std::abs(u) < 1e7 && std::abs(v) < 1e7)) {
    mix.none = 1.0;
    return mix;
  }
  const double width_u = std::abs(f(0, 0)) + std::abs(f(0, 1));
  const double width_v = std::abs(f(1, 0)) + std::abs(f(1, 1));
  const double paper = RectCoverage(u, v, paper_, width_u, width_v);
  if (!(paper > 0)) {  // also NaN
    mix.none = 1.0;
    return mix;
  }
  const double printed = RectCoverage(u, v, extent_, width_u, width_v);
  double black = 0.0;
  if (printed > 0) {
    black = PatternBlack(u, v, f);
    if (variant_.inverted) black = 1.0 - black;
  }
  mix.black = printed * black;
  mix.white = paper - mix.black;
  mix.none = 1.0 - paper;
  return mix;
}

double BoardPattern::PatternBlack(double u, double v,
                                  const Eigen::Matrix2d& footprint) const {
  // Tiles: the four tiles around the nearest grid crossing, weighted by the
  // footprint's share on each side of the two nearest lines (separable, so
  // exact at the X-junctions too).
  const double line_u = std::round(u), line_v = std::round(v);
  const int iu = static_cast<int>(line_u), iv = static_cast<int>(line_v);
  const double a = EdgeCoverage(u - line_u, footprint(0, 0), footprint(0, 1));
  const double b = EdgeCoverage(v - line_v, footprint(1, 0), footprint(1, 1));
  double black = (1 - a) * (1 - b) * TileIsBlack(iu - 1, iv - 1) +
                 a * (1 - b) * TileIsBlack(iu, iv - 1) +
                 (1 - a) * b * TileIsBlack(iu - 1, iv) +
                 a * b * TileIsBlack(iu, iv);
  if (!board_.Traits().absolute_ids) return black;  // no edge bits
  const int x0 = board_.origin.x(), y0 = board_.origin.y();
  const int x1 = x0 + board_.cols, y1 = y0 + board_.rows;
  auto add_disc = [&](double cu, double cv, int bit) {
    const double du = u - cu, dv = v - cv;
    const double dist = std::sqrt(du * du + dv * dv);
    // The rim is locally straight at the footprint's scale.
    double inside;
    if (dist > 1e-12) {
      const Eigen::RowVector2d rate =
          Eigen::RowVector2d(du / dist, dv / dist) * footprint;
      inside = EdgeCoverage(kDiscRadius - dist, rate(0), rate(1));
    } else {
      inside = 1.0;
    }
    black = inside * (bit ? 0.0 : 1.0) + (1 - inside) * black;
  };
  // Discs are 0.7 tiles apart, so only the nearest vertical and the nearest
  // horizontal one can touch a small footprint.
  const int tile_x = static_cast<int>(std::floor(u));
  const int tile_y = static_cast<int>(std::floor(v));
  if (iu >= x0 && iu < x1 && tile_y >= y0 && tile_y < y1 - 1) {
    add_disc(line_u, tile_y + 0.5, VerticalEdgeBit(iu, tile_y));
  }
  if (iv >= y0 && iv < y1 && tile_x >= x0 && tile_x < x1 - 1) {
    add_disc(tile_x + 0.5, line_v, HorizontalEdgeBit(tile_x, iv));
  }
  return black;
}

BoardPattern::BoxContent BoardPattern::Classify(double min_u, double min_v,
                                                double max_u,
                                                double max_v) const {
  if (!(min_u <= max_u && min_v <= max_v)) return BoxContent::kComplex;
  if (variant_.mirrored) {
    const double m = 2.0 * board_.origin.x() + board_.cols - 1;
    const double mirrored_min = m - max_u;
    max_u = m - min_u;
    min_u = mirrored_min;
  }
  auto disjoint = [&](const PatternExtent& r) {
    return max_u < r.min_x || min_u > r.max_x || max_v < r.min_y ||
           min_v > r.max_y;
  };
  auto inside = [&](const PatternExtent& r) {
    return min_u > r.min_x && max_u < r.max_x && min_v > r.min_y &&
           max_v < r.max_y;
  };
  if (disjoint(paper_)) return BoxContent::kUniform;
  if (!inside(paper_)) return BoxContent::kComplex;
  if (disjoint(extent_)) return BoxContent::kUniform;
  if (!inside(extent_)) return BoxContent::kComplex;
  // Grid lines crossing the box.
  const double lines_u = std::floor(max_u) - std::floor(min_u);
  const double lines_v = std::floor(max_v) - std::floor(min_v);
  if (lines_u + lines_v > 1) return BoxContent::kComplex;
  if (board_.Traits().absolute_ids) {
    // Disc centres near the box, printed or not (to stay simple).
    const int u0 = static_cast<int>(std::floor(min_u)) - 1;
    const int u1 = static_cast<int>(std::floor(max_u)) + 1;
    const int v0 = static_cast<int>(std::floor(min_v)) - 1;
    const int v1 = static_cast<int>(std::floor(max_v)) + 1;
    auto touches = [&](double cu, double cv) {
      const double du = std::max({min_u - cu, 0.0, cu - max_u});
      const double dv = std::max({min_v - cv, 0.0, cv - max_v});
      return du * du + dv * dv <= kDiscRadius * kDiscRadius;
    };
    for (int iu = u0; iu <= u1; ++iu) {
      for (int iv = v0; iv <= v1; ++iv) {
        if (touches(iu, iv + 0.5) || touches(iu + 0.5, iv)) {
          return BoxContent::kComplex;
        }
      }
    }
  }
  return lines_u + lines_v == 0 ? BoxContent::kUniform : BoxContent::kOneEdge;
}

BoardInk BoardPattern::Sample(double u, double v) const {
  if (variant_.mirrored) {
    // Mirror about the vertical centre line of the printed corners.
    u = 2.0 * board_.origin.x() + board_.cols - 1 - u;
  }
  const BoardInk ink = SampleUnmirrored(u, v);
  if (!variant_.inverted) return ink;
  if (ink == BoardInk::kBlack) return BoardInk::kWhite;
  if (ink == BoardInk::kWhite) return BoardInk::kBlack;
  return ink;
}

BoardInk BoardPattern::SampleUnmirrored(double u, double v) const {
  // Written so that NaN fails every comparison and lands off the paper.
  if (!(u >= paper_.min_x && u <= paper_.max_x && v >= paper_.min_y &&
        v <= paper_.max_y)) {
    return BoardInk::kNone;
  }
  if (!(u >= extent_.min_x && u <= extent_.max_x && v >= extent_.min_y &&
        v <= extent_.max_y)) {
    return BoardInk::kPaper;
  }
  const int tile_x = static_cast<int>(std::floor(u));
  const int tile_y = static_cast<int>(std::floor(v));
  if (board_.Traits().absolute_ids) {
    const int x0 = board_.origin.x(), y0 = board_.origin.y();
    const int x1 = x0 + board_.cols, y1 = y0 + board_.rows;
    constexpr double kR2 = kDiscRadius * kDiscRadius;
    // Discs are 0.7 tiles apart at least and 1/3 tile wide, so a point lies
    // in at most one: the nearest vertical or the nearest horizontal one.
    const int vx = static_cast<int>(std::lround(u));
    if (vx >= x0 && vx < x1 && tile_y >= y0 && tile_y < y1 - 1) {
      const double du = u - vx, dv = v - (tile_y + 0.5);
      if (du * du + dv * dv < kR2) {
        return VerticalEdgeBit(vx, tile_y) ? BoardInk::kWhite
                                           : BoardInk::kBlack;
      }
    }
    const int hy = static_cast<int>(std::lround(v));
    if (hy >= y0 && hy < y1 && tile_x >= x0 && tile_x < x1 - 1) {
      const double du = u - (tile_x + 0.5), dv = v - hy;
      if (du * du + dv * dv < kR2) {
        return HorizontalEdgeBit(tile_x, hy) ? BoardInk::kWhite
                                             : BoardInk::kBlack;
      }
    }
  }
  return TileIsBlack(tile_x, tile_y) ? BoardInk::kBlack : BoardInk::kWhite;
}

}  // namespace puzzlecal
