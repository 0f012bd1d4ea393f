#include "sim/print_board.h"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <vector>

#include "target/puzzleboard.h"
#include "util/enum_names.h"
#include "util/failure.h"

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
  return board.Traits().border_tiles;
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
  if (!board.Traits().absolute_ids) return;  // no edge bits to print
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

std::string XmlEscaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '&') {
      out += "&amp;";
    } else if (c == '<') {
      out += "&lt;";
    } else if (c == '>') {
      out += "&gt;";
    } else {
      out += c;
    }
  }
  return out;
}

// Label band below the pattern (millimetres): gap, label line, gap, scale
// bar with its text.
constexpr double kBandGapMm = 5.0;
constexpr double kLabelFontMm = 3.5;
constexpr double kBarGapMm = 3.0;
constexpr double kBarHeightMm = 1.5;
constexpr double kTickHeightMm = 4.0;
constexpr double kTickWidthMm = 0.3;
constexpr double kBandHeightMm =
    kBandGapMm + kLabelFontMm + kBarGapMm + kTickHeightMm + kLabelFontMm;
// The label band needs this width (the bar and its text).
constexpr double kBandWidthMm = kScaleBarMm + 25.0;

// The scale bar's black shapes: the bar and ticks every 10 mm (tall at 0,
// 50 and 100 mm).
std::vector<Rect> ScaleBar(const PageLayout& layout) {
  std::vector<Rect> shapes;
  const double x = layout.scale_bar_x_mm, y = layout.scale_bar_y_mm;
  shapes.push_back(
      {x, y + kTickHeightMm - kBarHeightMm, kScaleBarMm, kBarHeightMm});
  for (int k = 0; k <= 10; ++k) {
    const double h = k % 5 == 0 ? kTickHeightMm : 0.5 * kTickHeightMm;
    shapes.push_back({x + k * 10.0 - 0.5 * kTickWidthMm, y + kTickHeightMm - h,
                      kTickWidthMm, h});
  }
  return shapes;
}

std::string Svg(const Board& board, const PageLayout& layout) {
  std::vector<Rect> tiles;
  std::vector<Disc> discs;
  Layout(board, &tiles, &discs);
  const double ox = layout.pattern_x_mm, oy = layout.pattern_y_mm;
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<!-- " << BoardTypeName(board.type) << " " << board.cols << " x "
      << board.rows << " corners from (" << board.origin.x() << ", "
      << board.origin.y() << "), tile " << Number(board.tile_size_m * 1000)
      << " mm; user units are millimetres. Print at 100 %. -->\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\""
      << Number(layout.width_mm) << "mm\" height=\"" << Number(layout.height_mm)
      << "mm\" viewBox=\"0 0 " << Number(layout.width_mm) << " "
      << Number(layout.height_mm) << "\">\n"
      << "<rect x=\"0\" y=\"0\" width=\"" << Number(layout.width_mm)
      << "\" height=\"" << Number(layout.height_mm)
      << "\" fill=\"#ffffff\"/>\n<g fill=\"#000000\">\n";
  for (const Rect& t : tiles) {
    out << "<rect x=\"" << Number(ox + t.x) << "\" y=\"" << Number(oy + t.y)
        << "\" width=\"" << Number(t.w) << "\" height=\"" << Number(t.h)
        << "\"/>\n";
  }
  out << "</g>\n";
  for (const Disc& d : discs) {
    out << "<circle cx=\"" << Number(ox + d.cx) << "\" cy=\""
        << Number(oy + d.cy) << "\" r=\"" << Number(d.r) << "\" fill=\""
        << (d.white ? "#ffffff" : "#000000") << "\"/>\n";
  }
  if (layout.has_label) {
    out << "<g fill=\"#000000\">\n";
    for (const Rect& r : ScaleBar(layout)) {
      out << "<rect x=\"" << Number(r.x) << "\" y=\"" << Number(r.y)
          << "\" width=\"" << Number(r.w) << "\" height=\"" << Number(r.h)
          << "\"/>\n";
    }
    out << "</g>\n<g font-family=\"sans-serif\" font-size=\""
        << Number(kLabelFontMm) << "\" fill=\"#000000\">\n"
        << "<text x=\"" << Number(layout.pattern_x_mm) << "\" y=\""
        << Number(layout.label_y_mm) << "\">" << XmlEscaped(layout.label)
        << "</text>\n"
        << "<text x=\"" << Number(layout.scale_bar_x_mm + kScaleBarMm + 2)
        << "\" y=\"" << Number(layout.scale_bar_y_mm + kTickHeightMm)
        << "\">100 mm</text>\n</g>\n";
  }
  out << "</svg>\n";
  return out.str();
}

