#include "apps/report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>

#include "apps/plot.h"
#include "util/atomic_file.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

using plot::Align;

constexpr double kDeg = M_PI / 180.0;
// Largest image side the report accepts (guards the plot sizes).
constexpr int kMaxImageSide = 100000;

// One corner of a used view with a finite residual.
struct ResidualSample {
  int view = 0;
  Eigen::Vector2d detected;
  Eigen::Vector2d residual;  // reprojected minus detected
  bool inlier = true;
};

// Everything the plots and the summary share, checked once.
struct ReportData {
  const ReportInput* input = nullptr;
  const CalibrationResult* result = nullptr;
  const std::vector<CalibrationView>* views = nullptr;
  int width = 0, height = 0;
  bool camera_valid = false;  // parameters usable for projection
  std::vector<ResidualSample> samples;
  // Per view: image number (1-based, input order) or the view's own number
  // when the images do not name it; the image file.
  std::vector<int> view_number;
  std::vector<std::string> view_file;
  std::vector<int> view_outliers;
  std::vector<int> view_inliers;
  std::vector<double> view_rms;  // NaN when not used
  int num_inliers = 0, num_outliers = 0;
};

bool ViewResidualsConsistent(const CalibrationResult& result,
                             const std::vector<CalibrationView>& views,
                             size_t v) {
  return v < result.view_used.size() && result.view_used[v] &&
         v < result.residuals.size() && v < result.inlier.size() &&
         result.residuals[v].size() == views[v].image_points.size() &&
         result.inlier[v].size() == views[v].image_points.size();
}

ReportData GatherData(const ReportInput& input) {
  ReportData data;
  data.input = &input;
  data.result = input.result;
  data.views = input.views;
  const CalibrationResult& result = *input.result;
  const auto& views = *input.views;
  data.width = result.camera.width;
  data.height = result.camera.height;
  const auto& p = result.camera.params;
  data.camera_valid =
      static_cast<int>(p.size()) == CameraModelNumParams(result.camera.model) &&
      std::all_of(p.begin(), p.end(),
                  [](double x) { return std::isfinite(x); }) &&
      p[0] > 0 && p[1] > 0;
  const size_t num_views = views.size();
  data.view_number.resize(num_views);
  data.view_file.resize(num_views);
  for (size_t v = 0; v < num_views; ++v) {
    data.view_number[v] = static_cast<int>(v) + 1;
    data.view_file[v] = views[v].name;
  }
  for (size_t i = 0; i < input.images.size(); ++i) {
    const int v = input.images[i].view_index;
    if (v >= 0 && v < static_cast<int>(num_views)) {
      data.view_number[v] = static_cast<int>(i) + 1;
      data.view_file[v] = input.images[i].file;
    }
  }
  data.view_outliers.assign(num_views, 0);
  data.view_inliers.assign(num_views, 0);
  data.view_rms.assign(num_views, std::nan(""));
  for (size_t v = 0; v < num_views; ++v) {
    if (!ViewResidualsConsistent(result, views, v)) continue;
    if (v < result.view_rms_px.size()) data.view_rms[v] = result.view_rms_px[v];
    for (size_t i = 0; i < views[v].image_points.size(); ++i) {
      const Eigen::Vector2d& r = result.residuals[v][i];
      const Eigen::Vector2d& xy = views[v].image_points[i];
      if (!r.allFinite() || !xy.allFinite()) continue;
      ResidualSample s;
      s.view = static_cast<int>(v);
      s.detected = xy;
      s.residual = r;
      s.inlier = result.inlier[v][i];
      data.samples.push_back(s);
      if (s.inlier) {
        ++data.view_inliers[v];
        ++data.num_inliers;
      } else {
        ++data.view_outliers[v];
        ++data.num_outliers;
      }
    }
  }
  return data;
}

double Percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0;
  const size_t k = std::min(values.size() - 1,
                            static_cast<size_t>(fraction * values.size()));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

std::string FileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

// Markdown table cells must not contain '|' or line breaks.
std::string Cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') {
      out += "\\|";
    } else if (c == '\n' || c == '\r') {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out;
}

std::string Seconds(double s) {
  return s >= 0 ? StringPrintf("%.2f", s) : std::string("not measured");
}

// ---------------------------------------------------------------------------
// Image-shaped plots share one layout: the image rectangle scaled to the plot
// width, title above, axes in image pixels, room on the right for a colour
// bar and below for notes.

struct ImageLayout {
  cv::Mat canvas;
  plot::Frame frame;
  double scale = 1;  // canvas pixels per image pixel
  int notes_y = 0;   // baseline of the first note line below the axes
};

ImageLayout MakeImageLayout(int plot_width, int width, int height,
                            int note_lines) {
  constexpr int kLeft = 80, kRight = 150, kTop = 80, kBottom = 70;
  ImageLayout layout;
  const int area_width = std::max(100, plot_width - kLeft - kRight);
  layout.scale = static_cast<double>(area_width) / width;
  const int area_height =
      std::max(1, static_cast<int>(std::lround(height * layout.scale)));
  const int canvas_height = kTop + area_height + kBottom + 22 * note_lines;
  layout.canvas = cv::Mat(canvas_height, kLeft + area_width + kRight, CV_8UC3,
                          plot::kWhite);
  layout.frame.area = cv::Rect(kLeft, kTop, area_width, area_height);
  layout.frame.x_min = -0.5;
  layout.frame.x_max = width - 0.5;
  layout.frame.y_min = -0.5;
  layout.frame.y_max = height - 0.5;
  layout.frame.y_down = true;
  layout.notes_y = kTop + area_height + kBottom;
  return layout;
}

void DrawNote(ImageLayout* layout, int line, const std::string& text) {
  plot::DrawText(&layout->canvas, text,
                 cv::Point(layout->frame.area.x, layout->notes_y + 22 * line),
                 plot::kTickScale, cv::Scalar(60, 60, 60));
}

// Sub-pixel drawing in the plot area.
constexpr int kShift = 4;
cv::Point Fixed(cv::Point2d p) {
  return cv::Point(static_cast<int>(std::lround(p.x * (1 << kShift))),
                   static_cast<int>(std::lround(p.y * (1 << kShift))));
}

// The factor residual arrows are drawn with (options or automatic: the 95th
// percentile inlier residual becomes 3 % of the image width), and that
// percentile.
double ResidualArrowScale(const ReportData& data, const ReportOptions& options,
                          double* p95_px) {
  std::vector<double> norms;
  for (const ResidualSample& s : data.samples) {
    if (s.inlier) norms.push_back(s.residual.norm());
  }
  const double p95 = Percentile(norms, 0.95);
  if (p95_px) *p95_px = p95;
  if (options.residual_arrow_scale > 0) return options.residual_arrow_scale;
  return p95 > 0 ? plot::NiceNumber(0.03 * data.width / p95, true) : 1;
}

cv::Mat PlotResiduals(const ReportData& data, const ReportOptions& options) {
  ImageLayout layout =
      MakeImageLayout(options.image_plot_width, data.width, data.height, 3);
  cv::Mat& canvas = layout.canvas;
  const plot::Frame& frame = layout.frame;
  canvas(frame.area).setTo(cv::Scalar(246, 246, 246));

  double p95 = 0;
  const double arrow_scale = ResidualArrowScale(data, options, &p95);
  // Draw inside the plot area only: arrows of outliers may leave it.
  cv::Mat area = canvas(frame.area);
  const cv::Point2d origin(frame.area.x, frame.area.y);
  // Outliers can be off by tens of pixels: their arrows are cut to this
  // length (canvas pixels) so they do not hide the rest.
  const double outlier_cap =
      std::max(40.0, 3 * p95 * arrow_scale * layout.scale);
  int num_capped = 0;
  auto draw = [&](const ResidualSample& s, const cv::Scalar& colour) {
    const cv::Point2d from =
        frame.ToCanvas(s.detected.x(), s.detected.y()) - origin;
    const Eigen::Vector2d tip_image = s.detected + arrow_scale * s.residual;
    cv::Point2d to = frame.ToCanvas(tip_image.x(), tip_image.y()) - origin;
    double length = std::hypot(to.x - from.x, to.y - from.y);
    if (!s.inlier && length > outlier_cap) {
      to = from + (to - from) * (outlier_cap / length);
      length = outlier_cap;
      ++num_capped;
    }
    if (length < 1.5) {
      cv::circle(area, Fixed(from), 1 << kShift, colour, cv::FILLED,
                 cv::LINE_AA, kShift);
      return;
    }
    const double tip = std::min(0.35, 5.0 / length);
    cv::arrowedLine(area, Fixed(from), Fixed(to), colour, 1, cv::LINE_AA,
                    kShift, tip);
  };
  for (const ResidualSample& s : data.samples) {
    if (s.inlier) draw(s, plot::kBlue);
  }
  for (const ResidualSample& s : data.samples) {
    if (!s.inlier) draw(s, plot::kRed);
  }
  plot::DrawAxes(&canvas, frame, "x (px)", "y (px)", false);
  plot::DrawTitle(
      &canvas,
      StringPrintf("Reprojection residuals, arrows %gx longer than the error",
                   arrow_scale),
      StringPrintf("%d corners used (blue), %d outliers (red) from %d views; "
                   "RMS %.3f px per coordinate",
                   data.num_inliers, data.num_outliers,
                   data.result->num_views_used, data.result->rms_px));
  // Scale reference: an arrow for a round residual near the 95th percentile.
  const double reference = plot::NiceNumber(p95 > 0 ? p95 : 1.0, false);
  const double reference_length = reference * arrow_scale * layout.scale;
  const int y0 = layout.notes_y - 6;
  const int x0 = frame.area.x;
  cv::arrowedLine(canvas, Fixed(cv::Point2d(x0, y0)),
                  Fixed(cv::Point2d(x0 + reference_length, y0)), plot::kBlue, 1,
                  cv::LINE_AA, kShift,
                  std::min(0.35, 5.0 / std::max(1.0, reference_length)));
  plot::DrawText(
      &canvas,
      StringPrintf("= %g px residual (scale x%g)", reference, arrow_scale),
      {x0 + static_cast<int>(reference_length) + 10, y0 + 5}, plot::kTickScale,
      plot::kBlack);
  DrawNote(&layout, 1,
           "Each arrow starts at a detected corner and points to where the "
           "calibrated model reprojects it." +
               (num_capped > 0
                    ? StringPrintf(" %d outlier arrows are cut to %.0f px.",
                                   num_capped, outlier_cap)
                    : std::string()));
  DrawNote(&layout, 2,
           "Random directions = noise; arrows aligned over a region = model "
           "error there (try another model) or a bent board.");
  return canvas;
}

