#include "sim/print_board.h"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "decode/puzzleboard.h"

namespace puzzlecal {
namespace {

// A filled shape on the page, in millimetres.
struct Rect {
  double x, y, w, h;
};
struct Disc {
  double cx, cy, r;
  bool white;
};

// Offset (in tiles) of corner (x0, y0) from the page's top-left corner.
double CornerInsetTiles(const Board& board) {
  return board.type == BoardType::kPuzzleBoard ? 0.5 : 1.0;
}

// Black tiles clipped to the page, and the discs.
void Layout(const Board& board, std::vector<Rect>* black_tiles,
            std::vector<Disc>* discs) {
  const double s = board.tile_size_m * 1000.0;
  double page_w, page_h;
  PrintedPageSizeMm(board, &page_w, &page_h);
  const double inset = CornerInsetTiles(board);
  const int x0 = board.origin.x(), y0 = board.origin.y();
  // Tile T(x, y) has corners (x, y), (x + 1, y + 1); tiles from x0 - 1 to
  // x0 + cols - 1 touch the page.
  for (int y = y0 - 1; y < y0 + board.rows; ++y) {
    for (int x = x0 - 1; x < x0 + board.cols; ++x) {
      if (!PuzzleBoardTileIsBlack(x, y)) continue;
      const double left = std::max(0.0, (x - x0 + inset) * s);
      const double top = std::max(0.0, (y - y0 + inset) * s);
      const double right = std::min(page_w, (x - x0 + 1 + inset) * s);
      const double bottom = std::min(page_h, (y - y0 + 1 + inset) * s);
      if (right > left && bottom > top) {
        black_tiles->push_back({left, top, right - left, bottom - top});
      }
    }
  }
  if (board.type != BoardType::kPuzzleBoard) return;
  const double r = s / 6.0;
  for (int y = y0; y < y0 + board.rows; ++y) {
    for (int x = x0; x < x0 + board.cols; ++x) {
      const double cx = (x - x0 + inset) * s, cy = (y - y0 + inset) * s;
      if (y + 1 < y0 + board.rows) {  // vertical edge (x, y) -> (x, y + 1)
        discs->push_back(
            {cx, cy + 0.5 * s, r, PuzzleBoardVerticalEdgeBit(x, y) == 1});
      }
      if (x + 1 < x0 + board.cols) {  // horizontal edge (x, y) -> (x + 1, y)
        discs->push_back(
            {cx + 0.5 * s, cy, r, PuzzleBoardHorizontalEdgeBit(x, y) == 1});
      }
    }
  }
}

std::string Number(double value) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.10g", value);
  return text;
}

std::string Svg(const Board& board) {
  double page_w, page_h;
  PrintedPageSizeMm(board, &page_w, &page_h);
  std::vector<Rect> tiles;
  std::vector<Disc> discs;
  Layout(board, &tiles, &discs);
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<!-- " << BoardTypeName(board.type) << " " << board.cols << " x "
      << board.rows << " corners from (" << board.origin.x() << ", "
      << board.origin.y() << "), tile " << Number(board.tile_size_m * 1000)
      << " mm; user units are millimetres. Print at 100 %. -->\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << Number(page_w)
      << "mm\" height=\"" << Number(page_h) << "mm\" viewBox=\"0 0 "
      << Number(page_w) << " " << Number(page_h) << "\">\n"
      << "<rect x=\"0\" y=\"0\" width=\"" << Number(page_w) << "\" height=\""
      << Number(page_h) << "\" fill=\"#ffffff\"/>\n<g fill=\"#000000\">\n";
  for (const Rect& t : tiles) {
    out << "<rect x=\"" << Number(t.x) << "\" y=\"" << Number(t.y)
        << "\" width=\"" << Number(t.w) << "\" height=\"" << Number(t.h)
        << "\"/>\n";
  }
  out << "</g>\n";
  for (const Disc& d : discs) {
    out << "<circle cx=\"" << Number(d.cx) << "\" cy=\"" << Number(d.cy)
        << "\" r=\"" << Number(d.r) << "\" fill=\""
        << (d.white ? "#ffffff" : "#000000") << "\"/>\n";
  }
  out << "</svg>\n";
  return out.str();
}

cairo_status_t AppendBytes(void* closure, const unsigned char* data,
                           unsigned int length) {
  static_cast<std::string*>(closure)->append(
      reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

// Draws the page with user units of millimetres scaled by `scale`.
void Draw(cairo_t* cr, const Board& board, double scale) {
  double page_w, page_h;
  PrintedPageSizeMm(board, &page_w, &page_h);
  std::vector<Rect> tiles;
  std::vector<Disc> discs;
  Layout(board, &tiles, &discs);
  cairo_scale(cr, scale, scale);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_rectangle(cr, 0, 0, page_w, page_h);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  for (const Rect& t : tiles) cairo_rectangle(cr, t.x, t.y, t.w, t.h);
  cairo_fill(cr);
  for (int white = 0; white < 2; ++white) {
    cairo_set_source_rgb(cr, white, white, white);
    for (const Disc& d : discs) {
      if (d.white != (white == 1)) continue;
      cairo_new_sub_path(cr);
      cairo_arc(cr, d.cx, d.cy, d.r, 0, 2 * M_PI);
      cairo_close_path(cr);
    }
    cairo_fill(cr);
  }
}

}  // namespace

bool PrintFormatFromPath(const std::string& path, PrintFormat* format) {
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos) return false;
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(c));
  if (ext == "svg") {
    *format = PrintFormat::kSvg;
  } else if (ext == "pdf") {
    *format = PrintFormat::kPdf;
  } else if (ext == "png") {
    *format = PrintFormat::kPng;
  } else {
    return false;
  }
  return true;
}

