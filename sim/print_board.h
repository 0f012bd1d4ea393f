#ifndef PUZZLECAL_SIM_PRINT_BOARD_H_
#define PUZZLECAL_SIM_PRINT_BOARD_H_

// Printable boards, laid out as docs/puzzleboard.md's 'Printed boards' section says: the
// page is W x H tiles (W x H = cols x rows corners), corner (x0 + i, y0 + j)
// sits at ((i + 1/2) s, (j + 1/2) s) from the top-left page corner, the
// border tiles are half tiles, and every edge between two printed corners
// carries a disc of diameter s/3 (white for bit 1). A plain checkerboard page
// holds (cols + 1) x (rows + 1) full tiles.

#include <string>

#include "decode/board.h"

namespace puzzlecal {

enum class PrintFormat { kSvg, kPdf, kPng };

// From the file name's extension (.svg, .pdf, .png; case-insensitive).
bool PrintFormatFromPath(const std::string& path, PrintFormat* format);

struct PrintOptions {
  // Resolution of PNG output in dots per inch; in [10, 2400]. The page is
  // rounded to whole pixels, the pattern itself scaled exactly.
  double dpi = 300.0;
  // Largest PNG side in pixels (memory guard); >= 16.
  int max_png_side_px = 30000;

  bool Check(std::string* why = nullptr) const;
};

// Page size of the printed board in millimetres.
void PrintedPageSizeMm(const Board& board, double* width_mm, double* height_mm);

// Page coordinates (mm from the top-left page corner) of corner `id`.
void PrintedCornerMm(const Board& board, int col, int row, double* x_mm,
                     double* y_mm);

// The file contents of the printable board. SVG is written directly in
// millimetres (width="...mm", viewBox in mm, so the tile size is exact in the
// file); PDF (points, 1 mm = 72/25.4 pt) and PNG (at options.dpi) are drawn
// with cairo. False with a reason on bad input or a cairo failure.
bool RenderPrintableBoard(const Board& board, PrintFormat format,
                          const PrintOptions& options, std::string* bytes,
                          std::string* why = nullptr);

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_PRINT_BOARD_H_