cv::Mat PlotCoverage(const ReportData& data, const ReportOptions& options) {
  ImageLayout layout =
      MakeImageLayout(options.image_plot_width, data.width, data.height, 2);
  cv::Mat& canvas = layout.canvas;
  const plot::Frame& frame = layout.frame;
  const double cell =
      static_cast<double>(data.width) / options.coverage_cells_across;
  const int cols = options.coverage_cells_across;
  const int rows = std::max(1, static_cast<int>(std::ceil(data.height / cell)));
  std::vector<int> counts(static_cast<size_t>(cols) * rows, 0);
  for (const ResidualSample& s : data.samples) {
    if (!s.inlier) continue;
    const int cx = static_cast<int>(std::floor((s.detected.x() + 0.5) / cell));
    const int cy = static_cast<int>(std::floor((s.detected.y() + 0.5) / cell));
    if (cx < 0 || cy < 0 || cx >= cols || cy >= rows) continue;
    ++counts[static_cast<size_t>(cy) * cols + cx];
  }
  const int max_count = *std::max_element(counts.begin(), counts.end());
  int empty = 0;
  cv::Mat area = canvas(frame.area);
  const cv::Point2d origin(frame.area.x, frame.area.y);
  for (int cy = 0; cy < rows; ++cy) {
    for (int cx = 0; cx < cols; ++cx) {
      const int n = counts[static_cast<size_t>(cy) * cols + cx];
      const double x0 = cx * cell - 0.5, y0 = cy * cell - 0.5;
      const double x1 = std::min((cx + 1) * cell, 1.0 * data.width) - 0.5;
      const double y1 = std::min((cy + 1) * cell, 1.0 * data.height) - 0.5;
      const cv::Point a = frame.ToCanvasPixel(x0, y0) - cv::Point(origin);
      const cv::Point b = frame.ToCanvasPixel(x1, y1) - cv::Point(origin);
      if (n == 0) ++empty;
      const cv::Scalar colour =
          n == 0 ? plot::kWhite
                 : plot::ColourMapValue(
                       cv::COLORMAP_VIRIDIS,
                       max_count > 1 ? (n - 1.0) / (max_count - 1) : 1.0);
      cv::rectangle(area, cv::Rect(a, b), colour, cv::FILLED);
      cv::rectangle(area, cv::Rect(a, b), plot::kLightGrey, 1);
    }
  }
  plot::DrawAxes(&canvas, frame, "x (px)", "y (px)", false);
  const cv::Rect bar(frame.area.x + frame.area.width + 20, frame.area.y, 22,
                     frame.area.height);
  plot::DrawColourBar(&canvas, bar, 1, std::max(2, max_count),
                      cv::COLORMAP_VIRIDIS, "used corners per cell (white: 0)");
  plot::DrawTitle(
      &canvas,
      StringPrintf("Coverage: used corners per %.0f x %.0f px cell", cell,
                   cell),
      StringPrintf("%d corners from %d views; %d of %d cells empty (white); "
                   "the calibration's coverage figure: %.0f %%",
                   data.num_inliers, data.result->num_views_used, empty,
                   rows * cols, 100.0 * data.result->coverage));
  DrawNote(&layout, 0,
           "The model is only trustworthy where corners were seen. Fill white "
           "cells (image corners and edges matter most for distortion)");
  DrawNote(&layout, 1, "by adding views that put the board there.");
  return canvas;
}