bool PrintOptions::Check(std::string* why) const {
  if (!(std::isfinite(dpi) && dpi >= 10 && dpi <= 2400)) {
    if (why != nullptr) *why = "dpi must be in [10, 2400]";
    return false;
  }
  if (max_png_side_px < 16) {
    if (why != nullptr) *why = "max_png_side_px must be >= 16";
    return false;
  }
  return true;
}

void PrintedPageSizeMm(const Board& board, double* width_mm,
                       double* height_mm) {
  const double s = board.tile_size_m * 1000.0;
  const int extra = board.type == BoardType::kPuzzleBoard ? 0 : 1;
  *width_mm = (board.cols + extra) * s;
  *height_mm = (board.rows + extra) * s;
}

void PrintedCornerMm(const Board& board, int col, int row, double* x_mm,
                     double* y_mm) {
  const double s = board.tile_size_m * 1000.0;
  const double inset = CornerInsetTiles(board);
  *x_mm = (col - board.origin.x() + inset) * s;
  *y_mm = (row - board.origin.y() + inset) * s;
}

bool RenderPrintableBoard(const Board& board, PrintFormat format,
                          const PrintOptions& options, std::string* bytes,
                          std::string* why) {
  auto fail = [why](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  std::string reason;
  if (!board.Check(&reason)) return fail("board: " + reason);
  if (!options.Check(&reason)) return fail("print options: " + reason);
  bytes->clear();
  if (format == PrintFormat::kSvg) {
    *bytes = Svg(board);
    return true;
  }
  double page_w, page_h;
  PrintedPageSizeMm(board, &page_w, &page_h);
  cairo_surface_t* surface = nullptr;
  double scale = 1.0;
  if (format == PrintFormat::kPdf) {
    scale = 72.0 / 25.4;  // points per millimetre
    surface = cairo_pdf_surface_create_for_stream(
        &AppendBytes, bytes, page_w * scale, page_h * scale);
  } else {
    scale = options.dpi / 25.4;  // pixels per millimetre
    const double w = std::round(page_w * scale), h = std::round(page_h * scale);
    if (w > options.max_png_side_px || h > options.max_png_side_px) {
      return fail("the PNG would be " + Number(w) + " x " + Number(h) +
                  " pixels; lower the dpi");
    }
    surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24,
                                         static_cast<int>(std::max(w, 1.0)),
                                         static_cast<int>(std::max(h, 1.0)));
  }
  if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS) {
    const std::string message =
        cairo_status_to_string(cairo_surface_status(surface));
    cairo_surface_destroy(surface);
    return fail("cairo: " + message);
  }
  cairo_t* cr = cairo_create(surface);
  Draw(cr, board, scale);
  cairo_status_t status = cairo_status(cr);
  cairo_destroy(cr);
  if (status == CAIRO_STATUS_SUCCESS) {
    if (format == PrintFormat::kPng) {
      cairo_surface_flush(surface);
      status = cairo_surface_write_to_png_stream(surface, &AppendBytes, bytes);
    } else {
      cairo_surface_finish(surface);  // writes the PDF
      status = cairo_surface_status(surface);
    }
  }
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS) {
    bytes->clear();
    return fail(std::string("cairo: ") + cairo_status_to_string(status));
  }
  return true;
}

}  // namespace puzzlecal
