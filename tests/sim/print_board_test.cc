#include "sim/print_board.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "decode/puzzleboard.h"

namespace puzzlecal {
namespace {

Board MediumPuzzleBoard() {
  return MakeBoard(BoardType::kPuzzleBoard, 23, 16, Eigen::Vector2i(50, 100),
                   0.03);
}

cv::Mat RenderPng(const Board& board, double dpi) {
  PrintOptions options;
  options.dpi = dpi;
  std::string bytes, why;
  EXPECT_TRUE(
      RenderPrintableBoard(board, PrintFormat::kPng, options, &bytes, &why))
      << why;
  const std::vector<uchar> buffer(bytes.begin(), bytes.end());
  return cv::imdecode(buffer, cv::IMREAD_GRAYSCALE);
}

// Grey value at page position (mm), pixel centres at (i + 0.5) / px_per_mm.
int GreyAt(const cv::Mat& image, double x_mm, double y_mm, double dpi) {
  const double px_per_mm = dpi / 25.4;
  const int x = static_cast<int>(std::floor(x_mm * px_per_mm));
  const int y = static_cast<int>(std::floor(y_mm * px_per_mm));
  return image.at<uchar>(y, x);
}

TEST(PrintBoardTest, PngTilesAndDiscsFollowTheCode) {
  const Board board = MediumPuzzleBoard();
  constexpr double kDpi = 60.0;
  const cv::Mat image = RenderPng(board, kDpi);
  ASSERT_FALSE(image.empty());
  // Page 23 x 16 tiles of 30 mm.
  EXPECT_EQ(image.cols, static_cast<int>(std::lround(690.0 / 25.4 * kDpi)));
  EXPECT_EQ(image.rows, static_cast<int>(std::lround(480.0 / 25.4 * kDpi)));
  const double s = 30.0;
  int tiles = 0, discs = 0, white_discs = 0;
  // Tile centres (away from the discs): corner (x, y) + (0.5, 0.5) tiles,
  // including the half border tiles (sampled a quarter tile in).
  for (int y = board.origin.y() - 1; y < board.origin.y() + board.rows; ++y) {
    for (int x = board.origin.x() - 1; x < board.origin.x() + board.cols; ++x) {
      double cx, cy;
      PrintedCornerMm(board, x, y, &cx, &cy);
      double px = cx + 0.5 * s, py = cy + 0.5 * s;
      if (x < board.origin.x()) px = cx + 0.75 * s;
      if (y < board.origin.y()) py = cy + 0.75 * s;
      if (x == board.origin.x() + board.cols - 1) px = cx + 0.25 * s;
      if (y == board.origin.y() + board.rows - 1) py = cy + 0.25 * s;
      const int grey = GreyAt(image, px, py, kDpi);
      EXPECT_EQ(grey, PuzzleBoardTileIsBlack(x, y) ? 0 : 255)
          << "tile " << x << ", " << y;
      ++tiles;
    }
  }
  // Disc centres on every edge between printed corners.
  for (int y = board.origin.y(); y < board.origin.y() + board.rows; ++y) {
    for (int x = board.origin.x(); x < board.origin.x() + board.cols; ++x) {
      double cx, cy;
      PrintedCornerMm(board, x, y, &cx, &cy);
      if (y + 1 < board.origin.y() + board.rows) {
        const int bit = PuzzleBoardVerticalEdgeBit(x, y);
        EXPECT_EQ(GreyAt(image, cx, cy + 0.5 * s, kDpi), bit ? 255 : 0)
            << "vertical edge " << x << ", " << y;
        ++discs;
        white_discs += bit;
      }
      if (x + 1 < board.origin.x() + board.cols) {
        const int bit = PuzzleBoardHorizontalEdgeBit(x, y);
        EXPECT_EQ(GreyAt(image, cx + 0.5 * s, cy, kDpi), bit ? 255 : 0)
            << "horizontal edge " << x << ", " << y;
        ++discs;
        white_discs += bit;
      }
    }
  }
  EXPECT_EQ(tiles, 24 * 17);
  EXPECT_EQ(discs, 23 * 15 + 22 * 16);
  EXPECT_GT(white_discs, discs / 4);
  EXPECT_LT(white_discs, 3 * discs / 4);
  // Disc size (radius s/6 = 5 mm): a white disc seen from its black tile's
  // side is white 4.4 mm from its centre and black 5.6 mm from it.
  for (int x = board.origin.x(); x < board.origin.x() + board.cols; ++x) {
    const int y = board.origin.y();
    if (PuzzleBoardVerticalEdgeBit(x, y) != 1) continue;
    double cx, cy;
    PrintedCornerMm(board, x, y, &cx, &cy);
    // The tile left of the vertical edge is T(x - 1, y).
    const bool left_black = PuzzleBoardTileIsBlack(x - 1, y);
    const double side = left_black ? -1.0 : 1.0;  // towards the black tile
    EXPECT_EQ(GreyAt(image, cx + side * 4.4, cy + 0.5 * s, kDpi), 255);
    EXPECT_EQ(GreyAt(image, cx + side * 5.6, cy + 0.5 * s, kDpi), 0);
    break;
  }
}

TEST(PrintBoardTest, SvgAndPdfHaveTheExactPhysicalSize) {
  const Board board = MediumPuzzleBoard();
  std::string svg, pdf, why;
  ASSERT_TRUE(RenderPrintableBoard(board, PrintFormat::kSvg, PrintOptions(),
                                   &svg, &why))
      << why;
  EXPECT_NE(
      svg.find("width=\"690mm\" height=\"480mm\" viewBox=\"0 0 690 480\""),
      std::string::npos);
  // The first black tile is the top-left half tile T(49, 99): 49 + 99 even.
  EXPECT_NE(svg.find("<rect x=\"0\" y=\"0\" width=\"15\" height=\"15\"/>"),
            std::string::npos);
  EXPECT_NE(svg.find("r=\"5\""), std::string::npos);
  ASSERT_TRUE(RenderPrintableBoard(board, PrintFormat::kPdf, PrintOptions(),
                                   &pdf, &why))
      << why;
  EXPECT_EQ(pdf.rfind("%PDF", 0), 0u);
  // 690 mm = 1955.905... pt, 480 mm = 1360.629... pt.
  EXPECT_NE(pdf.find("/MediaBox [ 0 0 1955.9"), std::string::npos);
}

TEST(PrintBoardTest, CheckerboardPageHasFullBorderTiles) {
  Board board =
      MakeBoard(BoardType::kCheckerboard, 11, 8, Eigen::Vector2i::Zero(), 0.02);
  double w, h;
  PrintedPageSizeMm(board, &w, &h);
  EXPECT_DOUBLE_EQ(w, 240.0);
  EXPECT_DOUBLE_EQ(h, 180.0);
  const cv::Mat image = RenderPng(board, 50.0);
  ASSERT_FALSE(image.empty());
  // Top-left tile T(-1, -1) is black, its right neighbour white.
  EXPECT_EQ(GreyAt(image, 10, 10, 50.0), 0);
  EXPECT_EQ(GreyAt(image, 30, 10, 50.0), 255);
}

TEST(PrintBoardTest, BadInputSaysWhy) {
  Board board = MediumPuzzleBoard();
  board.cols = 1;
  std::string bytes, why;
  EXPECT_FALSE(RenderPrintableBoard(board, PrintFormat::kSvg, PrintOptions(),
                                    &bytes, &why));
  EXPECT_NE(why.find("board"), std::string::npos);
  PrintOptions options;
  options.dpi = 1e6;
  EXPECT_FALSE(RenderPrintableBoard(MediumPuzzleBoard(), PrintFormat::kPng,
                                    options, &bytes, &why));
  EXPECT_NE(why.find("dpi"), std::string::npos);
  PrintFormat format;
  EXPECT_FALSE(PrintFormatFromPath("board.jpg", &format));
  EXPECT_TRUE(PrintFormatFromPath("BOARD.PDF", &format));
  EXPECT_EQ(format, PrintFormat::kPdf);
}

}  // namespace
}  // namespace puzzlecal