cv::Mat PlotDistortion(const ReportData& data, const ReportOptions& options) {
  const Camera& camera = data.result->camera;
  const bool fisheye = !CameraModelIsPinhole(camera.model);
  ImageLayout layout =
      MakeImageLayout(options.image_plot_width, data.width, data.height, 4);
  cv::Mat& canvas = layout.canvas;
  const plot::Frame& frame = layout.frame;

  // The widest ray angle of any used corner: beyond it the model is
  // extrapolated.
  double observed_theta = 0;
  for (const ResidualSample& s : data.samples) {
    double shift = 0, angle = 0;
    if (s.inlier && DistortionShift(camera, s.detected, &shift, &angle)) {
      observed_theta = std::max(observed_theta, angle);
    }
  }
  const bool have_observed = observed_theta > 0;
  const int step = options.distortion_grid_step_px;
  const int nx = (data.width - 1 + step - 1) / step + 1;
  const int ny = (data.height - 1 + step - 1) / step + 1;
  cv::Mat magnitude(ny, nx, CV_64F), theta(ny, nx, CV_64F);
  double max_magnitude = 0, max_theta = 0;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector2d pixel(std::min(i * step, data.width - 1),
                                  std::min(j * step, data.height - 1));
      double m = std::nan(""), t = std::nan("");
      if (DistortionShift(camera, pixel, &m, &t)) {
        // The colour scale covers the observed field only.
        if (!have_observed || t <= observed_theta) {
          max_magnitude = std::max(max_magnitude, m);
        }
        max_theta = std::max(max_theta, t);
      } else {
        m = t = std::nan("");
      }
      magnitude.at<double>(j, i) = m;
      theta.at<double>(j, i) = t;
    }
  }
  const double colour_max = max_magnitude > 0 ? max_magnitude : 1.0;
  // Bilinear upsampling to the plot area; a cell with a missing corner value
  // takes the nearest sample.
  const cv::Rect& a = frame.area;
  cv::Mat theta_plot(a.height, a.width, CV_64F);
  cv::Mat lut(256, 1, CV_8UC1);
  for (int i = 0; i < 256; ++i) lut.at<uint8_t>(i) = static_cast<uint8_t>(i);
  cv::Mat lut_colour;
  cv::applyColorMap(lut, lut_colour, cv::COLORMAP_VIRIDIS);
  auto sample = [&](const cv::Mat& grid, double gx, double gy) {
    const int i0 = std::clamp(static_cast<int>(std::floor(gx)), 0, nx - 1);
    const int j0 = std::clamp(static_cast<int>(std::floor(gy)), 0, ny - 1);
    const int i1 = std::min(i0 + 1, nx - 1), j1 = std::min(j0 + 1, ny - 1);
    const double fx = std::clamp(gx - i0, 0.0, 1.0);
    const double fy = std::clamp(gy - j0, 0.0, 1.0);
    const double v00 = grid.at<double>(j0, i0), v10 = grid.at<double>(j0, i1);
    const double v01 = grid.at<double>(j1, i0), v11 = grid.at<double>(j1, i1);
    if (std::isfinite(v00) && std::isfinite(v10) && std::isfinite(v01) &&
        std::isfinite(v11)) {
      return (1 - fy) * ((1 - fx) * v00 + fx * v10) +
             fy * ((1 - fx) * v01 + fx * v11);
    }
    return grid.at<double>(std::lround(fy) ? j1 : j0,
                           std::lround(fx) ? i1 : i0);
  };
  int num_without_ray = 0;
  for (int v = 0; v < a.height; ++v) {
    for (int u = 0; u < a.width; ++u) {
      const double x = (u + 0.5) / layout.scale - 0.5;
      const double y = (v + 0.5) / layout.scale - 0.5;
      const double gx = x / step, gy = y / step;
      const double m = sample(magnitude, gx, gy);
      const double t = sample(theta, gx, gy);
      theta_plot.at<double>(v, u) = t;
      cv::Vec3b colour(170, 170, 170);  // no ray
      if (!std::isfinite(m)) ++num_without_ray;
      if (std::isfinite(m)) {
        const int index = static_cast<int>(
            std::lround(std::clamp(m / colour_max, 0.0, 1.0) * 255));
        colour = lut_colour.at<cv::Vec3b>(index);
        // Fade the extrapolated field; hatch rays beyond 90 degrees.
        if (have_observed && std::isfinite(t) && t > observed_theta) {
          for (int c = 0; c < 3; ++c) {
            colour[c] = static_cast<uint8_t>((2 * colour[c] + 3 * 255) / 5);
          }
        }
        if (std::isfinite(t) && t > 90 && (u + v) % 10 < 2) {
          colour = cv::Vec3b((colour[0] + 255) / 2, (colour[1] + 255) / 2,
                             (colour[2] + 255) / 2);
        }
      }
      canvas.at<cv::Vec3b>(a.y + v, a.x + u) = colour;
    }
  }
  // Iso-angle lines: where the ray angle crosses a level between neighbours.
  const double level_step = max_theta > 75 ? 30 : 15;
  std::vector<double> levels;
  for (double level = level_step; level < max_theta; level += level_step) {
    levels.push_back(level);
  }
  if (fisheye && max_theta > 90 &&
      std::find(levels.begin(), levels.end(), 90.0) == levels.end()) {
    levels.push_back(90);
  }
  const Eigen::Vector2d principal(camera.params[2], camera.params[3]);
  const int label_row = std::clamp(
      static_cast<int>(std::lround(frame.ToCanvas(0, principal.y()).y)) - a.y,
      0, a.height - 1);
  for (double level : levels) {
    const cv::Vec3b line_colour(255, 255, 255);
    const int width = level == 90 ? 2 : 1;
    int label_u = -1, label_v = -1;
    for (int v = 0; v + 1 < a.height; ++v) {
      for (int u = 0; u + 1 < a.width; ++u) {
        const double t = theta_plot.at<double>(v, u);
        const double tr = theta_plot.at<double>(v, u + 1);
        const double td = theta_plot.at<double>(v + 1, u);
        if (!std::isfinite(t)) continue;
        const bool cross = (std::isfinite(tr) && (t < level) != (tr < level)) ||
                           (std::isfinite(td) && (t < level) != (td < level));
        if (!cross) continue;
        for (int dv = 0; dv < width; ++dv) {
          for (int du = 0; du < width; ++du) {
            canvas.at<cv::Vec3b>(a.y + v + dv, a.x + u + du) = line_colour;
          }
        }
        // Label where the line is nearest the principal point's row (the
        // right-most such place).
        if (label_v < 0 ||
            std::abs(v - label_row) < std::abs(label_v - label_row) ||
            (std::abs(v - label_row) == std::abs(label_v - label_row) &&
             u > label_u)) {
          label_u = u;
          label_v = v;
        }
      }
    }
    if (label_u >= 0) {
      const std::string text = StringPrintf("%.0f deg", level);
      const cv::Size size = plot::TextSize(text, plot::kTickScale);
      const cv::Point anchor(
          a.x + std::clamp(label_u + 4, 2, a.width - size.width - 4),
          a.y + std::clamp(label_v - 4, size.height + 4, a.height - 4));
      plot::DrawText(&canvas, text, anchor, plot::kTickScale, plot::kBlack,
                     Align::kLeft, 3);
      plot::DrawText(&canvas, text, anchor, plot::kTickScale, plot::kWhite);
    }
  }
  plot::DrawAxes(&canvas, frame, "x (px)", "y (px)", false);
  const cv::Rect bar(a.x + a.width + 20, a.y, 22, a.height);
  plot::DrawColourBar(&canvas, bar, 0, colour_max, cv::COLORMAP_VIRIDIS,
                      "distortion (px)");
  if (fisheye) {
    plot::DrawTitle(
        &canvas, "Distortion: shift from the equidistant fisheye r = f * theta",
        StringPrintf(
            "Pixels between where each pixel's ray lands with the model "
            "and with k1..k4 = 0 (same fx fy cx cy); max %.1f px",
            max_magnitude) +
            std::string(have_observed ? " where seen" : ""));
  } else {
    plot::DrawTitle(
        &canvas, "Distortion: shift from the distortion-free pinhole",
        StringPrintf(
            "Pixels between where each pixel's ray lands with the model "
            "and with no distortion (same fx fy cx cy); max %.1f px",
            max_magnitude) +
            std::string(have_observed ? " where seen" : ""));
  }
  DrawNote(&layout, 0,
           StringPrintf(
               "White lines: angle of the pixel's ray from the optical axis "
               "(every %.0f deg).%s",
               level_step,
               fisheye ? " Hatched: rays more than 90 deg off the axis "
                         "(behind the image plane)."
                       : ""));
  DrawNote(
      &layout, 1,
      StringPrintf("Red cross: principal point (%.1f, %.1f). Computed every %d "
                   "px and interpolated.",
                   principal.x(), principal.y(), step));
  int line = 2;
  if (have_observed && observed_theta < max_theta) {
    DrawNote(&layout, line++,
             StringPrintf(
                 "Faded: rays beyond %.1f deg, the widest angle of any used "
                 "corner; the model is extrapolated there (colours scaled "
                 "to the rest).",
                 observed_theta));
  }
  if (num_without_ray > 0) {
    DrawNote(&layout, line++,
             "Grey: the model has no ray for these pixels (its distortion "
             "folds back or cannot be inverted there).");
  }
  cv::drawMarker(canvas, frame.ToCanvasPixel(principal.x(), principal.y()),
                 plot::kRed, cv::MARKER_CROSS, 14, 2, cv::LINE_AA);
  return canvas;
}

cv::Mat PlotHistogram(const ReportData& data, const ReportOptions& options) {
  cv::Mat canvas(options.chart_height, options.chart_width, CV_8UC3,
                 plot::kWhite);
  // The histogram, and right of it one bar for everything beyond its range.
  constexpr int kOverflowWidth = 60;
  plot::Frame frame;
  frame.area =
      cv::Rect(90, 80, options.chart_width - 90 - 30 - kOverflowWidth - 20,
               options.chart_height - 80 - 70);
  std::vector<double> inlier_norms, outlier_norms;
  for (const ResidualSample& s : data.samples) {
    (s.inlier ? inlier_norms : outlier_norms).push_back(s.residual.norm());
  }
  const double sigma = data.result->rms_px;
  double range = std::max(1.15 * Percentile(inlier_norms, 0.995), 4 * sigma);
  if (!(range > 0)) range = 1;
  const int bins = options.histogram_bins;
  const double width = range / bins;
  std::vector<int> inliers(bins, 0), outliers(bins, 0);
  int inliers_beyond = 0, outliers_beyond = 0;
  auto add = [&](double norm, std::vector<int>* counts, int* beyond) {
    // Compared as doubles first: a huge residual would overflow the int.
    if (!(norm < bins * width)) {
      ++*beyond;
      return;
    }
    ++(*counts)[std::max(0, static_cast<int>(norm / width))];
  };
  for (double n : inlier_norms) add(n, &inliers, &inliers_beyond);
  for (double n : outlier_norms) add(n, &outliers, &outliers_beyond);
  // Expected counts for Gaussian noise of sigma per coordinate: the error
  // length then follows a Rayleigh distribution.
  std::vector<double> expected(bins, 0);
  int highest = std::max(1, inliers_beyond + outliers_beyond);
  for (int b = 0; b < bins; ++b) {
    highest = std::max(highest, inliers[b] + outliers[b]);
    if (sigma > 0) {
      auto cdf = [&](double r) {
        return 1 - std::exp(-r * r / (2 * sigma * sigma));
      };
      expected[b] =
          inlier_norms.size() * (cdf((b + 1) * width) - cdf(b * width));
    }
  }
  const double y_max =
      1.1 * std::max<double>(
                highest, *std::max_element(expected.begin(), expected.end()));
  frame.x_min = 0;
  frame.x_max = range;
  frame.y_min = 0;
  frame.y_max = y_max;
  plot::DrawAxes(&canvas, frame,
                 "residual length |reprojected - detected| (px)",
                 "corners per bin", true);
  for (int b = 0; b < bins; ++b) {
    const cv::Point p0 = frame.ToCanvasPixel(b * width, 0);
    const cv::Point p1 = frame.ToCanvasPixel((b + 1) * width, inliers[b]);
    const cv::Point p2 =
        frame.ToCanvasPixel((b + 1) * width, inliers[b] + outliers[b]);
    if (inliers[b] > 0) {
      cv::rectangle(canvas,
                    cv::Rect(p0.x + 1, p1.y, p1.x - p0.x - 1, p0.y - p1.y),
                    plot::kBlue, cv::FILLED);
    }
    if (outliers[b] > 0) {
      cv::rectangle(canvas,
                    cv::Rect(p0.x + 1, p2.y, p1.x - p0.x - 1, p1.y - p2.y),
                    plot::kRed, cv::FILLED);
    }
  }
  if (sigma > 0) {
    std::vector<cv::Point> curve;
    for (int b = 0; b < bins; ++b) {
      curve.push_back(frame.ToCanvasPixel((b + 0.5) * width, expected[b]));
    }
    cv::polylines(canvas, curve, false, plot::kOrange, 2, cv::LINE_AA);
  }
  cv::rectangle(canvas, frame.area, plot::kBlack, 1);
  plot::DrawTitle(
      &canvas, "Residual lengths",
      StringPrintf(
          "%zu used corners, %zu outliers; RMS %.3f px per coordinate; "
          "median length %.3f px, 95 %% below %.3f px",
          inlier_norms.size(), outlier_norms.size(), sigma,
          Percentile(inlier_norms, 0.5), Percentile(inlier_norms, 0.95)));
  // The overflow bar, on the histogram's count scale.
  const cv::Rect overflow(frame.area.x + frame.area.width + 20, frame.area.y,
                          kOverflowWidth, frame.area.height);
  cv::rectangle(canvas, overflow, plot::kBlack, 1);
  const int base_y = overflow.y + overflow.height;
  const int inlier_top = frame.ToCanvasPixel(0, inliers_beyond).y;
  const int outlier_top =
      frame.ToCanvasPixel(0, inliers_beyond + outliers_beyond).y;
  if (inliers_beyond > 0) {
    cv::rectangle(canvas,
                  cv::Rect(overflow.x + 10, inlier_top, overflow.width - 20,
                           base_y - inlier_top),
                  plot::kBlue, cv::FILLED);
  }
  if (outliers_beyond > 0) {
    cv::rectangle(canvas,
                  cv::Rect(overflow.x + 10, outlier_top, overflow.width - 20,
                           inlier_top - outlier_top),
                  plot::kRed, cv::FILLED);
  }
  plot::DrawText(&canvas, StringPrintf("> %.3g", range),
                 {overflow.x + overflow.width / 2, base_y + 21},
                 plot::kTickScale, plot::kBlack, Align::kCenter);
  plot::DrawText(&canvas, StringPrintf("%d", inliers_beyond + outliers_beyond),
                 {overflow.x + overflow.width / 2, outlier_top - 6},
                 plot::kTickScale, plot::kBlack, Align::kCenter);
  const std::vector<plot::LegendEntry> legend = {
      {plot::LegendEntry::Marker::kBox, plot::kBlue, "used corners"},
      {plot::LegendEntry::Marker::kBox, plot::kRed, "outliers (dropped)"},
      {plot::LegendEntry::Marker::kLine, plot::kOrange,
       "expected for Gaussian noise of sigma = RMS (Rayleigh)"}};
  const cv::Size legend_size = plot::LegendSize(legend);
  plot::DrawLegend(&canvas,
                   {frame.area.x + frame.area.width - legend_size.width - 10,
                    frame.area.y + 10},
                   legend);
  return canvas;
}

