#include "apps/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "util/string_format.h"

namespace puzzlecal {
namespace plot {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// OpenCV drawing with sub-pixel coordinates: 4 fractional bits.
constexpr int kShift = 4;
constexpr double kShiftScale = 1 << kShift;

cv::Point Fixed(cv::Point2d p) {
  return cv::Point(static_cast<int>(std::lround(p.x * kShiftScale)),
                   static_cast<int>(std::lround(p.y * kShiftScale)));
}

}  // namespace

cv::Point2d Frame::ToCanvas(double x, double y) const {
  const double u = (x - x_min) / (x_max - x_min);
  const double v = (y - y_min) / (y_max - y_min);
  const double cx = area.x + u * area.width;
  const double cy =
      y_down ? area.y + v * area.height : area.y + (1.0 - v) * area.height;
  return {cx, cy};
}

cv::Point Frame::ToCanvasPixel(double x, double y) const {
  const cv::Point2d p = ToCanvas(x, y);
  return cv::Point(static_cast<int>(std::lround(p.x)),
                   static_cast<int>(std::lround(p.y)));
}

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

std::vector<double> NiceTicks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo) || target < 1) {
    return ticks;
  }
  const double step = NiceNumber((hi - lo) / target, false);
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (int i = 0; i < 1000; ++i) {
    const double t = first + i * step;
    if (t > hi + 1e-9 * step) break;
    ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  }
  return ticks;
}

std::string FormatTick(double value, double step) {
  int decimals = 0;
  if (step > 0 && std::isfinite(step)) {
    decimals =
        std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  }
  return StringPrintf("%.*f", std::min(decimals, 10), value);
}

cv::Size TextSize(const std::string& text, double scale, int thickness) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, thickness, &baseline);
}

void DrawText(cv::Mat* canvas, const std::string& text, cv::Point anchor,
              double scale, const cv::Scalar& colour, Align align,
              int thickness) {
  const cv::Size size = TextSize(text, scale, thickness);
  int x = anchor.x;
  if (align == Align::kCenter) x -= size.width / 2;
  if (align == Align::kRight) x -= size.width;
  cv::putText(*canvas, text, cv::Point(x, anchor.y), kFont, scale, colour,
              thickness, cv::LINE_AA);
}

void DrawVerticalText(cv::Mat* canvas, const std::string& text,
                      cv::Point center, double scale,
                      const cv::Scalar& colour) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, 1, &baseline);
  const int w = size.width + 4;
  const int h = size.height + baseline + 4;
  // Draw black-on-white into a patch, rotate it, and blend it in as a mask
  // so the text keeps its colour over any background.
  cv::Mat patch(h, w, CV_8UC1, cv::Scalar(0));
  cv::putText(patch, text, cv::Point(2, 2 + size.height), kFont, scale,
              cv::Scalar(255), 1, cv::LINE_AA);
  cv::Mat rotated;
  cv::rotate(patch, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  const cv::Rect target(center.x - rotated.cols / 2,
                        center.y - rotated.rows / 2, rotated.cols,
                        rotated.rows);
  const cv::Rect clipped = target & cv::Rect(0, 0, canvas->cols, canvas->rows);
  for (int y = clipped.y; y < clipped.y + clipped.height; ++y) {
    for (int x = clipped.x; x < clipped.x + clipped.width; ++x) {
      const double a = rotated.at<uint8_t>(y - target.y, x - target.x) / 255.0;
      cv::Vec3b& px = canvas->at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) {
        px[c] = cv::saturate_cast<uint8_t>((1 - a) * px[c] + a * colour[c]);
      }
    }
  }
}

void DrawTitle(cv::Mat* canvas, const std::string& title,
               const std::string& subtitle) {
  DrawText(canvas, title, cv::Point(20, 32), kTitleScale, kBlack, Align::kLeft,
           2);
  if (!subtitle.empty()) {
    DrawText(canvas, subtitle, cv::Point(20, 58), kLabelScale,
             cv::Scalar(70, 70, 70));
  }
}

