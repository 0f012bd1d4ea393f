#include "report/report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>

#include "formats/png_writer.h"
#include "report/advice_report.h"
#include "report/html.h"
#include "report/image_chart.h"
#include "report/overlay.h"
#include "report/plot.h"
#include "util/angles.h"
#include "util/atomic_file.h"
#include "util/failure.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

using plot::Colour;

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
  const ImageLayout layout =
      MakeImageLayout(options.image_plot_width, data.width, data.height, 3);
  plot::Chart chart(layout.canvas.width, layout.canvas.height);
  SetImageArea(layout, data.width, data.height, &chart);
  chart.FilledRect(-0.5, -0.5, data.width - 0.5, data.height - 0.5,
                   Colour::kPaper);
  double p95 = 0;
  const double arrow_scale = ResidualArrowScale(data, options, &p95);
  // Outliers can be off by tens of pixels: their arrows are cut to this
  // length (canvas pixels) so they do not hide the rest.
  const double outlier_cap =
      std::max(40.0, 3 * p95 * arrow_scale * layout.scale);
  int num_capped = 0;
  std::vector<double> dot_x, dot_y;
  auto draw = [&](const ResidualSample& s, Colour colour) {
    Eigen::Vector2d arrow = arrow_scale * s.residual;
    double length = arrow.norm() * layout.scale;
    if (!s.inlier && length > outlier_cap) {
      arrow *= outlier_cap / length;
      length = outlier_cap;
      ++num_capped;
    }
    if (length < 1.5) {
      dot_x.push_back(s.detected.x());
      dot_y.push_back(s.detected.y());
      return;
    }
    const Eigen::Vector2d tip = s.detected + arrow;
    chart.Arrow(s.detected.x(), s.detected.y(), tip.x(), tip.y(), colour, 5);
  };
  for (const ResidualSample& s : data.samples) {
    if (s.inlier) draw(s, Colour::kBlue);
  }
  chart.Markers(dot_x, dot_y, plot::LegendEntry::Sample::kCircle, Colour::kBlue,
                3);
  for (const ResidualSample& s : data.samples) {
    if (!s.inlier) draw(s, Colour::kRed);
  }
  chart.Axes("x (px)", "y (px)", false);
  chart.Title(
      StringPrintf("Reprojection residuals, arrows %gx longer than the error",
                   arrow_scale),
      StringPrintf("%d corners used (blue), %d outliers (red) from %d views; "
                   "RMS %.3f px per coordinate",
                   data.num_inliers, data.num_outliers,
                   data.result->num_views_used, data.result->rms_px));
  // Scale reference: an arrow for a round residual near the 95th percentile.
  const double reference = plot::NiceNumber(p95 > 0 ? p95 : 1.0, false);
  const double reference_length = reference * arrow_scale * layout.scale;
  const cv::Point2d from(layout.area.x, layout.notes_y - 6);
  chart.CanvasArrow(from, from + cv::Point2d(reference_length, 0),
                    Colour::kBlue, 5);
  chart.CanvasText(
      from.x + reference_length + 10, layout.notes_y,
      StringPrintf("= %g px residual (scale x%g)", reference, arrow_scale),
      plot::kTickHeight, Colour::kBlack);
  DrawNote(layout, 1,
           "Each arrow starts at a detected corner and points to where the "
           "calibrated model reprojects it." +
               (num_capped > 0
                    ? StringPrintf(" %d outlier arrows are cut to %.0f px.",
                                   num_capped, outlier_cap)
                    : std::string()),
           &chart);
  DrawNote(layout, 2,
           "Random directions = noise; arrows aligned over a region = model "
           "error there (try another model) or a bent board.",
           &chart);
  return chart.Finish();
}

cv::Mat PlotCoverage(const ReportData& data, const ReportOptions& options) {
  const ImageLayout layout =
      MakeImageLayout(options.image_plot_width, data.width, data.height, 2);
  const double cell =
      static_cast<double>(data.width) / options.coverage_cells_across;
  const int cols = options.coverage_cells_across;
  const int rows = std::max(1, static_cast<int>(std::ceil(data.height / cell)));
  cv::Mat counts(rows, cols, CV_64F, cv::Scalar(0));
  for (const ResidualSample& s : data.samples) {
    if (!s.inlier) continue;
    const int cx = static_cast<int>(std::floor((s.detected.x() + 0.5) / cell));
    const int cy = static_cast<int>(std::floor((s.detected.y() + 0.5) / cell));
    if (cx < 0 || cy < 0 || cx >= cols || cy >= rows) continue;
    counts.at<double>(cy, cx) += 1;
  }
  double max_count = 0;
  cv::minMaxLoc(counts, nullptr, &max_count);
  const int empty = rows * cols - cv::countNonZero(counts);
  plot::Chart chart(layout.canvas.width, layout.canvas.height);
  SetImageArea(layout, data.width, data.height, &chart);
  // Empty cells stay white.
  const double colour_max = std::max(2.0, max_count);
  chart.Cells(counts, -0.5, -0.5, cell, cell, 1, colour_max);
  for (int cx = 1; cx < cols; ++cx) {
    chart.Polyline({cx * cell - 0.5, cx * cell - 0.5},
                   {-0.5, data.height - 0.5}, Colour::kLightGrey, 1);
  }
  for (int cy = 1; cy < rows; ++cy) {
    chart.Polyline({-0.5, data.width - 0.5}, {cy * cell - 0.5, cy * cell - 0.5},
                   Colour::kLightGrey, 1);
  }
  chart.Axes("x (px)", "y (px)", false);
  chart.ColourBar(1, colour_max, "used corners per cell (white: 0)");
  chart.Title(
      StringPrintf("Coverage: used corners per %.0f x %.0f px cell", cell,
                   cell),
      StringPrintf("%d corners from %d views; %d of %d cells empty (white); "
                   "the calibration's coverage figure: %.0f %%",
                   data.num_inliers, data.result->num_views_used, empty,
                   rows * cols, 100.0 * data.result->coverage));
  DrawNote(layout, 0,
           "The model is only trustworthy where corners were seen. Fill white "
           "cells (image corners and edges matter most for distortion)",
           &chart);
  DrawNote(layout, 1, "by adding views that put the board there.", &chart);
  return chart.Finish();
}