cv::Mat PlotViewRms(const ReportData& data, const ReportOptions& options) {
  cv::Mat canvas(options.chart_height, options.chart_width, CV_8UC3,
                 plot::kWhite);
  const int num_views = static_cast<int>(data.view_rms.size());
  plot::Frame frame;
  frame.area = cv::Rect(90, 80, options.chart_width - 90 - 30,
                        options.chart_height - 80 - 70);
  const double overall = data.result->rms_px;
  const double high = options.high_rms_factor * overall;
  double highest = high;
  int worst = -1;
  for (int v = 0; v < num_views; ++v) {
    if (std::isfinite(data.view_rms[v])) {
      if (worst < 0 || data.view_rms[v] > data.view_rms[worst]) worst = v;
      highest = std::max(highest, data.view_rms[v]);
    }
  }
  frame.x_min = 0.5;
  frame.x_max = std::max(1, num_views) + 0.5;
  frame.y_min = 0;
  frame.y_max = highest > 0 ? 1.12 * highest : 1;
  plot::DrawAxes(&canvas, frame, "", "RMS per coordinate (px)", true,
                 /*x_ticks=*/false);
  const double bar_width =
      std::max(1.0, 0.75 * frame.area.width / std::max(1, num_views));
  const int label_every = std::max(1, (num_views + 29) / 30);
  const double bar_pitch =
      static_cast<double>(frame.area.width) / std::max(1, num_views);
  int num_high = 0, num_unused = 0;
  for (int v = 0; v < num_views; ++v) {
    const cv::Point2d base = frame.ToCanvas(v + 1, 0);
    if (std::isfinite(data.view_rms[v])) {
      const bool is_high = data.view_rms[v] > high;
      num_high += is_high;
      const cv::Point2d top = frame.ToCanvas(v + 1, data.view_rms[v]);
      cv::rectangle(
          canvas,
          cv::Point(static_cast<int>(std::lround(base.x - bar_width / 2)),
                    static_cast<int>(std::lround(top.y))),
          cv::Point(static_cast<int>(std::lround(base.x + bar_width / 2)) - 1,
                    static_cast<int>(std::lround(base.y)) - 1),
          is_high ? plot::kOrange : plot::kBlue, cv::FILLED);
    } else {
      ++num_unused;
      plot::DrawCross(&canvas, base - cv::Point2d(0, 8), 5, plot::kGrey, 2);
    }
    const bool crowds_worst =
        v != worst && worst >= 0 && std::abs(v - worst) * bar_pitch < 34;
    if ((v % label_every == 0 && !crowds_worst) || v == worst) {
      plot::DrawText(&canvas, StringPrintf("%d", data.view_number[v]),
                     {static_cast<int>(std::lround(base.x)),
                      frame.area.y + frame.area.height + 20},
                     plot::kTickScale, v == worst ? plot::kRed : plot::kBlack,
                     Align::kCenter);
    }
  }
  plot::DrawDashedLine(&canvas, frame.ToCanvas(0.5, overall),
                       frame.ToCanvas(frame.x_max, overall), plot::kRed, 2, 8);
  plot::DrawDashedLine(&canvas, frame.ToCanvas(0.5, high),
                       frame.ToCanvas(frame.x_max, high), plot::kOrange, 1, 4);
  cv::rectangle(canvas, frame.area, plot::kBlack, 1);
  plot::DrawText(&canvas,
                 "image number (as in summary.md; red: the worst view)",
                 {frame.area.x + frame.area.width / 2,
                  frame.area.y + frame.area.height + 46},
                 plot::kLabelScale, plot::kBlack, Align::kCenter);
  plot::DrawTitle(
      &canvas, "Reprojection RMS per view",
      StringPrintf(
          "%d views: %d used, %d not used; %d above %.3gx the overall RMS",
          num_views, num_views - num_unused, num_unused, num_high,
          options.high_rms_factor));
  const std::vector<plot::LegendEntry> legend = {
      {plot::LegendEntry::Marker::kBox, plot::kBlue, "view RMS"},
      {plot::LegendEntry::Marker::kBox, plot::kOrange,
       StringPrintf("view RMS above %gx overall (dotted): check the image",
                    options.high_rms_factor)},
      {plot::LegendEntry::Marker::kDashedLine, plot::kRed,
       StringPrintf("overall RMS %.3f px", overall)},
      {plot::LegendEntry::Marker::kCross, plot::kGrey,
       "view not used (reason in summary.md)"}};
  const cv::Size legend_size = plot::LegendSize(legend);
  plot::DrawLegend(&canvas,
                   {frame.area.x + frame.area.width - legend_size.width - 10,
                    frame.area.y + 10},
                   legend);
  return canvas;
}