void DrawAxes(cv::Mat* canvas, const Frame& frame, const std::string& x_label,
              const std::string& y_label, bool grid, bool x_ticks_on) {
  const cv::Rect& a = frame.area;
  const int tick = 5;
  const int x_target = std::max(2, a.width / 110);
  const int y_target = std::max(2, a.height / 70);
  const std::vector<double> x_ticks =
      x_ticks_on ? NiceTicks(frame.x_min, frame.x_max, x_target)
                 : std::vector<double>();
  const std::vector<double> y_ticks =
      NiceTicks(std::min(frame.y_min, frame.y_max),
                std::max(frame.y_min, frame.y_max), y_target);
  const double x_step = x_ticks.size() > 1 ? x_ticks[1] - x_ticks[0] : 1;
  const double y_step = y_ticks.size() > 1 ? y_ticks[1] - y_ticks[0] : 1;
  for (double t : x_ticks) {
    const int x = frame.ToCanvasPixel(t, frame.y_min).x;
    if (grid) {
      cv::line(*canvas, {x, a.y}, {x, a.y + a.height}, kLightGrey, 1);
    }
    cv::line(*canvas, {x, a.y + a.height}, {x, a.y + a.height + tick}, kBlack,
             1);
    DrawText(canvas, FormatTick(t, x_step), {x, a.y + a.height + tick + 16},
             kTickScale, kBlack, Align::kCenter);
  }
  for (double t : y_ticks) {
    const int y = frame.ToCanvasPixel(frame.x_min, t).y;
    if (grid) {
      cv::line(*canvas, {a.x, y}, {a.x + a.width, y}, kLightGrey, 1);
    }
    cv::line(*canvas, {a.x - tick, y}, {a.x, y}, kBlack, 1);
    DrawText(canvas, FormatTick(t, y_step), {a.x - tick - 4, y + 5}, kTickScale,
             kBlack, Align::kRight);
  }
  cv::rectangle(*canvas, a, kBlack, 1);
  if (!x_label.empty()) {
    DrawText(canvas, x_label, {a.x + a.width / 2, a.y + a.height + 46},
             kLabelScale, kBlack, Align::kCenter);
  }
  if (!y_label.empty()) {
    // Left of the widest tick label.
    int widest = 0;
    for (double t : y_ticks) {
      widest =
          std::max(widest, TextSize(FormatTick(t, y_step), kTickScale).width);
    }
    DrawVerticalText(canvas, y_label,
                     {a.x - tick - 14 - widest, a.y + a.height / 2},
                     kLabelScale, kBlack);
  }
}