cv::Mat PlotDistortion(const ReportData& data, const ReportOptions& options) {
  const Camera& camera = data.result->camera;
  const bool fisheye = !CameraModelIsPinhole(camera.model);
  const ImageLayout layout =
      MakeImageLayout(options.image_plot_width, data.width, data.height, 4);

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
  int num_without_ray = 0;
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
        ++num_without_ray;
      }
      magnitude.at<double>(j, i) = m;
      theta.at<double>(j, i) = t;
    }
  }
  const double colour_max = max_magnitude > 0 ? max_magnitude : 1.0;
  const std::vector<double> xs = SamplePositions(nx, step, data.width);
  const std::vector<double> ys = SamplePositions(ny, step, data.height);

  plot::Chart chart(layout.canvas.width, layout.canvas.height,
                    /*antialias=*/false);
  SetImageArea(layout, data.width, data.height, &chart);
  chart.FilledRect(-0.5, -0.5, data.width - 0.5, data.height - 0.5,
                   Colour::kNoData);
  chart.Shades(magnitude, xs, ys, 0, colour_max);
  // Fade the extrapolated field; hatch rays beyond 90 degrees.
  if (have_observed && observed_theta < max_theta) {
    chart.FillWhere(theta, xs, ys, observed_theta, 1e9, Colour::kFade, false);
  }
  if (fisheye && max_theta > 90) {
    chart.FillWhere(theta, xs, ys, 90, 1e9, Colour::kWhite, true);
  }
  // Iso-angle lines.
  const double level_step = max_theta > 75 ? 30 : 15;
  std::vector<double> levels;
  for (double level = level_step; level < max_theta; level += level_step) {
    levels.push_back(level);
  }
  if (fisheye && max_theta > 90 &&
      std::find(levels.begin(), levels.end(), 90.0) == levels.end()) {
    levels.push_back(90);
  }
  chart.Contours(theta, xs, ys, levels, Colour::kWhite, 1);
  const Eigen::Vector2d principal(camera.params[2], camera.params[3]);
  chart.Markers({principal.x()}, {principal.y()},
                plot::LegendEntry::Sample::kCross, Colour::kRed, 18);
  chart.Axes("x (px)", "y (px)", false);
  chart.ColourBar(0, colour_max, "distortion (px)");
  const std::string max_text = StringPrintf("max %.1f px", max_magnitude) +
                               std::string(have_observed ? " where seen" : "");
  if (fisheye) {
    chart.Title("Distortion: shift from the equidistant fisheye r = f * theta",
                "Pixels between where each pixel's ray lands with the model "
                "and with k1..k4 = 0 (same fx fy cx cy); " +
                    max_text);
  } else {
    chart.Title("Distortion: shift from the distortion-free pinhole",
                "Pixels between where each pixel's ray lands with the model "
                "and with no distortion (same fx fy cx cy); " +
                    max_text);
  }
  DrawNote(layout, 0,
           StringPrintf(
               "White lines: angle of the pixel's ray from the optical axis "
               "in deg (every %.0f deg).%s",
               level_step,
               fisheye ? " Hatched: rays more than 90 deg off the axis "
                         "(behind the image plane)."
                       : ""),
           &chart);
  DrawNote(
      layout, 1,
      StringPrintf("Red cross: principal point (%.1f, %.1f). Computed every %d "
                   "px and interpolated.",
                   principal.x(), principal.y(), step),
      &chart);
  int line = 2;
  if (have_observed && observed_theta < max_theta) {
    DrawNote(layout, line++,
             StringPrintf(
                 "Faded: rays beyond %.1f deg, the widest angle of any used "
                 "corner; the model is extrapolated there (colours scaled "
                 "to the rest).",
                 observed_theta),
             &chart);
  }
  if (num_without_ray > 0) {
    DrawNote(layout, line++,
             "Grey: the model has no ray for these pixels (its distortion "
             "folds back or cannot be inverted there).",
             &chart);
  }
  return chart.Finish();
}