// The view image with the detected corners and their reprojections.
cv::Mat PlotOverlay(const ReportData& data, int v, const std::string& rank,
                    const ReportOptions& options, std::string* warning) {
  const CalibrationView& view = (*data.views)[v];
  const CalibrationResult& result = *data.result;
  cv::Mat grey;
  std::string load_error;
  if (!LoadGreyImage(data.view_file[v], options.load, &grey, &load_error)) {
    *warning = "overlay drawn without the image: " + load_error;
    grey = cv::Mat(data.height, data.width, CV_8UC1, cv::Scalar(128));
  } else if (grey.cols != data.width || grey.rows != data.height) {
    *warning = StringPrintf(
        "%s is %d x %d, the calibration %d x %d; overlay "
        "drawn at the image's size",
        data.view_file[v].c_str(), grey.cols, grey.rows, data.width,
        data.height);
  }
  const double scale = static_cast<double>(options.overlay_width) / grey.cols;
  const cv::Size scaled_size(
      options.overlay_width,
      std::max(1, static_cast<int>(std::lround(grey.rows * scale))));
  cv::Mat small;
  cv::resize(grey, small, scaled_size, 0, 0,
             scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  // Fade the photo so the markers stand out.
  cv::Mat faded;
  small.convertTo(faded, CV_8U, 0.6, 50);
  constexpr int kHeader = 70, kFooter = 40;
  cv::Mat canvas(small.rows + kHeader + kFooter, small.cols, CV_8UC3,
                 plot::kWhite);
  cv::cvtColor(faded, canvas(cv::Rect(0, kHeader, small.cols, small.rows)),
               cv::COLOR_GRAY2BGR);
  cv::Mat image_area = canvas(cv::Rect(0, kHeader, small.cols, small.rows));
  auto to_canvas = [&](const Eigen::Vector2d& p) {
    return cv::Point2d((p.x() + 0.5) * scale - 0.5,
                       (p.y() + 0.5) * scale - 0.5);
  };
  const int radius = 6;
  double p95 = 0;
  const double arrow_scale = ResidualArrowScale(data, options, &p95);
  const cv::Scalar arrow_colour(0, 210, 255);  // yellow
  int inliers = 0, outliers = 0;
  const bool has_pose = v < static_cast<int>(result.cam_from_board.size());
  const Eigen::Isometry3d pose =
      has_pose ? result.cam_from_board[v] : Eigen::Isometry3d::Identity();
  for (size_t i = 0; i < view.image_points.size(); ++i) {
    const Eigen::Vector2d& xy = view.image_points[i];
    if (!xy.allFinite()) continue;
    const bool inlier = result.inlier[v][i];
    (inlier ? inliers : outliers)++;
    const cv::Point2d detected = to_canvas(xy);
    cv::circle(image_area, Fixed(detected),
               (inlier ? radius : radius + 3) << kShift,
               inlier ? plot::kGreen : plot::kRed, 2, cv::LINE_AA, kShift);
    Eigen::Vector2d projected;
    if (data.camera_valid && has_pose &&
        result.camera.Project(pose * view.board_points[i], &projected) &&
        projected.allFinite()) {
      // The residual magnified like in residuals.png (outliers cut), then
      // the true reprojection.
      Eigen::Vector2d arrow = arrow_scale * (projected - xy);
      const double cap = std::max(40.0, 3 * p95 * arrow_scale);
      if (arrow.norm() > cap) arrow *= cap / arrow.norm();
      const cv::Point2d tip = to_canvas(xy + arrow);
      if (std::hypot(tip.x - detected.x, tip.y - detected.y) > 1.5) {
        cv::arrowedLine(image_area, Fixed(detected), Fixed(tip),
                        inlier ? arrow_colour : plot::kRed, 1, cv::LINE_AA,
                        kShift, 0.25);
      }
      plot::DrawCross(&image_area, to_canvas(projected), radius - 2,
                      cv::Scalar(200, 0, 200), 1);
    }
  }
  const std::string name = FileName(data.view_file[v]);
  plot::DrawText(&canvas,
                 StringPrintf("#%d %s  (%s)", data.view_number[v], name.c_str(),
                              rank.c_str()),
                 {12, 28}, plot::kTitleScale, plot::kBlack, Align::kLeft, 2);
  plot::DrawText(
      &canvas,
      StringPrintf(
          "view RMS %.3f px per coordinate (overall %.3f px); %d corners "
          "used, %d outliers",
          data.view_rms[v], result.rms_px, inliers, outliers),
      {12, 56}, plot::kLabelScale, cv::Scalar(60, 60, 60));
  // Legend line; each entry placed after the previous one's text.
  const int y = canvas.rows - 15;
  int x = 20;
  cv::circle(canvas, {x, y - 5}, 5, plot::kGreen, 2, cv::LINE_AA);
  x += 12;
  const std::string used_text = "detected corner (used)";
  plot::DrawText(&canvas, used_text, {x, y}, plot::kTickScale, plot::kBlack);
  x += plot::TextSize(used_text, plot::kTickScale).width + 30;
  cv::circle(canvas, {x, y - 5}, 5, plot::kRed, 2, cv::LINE_AA);
  x += 12;
  const std::string outlier_text = "outlier";
  plot::DrawText(&canvas, outlier_text, {x, y}, plot::kTickScale, plot::kBlack);
  x += plot::TextSize(outlier_text, plot::kTickScale).width + 30;
  plot::DrawCross(&canvas, cv::Point2d(x, y - 5), 5, cv::Scalar(200, 0, 200),
                  1);
  x += 12;
  const std::string cross_text = "reprojected by the calibrated model";
  plot::DrawText(&canvas, cross_text, {x, y}, plot::kTickScale, plot::kBlack);
  x += plot::TextSize(cross_text, plot::kTickScale).width + 30;
  cv::arrowedLine(canvas, {x - 6, y - 5}, {x + 22, y - 5}, arrow_colour, 2,
                  cv::LINE_AA, 0, 0.3);
  plot::DrawText(
      &canvas, StringPrintf("residual x%g (as in residuals.png)", arrow_scale),
      {x + 30, y}, plot::kTickScale, plot::kBlack);
  return canvas;
}

// ---------------------------------------------------------------------------
// Evidence plots (calib/evidence.h).

// A PixelMap drawn over the image rectangle (bilinear between samples,
// grey where the map has no value), with a colour bar from 0 to `colour_max`
// (0: the map's largest value).
cv::Mat PlotPixelMap(const ReportData& data, const ReportOptions& options,
                     const PixelMap& map, double colour_max,
                     const std::string& title, const std::string& subtitle,
                     const std::string& bar_label,
                     const std::vector<std::string>& notes) {
  ImageLayout layout =
      MakeImageLayout(options.image_plot_width, data.width, data.height,
                      static_cast<int>(notes.size()));
  cv::Mat& canvas = layout.canvas;
  const plot::Frame& frame = layout.frame;
  double largest = 0;
  for (double value : map.values) {
    if (std::isfinite(value)) largest = std::max(largest, value);
  }
  if (!(colour_max > 0)) colour_max = largest > 0 ? largest : 1.0;
  const cv::Rect& a = frame.area;
  const int step = std::max(1, map.step_px);
  auto value_at = [&](double x, double y) {
    const double gx = x / step, gy = y / step;
    const int i0 =
        std::clamp(static_cast<int>(std::floor(gx)), 0, map.cols - 1);
    const int j0 =
        std::clamp(static_cast<int>(std::floor(gy)), 0, map.rows - 1);
    const int i1 = std::min(i0 + 1, map.cols - 1);
    const int j1 = std::min(j0 + 1, map.rows - 1);
    const double fx = std::clamp(gx - i0, 0.0, 1.0);
    const double fy = std::clamp(gy - j0, 0.0, 1.0);
    const double v00 = map.At(i0, j0), v10 = map.At(i1, j0);
    const double v01 = map.At(i0, j1), v11 = map.At(i1, j1);
    if (std::isfinite(v00) && std::isfinite(v10) && std::isfinite(v01) &&
        std::isfinite(v11)) {
      return (1 - fy) * ((1 - fx) * v00 + fx * v10) +
             fy * ((1 - fx) * v01 + fx * v11);
    }
    return map.At(fx < 0.5 ? i0 : i1, fy < 0.5 ? j0 : j1);
  };
  cv::Mat lut(256, 1, CV_8UC1);
  for (int i = 0; i < 256; ++i) lut.at<uint8_t>(i) = static_cast<uint8_t>(i);
  cv::Mat lut_colour;
  cv::applyColorMap(lut, lut_colour, cv::COLORMAP_VIRIDIS);
  if (map.cols > 0 && map.rows > 0) {
    for (int v = 0; v < a.height; ++v) {
      for (int u = 0; u < a.width; ++u) {
        const double x = (u + 0.5) / layout.scale - 0.5;
        const double y = (v + 0.5) / layout.scale - 0.5;
        const double value = value_at(x, y);
        cv::Vec3b colour(170, 170, 170);
        if (std::isfinite(value)) {
          colour = lut_colour.at<cv::Vec3b>(static_cast<int>(
              std::lround(std::clamp(value / colour_max, 0.0, 1.0) * 255)));
        }
        canvas.at<cv::Vec3b>(a.y + v, a.x + u) = colour;
      }
    }
  }
  plot::DrawAxes(&canvas, frame, "x (px)", "y (px)", false);
  const cv::Rect bar(a.x + a.width + 20, a.y, 22, a.height);
  plot::DrawColourBar(&canvas, bar, 0, colour_max, cv::COLORMAP_VIRIDIS,
                      bar_label);
  plot::DrawTitle(&canvas, title, subtitle);
  for (size_t k = 0; k < notes.size(); ++k) {
    DrawNote(&layout, static_cast<int>(k), notes[k]);
  }
  return canvas;
}

cv::Mat PlotCrossValidation(const ReportData& data,
                            const ReportOptions& options,
                            const CrossValidation& cv) {
  double largest_band = 0;
  for (const AngleBand& band : cv.difference_bands) {
    if (band.count > 0) largest_band = std::max(largest_band, band.p95);
  }
  return PlotPixelMap(
      data, options, cv.difference_px, largest_band,
      "Cross-validation: projection difference between two halves of the views",
      StringPrintf("%d + %d views calibrated apart (alternating); far-field "
                   "difference after the best-fit rotation (%.3f deg)",
                   cv.views_a, cv.views_b, cv.rotation_deg),
      "|A - B| (px)",
      {"Each pixel's ray under half A, rotated into half B's frame and "
       "projected by B, against the pixel. Colours up to the largest "
       "band's 95th percentile.",
       "Noise alone predicts differences of the size in summary.md "
       "(\"expected\"); far larger ones are model error.",
       "Grey: beyond the widest field angle of any used corner (not "
       "compared) or no ray."});
}

cv::Mat PlotUncertainty(const ReportData& data, const ReportOptions& options,
                        const ProjectionUncertainty& uncertainty,
                        double max_angle_deg) {
  PixelMap map = uncertainty.sigma_px;
  double largest = 0;
  for (size_t k = 0; k < map.values.size(); ++k) {
    if (std::isfinite(map.values[k]) && std::isfinite(map.angle_deg[k]) &&
        map.angle_deg[k] <= max_angle_deg) {
      largest = std::max(largest, map.values[k]);
    }
  }
  return PlotPixelMap(
      data, options, map, largest,
      "Projection uncertainty (1 sigma) of a far point at each pixel",
      "sqrt(tr(C) / 2) per axis, C = A Sigma A^T, A = d pixel / d intrinsics "
      "(ray fixed) less the part a common rotation undoes",
      "1 sigma (px)",
      {StringPrintf("Colours scaled to the observed field (up to %.1f deg); "
                    "beyond it the value grows and saturates.",
                    max_angle_deg),
       "Sigma: the intrinsics' covariance marginal over the board poses, "
       "scaled by the residual variance."});
}

cv::Mat PlotResidualBins(const ReportData& data, const ReportOptions& options,
                         const SystematicResiduals& residuals) {
  (void)data;
  cv::Mat canvas(options.chart_height, options.chart_width, CV_8UC3,
                 plot::kWhite);
  const int half = options.chart_width / 2;
  auto panel = [&](const std::vector<ResidualBin>& bins, int x0,
                   const std::string& x_label) {
    plot::Frame frame;
    frame.area =
        cv::Rect(x0 + 90, 90, half - 90 - 30, options.chart_height - 90 - 80);
    double lo = 0, hi = 1, extent = 0.05;
    if (!bins.empty()) {
      lo = bins.front().lo;
      hi = bins.back().hi;
    }
    for (const ResidualBin& b : bins) {
      if (b.count < 2) continue;
      extent =
          std::max({extent, std::abs(b.mean_radial_px) + 2 * b.se_radial_px,
                    std::abs(b.mean_tangential_px) + 2 * b.se_tangential_px});
    }
    frame.x_min = lo;
    frame.x_max = hi > lo ? hi : lo + 1;
    frame.y_min = -1.1 * extent;
    frame.y_max = 1.1 * extent;
    plot::DrawAxes(&canvas, frame, x_label, "mean residual (px)", true);
    plot::DrawDashedLine(&canvas, frame.ToCanvas(frame.x_min, 0),
                         frame.ToCanvas(frame.x_max, 0), plot::kGrey, 1, 6);
    for (const ResidualBin& b : bins) {
      if (b.count < 2) continue;
      const double width = b.hi - b.lo;
      for (int c = 0; c < 2; ++c) {
        const double mean = c == 0 ? b.mean_radial_px : b.mean_tangential_px;
        const double se = c == 0 ? b.se_radial_px : b.se_tangential_px;
        const double x = b.lo + width * (c == 0 ? 0.4 : 0.6);
        const cv::Scalar colour = c == 0 ? plot::kBlue : plot::kOrange;
        cv::line(canvas, frame.ToCanvasPixel(x, mean - 2 * se),
                 frame.ToCanvasPixel(x, mean + 2 * se), colour, 2, cv::LINE_AA);
        cv::circle(canvas, frame.ToCanvasPixel(x, mean), 5, colour, cv::FILLED,
                   cv::LINE_AA);
      }
      plot::DrawText(&canvas, StringPrintf("%d", b.count),
                     frame.ToCanvasPixel(b.lo + 0.5 * width, frame.y_max) +
                         cv::Point(0, 14),
                     plot::kTickScale, plot::kGrey, Align::kCenter);
    }
    cv::rectangle(canvas, frame.area, plot::kBlack, 1);
  };
  panel(residuals.by_angle, 0, "field angle of the corner's ray (deg)");
  panel(residuals.by_distance, half,
        "distance of the corner from the camera (m)");
  plot::DrawTitle(
      &canvas, "Binned residual means (radial and tangential, +- 2 SE)",
      "A right model leaves every mean near zero; grey numbers: corners "
      "per bin");
  const std::vector<plot::LegendEntry> legend = {
      {plot::LegendEntry::Marker::kCircle, plot::kBlue,
       "radial (> 0: projected farther out than seen)"},
      {plot::LegendEntry::Marker::kCircle, plot::kOrange, "tangential"}};
  plot::DrawLegend(&canvas, {100, 100}, legend);
  return canvas;
}

std::string SafeStem(const std::string& file) {
  std::string stem = std::filesystem::path(file).stem().string();
  for (char& c : stem) {
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '-' ||
                    c == '_' || c == '.';
    if (!ok) c = '_';
  }
  return stem.empty() ? "view" : stem;
}

// Views for the overlays: the worst by RMS first (the second of them the
// view with the most outliers, when there are outliers, so the user sees
// what was dropped), then the best; each view once.
std::vector<std::pair<int, std::string>> PickOverlayViews(
    const ReportData& data, int count) {
  std::vector<int> used;
  for (size_t v = 0; v < data.view_rms.size(); ++v) {
    if (std::isfinite(data.view_rms[v])) used.push_back(static_cast<int>(v));
  }
  std::stable_sort(used.begin(), used.end(), [&](int a, int b) {
    return data.view_rms[a] > data.view_rms[b];
  });
  const int n = std::min<int>(count, used.size());
  const int num_worst = (n + 1) / 2;
  int most_outliers = -1;
  for (int v : used) {
    if (data.view_outliers[v] > 0 &&
        (most_outliers < 0 ||
         data.view_outliers[v] > data.view_outliers[most_outliers])) {
      most_outliers = v;
    }
  }
  std::vector<std::pair<int, std::string>> picked;
  std::set<int> taken;
  auto take = [&](int v, const std::string& rank) {
    if (taken.insert(v).second) picked.emplace_back(v, rank);
  };
  for (int k = 0; k < static_cast<int>(used.size()) &&
                  static_cast<int>(picked.size()) < num_worst;
       ++k) {
    if (k == 1 && most_outliers >= 0 && !taken.count(most_outliers)) {
      take(most_outliers, StringPrintf("most outliers: %d",
                                       data.view_outliers[most_outliers]));
      if (static_cast<int>(picked.size()) >= num_worst) break;
    }
    take(used[k],
         k == 0 ? "worst view" : StringPrintf("%d. worst view", k + 1));
  }
  for (int k = 0;
       k < static_cast<int>(used.size()) && static_cast<int>(picked.size()) < n;
       ++k) {
    take(used[used.size() - 1 - k],
         k == 0 ? "best view" : StringPrintf("%d. best view", k + 1));
  }
  return picked;
}

bool WritePng(const std::filesystem::path& path, const cv::Mat& image,
              std::string* error) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes)) {
    *error = "cannot encode " + path.string() + " as PNG";
    return false;
  }
  return WriteFileAtomically(path.string(),
                             std::string(bytes.begin(), bytes.end()), error);
}

}  // namespace

