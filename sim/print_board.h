#ifndef PUZZLECAL_SIM_PRINT_BOARD_H_
#define PUZZLECAL_SIM_PRINT_BOARD_H_

// Printable boards, laid out as docs/puzzleboard.md's 'Printed boards' section
// says: the page is W x H tiles (W x H = cols x rows corners), corner (x0 + i,
// y0 + j) sits at ((i + 1/2) s, (j + 1/2) s) from the top-left page corner, the
// border tiles are half tiles, and every edge between two printed corners
// carries a disc of diameter s/3 (white for bit 1). A plain checkerboard page
// holds (cols + 1) x (rows + 1) full tiles. The pattern is printed alone or
// centred on a sheet (A4, A3, Letter, or just large enough) with a label
// line and a 100 mm scale bar.

#include <string>

#include "target/board.h"

namespace puzzlecal {

enum class PrintFormat { kSvg, kPdf, kPng };

// The sheet the pattern is printed on.
enum class PageSize {
  kPatternOnly,  // the pattern alone, edge to edge (no margin, no label)
  kFit,          // the pattern plus a printable margin and the label
  kA4,           // 210 x 297 mm
  kA3,           // 297 x 420 mm
  kLetter,       // 8.5 x 11 in (215.9 x 279.4 mm)
};

// "pattern", "fit", "a4", "a3", "letter".
const char* PageSizeName(PageSize page);
bool PageSizeFromName(const std::string& name, PageSize* page);

// From the file name's extension (.svg, .pdf, .png; case-insensitive).
bool PrintFormatFromPath(const std::string& path, PrintFormat* format);

struct PrintOptions {
  // Resolution of PNG output in dots per inch; in [10, 2400]. The page is
  // rounded to whole pixels, the pattern itself scaled exactly.
  double dpi = 300.0;
  // Largest PNG side in pixels (memory guard); >= 16.
  int max_png_side_px = 30000;
  // The sheet. Default kPatternOnly (the pattern alone).
  PageSize page = PageSize::kPatternOnly;
  // White space kept clear at every sheet edge (what printers cannot print),
  // millimetres; in [0, 50]. Default 10. Not used by kPatternOnly.
  double margin_mm = 10.0;
  // Name of the board file, shown on the label line (may be empty).
  std::string board_name;

  bool Check(std::string* why = nullptr) const;
};

// Size of the printed pattern in millimetres (the page of kPatternOnly).
void PrintedPageSizeMm(const Board& board, double* width_mm, double* height_mm);

// Pattern coordinates (mm from the pattern's top-left corner) of corner
// (col, row).
void PrintedCornerMm(const Board& board, int col, int row, double* x_mm,
                     double* y_mm);

// Where everything sits on the sheet, millimetres from its top-left corner.
// The pattern is centred in the sheet above the label band; the band holds
// the label line and a 100 mm scale bar.
struct PageLayout {
  double width_mm = 0, height_mm = 0;  // the sheet (landscape if it fits so)
  double pattern_x_mm = 0, pattern_y_mm = 0;  // the pattern's top-left
  double pattern_w_mm = 0, pattern_h_mm = 0;
  bool has_label = false;                         // false for kPatternOnly
  double label_y_mm = 0;                          // baseline of the label line
  double scale_bar_x_mm = 0, scale_bar_y_mm = 0;  // left end, top of the bar
  std::string label;  // "NAME: puzzleboard, 23 x 16 corners, tile 30 mm, ..."
};

// Length of the scale bar, millimetres.
inline constexpr double kScaleBarMm = 100.0;

// Lays the board out on options.page; false with the sizes when it does not
// fit ("the pattern is 270 x 180 mm; an A4 sheet holds 190 x 262 mm inside
// its margins and label").
bool LayOutPage(const Board& board, const PrintOptions& options,
                PageLayout* layout, std::string* why = nullptr);

// The file contents of the printable board on options.page. SVG is written
// directly in millimetres (width="...mm", viewBox in mm, so the tile size is
// exact in the file); PDF (points, 1 mm = 72/25.4 pt) and PNG (at
// options.dpi, stored in its pHYs chunk) are drawn with cairo. False with a
// reason on bad input, a board that does not fit the page, or a cairo
// failure.
bool RenderPrintableBoard(const Board& board, PrintFormat format,
                          const PrintOptions& options, std::string* bytes,
                          std::string* why = nullptr);

}  // namespace puzzlecal

#endif  // PUZZLECAL_SIM_PRINT_BOARD_H_