cv::Mat PlotHistogram(const ReportData& data, const ReportOptions& options) {
  // The histogram, and right of it one bar for everything beyond its range.
  constexpr int kOverflowWidth = 60;
  const cv::Rect area(90, 80,
                      options.chart_width - 90 - 30 - kOverflowWidth - 20,
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

  plot::Chart chart(options.chart_width, options.chart_height);
  chart.SetArea(area, 0, range, 0, y_max);
  chart.Axes("residual length |reprojected - detected| (px)", "corners per bin",
             true);
  // A pixel of white between the bars.
  const double gap = range / area.width;
  for (int b = 0; b < bins; ++b) {
    if (inliers[b] > 0) {
      chart.FilledRect(b * width + gap, 0, (b + 1) * width, inliers[b],
                       Colour::kBlue);
    }
    if (outliers[b] > 0) {
      chart.FilledRect(b * width + gap, inliers[b], (b + 1) * width,
                       inliers[b] + outliers[b], Colour::kRed);
    }
  }
  if (sigma > 0) {
    std::vector<double> x(bins);
    for (int b = 0; b < bins; ++b) x[b] = (b + 0.5) * width;
    chart.Polyline(x, expected, Colour::kOrange, 2);
  }
  chart.Legend(
      {{plot::LegendEntry::Sample::kBox, Colour::kBlue, "used corners"},
       {plot::LegendEntry::Sample::kBox, Colour::kRed, "outliers (dropped)"},
       {plot::LegendEntry::Sample::kLine, Colour::kOrange,
        "expected for Gaussian noise of sigma = RMS (Rayleigh)"}});
  chart.Title(
      "Residual lengths",
      StringPrintf(
          "%zu used corners, %zu outliers; RMS %.3f px per coordinate; "
          "median length %.3f px, 95 %% below %.3f px",
          inlier_norms.size(), outlier_norms.size(), sigma,
          Percentile(inlier_norms, 0.5), Percentile(inlier_norms, 0.95)));
  // The overflow bar, on the histogram's count scale.
  const cv::Rect overflow(area.x + area.width + 20, area.y, kOverflowWidth,
                          area.height);
  chart.SetArea(overflow, 0, 1, 0, y_max);
  chart.Frame();
  if (inliers_beyond > 0) {
    chart.FilledRect(0.17, 0, 0.83, inliers_beyond, Colour::kBlue);
  }
  if (outliers_beyond > 0) {
    chart.FilledRect(0.17, inliers_beyond, 0.83,
                     inliers_beyond + outliers_beyond, Colour::kRed);
  }
  chart.CanvasText(
      overflow.x + overflow.width / 2.0, overflow.y + overflow.height + 21,
      StringPrintf("> %.3g", range), plot::kTickHeight, Colour::kBlack, 0.5);
  chart.CanvasText(overflow.x + overflow.width / 2.0,
                   chart.ToCanvas(0, inliers_beyond + outliers_beyond).y - 6,
                   StringPrintf("%d", inliers_beyond + outliers_beyond),
                   plot::kTickHeight, Colour::kBlack, 0.5);
  return chart.Finish();
}

// The verdict's judgement of view v (null: no verdict, or none for v).
const ViewJudgement* JudgementOf(const ReportData& data, size_t v) {
  const Verdict* verdict = data.input->verdict;
  if (verdict == nullptr || v >= verdict->views.size()) return nullptr;
  return &verdict->views[v];
}

// Whether the verdict names view v (bad detections or a view-level error).
bool StandsOut(const ReportData& data, size_t v) {
  const ViewJudgement* judged = JudgementOf(data, v);
  return judged != nullptr && (judged->standing == ViewStanding::kStandsOut ||
                               judged->standing == ViewStanding::kViewError);
}

// The used views (and views the verdict names though the calibration
// dropped them), worst first: the views the verdict names, then by inlier
// RMS. The table of worst views and the overlays follow this order.
std::vector<int> ViewsWorstFirst(const ReportData& data) {
  std::vector<int> views;
  for (size_t v = 0; v < data.view_rms.size(); ++v) {
    if (std::isfinite(data.view_rms[v]) || StandsOut(data, v)) {
      views.push_back(static_cast<int>(v));
    }
  }
  auto rms_or_zero = [&](int v) {
    return std::isfinite(data.view_rms[v]) ? data.view_rms[v] : 0.0;
  };
  std::stable_sort(views.begin(), views.end(), [&](int a, int b) {
    if (StandsOut(data, a) != StandsOut(data, b)) return StandsOut(data, a);
    return rms_or_zero(a) > rms_or_zero(b);
  });
  return views;
}

cv::Mat PlotViewRms(const ReportData& data, const ReportOptions& options) {
  const int num_views = static_cast<int>(data.view_rms.size());
  const cv::Rect area(90, 80, options.chart_width - 90 - 30,
                      options.chart_height - 80 - 70);
  const double overall = data.result->rms_px;
  // The verdict's limit for a view's inliers (0: no verdict).
  const double limit = data.input->verdict != nullptr
                           ? data.input->verdict->view_rms_limit_px
                           : 0.0;
  double highest = std::max(limit, overall);
  int worst = -1;
  for (int v = 0; v < num_views; ++v) {
    if (std::isfinite(data.view_rms[v])) {
      if (worst < 0 || data.view_rms[v] > data.view_rms[worst]) worst = v;
      highest = std::max(highest, data.view_rms[v]);
    }
  }
  const double x_max = std::max(1, num_views) + 0.5;
  const double y_max = highest > 0 ? 1.12 * highest : 1;
  plot::Chart chart(options.chart_width, options.chart_height);
  chart.SetArea(area, 0.5, x_max, 0, y_max);
  chart.Axes("", "RMS of the inliers per coordinate (px)", true,
             /*x_numbers=*/false);
  const int label_every = std::max(1, (num_views + 29) / 30);
  const double bar_pitch =
      static_cast<double>(area.width) / std::max(1, num_views);
  int num_named = 0, num_unused = 0;
  std::vector<double> unused_x, unused_y;
  for (int v = 0; v < num_views; ++v) {
    if (std::isfinite(data.view_rms[v])) {
      const bool named = StandsOut(data, v);
      num_named += named;
      chart.FilledRect(v + 1 - 0.375, 0, v + 1 + 0.375, data.view_rms[v],
                       named ? Colour::kOrange : Colour::kBlue);
    } else {
      ++num_unused;
      unused_x.push_back(v + 1);
      unused_y.push_back(8 * y_max / area.height);
    }
    const bool crowds_worst =
        v != worst && worst >= 0 && std::abs(v - worst) * bar_pitch < 34;
    if ((v % label_every == 0 && !crowds_worst) || v == worst) {
      chart.CanvasText(chart.ToCanvas(v + 1, 0).x, area.y + area.height + 20,
                       StringPrintf("%d", data.view_number[v]),
                       plot::kTickHeight,
                       v == worst ? Colour::kRed : Colour::kBlack, 0.5);
    }
  }
  chart.Markers(unused_x, unused_y, plot::LegendEntry::Sample::kCross,
                Colour::kGrey, 14);
  chart.Polyline({0.5, x_max}, {overall, overall}, Colour::kRed, 2, true);
  if (limit > 0) {
    chart.Polyline({0.5, x_max}, {limit, limit}, Colour::kOrange, 1, true);
  }
  chart.CanvasText(area.x + area.width / 2.0, area.y + area.height + 46,
                   "image number (as in summary.md; red: the worst view)",
                   plot::kLabelHeight, Colour::kBlack, 0.5);
  chart.Title(
      "Reprojection RMS per view",
      data.input->verdict != nullptr
          ? StringPrintf("%d views: %d used, %d not used; %d named by the "
                         "verdict",
                         num_views, num_views - num_unused, num_unused,
                         num_named)
          : StringPrintf("%d views: %d used, %d not used (no verdict)",
                         num_views, num_views - num_unused, num_unused));
  chart.Legend(
      {{plot::LegendEntry::Sample::kBox, Colour::kBlue, "view RMS"},
       {plot::LegendEntry::Sample::kBox, Colour::kOrange,
        limit > 0 ? StringPrintf("named by the verdict (inliers above %.3f "
                                 "px, dashed; many rejected corners; a "
                                 "smooth field)",
                                 limit)
                  : std::string("named by the verdict")},
       {plot::LegendEntry::Sample::kDashedLine, Colour::kRed,
        StringPrintf("overall RMS %.3f px", overall)},
       {plot::LegendEntry::Sample::kCross, Colour::kGrey,
        "view not used (reason in summary.md)"}});
  return chart.Finish();
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
  const cv::Scalar green(60, 170, 40), red(40, 40, 215), magenta(200, 0, 200);
  const cv::Scalar yellow(0, 210, 255);
  const double radius = 6;
  double p95 = 0;
  const double arrow_scale = ResidualArrowScale(data, options, &p95);
  int inliers = 0, outliers = 0;
  const bool has_pose = v < static_cast<int>(result.cam_from_board.size());
  const Eigen::Isometry3d pose =
      has_pose ? result.cam_from_board[v] : Eigen::Isometry3d::Identity();
  Overlay overlay;
  for (size_t i = 0; i < view.image_points.size(); ++i) {
    const Eigen::Vector2d& xy = view.image_points[i];
    if (!xy.allFinite()) continue;
    const bool inlier = result.inlier[v][i];
    (inlier ? inliers : outliers)++;
    OverlayMark circle;
    circle.kind = OverlayMark::Kind::kCircle;
    circle.at = xy;
    circle.size = inlier ? radius : radius + 3;
    circle.thickness = 2;
    circle.colour = inlier ? green : red;
    overlay.marks.push_back(circle);
    Eigen::Vector2d projected;
    if (data.camera_valid && has_pose &&
        result.camera.Project(pose * view.board_points[i], &projected) &&
        projected.allFinite()) {
      // The residual magnified like in residuals.png (outliers cut, in
      // overlay pixels), then the true reprojection.
      Eigen::Vector2d arrow = arrow_scale * (projected - xy);
      const double cap = std::max(40.0, 3 * p95 * arrow_scale) / scale;
      if (arrow.norm() > cap) arrow *= cap / arrow.norm();
      OverlayMark residual;
      residual.kind = OverlayMark::Kind::kArrow;
      residual.at = xy;
      residual.to = xy + arrow;
      residual.colour = inlier ? yellow : red;
      overlay.marks.push_back(residual);
      OverlayMark cross;
      cross.kind = OverlayMark::Kind::kCross;
      cross.at = projected;
      cross.size = radius - 2;
      cross.colour = magenta;
      overlay.marks.push_back(cross);
    }
  }
  overlay.title =
      StringPrintf("#%d %s  (%s)", data.view_number[v],
                   FileName(data.view_file[v]).c_str(), rank.c_str());
  overlay.subtitle = StringPrintf(
      "view RMS %.3f px per coordinate (overall %.3f px); %d corners used, "
      "%d outliers",
      data.view_rms[v], result.rms_px, inliers, outliers);
  overlay.legend = {
      {OverlayMark::Kind::kCircle, green, "detected corner (used)"},
      {OverlayMark::Kind::kCircle, red, "outlier"},
      {OverlayMark::Kind::kCross, magenta,
       "reprojected by the calibrated model"},
      {OverlayMark::Kind::kArrow, yellow,
       StringPrintf("residual x%g (as in residuals.png)", arrow_scale)}};
  OverlayOptions overlay_options;
  overlay_options.width = options.overlay_width;
  overlay_options.fade = 0.6;  // the markers stand out on a faded photo
  return DrawOverlay(grey, overlay, overlay_options);
}

// ---------------------------------------------------------------------------
// Evidence plots (evidence/evidence.h).

// A PixelMap drawn over the image rectangle (image_chart.h), with a colour
// bar from 0 to `colour_max` (0: the map's largest value).
cv::Mat PlotPixelMap(const ReportData& data, const ReportOptions& options,
                     const PixelMap& map, double colour_max,
                     const std::string& title, const std::string& subtitle,
                     const std::string& bar_label,
                     const std::vector<std::string>& notes) {
  PixelMapChart chart;
  chart.title = title;
  chart.subtitle = subtitle;
  chart.bar_label = bar_label;
  chart.notes = notes;
  chart.colour_max = colour_max;
  chart.plot_width = options.image_plot_width;
  return DrawPixelMapChart(map, data.width, data.height, chart);
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
      (cv.splits > 1
           ? StringPrintf("%d + %d views calibrated apart (the first of %d "
                          "splits); ",
                          cv.views_a, cv.views_b, cv.splits)
           : StringPrintf("%d + %d views calibrated apart (alternating); ",
                          cv.views_a, cv.views_b)) +
          StringPrintf("far-field difference after the best-fit rotation "
                       "(%.3f deg)",
                       cv.rotation_deg),
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
  plot::Chart chart(options.chart_width, options.chart_height);
  const int half = options.chart_width / 2;
  auto panel = [&](const std::vector<ResidualBin>& bins, int x0,
                   const std::string& x_label, bool legend) {
    const cv::Rect area(x0 + 90, 90, half - 90 - 30,
                        options.chart_height - 90 - 80);
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
    chart.SetArea(area, lo, hi > lo ? hi : lo + 1, -1.1 * extent, 1.1 * extent);
    chart.Axes(x_label, "mean residual (px)", true);
    chart.Polyline({lo, hi > lo ? hi : lo + 1}, {0, 0}, Colour::kGrey, 1, true);
    for (int c = 0; c < 2; ++c) {
      std::vector<double> x, mean, y_lo, y_hi;
      for (const ResidualBin& b : bins) {
        if (b.count < 2) continue;
        const double m = c == 0 ? b.mean_radial_px : b.mean_tangential_px;
        const double se = c == 0 ? b.se_radial_px : b.se_tangential_px;
        x.push_back(b.lo + (b.hi - b.lo) * (c == 0 ? 0.4 : 0.6));
        mean.push_back(m);
        y_lo.push_back(m - 2 * se);
        y_hi.push_back(m + 2 * se);
      }
      const Colour colour = c == 0 ? Colour::kBlue : Colour::kOrange;
      chart.ErrorBars(x, y_lo, y_hi, colour, 2);
      chart.Markers(x, mean, plot::LegendEntry::Sample::kCircle, colour, 12);
    }
    for (const ResidualBin& b : bins) {
      if (b.count < 2) continue;
      chart.CanvasText(chart.ToCanvas(0.5 * (b.lo + b.hi), 0).x, area.y + 16,
                       StringPrintf("%d", b.count), plot::kTickHeight,
                       Colour::kGrey, 0.5);
    }
    if (legend) {
      chart.Legend(
          {{plot::LegendEntry::Sample::kCircle, Colour::kBlue,
            "radial (> 0: projected farther out than seen)"},
           {plot::LegendEntry::Sample::kCircle, Colour::kOrange, "tangential"}},
          plot::Chart::Corner::kBottomLeft);
    }
  };
  panel(residuals.by_angle, 0, "field angle of the corner's ray (deg)", true);
  panel(residuals.by_distance, half,
        "distance of the corner from the camera (m)", false);
  chart.Title(
      "Binned residual means (radial and tangential, +- 2 SE)",
      "A right model leaves every mean near zero; grey numbers: corners "
      "per bin");
  return chart.Finish();
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
  // Overlays show views with inliers only.
  std::vector<int> used = ViewsWorstFirst(data);
  used.erase(
      std::remove_if(used.begin(), used.end(),
                     [&](int v) { return !std::isfinite(data.view_rms[v]); }),
      used.end());
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
    take(used[k], StandsOut(data, used[k]) ? std::string("named by the verdict")
                  : k == 0                 ? std::string("worst view")
                           : StringPrintf("%d. worst view", k + 1));
  }
  for (int k = 0;
       k < static_cast<int>(used.size()) && static_cast<int>(picked.size()) < n;
       ++k) {
    take(used[used.size() - 1 - k],
         k == 0 ? "best view" : StringPrintf("%d. best view", k + 1));
  }
  return picked;
}

}  // namespace