bool ReportOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  if (num_overlays < 0) return fail("num_overlays must be >= 0");
  if (num_worst_views < 0) return fail("num_worst_views must be >= 0");
  if (!(residual_arrow_scale >= 0) || !std::isfinite(residual_arrow_scale)) {
    return fail("residual_arrow_scale must be >= 0 (0 = automatic)");
  }
  if (histogram_bins < 2 || histogram_bins > 1000) {
    return fail("histogram_bins must be in [2, 1000]");
  }
  if (coverage_cells_across < 1 || coverage_cells_across > 1000) {
    return fail("coverage_cells_across must be in [1, 1000]");
  }
  if (distortion_grid_step_px < 1) {
    return fail("distortion_grid_step_px must be >= 1");
  }
  if (image_plot_width < 400 || image_plot_width > 10000) {
    return fail("image_plot_width must be in [400, 10000]");
  }
  if (chart_width < 400 || chart_width > 10000 || chart_height < 300 ||
      chart_height > 10000) {
    return fail(
        "chart_width must be in [400, 10000], chart_height in "
        "[300, 10000]");
  }
  if (overlay_width < 400 || overlay_width > 10000) {
    return fail("overlay_width must be in [400, 10000]");
  }
  if (!(high_rms_factor > 1) || !std::isfinite(high_rms_factor)) {
    return fail("high_rms_factor must be > 1");
  }
  std::string load_why;
  if (!load.Check(&load_why)) return fail("load: " + load_why);
  return true;
}

bool DistortionShift(const Camera& lens, const Eigen::Vector2d& pixel,
                     double* shift_px, double* ray_angle_deg) {
  if (static_cast<int>(lens.params.size()) !=
          CameraModelNumParams(lens.model) ||
      !pixel.allFinite()) {
    return false;
  }
  // Directions: a non-central camera's far-field part.
  const Camera camera = FarFieldCamera(lens);
  // Reference: the same camera without distortion, i.e. the pinhole
  // (pinhole models) or the equidistant fisheye r = f * theta (KB).
  double reference[16] = {};
  std::copy(camera.params.begin(), camera.params.begin() + kDistortionBegin,
            reference);
  Eigen::Vector3d ray;
  const UnprojectStatus status = camera.Unproject(pixel, &ray);
  Eigen::Vector2d ideal;
  if (!status.converged || !ray.allFinite() ||
      !ProjectPoint(camera.model, reference, ray, &ideal) ||
      !ideal.allFinite()) {
    return false;
  }
  // Beyond a fold of the distortion (its radial curve turns back) the
  // undistortion can still converge, to a ray the lens does not see there:
  // a ray slightly nearer the axis must land nearer the principal point.
  const double theta = std::atan2(ray.head<2>().norm(), ray.z());
  if (theta > 1e-6) {
    const double inner = theta * (1 - 1e-4);
    const Eigen::Vector2d direction = ray.head<2>().normalized();
    const Eigen::Vector3d inner_ray(std::sin(inner) * direction.x(),
                                    std::sin(inner) * direction.y(),
                                    std::cos(inner));
    Eigen::Vector2d inner_pixel;
    const auto& p = camera.params;
    auto radius = [&](const Eigen::Vector2d& q) {
      return std::hypot((q.x() - p[2]) / p[0], (q.y() - p[3]) / p[1]);
    };
    if (!camera.Project(inner_ray, &inner_pixel) ||
        !(radius(inner_pixel) < radius(pixel))) {
      return false;
    }
  }
  *shift_px = (ideal - pixel).norm();
  *ray_angle_deg = theta / kDeg;
  return true;
}

