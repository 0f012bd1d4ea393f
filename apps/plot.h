#ifndef PUZZLECAL_APPS_PLOT_H_
#define PUZZLECAL_APPS_PLOT_H_

// Small plotting helpers on top of OpenCV drawing: linear axes with ticks and
// labels, titles, colour bars and legends, for the calibration report's PNGs.
// Colours are BGR, canvases CV_8UC3.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace puzzlecal {
namespace plot {

// Frequently used colours (BGR).
inline const cv::Scalar kBlack(0, 0, 0);
inline const cv::Scalar kWhite(255, 255, 255);
inline const cv::Scalar kGrey(128, 128, 128);
inline const cv::Scalar kLightGrey(225, 225, 225);
inline const cv::Scalar kBlue(180, 110, 30);
inline const cv::Scalar kRed(40, 40, 215);
inline const cv::Scalar kGreen(60, 170, 40);
inline const cv::Scalar kOrange(20, 140, 240);

// Text sizes (OpenCV Hershey scale factors) used throughout.
inline constexpr double kTitleScale = 0.75;
inline constexpr double kLabelScale = 0.55;
inline constexpr double kTickScale = 0.45;

enum class Align { kLeft, kCenter, kRight };

// A rectangle of the canvas showing data coordinates [x_min, x_max] x
// [y_min, y_max]; y grows upwards unless y_down (image coordinates).
struct Frame {
  cv::Rect area;
  double x_min = 0, x_max = 1;
  double y_min = 0, y_max = 1;
  bool y_down = false;

  // Canvas position (sub-pixel) of the data point (x, y).
  cv::Point2d ToCanvas(double x, double y) const;
  // Rounded to whole canvas pixels.
  cv::Point ToCanvasPixel(double x, double y) const;
};

// Rounds `value` > 0 to 1, 2 or 5 times a power of ten: the largest such
// number <= value when `down`, otherwise the nearest one.
double NiceNumber(double value, bool down);

// Tick positions at a 1-2-5 step covering [lo, hi] with about `target` ticks
// (only ticks inside [lo, hi]).
std::vector<double> NiceTicks(double lo, double hi, int target);

// A tick value printed with as many decimals as the step needs.
std::string FormatTick(double value, double step);

// Width and height of `text` drawn at `scale`.
cv::Size TextSize(const std::string& text, double scale, int thickness = 1);

// Draws `text` with its baseline at `anchor.y`, aligned horizontally at
// anchor.x. Anti-aliased Hershey simplex.
void DrawText(cv::Mat* canvas, const std::string& text, cv::Point anchor,
              double scale, const cv::Scalar& colour,
              Align align = Align::kLeft, int thickness = 1);

// Draws `text` rotated by 90 degrees (reading upwards), centred on `center`.
void DrawVerticalText(cv::Mat* canvas, const std::string& text,
                      cv::Point center, double scale, const cv::Scalar& colour);

// A title (bold) and an optional subtitle line at the top of the canvas.
void DrawTitle(cv::Mat* canvas, const std::string& title,
               const std::string& subtitle);

// Frame border, ticks with labels, optional light grid lines, and the axis
// labels below and left of the frame. x_ticks false leaves the x axis bare
// (for charts that label their categories themselves).
void DrawAxes(cv::Mat* canvas, const Frame& frame, const std::string& x_label,
              const std::string& y_label, bool grid, bool x_ticks = true);

// Colour of `t` in [0, 1] (clamped) under an OpenCV colour map
// (cv::COLORMAP_*).
cv::Scalar ColourMapValue(int colormap, double t);

// A vertical colour bar in `bar` from v_min (bottom) to v_max (top) with tick
// labels to its right and `label` rotated alongside them.
void DrawColourBar(cv::Mat* canvas, const cv::Rect& bar, double v_min,
                   double v_max, int colormap, const std::string& label);

// One legend line: a marker sample and its text.
struct LegendEntry {
  enum class Marker { kLine, kDashedLine, kBox, kCircle, kCross, kArrow };
  Marker marker = Marker::kBox;
  cv::Scalar colour;
  std::string text;
};

// A legend box with its top-left corner at `top_left` (white background,
// grey border). Returns the box drawn.
cv::Rect DrawLegend(cv::Mat* canvas, cv::Point top_left,
                    const std::vector<LegendEntry>& entries);
// The size DrawLegend would need.
cv::Size LegendSize(const std::vector<LegendEntry>& entries);

// A dashed straight line.
void DrawDashedLine(cv::Mat* canvas, cv::Point2d from, cv::Point2d to,
                    const cv::Scalar& colour, int thickness, double dash_px);

// A cross marker (+) of half-size `radius` pixels.
void DrawCross(cv::Mat* canvas, cv::Point2d center, int radius,
               const cv::Scalar& colour, int thickness);

}  // namespace plot
}  // namespace puzzlecal

#endif  // PUZZLECAL_APPS_PLOT_H_
