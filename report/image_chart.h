#ifndef PUZZLECAL_REPORT_IMAGE_CHART_H_
#define PUZZLECAL_REPORT_IMAGE_CHART_H_

// Charts shaped like the image (plot.h): the image rectangle scaled to the
// plot width, title above, axes in image pixels, room on the right for a
// colour bar and below for notes; and a quantity sampled over the image
// (evidence/evidence.h PixelMap) drawn on it, as the report draws its
// cross-validation and uncertainty maps and `puzzlecal diff` and `check`
// their projection differences.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "evidence/evidence.h"
#include "report/plot.h"

namespace puzzlecal {

struct ImageLayout {
  cv::Size canvas;
  cv::Rect area;
  double scale = 1;  // canvas pixels per image pixel
  int notes_y = 0;   // baseline of the first note line below the axes
};

// The layout of a plot `plot_width` canvas pixels wide for an image of
// width x height with `note_lines` lines of notes below.
ImageLayout MakeImageLayout(int plot_width, int width, int height,
                            int note_lines);

// The plot area in image pixel coordinates (y down).
void SetImageArea(const ImageLayout& layout, int width, int height,
                  plot::Chart* chart);

// Note line `line` (0 first) below the axes.
void DrawNote(const ImageLayout& layout, int line, const std::string& text,
              plot::Chart* chart);

// Sample positions of a field computed every `step` pixels (the last one
// on the image's last pixel), the outer ones moved to the image's edges so
// the field fills the image rectangle.
std::vector<double> SamplePositions(int count, int step, int size);

// The words and scale of a PixelMap chart.
struct PixelMapChart {
  std::string title;
  std::string subtitle;
  std::string bar_label;
  std::vector<std::string> notes;  // one line each, below the axes
  // The colour bar runs from 0 to this; 0: the map's largest value.
  double colour_max = 0;
  // Canvas width in pixels (the height follows the image). Default 1200.
  int plot_width = 1200;
};

// `map` drawn over the image rectangle of width x height pixels
// (interpolated between samples, grey where the map has no value), in
// viridis with a colour bar. CV_8UC3 (BGR); empty when charts cannot be
// drawn (plot::ChartsAvailable).
cv::Mat DrawPixelMapChart(const PixelMap& map, int width, int height,
                          const PixelMapChart& chart);

// Writes the chart of a projection difference (ProjectionDifference) as a
// PNG file at `path` (atomically): `title` over the map, the rotation and
// the compared field below it, colours up to the largest band's 95th
// percentile. False with a message naming the path when charts cannot be
// drawn or the file cannot be written.
bool WriteProjectionDifferenceChart(const std::string& path,
                                    const ProjectionDiff& diff, int width,
                                    int height, const std::string& title,
                                    std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_REPORT_IMAGE_CHART_H_