std::string FormatWithSigma(double value, double sigma,
                            std::string* sigma_text) {
  if (sigma > 0 && std::isfinite(sigma)) {
    const int decimals =
        std::clamp(2 - static_cast<int>(std::floor(std::log10(sigma))), 0, 12);
    if (sigma_text) *sigma_text = StringPrintf("%.*f", decimals, sigma);
    return StringPrintf("%.*f", decimals, value);
  }
  if (sigma_text) *sigma_text = "";
  return StringPrintf("%.8g", value);
}

namespace {

// The evidence section of summary.md.
std::string EvidenceMarkdown(const ReportInput& input) {
  const Evidence& evidence = *input.evidence;
  std::ostringstream md;
  md << "## Evidence\n\n";
  if (input.verdict != nullptr) {
    md << "Verdict **" << VerdictKindName(input.verdict->kind)
       << "**: " << input.verdict->reason
       << ". Next step: " << input.verdict->next_step << ".\n\n";
    if (input.verdict->findings.size() > 1) {
      md << "All findings:\n\n";
      for (const std::string& f : input.verdict->findings) {
        md << "- " << f << "\n";
      }
      md << "\n";
    }
  }
  const CrossValidation& cv = evidence.cross_validation;
  md << "### Cross-validation (two halves of the views)\n\n";
  if (cv.ok) {
    md << StringPrintf(
        "Views alternately into halves of %d and %d, each calibrated alone "
        "(RMS %.3f and %.3f px). Far-field projection difference after the "
        "best-fit rotation between the halves' camera frames (%.3f deg), "
        "against the difference the halves' own covariances predict (RMS "
        "length):\n\n",
        cv.views_a, cv.views_b, cv.rms_a_px, cv.rms_b_px, cv.rotation_deg);
    md << "| field angle | samples | difference median (px) | p95 (px) | "
          "expected median (px) | p95 (px) |\n|---|---:|---:|---:|---:|---:|\n";
    for (size_t b = 0; b < cv.difference_bands.size(); ++b) {
      const AngleBand& d = cv.difference_bands[b];
      const AngleBand& e = cv.expected_bands[b];
      if (d.count == 0) continue;
      md << StringPrintf("| %.0f-%.0f deg | %d | %.3f | %.3f | %.3f | %.3f |\n",
                         d.lo_deg, d.hi_deg, d.count, d.median, d.p95, e.median,
                         e.p95);
    }
    md << "\n";
  } else {
    md << "Not available: " << Cell(cv.error) << "\n\n";
  }
  md << "### Projection uncertainty\n\n";
  const ProjectionUncertainty& u = evidence.uncertainty;
  if (u.ok) {
    md << "1-sigma of the projection of a far point, per image axis "
          "(sqrt(tr(C) / 2) of its 2 x 2 covariance, from the intrinsics' "
          "covariance marginal over the poses); the largest over the "
          "directions at each angle that land in the image. First column: "
          "after the best-fit common rotation of the camera frame over the "
          "observed field (a shift of cx, cy that a rotation of all board "
          "poses undoes is no uncertainty of the lens; the map and the "
          "verdict use this). Second: the ray held fixed in the camera "
          "frame.\n\n| where | 1 sigma (px) | in the camera frame (px) "
          "|\n|---|---:|---:|\n";
    for (const UncertaintyPoint& p : u.points) {
      md << "| " << p.label << " | "
         << (p.in_image ? StringPrintf("%.4f | %.4f", p.sigma_px,
                                       p.camera_frame_sigma_px)
                        : std::string("not in image | not in image"))
         << " |\n";
    }
    md << "\n";
  } else {
    md << "Not available (no covariance).\n\n";
  }
  md << "### Systematic residuals\n\n"
        "Mean residual (projected minus detected) of the inlier corners, "
        "split into the component away from the principal point (radial) and "
        "across it (tangential), +- its standard error (corners taken as "
        "independent).\n\n";
  auto table = [&](const std::vector<ResidualBin>& bins, const char* what,
                   bool metres) {
    md << "| " << what << " | corners | radial (px) | tangential (px) |\n"
       << "|---|---:|---:|---:|\n";
    for (const ResidualBin& b : bins) {
      md << (metres ? StringPrintf("| %.3f-%.3f m", b.lo, b.hi)
                    : StringPrintf("| %.0f-%.0f deg", b.lo, b.hi))
         << StringPrintf(" | %d | %+.4f ± %.4f | %+.4f ± %.4f |\n", b.count,
                         b.mean_radial_px, b.se_radial_px, b.mean_tangential_px,
                         b.se_tangential_px);
    }
    md << "\n";
  };
  table(evidence.residuals.by_angle, "field angle", false);
  table(evidence.residuals.by_distance, "distance from the camera", true);
  md << StringPrintf(
      "Evidence computed in %.2f s (of which the two half "
      "calibrations %.2f s).\n\n",
      evidence.seconds, cv.seconds);
  return md.str();
}

}  // namespace