std::string ReportImage::OutcomeText() const {
  switch (use) {
    case ViewUse::kUsed:
      return "used";
    case ViewUse::kDropped:
      return "not used by the calibration";
    case ViewUse::kNoView:
      break;
  }
  return ImageOutcomeName(outcome);
}

std::vector<ReportImage> MakeReportImages(
    const std::vector<ImageResult>& images, const CalibrationResult* result) {
  std::vector<ReportImage> lines;
  for (const ImageResult& image : images) {
    ReportImage line;
    line.file = image.file;
    line.outcome = image.outcome;
    line.reason = image.reason;
    line.corners_detected = static_cast<int>(image.corners.size());
    line.view_index = image.view_index;
    const int v = line.view_index;
    if (v >= 0 && result != nullptr) {
      if (!result->view_used[v]) {
        line.use = ViewUse::kDropped;
        line.reason = result->view_reason[v];
      } else {
        for (bool inlier : result->inlier[v]) line.corners_used += inlier;
        line.use = ViewUse::kUsed;
      }
    }
    lines.push_back(line);
  }
  return lines;
}

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
  *ray_angle_deg = theta / kDegree;
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

std::string EvidenceMarkdown(const Evidence& evidence, const Verdict* verdict,
                             int heading_level) {
  const std::string heading(std::clamp(heading_level, 1, 5), '#');
  const std::string sub = heading + "#";
  std::ostringstream md;
  md << heading << " Evidence\n\n";
  if (verdict != nullptr) {
    md << "Verdict **" << VerdictKindName(verdict->kind)
       << "**: " << verdict->reason << ". Next step: " << verdict->next_step
       << ".\n\n";
    if (verdict->findings.size() > 1) {
      md << "All findings:\n\n";
      for (const std::string& f : verdict->findings) {
        md << "- " << f << "\n";
      }
      md << "\n";
    }
    if (!verdict->notes.empty()) {
      md << "Seen and handled:\n\n";
      for (const std::string& note : verdict->notes) {
        md << "- " << note << "\n";
      }
      md << "\n";
    }
  }
  const CrossValidation& cv = evidence.cross_validation;
  md << sub << " Cross-validation (two halves of the views)\n\n";
  if (cv.ok) {
    if (cv.splits > 1) {
      md << StringPrintf(
          "The views split into two halves in %d ways (each split orders "
          "the views by a hash of their corners and alternates, so the "
          "order of the files does not matter); each half calibrated alone "
          "(first split: %d and %d views, RMS %.3f and %.3f px). Far-field "
          "projection difference after the best-fit rotation between the "
          "halves' camera frames (first split: %.3f deg), against the "
          "difference the halves' own covariances predict (RMS length); "
          "each band's figures are those of the split with the median "
          "ratio:\n\n",
          cv.splits, cv.views_a, cv.views_b, cv.rms_a_px, cv.rms_b_px,
          cv.rotation_deg);
    } else {
      md << StringPrintf(
          "Views alternately into halves of %d and %d, each calibrated "
          "alone (RMS %.3f and %.3f px). Far-field projection difference "
          "after the best-fit rotation between the halves' camera frames "
          "(%.3f deg), against the difference the halves' own covariances "
          "predict (RMS length):\n\n",
          cv.views_a, cv.views_b, cv.rms_a_px, cv.rms_b_px, cv.rotation_deg);
    }
    md << "| field angle | samples | difference median (px) | p95 (px) | "
          "expected median (px) | p95 (px) |\n|---|---:|---:|---:|---:|---:|\n";
    for (size_t b = 0; b < cv.difference_bands.size(); ++b) {
      const AngleBand& d = cv.difference_bands[b];
      const AngleBand& e = cv.expected_bands[b];
      if (d.count == 0) continue;
      md << StringPrintf("| %s | %d | %.3f | %.3f | %.3f | %.3f |\n",
                         BandLabel(d).c_str(), d.count, d.median, d.p95,
                         e.median, e.p95);
    }
    md << "\n";
  } else {
    md << "Not available: " << Cell(cv.error) << "\n\n";
  }
  md << sub << " Projection uncertainty\n\n";
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
  md << sub << " Systematic residuals\n\n"
     << "Mean residual (projected minus detected) of the inlier corners, "
        "split into the component away from the principal point (radial) and "
        "across it (tangential), +- its standard error (corners taken as "
        "independent).\n\n";
  auto table = [&](const std::vector<ResidualBin>& bins, const char* what,
                   bool metres) {
    md << "| " << what << " | corners | radial (px) | tangential (px) |\n"
       << "|---|---:|---:|---:|\n";
    for (const ResidualBin& b : bins) {
      md << (metres ? StringPrintf("| %.3f-%.3f m", b.lo, b.hi)
                    : "| " + AngleRangeLabel(b.lo, b.hi))
         << StringPrintf(" | %d | %+.4f ± %.4f | %+.4f ± %.4f |\n", b.count,
                         b.mean_radial_px, b.se_radial_px, b.mean_tangential_px,
                         b.se_tangential_px);
    }
    md << "\n";
  };
  table(evidence.residuals.by_angle, "field angle", false);
  table(evidence.residuals.by_distance, "distance from the camera", true);
  const ViewConsistency& vc = evidence.view_consistency;
  md << sub << " The views one by one\n\n";
  if (vc.ok) {
    md << StringPrintf(
        "Focal length fitted per view (its pose free, the other intrinsics "
        "held): over %d views it spreads %.2f times its standard deviation "
        "(chi-square %.1f for %d degrees of freedom); a focal length of "
        "their own moves the views' corners by %.3f px RMS, noise alone "
        "%.3f px. Residual field: a smooth field across the board fitted to "
        "all of a view's corners' residuals (rejected ones included), "
        "against what noise gives and what it leaves. The views by how far "
        "their focal length differs:\n\n",
        static_cast<int>(vc.views.size()), vc.spread_ratio, vc.chi2, vc.dof,
        vc.effect_px, vc.expected_effect_px);
    md << "| photo | corners | f (px) | z | field (px) | noise gives (px) "
          "| rest (px) | rejected (following the field) |\n"
          "|---|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const ViewFocal& f :
         MostInconsistentViews(vc, static_cast<int>(vc.views.size()))) {
      md << "| " << Cell(f.name)
         << StringPrintf(" | %d | %.1f ± %.1f | %+.1f", f.corners,
                         vc.focal_px * f.scale, vc.focal_px * f.scale_sigma,
                         f.z);
      const ViewField* field = nullptr;
      for (const ViewField& candidate : vc.fields) {
        if (candidate.view == f.view) field = &candidate;
      }
      if (field != nullptr) {
        md << StringPrintf(" | %.3f | %.3f | %.3f | %d (%d) |\n",
                           field->smooth_rms_px, field->expected_smooth_px,
                           field->rest_rms_px, field->outliers,
                           field->outliers_explained);
      } else {
        md << " | | | | |\n";
      }
    }
    md << "\n";
  } else {
    md << "Not available: " << Cell(vc.error) << "\n\n";
  }
  md << StringPrintf(
      "Evidence computed in %.2f s (of which the two half "
      "calibrations %.2f s).\n\n",
      evidence.seconds, cv.seconds);
  return md.str();
}

