#include "report/plot.h"

#include <plplot.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <opencv2/imgproc.hpp>

namespace puzzlecal {
namespace plot {
namespace {

// The cairo driver draws at 72 dpi: PLplot's millimetres to canvas pixels.
constexpr double kPixelsPerMm = 72.0 / 25.4;

// Serialises the charts: PLplot's current stream is process-wide.
std::mutex& ChartMutex() {
  static std::mutex mutex;
  return mutex;
}

// PLplot reports recoverable errors through this handler instead of
// printing them; the chart drawing them comes out empty.
std::string& AbortMessage() {
  static std::string message;
  return message;
}
void RecordAbort(PLCHAR_VECTOR message) {
  AbortMessage() = message != nullptr ? message : "PLplot error";
}

struct Rgb {
  int r, g, b;
  double alpha = 1.0;
};

// Colour map 0, in the order of enum Colour.
const Rgb kPalette[] = {
    {255, 255, 255},       // white
    {0, 0, 0},             // black
    {128, 128, 128},       // grey
    {225, 225, 225},       // light grey
    {70, 70, 70},          // dark grey
    {30, 110, 180},        // blue
    {215, 40, 40},         // red
    {240, 140, 20},        // orange
    {246, 246, 246},       // paper
    {170, 170, 170},       // no data
    {255, 255, 255, 0.6},  // fade
};
constexpr int kNumColours = sizeof(kPalette) / sizeof(kPalette[0]);

PLINT Index(Colour colour) { return static_cast<PLINT>(colour); }

void SetTextHeight(double pixels) { plschr(pixels / kPixelsPerMm, 1.0); }

// Viridis as PLplot colour map 1, the same colours as OpenCV's
// COLORMAP_VIRIDIS (so the maps match the overlays' conventions).
void SetViridis() {
  cv::Mat ramp(256, 1, CV_8UC1);
  for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(i) = static_cast<uint8_t>(i);
  cv::Mat colour;
  cv::applyColorMap(ramp, colour, cv::COLORMAP_VIRIDIS);
  PLINT r[256], g[256], b[256];
  for (int i = 0; i < 256; ++i) {
    const cv::Vec3b c = colour.at<cv::Vec3b>(i);
    r[i] = c[2];
    g[i] = c[1];
    b[i] = c[0];
  }
  plscmap1(r, g, b, 256);
}

// A sampled field as PLplot wants it: column-major row pointers, and the
// sample coordinates for pltr1.
struct Field {
  std::vector<PLFLT> storage;
  std::vector<PLFLT*> columns;
  std::vector<PLFLT> xs, ys;
  PLcGrid grid{};

  Field(const cv::Mat& values, const std::vector<double>& x,
        const std::vector<double>& y, double lo, double hi)
      : xs(x), ys(y) {
    const int nx = values.cols, ny = values.rows;
    storage.resize(static_cast<size_t>(nx) * ny);
    columns.resize(nx);
    for (int i = 0; i < nx; ++i) {
      columns[i] = storage.data() + static_cast<size_t>(i) * ny;
      for (int j = 0; j < ny; ++j) {
        const double v = values.at<double>(j, i);
        columns[i][j] = std::isfinite(v) ? std::clamp(v, lo, hi) : v;
      }
    }
    grid.xg = xs.data();
    grid.yg = ys.data();
    grid.nx = nx;
    grid.ny = ny;
  }
  bool Valid() const {
    return !columns.empty() && static_cast<int>(xs.size()) == grid.nx &&
           static_cast<int>(ys.size()) == grid.ny && grid.ny > 0;
  }
  PLFLT_MATRIX Matrix() const {
    return const_cast<PLFLT_MATRIX>(columns.data());
  }
};

}  // namespace

double NiceNumber(double value, bool down) {
  if (!(value > 0) || !std::isfinite(value)) return 1.0;
  const double power = std::pow(10.0, std::floor(std::log10(value)));
  const double fraction = value / power;  // in [1, 10)
  double nice;
  if (down) {
    nice = fraction >= 5 ? 5 : fraction >= 2 ? 2 : 1;
  } else {
    nice = fraction < 1.5 ? 1 : fraction < 3.5 ? 2 : fraction < 7.5 ? 5 : 10;
  }
  return nice * power;
}

bool ChartsAvailable(std::string* why) {
  std::lock_guard<std::mutex> lock(ChartMutex());
  // plgDevs lists the devices whose drivers are installed; a device missing
  // at plinit would make PLplot prompt on the terminal for another.
  static const bool available = [] {
    // The caller's arrays; count is their size in, the number listed out.
    std::vector<const char*> menus(256), names(256);
    const char** menu_list = menus.data();
    const char** name_list = names.data();
    int count = static_cast<int>(names.size());
    plgDevs(&menu_list, &name_list, &count);
    for (int k = 0; k < count && k < static_cast<int>(names.size()); ++k) {
      if (names[k] != nullptr && std::strcmp(names[k], "memcairo") == 0) {
        return true;
      }
    }
    return false;
  }();
  if (!available && why != nullptr) {
    *why =
        "PLplot has no memcairo device (install the package "
        "plplot-driver-cairo)";
  }
  return available;
}

struct Chart::State {
  std::unique_lock<std::mutex> lock;
  std::vector<unsigned char> canvas;  // RGBA, drawn on by PLplot
  int width = 0, height = 0;
  bool ok = false;
  bool finished = false;
  cv::Rect area;
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  bool y_down = false;