std::string ReportMarkdown(const ReportInput& input,
                           const ReportOptions& options,
                           const std::vector<std::string>& png_files) {
  if (input.result == nullptr || input.views == nullptr ||
      input.result->view_used.size() != input.views->size()) {
    return "# Calibration report\n\nNo consistent calibration result was "
           "given.\n";
  }
  const ReportData data = GatherData(input);
  const CalibrationResult& result = *input.result;
  const Camera& camera = result.camera;
  std::ostringstream md;
  md << "# Calibration report\n\n";
  if (input.verdict != nullptr) md << "**" << input.verdict->Line() << "**\n\n";
  md << "Model **" << CameraModelName(camera.model) << "**, image "
     << camera.width << " x " << camera.height
     << " px; board: " << BoardTypeName(input.board.type) << ", "
     << input.board.cols << " x " << input.board.rows << " inner corners, "
     << StringPrintf("%g", input.board.tile_size_m * 1000) << " mm tiles.\n\n";
  if (!input.calibration_ok) {
    md << "> **Calibration failed:** " << input.calibration_error
       << "\n>\n> The figures below show what the failed attempt reached; do "
          "not use them.\n\n";
  }

  md << "## Result\n\n| | |\n|---|---|\n";
  md << StringPrintf(
      "| RMS reprojection error | %.4f px per coordinate (%.4f px "
      "per corner, OpenCV's figure) |\n",
      result.rms_px, result.rms_point_px);
  md << StringPrintf(
      "| images | %zu, %d used as views (%d views passed to the "
      "calibration) |\n",
      input.images.size(), result.num_views_used,
      static_cast<int>(input.views->size()));
  md << StringPrintf(
      "| corners used | %d (%d outliers dropped in %d rejection "
      "round%s) |\n",
      result.num_corners_used, result.num_outliers, result.outlier_rounds,
      result.outlier_rounds == 1 ? "" : "s");
  md << StringPrintf("| board orientations | normals spread over %.1f deg |\n",
                     result.orientation_spread_deg);
  md << StringPrintf(
      "| coverage | %.0f %% of the cells of an 8 x 8 grid over the "
      "image hold corners |\n",
      100 * result.coverage);
  md << "| initialisation | " << Cell(result.initialization_method) << " |\n";
  md << StringPrintf("| solver | %d iterations, ", result.iterations)
     << Cell(result.termination) << " |\n\n";

  md << "## Parameters (value ± 1 sigma)\n\n";
  md << "| parameter | value | ± 1 sigma | unit |\n|---|---:|---:|---|\n";
  const std::vector<std::string> names = CameraModelParamNames(camera.model);
  for (size_t k = 0; k < names.size() && k < camera.params.size(); ++k) {
    const bool fixed = k < result.param_fixed.size() && result.param_fixed[k];
    const double sigma = k < result.param_stddev.size() && result.covariance_ok
                             ? result.param_stddev[k]
                             : 0.0;
    std::string sigma_text;
    const std::string value =
        FormatWithSigma(camera.params[k], fixed ? 0.0 : sigma, &sigma_text);
    if (fixed) sigma_text = "fixed";
    if (sigma_text.empty()) sigma_text = "n/a";
    md << "| " << names[k] << " | " << value << " | " << sigma_text << " | "
       << (static_cast<int>(k) < kDistortionBegin ? "px" : "") << " |\n";
  }
  md << "\nSigma comes from the covariance of the bundle adjustment scaled by "
        "the residual variance: it measures how well the views pin the "
        "parameters down given the corner noise, not whether the model "
        "suits the lens.";
  if (!result.covariance_ok) md << " **The covariance could not be computed.**";
  md << "\n\n";

  if (!input.model_selection.empty()) {
    md << "## Model selection\n\n```\n" << input.model_selection << "```\n\n";
  }
  if (input.evidence != nullptr) md << EvidenceMarkdown(input);

  // Worst views.
  std::vector<int> used;
  for (size_t v = 0; v < data.view_rms.size(); ++v) {
    if (std::isfinite(data.view_rms[v])) used.push_back(static_cast<int>(v));
  }
  std::stable_sort(used.begin(), used.end(), [&](int a, int b) {
    return data.view_rms[a] > data.view_rms[b];
  });
  md << "## Worst views\n\n";
  if (!used.empty()) {
    md << StringPrintf(
        "Highest RMS of the %zu used views (overall %.3f px).\n\n", used.size(),
        result.rms_px);
  }
  if (used.empty()) {
    md << "No view was used.\n\n";
  } else {
    md << "| # | image | RMS (px) | corners used | outliers | |\n"
          "|---:|---|---:|---:|---:|---|\n";
    for (int k = 0;
         k < options.num_worst_views && k < static_cast<int>(used.size());
         ++k) {
      const int v = used[k];
      const bool high =
          data.view_rms[v] > options.high_rms_factor * result.rms_px;
      md << "| " << data.view_number[v] << " | "
         << Cell(FileName(data.view_file[v])) << " | "
         << StringPrintf("%.3f", data.view_rms[v]) << " | "
         << data.view_inliers[v] << " | " << data.view_outliers[v] << " | "
         << (high ? StringPrintf("above %gx the overall RMS: check the image "
                                 "(blur, a bent or moving board, wrong ids)",
                                 options.high_rms_factor)
                  : std::string(""))
         << " |\n";
    }
    md << "\n";
  }

  md << "## Images\n\n";
  md << "| # | file | outcome | corners detected | corners used | RMS (px) | "
        "details |\n|---:|---|---|---:|---:|---:|---|\n";
  for (size_t i = 0; i < input.images.size(); ++i) {
    const ReportImage& image = input.images[i];
    const int v = image.view_index;
    const bool is_view = v >= 0 && v < static_cast<int>(data.view_rms.size());
    const bool used_view = is_view && std::isfinite(data.view_rms[v]);
    std::string outcome = image.outcome;
    std::string reason = image.reason;
    // The calibration may drop a view the pipeline found usable.
    if (is_view && !used_view &&
        v < static_cast<int>(result.view_reason.size()) &&
        !result.view_reason[v].empty()) {
      if (!reason.empty()) reason += "; ";
      reason += result.view_reason[v];
    }
    md << "| " << i + 1 << " | " << Cell(image.file) << " | " << Cell(outcome)
       << " | " << image.corners_detected << " | "
       << (used_view ? data.view_inliers[v] : image.corners_used) << " | "
       << (used_view ? StringPrintf("%.3f", data.view_rms[v])
                     : std::string("-"))
       << " | " << Cell(reason) << " |\n";
  }
  md << "\n";

  md << "## Time\n\n| step | seconds |\n|---|---:|\n";
  md << "| reading and decoding image files | " << Seconds(input.seconds_load)
     << " |\n";
  md << "| detection (corners, grid, board ids) | "
     << Seconds(input.seconds_detect) << " |\n";
  md << "| calibration | " << Seconds(input.seconds_calibrate) << " |\n";
  md << "| whole run | " << Seconds(input.seconds_total) << " |\n\n";
  if (input.threads > 0) {
    md << "Reading and detection ran on " << input.threads
       << " threads; their times are summed over the images, so together "
          "they can exceed the whole run.\n\n";
  }

  md << "## Plots\n\n";
  if (png_files.empty()) md << "No plots were drawn.\n";
  std::vector<std::string> overlays;
  for (const std::string& file : png_files) {
    if (file.rfind("overlay_", 0) == 0) {
      overlays.push_back(file);
      continue;
    }
    md << "- `" << file << "`: ";
    if (file == "residuals.png") {
      md << "an arrow from every detected corner towards its reprojection, "
            "magnified (factor in the title). Random directions are noise; "
            "arrows that line up over a region show model error there. "
            "Outliers are red.\n";
    } else if (file == "residual_histogram.png") {
      md << "lengths of the residuals; for Gaussian corner noise the bars "
            "follow the orange curve. A long tail means bad corners or a "
            "model that does not fit.\n";
    } else if (file == "view_rms.png") {
      md << "RMS of each view; orange bars stand out and deserve a look at "
            "the image (blur, motion, a bent board).\n";
    } else if (file == "coverage.png") {
      md << "used corners per image cell; white cells saw no corner and the "
            "model is extrapolated there. Fill them with more views, "
            "especially near the image corners.\n";
    } else if (file == "distortion.png") {
      md << "how far the model moves each pixel compared with the same "
            "camera without distortion"
         << (CameraModelIsPinhole(camera.model)
                 ? " (a pinhole)"
                 : " (the equidistant fisheye r = f * theta); hatched: rays "
                   "more than 90 deg off the axis")
         << ". White lines mark the angle of the ray from the optical "
            "axis.\n";
    } else if (file == "cross_validation.png") {
      md << "how far the two halves of the views, calibrated apart, "
            "disagree on where a far point projects (after the best-fit "
            "rotation between their camera frames). Compare with the "
            "expected figures in the evidence section.\n";
    } else if (file == "uncertainty.png") {
      md << "the 1-sigma of the projection of a far point at each pixel, "
            "from the parameter covariance: how well the views pin the "
            "model down there (not whether the model suits the lens).\n";
    } else if (file == "residual_bins.png") {
      md << "residual means by field angle and by board distance with "
            "+- 2 standard errors; means away from zero are model error.\n";
    } else {
      md << "\n";
    }
  }
  if (!overlays.empty()) {
    // PickOverlayViews order: the worst views first, then the best.
    const size_t worst = (overlays.size() + 1) / 2;
    md << "- ";
    for (size_t k = 0; k < overlays.size(); ++k) {
      md << (k == 0       ? ""
             : k == worst ? " and "
                          : ", ")
         << "`" << overlays[k] << "`"
         << (k + 1 == worst ? " (the worst views by RMS)" : "")
         << (k + 1 == overlays.size() && k >= worst ? " (the best)" : "");
    }
    md << ": the view image with its detected corners (green circles; red = "
          "outlier) and their reprojections by the calibrated model (magenta "
          "crosses), which should sit inside the circles.\n";
  }
  return md.str();
}

bool WriteReport(const std::string& dir, const ReportInput& input,
                 const ReportOptions& options, std::string* error,
                 ReportSummary* summary) {
  std::string local_error;
  if (error == nullptr) error = &local_error;
  ReportSummary local_summary;
  if (summary == nullptr) summary = &local_summary;
  *summary = ReportSummary();
  std::string why;
  if (!options.Check(&why)) {
    *error = "report options: " + why;
    return false;
  }
  if (input.result == nullptr || input.views == nullptr) {
    *error = "report for " + dir + ": no calibration result or views given";
    return false;
  }
  const CalibrationResult& result = *input.result;
  if (result.view_used.size() != input.views->size()) {
    *error = StringPrintf(
        "report for %s: the result has %zu views, the view list "
        "%zu",
        dir.c_str(), result.view_used.size(), input.views->size());
    return false;
  }
  const int width = result.camera.width, height = result.camera.height;
  const bool size_ok = width > 0 && height > 0 && width <= kMaxImageSide &&
                       height <= kMaxImageSide;

  std::error_code ec;
  const std::filesystem::path folder(dir);
  if (dir.empty()) {
    *error = "report folder: empty path";
    return false;
  }
  std::filesystem::create_directories(folder, ec);
  if (ec || !std::filesystem::is_directory(folder)) {
    *error = "cannot create the report folder " + dir +
             (ec ? ": " + ec.message() : ": a file of that name exists");
    return false;
  }

  const ReportData data = GatherData(input);
  std::vector<std::string> png_files;
  auto write_png = [&](const std::string& name, const cv::Mat& image) {
    if (!WritePng(folder / name, image, error)) return false;
    summary->files.push_back(name);
    png_files.push_back(name);
    return true;
  };
  if (!size_ok) {
    summary->warnings.push_back(
        StringPrintf("no plots: the result's image size %d x %d is not valid",
                     width, height));
  } else {
    if (!write_png("residuals.png", PlotResiduals(data, options)) ||
        !write_png("residual_histogram.png", PlotHistogram(data, options)) ||
        !write_png("view_rms.png", PlotViewRms(data, options)) ||
        !write_png("coverage.png", PlotCoverage(data, options))) {
      return false;
    }
    if (data.camera_valid) {
      if (!write_png("distortion.png", PlotDistortion(data, options))) {
        return false;
      }
    } else {
      summary->warnings.push_back(
          "no distortion map: the result's camera parameters are not valid");
    }
    if (input.evidence != nullptr && data.camera_valid) {
      const Evidence& evidence = *input.evidence;
      if (evidence.cross_validation.ok &&
          !write_png(
              "cross_validation.png",
              PlotCrossValidation(data, options, evidence.cross_validation))) {
        return false;
      }
      if (evidence.uncertainty.ok &&
          !write_png("uncertainty.png",
                     PlotUncertainty(data, options, evidence.uncertainty,
                                     evidence.residuals.max_angle_deg))) {
        return false;
      }
      if (!write_png("residual_bins.png",
                     PlotResidualBins(data, options, evidence.residuals))) {
        return false;
      }
    }
    std::set<std::string> taken;
    for (const auto& [v, rank] : PickOverlayViews(data, options.num_overlays)) {
      std::string name = "overlay_" + SafeStem(data.view_file[v]);
      for (int k = 2; taken.count(name); ++k) {
        name =
            "overlay_" + SafeStem(data.view_file[v]) + StringPrintf("_%d", k);
      }
      taken.insert(name);
      std::string warning;
      const cv::Mat overlay = PlotOverlay(data, v, rank, options, &warning);
      if (!warning.empty()) summary->warnings.push_back(warning);
      if (!write_png(name + ".png", overlay)) return false;
    }
  }
  const std::string markdown = ReportMarkdown(input, options, png_files);
  if (!WriteFileAtomically((folder / "summary.md").string(), markdown, error)) {
    return false;
  }
  summary->files.insert(summary->files.begin(), "summary.md");
  return true;
}

}  // namespace puzzlecal
