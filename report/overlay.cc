#include "report/overlay.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "util/failure.h"

namespace puzzlecal {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kTitleBand = 70;
constexpr int kLegendBand = 40;
// OpenCV drawing with sub-pixel coordinates: 4 fractional bits.
constexpr int kShift = 4;

cv::Point Fixed(const cv::Point2d& p) {
  return cv::Point(static_cast<int>(std::lround(p.x * (1 << kShift))),
                   static_cast<int>(std::lround(p.y * (1 << kShift))));
}

double FontScale(double height, int thickness) {
  return cv::getFontScaleFromHeight(
      kFont, std::max(1, static_cast<int>(std::lround(height))), thickness);
}

void Text(cv::Mat* canvas, const std::string& text, cv::Point2d baseline,
          double height, const cv::Scalar& colour, int thickness) {
  cv::putText(
      *canvas, text,
      cv::Point(static_cast<int>(baseline.x), static_cast<int>(baseline.y)),
      kFont, FontScale(height, thickness), colour, thickness, cv::LINE_AA);
}

void DrawMark(cv::Mat* canvas, const OverlayMark& mark, const cv::Point2d& at,
              const cv::Point2d& to) {
  const int t = std::max(1, mark.thickness);
  switch (mark.kind) {
    case OverlayMark::Kind::kCircle:
      cv::circle(*canvas, Fixed(at),
                 static_cast<int>(std::lround(mark.size * (1 << kShift))),
                 mark.colour, t, cv::LINE_AA, kShift);
      break;
    case OverlayMark::Kind::kCross:
      cv::line(*canvas, Fixed(at - cv::Point2d(mark.size, 0)),
               Fixed(at + cv::Point2d(mark.size, 0)), mark.colour, t,
               cv::LINE_AA, kShift);
      cv::line(*canvas, Fixed(at - cv::Point2d(0, mark.size)),
               Fixed(at + cv::Point2d(0, mark.size)), mark.colour, t,
               cv::LINE_AA, kShift);
      break;
    case OverlayMark::Kind::kLine:
      cv::line(*canvas, Fixed(at), Fixed(to), mark.colour, t, cv::LINE_AA,
               kShift);
      break;
    case OverlayMark::Kind::kArrow: {
      const double length = std::hypot(to.x - at.x, to.y - at.y);
      if (length < 1.5) break;
      cv::arrowedLine(*canvas, Fixed(at), Fixed(to), mark.colour, t,
                      cv::LINE_AA, kShift, std::min(0.3, 6.0 / length));
      break;
    }
    case OverlayMark::Kind::kText:
      Text(canvas, mark.text, at, mark.size, mark.colour, t);
      break;
  }
}

// The legend line: each entry's sample, then its text.
void DrawLegend(cv::Mat* canvas, const std::vector<OverlayLegendEntry>& legend,
                int baseline) {
  constexpr double kTextHeight = 11;
  double x = 20;
  for (const OverlayLegendEntry& entry : legend) {
    OverlayMark sample;
    sample.kind = entry.kind;
    sample.colour = entry.colour;
    sample.thickness = entry.kind == OverlayMark::Kind::kCross ? 1 : 2;
    const cv::Point2d centre(x, baseline - 5);
    DrawMark(canvas, sample, centre, centre + cv::Point2d(28, 0));
    x += entry.kind == OverlayMark::Kind::kArrow ||
                 entry.kind == OverlayMark::Kind::kLine
             ? 36
             : 12;
    Text(canvas, entry.text, {x, static_cast<double>(baseline)}, kTextHeight,
         cv::Scalar(0, 0, 0), 1);
    int unused = 0;
    x += cv::getTextSize(entry.text, kFont, FontScale(kTextHeight, 1), 1,
                         &unused)
             .width +
         30;
  }
}

}  // namespace

bool OverlayOptions::Check(std::string* why) const {
  if (width < 0 || width > 100000)
    return Fail("width must be in [0, 100000]", why);
  if (!(fade > 0 && fade <= 1)) return Fail("fade must be in (0, 1]", why);
  return true;
}

cv::Mat DrawOverlay(const cv::Mat& photo, const Overlay& overlay,
                    const OverlayOptions& options) {
  if (photo.empty()) return cv::Mat();
  cv::Mat colour;
  if (photo.channels() == 1) {
    cv::cvtColor(photo, colour, cv::COLOR_GRAY2BGR);
  } else {
    colour = photo.clone();
  }
  const double scale =
      options.width > 0 ? static_cast<double>(options.width) / photo.cols : 1;
  if (options.width > 0 && options.width != photo.cols) {
    const cv::Size size(
        options.width,
        std::max(1, static_cast<int>(std::lround(photo.rows * scale))));
    cv::Mat scaled;
    cv::resize(colour, scaled, size, 0, 0,
               scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
    colour = scaled;
  }
  if (options.fade < 1) {
    colour.convertTo(colour, CV_8U, options.fade, (1 - options.fade) * 128);
  }
  const int top = overlay.title.empty() ? 0 : kTitleBand;
  const int bottom = overlay.legend.empty() ? 0 : kLegendBand;
  cv::Mat canvas(colour.rows + top + bottom, colour.cols, CV_8UC3,
                 cv::Scalar(255, 255, 255));
  colour.copyTo(canvas(cv::Rect(0, top, colour.cols, colour.rows)));
  cv::Mat photo_area = canvas(cv::Rect(0, top, colour.cols, colour.rows));
  // Pixel centres stay pixel centres under the scaling.
  auto place = [&](const Eigen::Vector2d& p) {
    return cv::Point2d((p.x() + 0.5) * scale - 0.5,
                       (p.y() + 0.5) * scale - 0.5);
  };
  for (const OverlayMark& mark : overlay.marks) {
    if (!mark.at.allFinite() || !mark.to.allFinite()) continue;
    DrawMark(&photo_area, mark, place(mark.at), place(mark.to));
  }
  if (top > 0) {
    Text(&canvas, overlay.title, {12, 28}, 17, cv::Scalar(0, 0, 0), 2);
    Text(&canvas, overlay.subtitle, {12, 56}, 12, cv::Scalar(60, 60, 60), 1);
  }
  if (bottom > 0) DrawLegend(&canvas, overlay.legend, canvas.rows - 15);
  return canvas;
}

}  // namespace puzzlecal
