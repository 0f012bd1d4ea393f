#ifndef PUZZLECAL_FUZZ_GRID_DECODE_CASE_H_
#define PUZZLECAL_FUZZ_GRID_DECODE_CASE_H_

// Fuzz case (b): arbitrary corner sets -> BuildGrid -> DecodeBoard.
//
// Bytes, in order:
//  0  board: PuzzleBoard 11x8, PuzzleBoard 23x16 at another torus origin, or
//     a plain checkerboard 11x8;
//  1  image: none, or a small synthetic checkerboard (8-bit, 16-bit, float)
//     drawn with the lattice parameters below;
//  2  options: neighbours, minimum component size, Kruskal passes, minimum
//     corners to decode;
//  3  corner set: a lattice with noise, drops and duplicates; random points;
//     raw doubles (NaN, inf, denormals, huge); or a lattice in which some
//     corners get raw doubles;
//  then the lattice parameters and the per-corner bytes.

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "decode/decoder.h"
#include "detection/corner.h"
#include "fuzz/byte_reader.h"
#include "grid/grid.h"
#include "grid/grid_component.h"
#include "target/board.h"

namespace puzzlecal {
namespace fuzz {

constexpr int kGridImageWidth = 320;
constexpr int kGridImageHeight = 240;
constexpr int kGridMaxCorners = 1500;

struct LatticeParams {
  double origin_x = 0, origin_y = 0;  // pixel position of lattice point (0,0)
  double spacing = 20;                // pixels per tile
  double angle = 0;                   // rotation of the lattice, radians
};

inline double WrapAngle(double a) {
  a = std::remainder(a, 2 * M_PI);
  return a <= -M_PI ? a + 2 * M_PI : a;
}

// A checkerboard image whose tile corners are the lattice points. Drawn by
// cv::warpAffine from a one-pixel-per-tile pattern (uninstrumented and fast,
// so the fuzzer spends its time in grid/ and decode/).
inline cv::Mat LatticeImage(const LatticeParams& lattice, int depth) {
  constexpr int kPatternTiles = 64;  // even, so wrapping keeps the parity
  static const cv::Mat pattern = [] {
    cv::Mat tiles(kPatternTiles, kPatternTiles, CV_32FC1);
    for (int v = 0; v < kPatternTiles; ++v) {
      for (int u = 0; u < kPatternTiles; ++u) {
        tiles.at<float>(v, u) = ((u + v) & 1) ? 0.85f : 0.15f;
      }
    }
    return tiles;
  }();
  // Image pixel -> pattern pixel: (u, v) = R(-angle) (p - origin) / spacing,
  // shifted by half a pixel so nearest-neighbour sampling floors.
  const double c = std::cos(lattice.angle), s = std::sin(lattice.angle);
  const double k = 1.0 / lattice.spacing;
  const cv::Matx23d image_to_pattern(
      c * k, s * k, -(c * lattice.origin_x + s * lattice.origin_y) * k - 0.5,
      -s * k, c * k, (s * lattice.origin_x - c * lattice.origin_y) * k - 0.5);
  cv::Mat image;
  cv::warpAffine(pattern, image, image_to_pattern,
                 cv::Size(kGridImageWidth, kGridImageHeight),
                 cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_WRAP);
  if (depth == CV_32F) return image;
  cv::Mat converted;
  image.convertTo(converted, depth, depth == CV_16U ? 65535.0 : 255.0);
  return converted;
}

inline Board BoardFromByte(uint8_t selector) {
  Board board;
  switch (selector % 3) {
    case 0:
      break;  // PuzzleBoard 11 x 8 at (0, 0)
    case 1:
      board.cols = 23;
      board.rows = 16;
      board.origin = Eigen::Vector2i(480, 490);  // wraps around the torus
      board.tile_size_m = 0.03;
      break;
    default:
      board.type = BoardType::kCheckerboard;
      break;
  }
  return board;
}

inline std::vector<Corner> CornersFromBytes(ByteReader* reader, uint8_t mode,
                                            const LatticeParams& lattice) {
  std::vector<Corner> corners;
  const double c = std::cos(lattice.angle), s = std::sin(lattice.angle);
  auto lattice_corner = [&](int i, int j, double noise_x, double noise_y,
                            double orientation_noise) {
    Corner corner;
    corner.xy.x() = lattice.origin_x + lattice.spacing * (c * i - s * j) + noise_x;
    corner.xy.y() = lattice.origin_y + lattice.spacing * (s * i + c * j) + noise_y;
    corner.response = 1.0;
    corner.orientation = WrapAngle(lattice.angle + M_PI / 4 +
                                   ((i + j) & 1) * M_PI / 2 + orientation_noise);
    return corner;
  };
  switch (mode % 4) {
    case 0:
    case 3: {  // lattice with noise, drops, duplicates (3: raw doubles too)
      const int cols = reader->IntInRange(1, 30);
      const int rows = reader->IntInRange(1, 30);
      const double noise = reader->DoubleInRange(0, 0.5) * lattice.spacing;
      for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < cols; ++i) {
          const uint8_t flags = reader->Byte();
          if ((flags & 7) == 0) continue;  // dropped
          Corner corner = lattice_corner(
              i, j, noise * (reader->Unit() - 0.5), noise * (reader->Unit() - 0.5),
              (flags & 8) ? reader->DoubleInRange(-0.5, 0.5) : 0.0);
          if (mode % 4 == 3 && (flags & 0x30) == 0x30) {
            corner.xy.x() = reader->RawDouble();
            corner.xy.y() = reader->RawDouble();
            corner.orientation = reader->RawDouble();
            corner.response = reader->RawDouble();
          }
          corners.push_back(corner);
          if (flags & 0x40) corners.push_back(corner);  // exact duplicate
          if (flags & 0x80) {                           // near duplicate
            corner.xy.x() += 0.25;
            corners.push_back(corner);
          }
        }
      }
      break;
    }
    case 1: {  // random points (with orientations)
      const int count = reader->IntInRange(0, 400);
      for (int k = 0; k < count; ++k) {
        Corner corner;
        corner.xy.x() = reader->DoubleInRange(-20, kGridImageWidth + 20);
        corner.xy.y() = reader->DoubleInRange(-20, kGridImageHeight + 20);
        corner.orientation = reader->DoubleInRange(-M_PI, M_PI);
        corner.response = reader->Unit();
        corners.push_back(corner);
      }
      break;
    }
    case 2: {  // raw doubles: NaN, inf, huge, denormal
      const int count = reader->IntInRange(0, 200);
      for (int k = 0; k < count; ++k) {
        Corner corner;
        corner.xy.x() = reader->RawDouble();
        corner.xy.y() = reader->RawDouble();
        corner.orientation = reader->RawDouble();
        corner.response = reader->RawDouble();
        corners.push_back(corner);
      }
      break;
    }
  }
  if (corners.size() > static_cast<size_t>(kGridMaxCorners)) {
    corners.resize(kGridMaxCorners);
  }
  return corners;
}