cv::Scalar ColourMapValue(int colormap, double t) {
  if (!std::isfinite(t)) t = 0;
  const int index =
      static_cast<int>(std::lround(std::clamp(t, 0.0, 1.0) * 255.0));
  cv::Mat grey(1, 1, CV_8UC1, cv::Scalar(index));
  cv::Mat colour;
  cv::applyColorMap(grey, colour, colormap);
  const cv::Vec3b c = colour.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

void DrawColourBar(cv::Mat* canvas, const cv::Rect& bar, double v_min,
                   double v_max, int colormap, const std::string& label) {
  cv::Mat ramp(bar.height, 1, CV_8UC1);
  for (int y = 0; y < bar.height; ++y) {
    ramp.at<uint8_t>(y, 0) = cv::saturate_cast<uint8_t>(std::lround(
        255.0 * (bar.height - 1 - y) / std::max(1, bar.height - 1)));
  }
  cv::Mat ramp_colour;
  cv::applyColorMap(ramp, ramp_colour, colormap);
  const cv::Rect clipped = bar & cv::Rect(0, 0, canvas->cols, canvas->rows);
  for (int x = clipped.x; x < clipped.x + clipped.width; ++x) {
    ramp_colour(cv::Rect(0, clipped.y - bar.y, 1, clipped.height))
        .copyTo((*canvas)(cv::Rect(x, clipped.y, 1, clipped.height)));
  }
  cv::rectangle(*canvas, bar, kBlack, 1);
  int widest = 0;
  if (v_max > v_min) {
    const std::vector<double> ticks = NiceTicks(v_min, v_max, 6);
    const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1;
    for (double t : ticks) {
      const int y = bar.y + bar.height -
                    static_cast<int>(std::lround((t - v_min) / (v_max - v_min) *
                                                 bar.height));
      cv::line(*canvas, {bar.x + bar.width, y}, {bar.x + bar.width + 4, y},
               kBlack, 1);
      const std::string text = FormatTick(t, step);
      widest = std::max(widest, TextSize(text, kTickScale).width);
      DrawText(canvas, text, {bar.x + bar.width + 7, y + 5}, kTickScale,
               kBlack);
    }
  }
  if (!label.empty()) {
    DrawVerticalText(canvas, label,
                     {bar.x + bar.width + 20 + widest, bar.y + bar.height / 2},
                     kLabelScale, kBlack);
  }
}

cv::Size LegendSize(const std::vector<LegendEntry>& entries) {
  int widest = 0;
  for (const LegendEntry& e : entries) {
    widest = std::max(widest, TextSize(e.text, kTickScale).width);
  }
  return cv::Size(widest + 52, static_cast<int>(entries.size()) * 20 + 10);
}

cv::Rect DrawLegend(cv::Mat* canvas, cv::Point top_left,
                    const std::vector<LegendEntry>& entries) {
  const cv::Rect box(top_left, LegendSize(entries));
  cv::rectangle(*canvas, box, kWhite, cv::FILLED);
  cv::rectangle(*canvas, box, kGrey, 1);
  for (size_t i = 0; i < entries.size(); ++i) {
    const LegendEntry& e = entries[i];
    const int cy = box.y + 15 + static_cast<int>(i) * 20;
    const cv::Point a(box.x + 8, cy), b(box.x + 34, cy);
    switch (e.marker) {
      case LegendEntry::Marker::kLine:
        cv::line(*canvas, a, b, e.colour, 2, cv::LINE_AA);
        break;
      case LegendEntry::Marker::kDashedLine:
        DrawDashedLine(canvas, a, b, e.colour, 2, 5);
        break;
      case LegendEntry::Marker::kBox:
        cv::rectangle(*canvas, cv::Rect(box.x + 12, cy - 6, 18, 12), e.colour,
                      cv::FILLED);
        break;
      case LegendEntry::Marker::kCircle:
        cv::circle(*canvas, {box.x + 21, cy}, 5, e.colour, 2, cv::LINE_AA);
        break;
      case LegendEntry::Marker::kCross:
        DrawCross(canvas, cv::Point2d(box.x + 21, cy), 5, e.colour, 1);
        break;
      case LegendEntry::Marker::kArrow:
        cv::arrowedLine(*canvas, a, b, e.colour, 1, cv::LINE_AA, 0, 0.3);
        break;
    }
    DrawText(canvas, e.text, {box.x + 42, cy + 5}, kTickScale, kBlack);
  }
  return box;
}

void DrawDashedLine(cv::Mat* canvas, cv::Point2d from, cv::Point2d to,
                    const cv::Scalar& colour, int thickness, double dash_px) {
  const cv::Point2d d = to - from;
  const double length = std::hypot(d.x, d.y);
  if (!(length > 0) || !(dash_px > 0)) return;
  const int dashes = static_cast<int>(std::ceil(length / dash_px));
  for (int i = 0; i < dashes; i += 2) {
    const double t0 = i * dash_px / length;
    const double t1 = std::min(1.0, (i + 1) * dash_px / length);
    cv::line(*canvas, Fixed(from + t0 * d), Fixed(from + t1 * d), colour,
             thickness, cv::LINE_AA, kShift);
  }
}

void DrawCross(cv::Mat* canvas, cv::Point2d center, int radius,
               const cv::Scalar& colour, int thickness) {
  cv::line(*canvas, Fixed(center - cv::Point2d(radius, 0)),
           Fixed(center + cv::Point2d(radius, 0)), colour, thickness,
           cv::LINE_AA, kShift);
  cv::line(*canvas, Fixed(center - cv::Point2d(0, radius)),
           Fixed(center + cv::Point2d(0, radius)), colour, thickness,
           cv::LINE_AA, kShift);
}

}  // namespace plot
}  // namespace puzzlecal
