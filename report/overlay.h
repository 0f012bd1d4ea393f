#ifndef PUZZLECAL_REPORT_OVERLAY_H_
#define PUZZLECAL_REPORT_OVERLAY_H_

// Marks drawn on a photo (detected corners, reprojections, lattice edges,
// epipolar rows) with OpenCV, and the one PNG writer of the program.
// Overlays are images, not charts: the marks sit on the photo's own pixels.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace puzzlecal {

// One mark, in the photo's pixel coordinates (OpenCV's: centre of the
// top-left pixel at (0, 0)). Sizes and thicknesses are output pixels.
struct OverlayMark {
  enum class Kind { kCircle, kCross, kLine, kArrow, kText };
  Kind kind = Kind::kCircle;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();  // centre, or line start
  Eigen::Vector2d to = Eigen::Vector2d::Zero();  // line and arrow end
  double size = 5;  // circle radius, cross half-size, text height
  int thickness = 1;
  cv::Scalar colour;  // BGR
  std::string text;   // kText
};

// A legend line below the photo: a mark sample and its text.
struct OverlayLegendEntry {
  OverlayMark::Kind kind = OverlayMark::Kind::kCircle;
  cv::Scalar colour;
  std::string text;
};

struct Overlay {
  std::string title;                       // bold, above the photo
  std::string subtitle;                    // below the title
  std::vector<OverlayMark> marks;          // drawn in order
  std::vector<OverlayLegendEntry> legend;  // one line below the photo
};

struct OverlayOptions {
  // Width of the photo in the output: scaled (up or down) to it; 0 keeps
  // the photo's size. Default 0.
  int width = 0;
  // The photo's grey values are mapped to fade * v + (1 - fade) * 128
  // (1 keeps it) so the marks stand out. Default 1.
  double fade = 1.0;
  bool Check(std::string* why = nullptr) const;
};

// The photo (grey or BGR) with `overlay` drawn on it: title band above
// when a title is given, legend band below when a legend is given.
// CV_8UC3. Marks outside the photo are clipped.
cv::Mat DrawOverlay(const cv::Mat& photo, const Overlay& overlay,
                    const OverlayOptions& options);

}  // namespace puzzlecal

#endif  // PUZZLECAL_REPORT_OVERLAY_H_
