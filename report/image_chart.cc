#include "report/image_chart.h"

#include <algorithm>
#include <cmath>

#include "formats/png_writer.h"
#include "util/failure.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

// The map at image pixel (x, y): bilinear between the four samples around
// it, or the nearest of them when one has no value.
double SampleMap(const PixelMap& map, double x, double y) {
  const int step = std::max(1, map.step_px);
  const double gx = x / step, gy = y / step;
  const int i0 = std::clamp(static_cast<int>(std::floor(gx)), 0, map.cols - 1);
  const int j0 = std::clamp(static_cast<int>(std::floor(gy)), 0, map.rows - 1);
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
}

}  // namespace

ImageLayout MakeImageLayout(int plot_width, int width, int height,
                            int note_lines) {
  constexpr int kLeft = 80, kRight = 150, kTop = 80, kBottom = 70;
  ImageLayout layout;
  const int area_width = std::max(100, plot_width - kLeft - kRight);
  layout.scale = static_cast<double>(area_width) / width;
  const int area_height =
      std::max(1, static_cast<int>(std::lround(height * layout.scale)));
  layout.canvas = cv::Size(kLeft + area_width + kRight,
                           kTop + area_height + kBottom + 22 * note_lines);
  layout.area = cv::Rect(kLeft, kTop, area_width, area_height);
  layout.notes_y = kTop + area_height + kBottom;
  return layout;
}

void SetImageArea(const ImageLayout& layout, int width, int height,
                  plot::Chart* chart) {
  chart->SetArea(layout.area, -0.5, width - 0.5, -0.5, height - 0.5,
                 /*y_down=*/true);
}

void DrawNote(const ImageLayout& layout, int line, const std::string& text,
              plot::Chart* chart) {
  chart->CanvasText(layout.area.x, layout.notes_y + 22 * line, text,
                    plot::kTickHeight, plot::Colour::kDarkGrey);
}

std::vector<double> SamplePositions(int count, int step, int size) {
  std::vector<double> positions(std::max(1, count));
  for (int i = 0; i < count; ++i) positions[i] = std::min(i * step, size - 1);
  positions.front() = -0.5;
  if (count > 1) positions.back() = size - 0.5;
  return positions;
}

cv::Mat DrawPixelMapChart(const PixelMap& map, int width, int height,
                          const PixelMapChart& spec) {
  const ImageLayout layout = MakeImageLayout(
      spec.plot_width, width, height, static_cast<int>(spec.notes.size()));
  double largest = 0;
  for (double value : map.values) {
    if (std::isfinite(value)) largest = std::max(largest, value);
  }
  const double colour_max = spec.colour_max > 0 ? spec.colour_max
                            : largest > 0       ? largest
                                                : 1.0;
  plot::Chart chart(layout.canvas.width, layout.canvas.height,
                    /*antialias=*/false);
  SetImageArea(layout, width, height, &chart);
  chart.FilledRect(-0.5, -0.5, width - 0.5, height - 0.5,
                   plot::Colour::kNoData);
  if (map.cols > 0 && map.rows > 0 &&
      map.values.size() == static_cast<size_t>(map.cols) * map.rows) {
    // Resampled every kStep px (the distortion map's default grid) so the
    // bands follow the bilinear surface and a sample without a value only
    // greys its own cell.
    constexpr int kStep = 8;
    const int nx = (width - 1 + kStep - 1) / kStep + 1;
    const int ny = (height - 1 + kStep - 1) / kStep + 1;
    cv::Mat values(ny, nx, CV_64F);
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        values.at<double>(j, i) = SampleMap(map, std::min(i * kStep, width - 1),
                                            std::min(j * kStep, height - 1));
      }
    }
    chart.Shades(values, SamplePositions(nx, kStep, width),
                 SamplePositions(ny, kStep, height), 0, colour_max);
  }
  chart.Axes("x (px)", "y (px)", false);
  chart.ColourBar(0, colour_max, spec.bar_label);
  chart.Title(spec.title, spec.subtitle);
  for (size_t k = 0; k < spec.notes.size(); ++k) {
    DrawNote(layout, static_cast<int>(k), spec.notes[k], &chart);
  }
  return chart.Finish();
}

bool WriteProjectionDifferenceChart(const std::string& path,
                                    const ProjectionDiff& diff, int width,
                                    int height, const std::string& title,
                                    std::string* error) {
  std::string why;
  if (!plot::ChartsAvailable(&why)) {
    return Fail(path + ": no charts: " + why, error);
  }
  PixelMapChart chart;
  chart.title = title;
  chart.subtitle = StringPrintf(
      "far-field difference after the best-fitting rotation (%.4f deg), up "
      "to %.1f deg off the axis",
      diff.rotation_deg, diff.max_angle_deg);
  chart.bar_label = "|B - A| (px)";
  for (const AngleBand& band : diff.difference_bands) {
    if (band.count > 0) chart.colour_max = std::max(chart.colour_max, band.p95);
  }
  chart.notes = {
      "Each pixel's ray under A, turned into B's camera frame and projected "
      "by B, against A's projection of it.",
      "Colours up to the largest field-angle band's 95th percentile; grey: "
      "not compared (no ray in one of the cameras, or beyond the field)."};
  const cv::Mat image =
      DrawPixelMapChart(diff.difference_px, width, height, chart);
  if (image.empty())
    return Fail(path + ": the chart could not be drawn", error);
  return WritePngFile(path, image, error);
}

}  // namespace puzzlecal