std::string EvidenceChartDescription(const std::string& chart) {
  if (chart == kCrossValidationChart) {
    return "how far the two halves of the views, calibrated apart, "
           "disagree on where a far point projects (after the best-fit "
           "rotation between their camera frames). Compare with the "
           "expected figures in the evidence section.";
  }
  if (chart == kUncertaintyChart) {
    return "the 1-sigma of the projection of a far point at each pixel, "
           "from the parameter covariance: how well the views pin the "
           "model down there (not whether the model suits the lens).";
  }
  if (chart == kResidualBinsChart) {
    return "residual means by field angle and by board distance with "
           "+- 2 standard errors; means away from zero are model error.";
  }
  return "";
}

namespace {

// ---- the sections of summary.md ----

// The title, the verdict, the model and board, and a failed calibration.
void MarkdownHeader(const ReportInput& input, std::ostringstream& md) {
  const Camera& camera = input.result->camera;
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
}

// RMS, counts, orientations, coverage, initialisation and solver.
void MarkdownResult(const ReportInput& input, std::ostringstream& md) {
  const CalibrationResult& result = *input.result;
  md << "## Result\n\n| what | value |\n|---|---|\n";
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
}

// Every parameter with its sigma (or "fixed").
void MarkdownParameters(const CalibrationResult& result,
                        std::ostringstream& md) {
  const Camera& camera = result.camera;
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
}

// The views the verdict names (bad detections, view-level errors), then
// the other used views of highest inlier RMS, up to num_worst_views rows in
// all (every named view gets a row).
void MarkdownWorstViews(const ReportData& data, const CalibrationResult& result,
                        const ReportOptions& options, std::ostringstream& md) {
  const std::vector<int> used = ViewsWorstFirst(data);
  md << "## Worst views\n\n";
  if (used.empty()) {
    md << "No view was used.\n\n";
    return;
  }
  const Verdict* verdict = data.input->verdict;
  const auto num_used = std::count_if(used.begin(), used.end(), [&](int v) {
    return std::isfinite(data.view_rms[v]);
  });
  md << StringPrintf(
      "The views the verdict names, then the highest inlier "
      "RMS of the %zu used views (overall %.3f px",
      static_cast<size_t>(num_used), result.rms_px);
  if (verdict != nullptr && verdict->view_rms_limit_px > 0) {
    md << StringPrintf(
        "; the median view's %.3f px, a view's inliers stand "
        "out above %.3f px",
        verdict->median_view_rms_px, verdict->view_rms_limit_px);
  }
  md << ").\n\n";
  md << "| # | image | RMS (px) | corners used | outliers | verdict |\n"
        "|---:|---|---:|---:|---:|---|\n";
  for (int k = 0; k < static_cast<int>(used.size()); ++k) {
    const int v = used[k];
    if (k >= options.num_worst_views && !StandsOut(data, v)) break;
    const ViewJudgement* judged = JudgementOf(data, v);
    std::string standing;
    if (judged != nullptr) {
      switch (judged->standing) {
        case ViewStanding::kStandsOut:
          standing = "bad detections: " + judged->why;
          break;
        case ViewStanding::kViewError:
          standing = "view-level error: " + judged->why;
          break;
        case ViewStanding::kHandled:
          standing = "handled: " + judged->why;
          break;
        case ViewStanding::kFits:
        case ViewStanding::kNotUsed:
          break;
      }
    }
    md << "| " << data.view_number[v] << " | "
       << Cell(FileName(data.view_file[v])) << " | "
       << (std::isfinite(data.view_rms[v])
               ? StringPrintf("%.3f", data.view_rms[v])
               : std::string("-"))
       << " | " << data.view_inliers[v] << " | " << data.view_outliers[v]
       << " | " << Cell(standing) << " |\n";
  }
  md << "\n";
}

// One row per input image: outcome, corners, RMS and details.
void MarkdownImages(const ReportInput& input, const ReportData& data,
                    std::ostringstream& md) {
  const CalibrationResult& result = *input.result;
  md << "## Images\n\n";
  md << "| # | file | outcome | corners detected | corners used | RMS (px) | "
        "details |\n|---:|---|---|---:|---:|---:|---|\n";
  for (size_t i = 0; i < input.images.size(); ++i) {
    const ReportImage& image = input.images[i];
    const int v = image.view_index;
    const bool is_view = v >= 0 && v < static_cast<int>(data.view_rms.size());
    const bool used_view = is_view && std::isfinite(data.view_rms[v]);
    const std::string outcome = image.OutcomeText();
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
}

// Time per step.
void MarkdownTime(const ReportInput& input, std::ostringstream& md) {
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
}

// Each chart and overlay, embedded, with what it shows and how to read it.
void MarkdownPlots(const Camera& camera,
                   const std::vector<std::string>& png_files,
                   std::ostringstream& md) {
  md << "## Plots\n\n";
  if (png_files.empty()) md << "No plots were drawn.\n";
  std::vector<std::string> overlays;
  for (const std::string& file : png_files) {
    if (file.rfind("overlay_", 0) == 0) {
      overlays.push_back(file);
      continue;
    }
    md << "### " << file << "\n\n![" << file << "](" << file << ")\n\n";
    if (file == "residuals.png") {
      md << "An arrow from every detected corner towards its reprojection, "
            "magnified (factor in the title). Random directions are noise; "
            "arrows that line up over a region show model error there. "
            "Outliers are red.";
    } else if (file == "residual_histogram.png") {
      md << "Lengths of the residuals; for Gaussian corner noise the bars "
            "follow the orange curve. A long tail means bad corners or a "
            "model that does not fit.";
    } else if (file == "view_rms.png") {
      md << "RMS of each view's inlier corners; orange bars are the views "
            "the verdict names (the rule of the table of worst views), "
            "which deserve a look at the image (blur, motion, a bent "
            "board).";
    } else if (file == "coverage.png") {
      md << "Used corners per image cell; white cells saw no corner and the "
            "model is extrapolated there. Fill them with more views, "
            "especially near the image corners.";
    } else if (file == "distortion.png") {
      md << "How far the model moves each pixel compared with the same "
            "camera without distortion"
         << (CameraModelIsPinhole(camera.model)
                 ? " (a pinhole)"
                 : " (the equidistant fisheye r = f * theta); hatched: rays "
                   "more than 90 deg off the axis")
         << ". White lines mark the angle of the ray from the optical "
            "axis.";
    } else if (std::string about = EvidenceChartDescription(file);
               !about.empty()) {
      about[0] = static_cast<char>(std::toupper(about[0]));
      md << about;
    }
    md << "\n\n";
  }
  if (!overlays.empty()) {
    // PickOverlayViews order: the worst views first, then the best.
    const size_t worst = (overlays.size() + 1) / 2;
    md << "### Views over their photos\n\n"
          "Each view's image with its detected corners (green circles; red = "
          "outlier) and their reprojections by the calibrated model (magenta "
          "crosses), which should sit inside the circles: first the worst "
          "views, in the order of the table of worst views, then the best.\n\n";
    for (size_t k = 0; k < overlays.size(); ++k) {
      md << "![" << overlays[k] << (k < worst ? " (worst)" : " (best)") << "]("
         << overlays[k] << ")\n\n";
    }
  }
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
  std::ostringstream md;
  MarkdownHeader(input, md);
  MarkdownResult(input, md);
  MarkdownParameters(result, md);
  if (!input.model_selection.empty()) {
    md << "## Model selection\n\n```\n" << input.model_selection << "```\n\n";
  }
  if (input.evidence != nullptr) {
    md << EvidenceMarkdown(*input.evidence, input.verdict, 2);
  }
  if (input.advice != nullptr) md << AdviceMarkdown(*input.advice, 2);
  MarkdownWorstViews(data, result, options, md);
  MarkdownImages(input, data, md);
  MarkdownTime(input, md);
  MarkdownPlots(result.camera, png_files, md);
  return md.str();
}

namespace {

// The evidence charts (those of them the evidence holds), named `prefix` +
// the chart's name, each passed to `write_png` (false: stop). The plots use
// only the image size of `data`.
template <typename WritePngFn>
bool WriteEvidenceChartsWith(const ReportData& data,
                             const ReportOptions& options,
                             const Evidence& evidence,
                             const std::string& prefix,
                             const WritePngFn& write_png) {
  if (evidence.cross_validation.ok &&
      !write_png(
          prefix + kCrossValidationChart,
          PlotCrossValidation(data, options, evidence.cross_validation))) {
    return false;
  }
  if (evidence.uncertainty.ok &&
      !write_png(prefix + kUncertaintyChart,
                 PlotUncertainty(data, options, evidence.uncertainty,
                                 evidence.residuals.max_angle_deg))) {
    return false;
  }
  return write_png(prefix + kResidualBinsChart,
                   PlotResidualBins(data, options, evidence.residuals));
}

// The charts of the report, each passed to `write_png` (false: stop).
template <typename WritePngFn>
bool WriteCharts(const ReportData& data, const ReportOptions& options,
                 const WritePngFn& write_png,
                 std::vector<std::string>* warnings) {
  if (!write_png("residuals.png", PlotResiduals(data, options)) ||
      !write_png("residual_histogram.png", PlotHistogram(data, options)) ||
      !write_png("view_rms.png", PlotViewRms(data, options)) ||
      !write_png("coverage.png", PlotCoverage(data, options))) {
    return false;
  }
  if (!data.camera_valid) {
    warnings->push_back(
        "no distortion map: the result's camera parameters are not valid");
    return true;
  }
  if (!write_png("distortion.png", PlotDistortion(data, options))) {
    return false;
  }
  if (data.input->evidence == nullptr) return true;
  return WriteEvidenceChartsWith(data, options, *data.input->evidence, "",
                                 write_png);
}

}  // namespace

bool WriteEvidenceCharts(const std::string& dir, const std::string& prefix,
                         int width, int height, const Evidence& evidence,
                         const ReportOptions& options,
                         std::vector<std::string>* files, std::string* error) {
  std::string why;
  if (!options.Check(&why)) return Fail("report options: " + why, error);
  if (width <= 0 || height <= 0 || width > kMaxImageSide ||
      height > kMaxImageSide) {
    return Fail(StringPrintf("evidence charts: the image size %d x %d is not "
                             "valid",
                             width, height),
                error);
  }
  if (!plot::ChartsAvailable(&why)) return Fail("no charts: " + why, error);
  ReportData data;  // the evidence plots need the image size alone
  data.width = width;
  data.height = height;
  const std::filesystem::path folder(dir);
  auto write_png = [&](const std::string& name, const cv::Mat& image) {
    if (!WritePngFile((folder / name).string(), image, error)) return false;
    if (files != nullptr) files->push_back(name);
    return true;
  };
  return WriteEvidenceChartsWith(data, options, evidence, prefix, write_png);
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
    if (!WritePngFile((folder / name).string(), image, error)) return false;
    summary->files.push_back(name);
    png_files.push_back(name);
    return true;
  };
  if (!size_ok) {
    summary->warnings.push_back(
        StringPrintf("no plots: the result's image size %d x %d is not valid",
                     width, height));
  } else {
    std::string charts_why;
    if (!plot::ChartsAvailable(&charts_why)) {
      summary->warnings.push_back("no charts: " + charts_why);
    } else if (!WriteCharts(data, options, write_png, &summary->warnings)) {
      return false;
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
  if (input.advice != nullptr && input.advice->ok && size_ok) {
    std::vector<std::string> advice_files;
    if (!WriteAdviceFiles(dir, *input.advice, SeenCorners(*input.views, result),
                          options.image_plot_width, &advice_files, error)) {
      return false;
    }
    summary->files.insert(summary->files.end(), advice_files.begin(),
                          advice_files.end());
  }
  const std::string markdown = ReportMarkdown(input, options, png_files);
  if (!WriteFileAtomically((folder / "summary.md").string(), markdown, error)) {
    return false;
  }
  summary->files.insert(summary->files.begin(), "summary.md");
  // The same as one web page with the plots inline, for readers without a
  // Markdown viewer.
  if (!WriteHtmlReport(dir, "Calibration report", error)) return false;
  summary->files.insert(summary->files.begin() + 1, "index.html");
  return true;
}

}  // namespace puzzlecal
