#include "sim/print_board.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "formats/board_file.h"
#include "pipeline/pipeline.h"
#include "target/puzzleboard.h"

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

// The pHYs chunk of a PNG: pixels per metre in x and y (0 when absent).
void ReadPhys(const std::string& png, uint32_t* x, uint32_t* y) {
  *x = *y = 0;
  auto be32 = [&](size_t at) {
    return (static_cast<uint32_t>(static_cast<unsigned char>(png[at])) << 24) |
           (static_cast<uint32_t>(static_cast<unsigned char>(png[at + 1]))
            << 16) |
           (static_cast<uint32_t>(static_cast<unsigned char>(png[at + 2]))
            << 8) |
           static_cast<uint32_t>(static_cast<unsigned char>(png[at + 3]));
  };
  for (size_t at = 8; at + 12 <= png.size();) {
    const uint32_t length = be32(at);
    if (png.compare(at + 4, 4, "pHYs") == 0 && length == 9 &&
        png[at + 16] == 1) {
      *x = be32(at + 8);
      *y = be32(at + 12);
      return;
    }
    at += 12 + length;
  }
}

// An A4 page: the sheet in landscape at the exact size, the pattern centred
// where LayOutPage says (decoded corners land at their page positions), a
// 100 mm scale bar 100 mm long, the dpi stored in pHYs.
TEST(PrintBoardTest, A4PageHoldsThePatternLabelAndScaleBar) {
  const Board board = MakeBoard(BoardType::kPuzzleBoard, 13, 8,
                                Eigen::Vector2i(100, 200), 0.02);
  PrintOptions options;
  options.page = PageSize::kA4;
  options.dpi = 150;
  options.board_name = "puzzleboard_a4.yaml";
  PageLayout layout;
  std::string why;
  ASSERT_TRUE(LayOutPage(board, options, &layout, &why)) << why;
  EXPECT_EQ(layout.width_mm, 297);
  EXPECT_EQ(layout.height_mm, 210);
  EXPECT_NEAR(2 * layout.pattern_x_mm + layout.pattern_w_mm, 297, 1e-9);
  EXPECT_GE(layout.pattern_y_mm, options.margin_mm);
  EXPECT_LE(layout.scale_bar_y_mm + 8, 210 - options.margin_mm);

  std::string bytes;
  ASSERT_TRUE(
      RenderPrintableBoard(board, PrintFormat::kPng, options, &bytes, &why))
      << why;
  uint32_t ppm_x, ppm_y;
  ReadPhys(bytes, &ppm_x, &ppm_y);
  EXPECT_EQ(ppm_x, static_cast<uint32_t>(std::lround(150 / 0.0254)));
  EXPECT_EQ(ppm_y, ppm_x);
  const cv::Mat page = cv::imdecode(
      std::vector<uchar>(bytes.begin(), bytes.end()), cv::IMREAD_GRAYSCALE);
  const double px_per_mm = 150 / 25.4;
  ASSERT_EQ(page.cols, std::lround(297 * px_per_mm));
  ASSERT_EQ(page.rows, std::lround(210 * px_per_mm));

  // The printed corners, found and decoded by the calibration's own
  // pipeline, sit at the page positions of the layout.
  ImageResult found;
  ProcessGreyImage(page, board, PipelineOptions(), &found);
  ASSERT_EQ(found.outcome, ImageOutcome::kUsable) << found.reason;
  EXPECT_GE(found.decode.observation.id.size(), 13u * 8u - 4);
  for (size_t k = 0; k < found.decode.observation.id.size(); ++k) {
    const Eigen::Vector2i id = found.decode.observation.id[k];
    double x_mm, y_mm;
    PrintedCornerMm(board, id.x(), id.y(), &x_mm, &y_mm);
    const Eigen::Vector2d expected(
        (layout.pattern_x_mm + x_mm) * px_per_mm - 0.5,
        (layout.pattern_y_mm + y_mm) * px_per_mm - 0.5);
    EXPECT_LT((found.decode.observation.xy[k] - expected).norm(), 0.3)
        << id.transpose();
  }

  // The scale bar: the longest black run on the bar's middle row.
  const int row =
      static_cast<int>((layout.scale_bar_y_mm + 4.0 - 0.75) * px_per_mm);
  int longest = 0, run = 0;
  for (int x = 0; x < page.cols; ++x) {
    run = page.at<uchar>(row, x) < 128 ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  // 100 mm between the centres of the end ticks; the ticks (well under a
  // millimetre wide) add their width.
  EXPECT_GE(longest, kScaleBarMm * px_per_mm - 1.0);
  EXPECT_LE(longest, (kScaleBarMm + 0.6) * px_per_mm + 1.0);

  // The label (SVG text).
  ASSERT_TRUE(
      RenderPrintableBoard(board, PrintFormat::kSvg, options, &bytes, &why));
  for (const char* part :
       {"puzzleboard_a4.yaml", "puzzleboard", "13 x 8 corners", "tile 20 mm",
        "origin [100, 200]", "print at 100 %", "100 mm", "width=\"297mm\"",
        "height=\"210mm\""}) {
    EXPECT_NE(bytes.find(part), std::string::npos) << part;
  }
}

TEST(PrintBoardTest, BoardsThatDoNotFitAreRefusedWithTheirSize) {
  PrintOptions options;
  options.page = PageSize::kA4;
  PageLayout layout;
  std::string why;
  EXPECT_FALSE(LayOutPage(MediumPuzzleBoard(), options, &layout, &why));
  EXPECT_NE(why.find("690 x 480 mm"), std::string::npos) << why;
  std::string bytes;
  EXPECT_FALSE(RenderPrintableBoard(MediumPuzzleBoard(), PrintFormat::kPdf,
                                    options, &bytes, &why));
  // fit: the pattern plus the margins and the label band.
  options.page = PageSize::kFit;
  ASSERT_TRUE(LayOutPage(MediumPuzzleBoard(), options, &layout, &why)) << why;
  EXPECT_NEAR(layout.width_mm, 690 + 2 * options.margin_mm, 1e-9);
  EXPECT_GT(layout.height_mm, 480 + 2 * options.margin_mm);
  EXPECT_NEAR(layout.pattern_x_mm, options.margin_mm, 1e-9);
}

// The presets in configs/boards/: each `a4` / `letter` board fits its sheet.
TEST(PrintBoardTest, SheetPresetsFitTheirSheets) {
  int presets = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator("configs/boards")) {
    const std::string name = entry.path().filename().string();
    PrintOptions options;
    if (name.find("a4") != std::string::npos) {
      options.page = PageSize::kA4;
    } else if (name.find("letter") != std::string::npos) {
      options.page = PageSize::kLetter;
    } else {
      continue;
    }
    Board board;
    std::string why;
    ASSERT_TRUE(LoadBoardFile(entry.path().string(), &board, &why)) << why;
    PageLayout layout;
    EXPECT_TRUE(LayOutPage(board, options, &layout, &why))
        << name << ": " << why;
    EXPECT_EQ(board.type, BoardType::kPuzzleBoard) << name;
    ++presets;
  }
  EXPECT_GE(presets, 2);
}

}  // namespace
}  // namespace puzzlecal