// Runs one fuzz case. Returns "" or the broken promise of BuildGrid /
// DecodeBoard (the fuzz target traps on it; the regression tests expect "").
inline std::string RunGridDecodeCase(const uint8_t* data, size_t size) {
  ByteReader reader(data, size);
  const Board board = BoardFromByte(reader.Byte());
  const uint8_t image_selector = reader.Byte();
  const uint8_t option_bits = reader.Byte();
  const uint8_t corner_mode = reader.Byte();

  LatticeParams lattice;
  lattice.origin_x = reader.DoubleInRange(-40, kGridImageWidth + 40);
  lattice.origin_y = reader.DoubleInRange(-40, kGridImageHeight + 40);
  lattice.spacing = reader.DoubleInRange(0.5, 60);
  lattice.angle = reader.DoubleInRange(-M_PI, M_PI);

  GridOptions grid_options;
  grid_options.candidates.num_neighbors = 2 + (option_bits & 7);  // 2..9
  grid_options.cleanup.min_component_size = 1 + ((option_bits >> 3) & 3) * 2;
  grid_options.merge.kruskal_passes = 1 + ((option_bits >> 5) & 1);
  DecodeOptions decode_options;
  decode_options.min_corners = 1 + ((option_bits >> 6) & 3) * 2;

  cv::Mat image;
  switch (image_selector % 4) {
    case 0: break;
    case 1: image = LatticeImage(lattice, CV_8U); break;
    case 2: image = LatticeImage(lattice, CV_16U); break;
    default: image = LatticeImage(lattice, CV_32F); break;
  }
  const std::vector<Corner> corners =
      CornersFromBytes(&reader, corner_mode, lattice);

  GridSummary grid_summary;
  const std::vector<GridComponent> components =
      BuildGrid(corners, image, grid_options, &grid_summary);
  size_t previous_size = static_cast<size_t>(-1);
  for (const GridComponent& component : components) {
    if (component.corner.size() != component.ij.size()) {
      return "a component's corner and ij sizes differ";
    }
    if (component.corner.size() > previous_size) {
      return "components are not sorted by size";
    }
    previous_size = component.corner.size();
    std::set<int> seen_corners;
    std::set<std::pair<int, int>> seen_labels;
    for (size_t k = 0; k < component.corner.size(); ++k) {
      const int index = component.corner[k];
      if (index < 0 || index >= static_cast<int>(corners.size())) {
        return "a component names a corner index out of range";
      }
      if (!corners[index].xy.allFinite()) {
        return "a component holds a corner with non-finite coordinates";
      }
      if (!seen_corners.insert(index).second) {
        return "a corner appears twice in one component";
      }
      if (!seen_labels.insert({component.ij[k].x(), component.ij[k].y()}).second) {
        return "two corners of one component share a label";
      }
    }
  }

  const DecodeResult result =
      DecodeBoard(board, corners, components, image, decode_options);
  const BoardObservation& observation = result.observation;
  if (observation.id.size() != observation.xy.size() ||
      result.corner_index.size() != observation.id.size() ||
      result.component.size() != observation.id.size()) {
    return "DecodeResult arrays differ in length";
  }
  if (result.components.size() != components.size()) {
    return "DecodeResult has not one ComponentDecoding per component";
  }
  std::set<std::pair<int, int>> seen_ids;
  for (size_t k = 0; k < observation.id.size(); ++k) {
    const int index = result.corner_index[k];
    if (index < 0 || index >= static_cast<int>(corners.size())) {
      return "DecodeResult names a corner index out of range";
    }
    if (!observation.xy[k].allFinite()) {
      return "DecodeResult holds a non-finite position";
    }
    if (result.absolute_ids) {
      if (!board.Contains(observation.id[k])) {
        return "DecodeResult holds an id outside the printed board";
      }
      if (!seen_ids.insert({observation.id[k].x(), observation.id[k].y()}).second) {
        return "DecodeResult holds one board id twice";
      }
    }
  }
  return "";
}

}  // namespace fuzz
}  // namespace puzzlecal

#endif  // PUZZLECAL_FUZZ_GRID_DECODE_CASE_H_
