#ifndef PUZZLECAL_REPORT_PLOT_H_
#define PUZZLECAL_REPORT_PLOT_H_

// The calibration report's charts, drawn by PLplot (its cairo memory
// device) into an image the caller writes as PNG. A thin layer: the chart's
// plot area placed by canvas pixels, the report's colours and text sizes,
// and PLplot's axes, legends, colour bars and filled contours with the
// arguments the report needs. Everything else is PLplot's.
//
// PLplot keeps global state (the current stream): one Chart exists at a
// time. A Chart made on another thread waits until the first is destroyed;
// two at once on one thread would wait for ever, so draw one chart, finish
// it, then the next.

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace puzzlecal {
namespace plot {

// The colours every chart has (PLplot colour map 0).
enum class Colour {
  kWhite,
  kBlack,
  kGrey,
  kLightGrey,
  kDarkGrey,
  kBlue,
  kRed,
  kOrange,
  kPaper,   // the background of image-shaped plot areas
  kNoData,  // areas without a value (no ray)
  kFade,    // translucent white laid over extrapolated areas
};

// Text heights in canvas pixels.
inline constexpr double kTitleHeight = 15;
inline constexpr double kLabelHeight = 11;
inline constexpr double kTickHeight = 10;

// A legend line: a sample and its text.
struct LegendEntry {
  enum class Sample { kBox, kLine, kDashedLine, kCircle, kCross };
  Sample sample = Sample::kBox;
  Colour colour = Colour::kBlack;
  std::string text;
};

// Rounds `value` > 0 to 1, 2 or 5 times a power of ten: the largest such
// number <= value when `down`, otherwise the nearest one.
double NiceNumber(double value, bool down);

// True when PLplot and its cairo memory device can be used (the package
// plplot-driver-cairo is installed); otherwise `why` says what is missing.
bool ChartsAvailable(std::string* why);

class Chart {
 public:
  // A white canvas of width x height pixels. Check ok() (false when PLplot
  // or its cairo driver is missing). `antialias` false draws lines and
  // fills without anti-aliasing (text keeps it): for maps, whose filled
  // bands, drawn cell by cell, would otherwise show the cells' seams
  // wherever they are translucent.
  Chart(int width, int height, bool antialias = true);
  ~Chart();
  Chart(const Chart&) = delete;
  Chart& operator=(const Chart&) = delete;

  bool ok() const;
  int width() const;
  int height() const;

  // The plot area: canvas rectangle `area` shows data x in [x_min, x_max],
  // y in [y_min, y_max], y upwards, or downwards when y_down (image
  // coordinates). Drawing is clipped to it.
  void SetArea(const cv::Rect& area, double x_min, double x_max, double y_min,
               double y_max, bool y_down = false);
  // Canvas position (pixels) of the data point (x, y) in the current area.
  cv::Point2d ToCanvas(double x, double y) const;

  // The frame, ticks with numbers (x_numbers false leaves x bare), light
  // grid lines when `grid`, and the axis labels.
  void Axes(const std::string& x_label, const std::string& y_label, bool grid,
            bool x_numbers = true);
  // Bold title and a subtitle line at the top left of the canvas.
  void Title(const std::string& title, const std::string& subtitle);
  // Text with its baseline at canvas pixel (x, y); `align` 0 left, 0.5
  // centred, 1 right.
  void CanvasText(double x, double y, const std::string& text, double height,
                  Colour colour, double align = 0);
  // Lines in data coordinates, `width` in canvas pixels.
  void Polyline(const std::vector<double>& x, const std::vector<double>& y,
                Colour colour, double width, bool dashed = false);
  // An arrow from (x0, y0) to (x1, y1) whose head is `head` canvas pixels
  // long (at most a third of the arrow).
  void Arrow(double x0, double y0, double x1, double y1, Colour colour,
             double head);
  // The same from and to canvas pixels (anywhere on the canvas).
  void CanvasArrow(const cv::Point2d& from, const cv::Point2d& to,
                   Colour colour, double head);
  // The frame of the plot area alone.
  void Frame();
  // A filled axis-aligned rectangle between two data corners.
  void FilledRect(double x0, double y0, double x1, double y1, Colour colour);
  // Markers centred at data points; `size` in canvas pixels.
  void Markers(const std::vector<double>& x, const std::vector<double>& y,
               LegendEntry::Sample shape, Colour colour, double size);
  // Vertical error bars from y_lo to y_hi at x.
  void ErrorBars(const std::vector<double>& x, const std::vector<double>& y_lo,
                 const std::vector<double>& y_hi, Colour colour, double width);

  // A field sampled at xs (columns) x ys (rows) of `values` (CV_64F, NaN
  // where undefined, which stays unfilled), in viridis from v_min to v_max,
  // as `levels` filled contour bands (values beyond the range are clamped).
  void Shades(const cv::Mat& values, const std::vector<double>& xs,
              const std::vector<double>& ys, double v_min, double v_max,
              int levels = 64);
  // Cells of a regular grid: cell (col, row) covers [x0 + col * dx, ...) x
  // [y0 + row * dy, ...); values < v_min are left unfilled.
  void Cells(const cv::Mat& values, double x0, double y0, double dx, double dy,
             double v_min, double v_max);
  // A translucent or plain fill over the part of the sampled field where
  // lo <= value <= hi; `hatched` draws diagonal lines instead.
  void FillWhere(const cv::Mat& values, const std::vector<double>& xs,
                 const std::vector<double>& ys, double lo, double hi,
                 Colour colour, bool hatched);
  // Labelled contour lines of the sampled field at `levels`.
  void Contours(const cv::Mat& values, const std::vector<double>& xs,
                const std::vector<double>& ys,
                const std::vector<double>& levels, Colour colour, double width);
  // A viridis colour bar from v_min to v_max right of the plot area, with
  // `label` along it.
  void ColourBar(double v_min, double v_max, const std::string& label);
  // A legend box inside a corner of the plot area.
  enum class Corner { kTopRight, kTopLeft, kBottomLeft };
  void Legend(const std::vector<LegendEntry>& entries,
              Corner corner = Corner::kTopRight);

  // Ends the PLplot stream and returns the canvas (CV_8UC3, BGR); empty
  // when !ok(). Drawing after Finish does nothing.
  cv::Mat Finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace plot
}  // namespace puzzlecal

#endif  // PUZZLECAL_REPORT_PLOT_H_