  // Makes the whole canvas the viewport, in pixel coordinates (y down).
  void PageWindow() const {
    plvpor(0, 1, 0, 1);
    plwind(0, width, height, 0);
  }
  void AreaWindow() const {
    plvpor(static_cast<double>(area.x) / width,
           static_cast<double>(area.x + area.width) / width,
           1.0 - static_cast<double>(area.y + area.height) / height,
           1.0 - static_cast<double>(area.y) / height);
    if (y_down) {
      plwind(x_min, x_max, y_max, y_min);
    } else {
      plwind(x_min, x_max, y_min, y_max);
    }
  }
  bool Drawing() const { return ok && !finished; }
};

Chart::Chart(int width, int height, bool antialias)
    : state_(std::make_unique<State>()) {
  const bool available = ChartsAvailable(nullptr);
  State& s = *state_;
  s.lock = std::unique_lock<std::mutex>(ChartMutex());
  s.width = width;
  s.height = height;
  s.area = cv::Rect(0, 0, width, height);
  if (!available || width < 1 || height < 1) return;
  s.canvas.assign(static_cast<size_t>(width) * height * 4, 255);
  plsabort(RecordAbort);
  AbortMessage().clear();
  PLINT stream = 0;
  plmkstrm(&stream);
  plsdev("memcairo");
  // cairo_antialias_t: 1 none, 0 cairo's default.
  plsetopt("drvopt",
           antialias ? "graphics_anti_aliasing=0" : "graphics_anti_aliasing=1");
  plsmema(width, height, s.canvas.data());
  plscmap0n(kNumColours);
  for (int k = 0; k < kNumColours; ++k) {
    plscol0a(k, kPalette[k].r, kPalette[k].g, kPalette[k].b, kPalette[k].alpha);
  }
  plinit();
  SetViridis();
  pladv(0);
  plsfont(PL_FCI_SANS, PL_FCI_UPRIGHT, PL_FCI_MEDIUM);
  SetTextHeight(kTickHeight);
  s.ok = AbortMessage().empty();
  s.AreaWindow();
}

Chart::~Chart() {
  if (state_->ok && !state_->finished) plend1();
}

bool Chart::ok() const { return state_->ok; }
int Chart::width() const { return state_->width; }
int Chart::height() const { return state_->height; }

void Chart::SetArea(const cv::Rect& area, double x_min, double x_max,
                    double y_min, double y_max, bool y_down) {
  State& s = *state_;
  s.area = area;
  s.x_min = x_min;
  s.x_max = x_max > x_min ? x_max : x_min + 1;
  s.y_min = y_min;
  s.y_max = y_max > y_min ? y_max : y_min + 1;
  s.y_down = y_down;
  if (s.Drawing()) s.AreaWindow();
}

cv::Point2d Chart::ToCanvas(double x, double y) const {
  const State& s = *state_;
  const double u = (x - s.x_min) / (s.x_max - s.x_min);
  const double v = (y - s.y_min) / (s.y_max - s.y_min);
  return {s.area.x + u * s.area.width,
          s.y_down ? s.area.y + v * s.area.height
                   : s.area.y + (1.0 - v) * s.area.height};
}

void Chart::Axes(const std::string& x_label, const std::string& y_label,
                 bool grid, bool x_numbers) {
  if (!state_->Drawing()) return;
  SetTextHeight(kTickHeight);
  plwidth(1);
  pllsty(1);
  if (grid) {
    plcol0(Index(Colour::kLightGrey));
    plbox(x_numbers ? "g" : "", 0, 0, "g", 0, 0);
  }
  plcol0(Index(Colour::kBlack));
  // "f": plain numbers, no separate "x10^n" label above the axis.
  plbox(x_numbers ? "bcnstf" : "bc", 0, 0, "bcnstvf", 0, 0);
  SetTextHeight(kLabelHeight);
  if (!x_label.empty()) plmtex("b", 3.4, 0.5, 0.5, x_label.c_str());
  if (!y_label.empty()) plmtex("l", 5.2, 0.5, 0.5, y_label.c_str());
  SetTextHeight(kTickHeight);
}

void Chart::Title(const std::string& title, const std::string& subtitle) {
  if (!state_->Drawing()) return;
  plsfont(PL_FCI_SANS, PL_FCI_UPRIGHT, PL_FCI_BOLD);
  CanvasText(20, 30, title, kTitleHeight, Colour::kBlack);
  plsfont(PL_FCI_SANS, PL_FCI_UPRIGHT, PL_FCI_MEDIUM);
  if (!subtitle.empty()) {
    CanvasText(20, 54, subtitle, kLabelHeight, Colour::kDarkGrey);
  }
}

void Chart::CanvasText(double x, double y, const std::string& text,
                       double height, Colour colour, double align) {
  const State& s = *state_;
  if (!s.Drawing() || text.empty()) return;
  s.PageWindow();
  SetTextHeight(height);
  plcol0(Index(colour));
  // PLplot places text by the line half a capital's height above the
  // baseline.
  plptex(x, y - 0.5 * height, 1, 0, align, text.c_str());
  SetTextHeight(kTickHeight);
  s.AreaWindow();
}

void Chart::Polyline(const std::vector<double>& x, const std::vector<double>& y,
                     Colour colour, double width, bool dashed) {
  if (!state_->Drawing() || x.size() != y.size() || x.size() < 2) return;
  plcol0(Index(colour));
  plwidth(width);
  pllsty(dashed ? 2 : 1);
  plline(static_cast<PLINT>(x.size()), x.data(), y.data());
  pllsty(1);
  plwidth(1);
}

namespace {
// An arrow head at canvas point `tip` of an arrow from `from`; `to_world`
// maps canvas pixels to the current window's coordinates.
template <typename ToWorld>
void ArrowHead(const cv::Point2d& from, const cv::Point2d& tip, double head,
               const ToWorld& to_world) {
  const double length = std::hypot(tip.x - from.x, tip.y - from.y);
  if (!(length > 0)) return;
  const double h = std::min(head, length / 3);
  const cv::Point2d d = (tip - from) / length;
  const double c = std::cos(0.45), n = std::sin(0.45);
  PLFLT x[3], y[3];
  for (int side = -1, k = 0; side <= 1; side += 2, k += 2) {
    const cv::Point2d barb(tip.x - (d.x * c - side * d.y * n) * h,
                           tip.y - (side * d.x * n + d.y * c) * h);
    const cv::Point2d w = to_world(barb);
    x[k] = w.x;
    y[k] = w.y;
  }
  const cv::Point2d w = to_world(tip);
  x[1] = w.x;
  y[1] = w.y;
  plline(3, x, y);
}
}  // namespace

void Chart::Arrow(double x0, double y0, double x1, double y1, Colour colour,
                  double head) {
  const State& s = *state_;
  if (!s.Drawing()) return;
  plcol0(Index(colour));
  plwidth(1);
  pljoin(x0, y0, x1, y1);
  const cv::Point2d a = ToCanvas(x0, y0);
  ArrowHead(a, ToCanvas(x1, y1), head, [&](const cv::Point2d& p) {
    const double u = (p.x - s.area.x) / s.area.width;
    const double v = (p.y - s.area.y) / s.area.height;
    return cv::Point2d(s.x_min + u * (s.x_max - s.x_min),
                       s.y_down ? s.y_min + v * (s.y_max - s.y_min)
                                : s.y_max - v * (s.y_max - s.y_min));
  });
}

void Chart::CanvasArrow(const cv::Point2d& from, const cv::Point2d& to,
                        Colour colour, double head) {
  const State& s = *state_;
  if (!s.Drawing()) return;
  s.PageWindow();
  plcol0(Index(colour));
  plwidth(1);
  pljoin(from.x, from.y, to.x, to.y);
  ArrowHead(from, to, head, [](const cv::Point2d& p) { return p; });
  s.AreaWindow();
}

void Chart::Frame() {
  if (!state_->Drawing()) return;
  plcol0(Index(Colour::kBlack));
  plwidth(1);
  plbox("bc", 0, 0, "bc", 0, 0);
}

void Chart::FilledRect(double x0, double y0, double x1, double y1,
                       Colour colour) {
  if (!state_->Drawing()) return;
  PLFLT x[4] = {x0, x1, x1, x0}, y[4] = {y0, y0, y1, y1};
  plcol0(Index(colour));
  plpsty(0);
  plfill(4, x, y);
}

namespace {
const char* Glyph(LegendEntry::Sample shape) {
  return shape == LegendEntry::Sample::kCross ? "+" : "●";
}
}  // namespace

void Chart::Markers(const std::vector<double>& x, const std::vector<double>& y,
                    LegendEntry::Sample shape, Colour colour, double size) {
  if (!state_->Drawing() || x.size() != y.size() || x.empty()) return;
  SetTextHeight(size);
  plcol0(Index(colour));
  plstring(static_cast<PLINT>(x.size()), x.data(), y.data(), Glyph(shape));
  SetTextHeight(kTickHeight);
}

void Chart::ErrorBars(const std::vector<double>& x,
                      const std::vector<double>& y_lo,
                      const std::vector<double>& y_hi, Colour colour,
                      double width) {
  if (!state_->Drawing() || x.size() != y_lo.size() ||
      x.size() != y_hi.size() || x.empty()) {
    return;
  }
  plcol0(Index(colour));
  plwidth(width);
  plsmin(0, 0.5);  // the bars' end ticks
  plerry(static_cast<PLINT>(x.size()), x.data(), y_lo.data(), y_hi.data());
  plwidth(1);
}

void Chart::Shades(const cv::Mat& values, const std::vector<double>& xs,
                   const std::vector<double>& ys, double v_min, double v_max,
                   int levels) {
  if (!state_->Drawing() || values.empty() || !(v_max > v_min)) return;
  const Field field(values, xs, ys, v_min, v_max);
  if (!field.Valid()) return;
  levels = std::max(2, levels);
  std::vector<PLFLT> edges(levels + 1);
  for (int k = 0; k <= levels; ++k) {
    edges[k] = v_min + (v_max - v_min) * k / levels;
  }
  plpsty(0);
  plshades(field.Matrix(), field.grid.nx, field.grid.ny, nullptr, xs.front(),
           xs.back(), ys.front(), ys.back(), edges.data(),
           static_cast<PLINT>(edges.size()), 0, 0, 0, plfill, 0, pltr1,
           const_cast<PLcGrid*>(&field.grid));
}

void Chart::Cells(const cv::Mat& values, double x0, double y0, double dx,
                  double dy, double v_min, double v_max) {
  if (!state_->Drawing() || values.empty() || !(v_max > v_min)) return;
  const int nx = values.cols, ny = values.rows;
  std::vector<double> xs(nx), ys(ny);
  for (int i = 0; i < nx; ++i) xs[i] = x0 + (i + 0.5) * dx;
  for (int j = 0; j < ny; ++j) ys[j] = y0 + (j + 0.5) * dy;
  const Field field(values, xs, ys, -HUGE_VAL, HUGE_VAL);
  plimagefr(field.Matrix(), nx, ny, x0, x0 + nx * dx, y0, y0 + ny * dy, v_min,
            HUGE_VAL, v_min, v_max, nullptr, nullptr);
}

void Chart::FillWhere(const cv::Mat& values, const std::vector<double>& xs,
                      const std::vector<double>& ys, double lo, double hi,
                      Colour colour, bool hatched) {
  if (!state_->Drawing() || values.empty() || !(hi > lo)) return;
  const Field field(values, xs, ys, -HUGE_VAL, HUGE_VAL);
  if (!field.Valid()) return;
  plpsty(hatched ? 3 : 0);
  plshade(field.Matrix(), field.grid.nx, field.grid.ny, nullptr, xs.front(),
          xs.back(), ys.front(), ys.back(), lo, hi, 0, Index(colour), 1, 0, 0,
          0, 0, plfill, 0, pltr1, const_cast<PLcGrid*>(&field.grid));
  plpsty(0);
}

void Chart::Contours(const cv::Mat& values, const std::vector<double>& xs,
                     const std::vector<double>& ys,
                     const std::vector<double>& levels, Colour colour,
                     double width) {
  if (!state_->Drawing() || values.empty() || levels.empty()) return;
  const Field field(values, xs, ys, -HUGE_VAL, HUGE_VAL);
  if (!field.Valid()) return;
  plcol0(Index(colour));
  plwidth(width);
  SetTextHeight(kTickHeight);
  pl_setcontlabelformat(4, 2);
  pl_setcontlabelparam(0.006, 0.8, 0.35, 1);
  plcont(field.Matrix(), field.grid.nx, field.grid.ny, 1, field.grid.nx, 1,
         field.grid.ny, levels.data(), static_cast<PLINT>(levels.size()), pltr1,
         const_cast<PLcGrid*>(&field.grid));
  pl_setcontlabelparam(0.006, 0.3, 0.1, 0);
  plwidth(1);
}

void Chart::ColourBar(double v_min, double v_max, const std::string& label) {
  const State& s = *state_;
  if (!s.Drawing() || !(v_max > v_min)) return;
  SetTextHeight(kTickHeight);
  plcol0(Index(Colour::kBlack));
  PLINT label_opts[1] = {PL_COLORBAR_LABEL_RIGHT};
  const char* labels[1] = {label.c_str()};
  const char* axis_opts[1] = {"bcvtmf"};
  PLFLT ticks[1] = {0};
  PLINT sub_ticks[1] = {0};
  // An image of the ramp, not PL_COLORBAR_GRADIENT: PLplot's cairo driver
  // does not free the cairo pattern it draws a gradient with.
  constexpr int kSteps = 256;
  std::vector<PLFLT> ramp(kSteps);
  for (int k = 0; k < kSteps; ++k) {
    ramp[k] = v_min + (v_max - v_min) * k / (kSteps - 1);
  }
  PLINT n_values[1] = {kSteps};
  const PLFLT* values[1] = {ramp.data()};
  PLFLT bar_width = 0, bar_height = 0;
  plcolorbar(&bar_width, &bar_height, PL_COLORBAR_IMAGE,
             PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT,
             20.0 / s.area.width, 0, 22.0 / s.area.width, 1.0,
             Index(Colour::kWhite), Index(Colour::kBlack), 1, 0, 0, 0, 0,
             label.empty() ? 0 : 1, label_opts, labels, 1, axis_opts, ticks,
             sub_ticks, n_values, const_cast<PLFLT_MATRIX>(values));
}

void Chart::Legend(const std::vector<LegendEntry>& entries, Corner corner) {
  if (!state_->Drawing() || entries.empty()) return;
  const size_t n = entries.size();
  std::vector<PLINT> opts(n), text_colours(n), box_colours(n), patterns(n, 0),
      line_colours(n), line_styles(n), symbol_colours(n), symbol_numbers(n, 1);
  std::vector<PLFLT> box_scales(n, 0.8), box_widths(n, 1), line_widths(n, 2),
      symbol_scales(n, 1.0);
  std::vector<const char*> texts(n), symbols(n);
  for (size_t k = 0; k < n; ++k) {
    const LegendEntry& e = entries[k];
    using Sample = LegendEntry::Sample;
    opts[k] = e.sample == Sample::kBox ? PL_LEGEND_COLOR_BOX
              : e.sample == Sample::kLine || e.sample == Sample::kDashedLine
                  ? PL_LEGEND_LINE
                  : PL_LEGEND_SYMBOL;
    text_colours[k] = Index(Colour::kBlack);
    texts[k] = e.text.c_str();
    box_colours[k] = line_colours[k] = symbol_colours[k] = Index(e.colour);
    line_styles[k] = e.sample == Sample::kDashedLine ? 2 : 1;
    symbols[k] = Glyph(e.sample);
  }
  SetTextHeight(kTickHeight);
  PLFLT legend_width = 0, legend_height = 0;
  pllegend(
      &legend_width, &legend_height,
      PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
      (corner == Corner::kBottomLeft ? PL_POSITION_BOTTOM : PL_POSITION_TOP) |
          (corner == Corner::kTopRight ? PL_POSITION_RIGHT : PL_POSITION_LEFT) |
          PL_POSITION_INSIDE | PL_POSITION_VIEWPORT,
      0.01, 0.02, 0.05, Index(Colour::kWhite), Index(Colour::kGrey), 1, 0, 0,
      static_cast<PLINT>(n), opts.data(), 1.0, 1.0, 2.0, 0.0,
      text_colours.data(), texts.data(), box_colours.data(), patterns.data(),
      box_scales.data(), box_widths.data(), line_colours.data(),
      line_styles.data(), line_widths.data(), symbol_colours.data(),
      symbol_scales.data(), symbol_numbers.data(), symbols.data());
}

cv::Mat Chart::Finish() {
  State& s = *state_;
  if (!s.Drawing()) return cv::Mat();
  plend1();
  s.finished = true;
  if (!AbortMessage().empty()) return cv::Mat();
  const cv::Mat rgba(s.height, s.width, CV_8UC4, s.canvas.data());
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  return bgr;
}

}  // namespace plot
}  // namespace puzzlecal