// The PNG with a pHYs chunk (pixels per metre, from `dpi`) after IHDR, so
// viewers and print dialogs know its physical size.
uint32_t Crc32(const std::string& bytes) {
  uint32_t crc = 0xffffffffu;
  for (unsigned char c : bytes) {
    crc ^= c;
    for (int k = 0; k < 8; ++k)
      crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xffffffffu;
}

void AppendBigEndian(uint32_t value, std::string* out) {
  for (int shift = 24; shift >= 0; shift -= 8) {
    out->push_back(static_cast<char>((value >> shift) & 0xff));
  }
}

bool InsertPhys(double dpi, std::string* png) {
  // Signature (8) + IHDR (4 length + 4 type + 13 data + 4 CRC).
  constexpr size_t kAfterIhdr = 8 + 25;
  if (png->size() < kAfterIhdr || png->compare(12, 4, "IHDR") != 0) {
    return false;
  }
  const uint32_t per_metre = static_cast<uint32_t>(std::lround(dpi / 0.0254));
  std::string body = "pHYs";
  AppendBigEndian(per_metre, &body);
  AppendBigEndian(per_metre, &body);
  body.push_back(1);  // unit: metre
  std::string chunk;
  AppendBigEndian(9, &chunk);
  chunk += body;
  AppendBigEndian(Crc32(body), &chunk);
  png->insert(kAfterIhdr, chunk);
  return true;
}

cairo_status_t AppendBytes(void* closure, const unsigned char* data,
                           unsigned int length) {
  static_cast<std::string*>(closure)->append(
      reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

// Draws the page with user units of millimetres scaled by `scale`.
void Draw(cairo_t* cr, const Board& board, const PageLayout& layout,
          double scale) {
  std::vector<Rect> tiles;
  std::vector<Disc> discs;
  Layout(board, &tiles, &discs);
  cairo_scale(cr, scale, scale);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_rectangle(cr, 0, 0, layout.width_mm, layout.height_mm);
  cairo_fill(cr);
  cairo_save(cr);
  cairo_translate(cr, layout.pattern_x_mm, layout.pattern_y_mm);
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
  cairo_restore(cr);
  if (!layout.has_label) return;
  cairo_set_source_rgb(cr, 0, 0, 0);
  for (const Rect& r : ScaleBar(layout))
    cairo_rectangle(cr, r.x, r.y, r.w, r.h);
  cairo_fill(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, kLabelFontMm);
  cairo_move_to(cr, layout.pattern_x_mm, layout.label_y_mm);
  cairo_show_text(cr, layout.label.c_str());
  cairo_move_to(cr, layout.scale_bar_x_mm + kScaleBarMm + 2,
                layout.scale_bar_y_mm + kTickHeightMm);
  cairo_show_text(cr, "100 mm");
}

// Sheet sizes in millimetres, portrait.
void SheetMm(PageSize page, double* w, double* h) {
  switch (page) {
    case PageSize::kA4:
      *w = 210;
      *h = 297;
      return;
    case PageSize::kA3:
      *w = 297;
      *h = 420;
      return;
    case PageSize::kLetter:
      *w = 215.9;
      *h = 279.4;
      return;
    case PageSize::kPatternOnly:
    case PageSize::kFit:
      break;
  }
  *w = *h = 0;
}

std::string Label(const Board& board, const PrintOptions& options) {
  std::ostringstream out;
  if (!options.board_name.empty()) out << options.board_name << ": ";
  out << BoardTypeName(board.type) << ", " << board.cols << " x " << board.rows
      << " corners (cols x rows), tile " << Number(board.tile_size_m * 1000)
      << " mm";
  if (board.Traits().has_origin) {
    out << ", origin [" << board.origin.x() << ", " << board.origin.y() << "]";
  }
  out << "; print at 100 %";
  return out.str();
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

constexpr EnumName<PageSize> kPageSizeNames[] = {
    {PageSize::kPatternOnly, "pattern"},
    {PageSize::kFit, "fit"},
    {PageSize::kA4, "a4"},
    {PageSize::kA3, "a3"},
    {PageSize::kLetter, "letter"},
};

const char* PageSizeName(PageSize page) {
  return NameOf(kPageSizeNames, page, "pattern");
}

bool PageSizeFromName(const std::string& name, PageSize* page) {
  return ValueOf(kPageSizeNames, name, page);
}

bool LayOutPage(const Board& board, const PrintOptions& options,
                PageLayout* layout, std::string* why) {
  *layout = PageLayout();
  PrintedPageSizeMm(board, &layout->pattern_w_mm, &layout->pattern_h_mm);
  const double pw = layout->pattern_w_mm, ph = layout->pattern_h_mm;
  if (options.page == PageSize::kPatternOnly) {
    layout->width_mm = pw;
    layout->height_mm = ph;
    return true;
  }
  const double m = options.margin_mm;
  // Room the pattern and the label band need.
  const double need_w = std::max(pw, kBandWidthMm);
  const double need_h = ph + kBandHeightMm;
  if (options.page == PageSize::kFit) {
    layout->width_mm = need_w + 2 * m;
    layout->height_mm = need_h + 2 * m;
  } else {
    double w, h;
    SheetMm(options.page, &w, &h);
    const bool portrait_fits = need_w <= w - 2 * m && need_h <= h - 2 * m;
    const bool landscape_fits = need_w <= h - 2 * m && need_h <= w - 2 * m;
    if (!portrait_fits && !landscape_fits) {
      if (why != nullptr) {
        std::string sheet = PageSizeName(options.page);
        for (char& c : sheet) c = static_cast<char>(std::toupper(c));
        if (options.page == PageSize::kLetter) sheet = "Letter";
        *why = "the board is " + Number(pw) + " x " + Number(ph) + " mm; " +
               (sheet[0] == 'A' ? "an " : "a ") + sheet + " sheet (" +
               Number(w) + " x " + Number(h) + " mm) holds " +
               Number(w - 2 * m) + " x " + Number(h - 2 * m - kBandHeightMm) +
               " mm inside its margins and label, or " + Number(h - 2 * m) +
               " x " + Number(w - 2 * m - kBandHeightMm) +
               " mm in landscape: choose a larger page, --page fit, or a "
               "board with fewer or smaller tiles";
      }
      return false;
    }
    // Landscape when only it fits, or when both do and the pattern is wide.
    const bool landscape = !portrait_fits || (landscape_fits && pw > ph);
    layout->width_mm = landscape ? h : w;
    layout->height_mm = landscape ? w : h;
  }
  layout->pattern_x_mm = 0.5 * (layout->width_mm - pw);
  layout->pattern_y_mm = 0.5 * (layout->height_mm - need_h);
  layout->has_label = true;
  layout->label_y_mm = layout->pattern_y_mm + ph + kBandGapMm + kLabelFontMm;
  layout->scale_bar_x_mm = layout->pattern_x_mm;
  layout->scale_bar_y_mm = layout->label_y_mm + kBarGapMm;
  layout->label = Label(board, options);
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
  if (!(margin_mm >= 0 && margin_mm <= 50)) {
    if (why != nullptr) *why = "margin_mm must be in [0, 50]";
    return false;
  }
  return true;
}

void PrintedPageSizeMm(const Board& board, double* width_mm,
                       double* height_mm) {
  const double s = board.tile_size_m * 1000.0;
  // The outer inner corners are cols - 1 tiles apart, plus a border each side.
  const double borders = 2 * board.Traits().border_tiles;
  *width_mm = (board.cols - 1 + borders) * s;
  *height_mm = (board.rows - 1 + borders) * s;
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
  std::string reason;
  if (!board.Check(&reason)) return Fail("board: " + reason, why);
  if (!options.Check(&reason)) return Fail("print options: " + reason, why);
  PageLayout layout;
  if (!LayOutPage(board, options, &layout, &reason)) return Fail(reason, why);
  bytes->clear();
  if (format == PrintFormat::kSvg) {
    *bytes = Svg(board, layout);
    return true;
  }
  const double page_w = layout.width_mm, page_h = layout.height_mm;
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
      return Fail("the PNG would be " + Number(w) + " x " + Number(h) +
                      " pixels; lower the dpi",
                  why);
    }
    surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24,
                                         static_cast<int>(std::max(w, 1.0)),
                                         static_cast<int>(std::max(h, 1.0)));
  }
  if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS) {
    const std::string message =
        cairo_status_to_string(cairo_surface_status(surface));
    cairo_surface_destroy(surface);
    return Fail("cairo: " + message, why);
  }
  cairo_t* cr = cairo_create(surface);
  Draw(cr, board, layout, scale);
  cairo_status_t status = cairo_status(cr);
  cairo_destroy(cr);
  if (status == CAIRO_STATUS_SUCCESS) {
    if (format == PrintFormat::kPng) {
      cairo_surface_flush(surface);
      status = cairo_surface_write_to_png_stream(surface, &AppendBytes, bytes);
      if (status == CAIRO_STATUS_SUCCESS && !InsertPhys(options.dpi, bytes)) {
        status = CAIRO_STATUS_WRITE_ERROR;
      }
    } else {
      cairo_surface_finish(surface);  // writes the PDF
      status = cairo_surface_status(surface);
    }
  }
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS) {
    bytes->clear();
    return Fail(std::string("cairo: ") + cairo_status_to_string(status), why);
  }
  return true;
}

}  // namespace puzzlecal
