#include "grid/edge_intensity.h"

#include <algorithm>
#include <cmath>

namespace puzzlecal {
namespace {

template <typename T>
double SampleBilinear(const cv::Mat& image, double x, double y) {
  x = std::clamp(x, 0.0, image.cols - 1.0);
  y = std::clamp(y, 0.0, image.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), image.cols - 1);
  const int y0 = std::min(static_cast<int>(y), image.rows - 1);
  const int x1 = std::min(x0 + 1, image.cols - 1);
  const int y1 = std::min(y0 + 1, image.rows - 1);
  const double fx = x - x0, fy = y - y0;
  const T* row0 = image.ptr<T>(y0);
  const T* row1 = image.ptr<T>(y1);
  const double top = row0[x0] + fx * (double(row0[x1]) - row0[x0]);
  const double bottom = row1[x0] + fx * (double(row1[x1]) - row1[x0]);
  return top + fy * (bottom - top);
}

// Bilinear without clamping: 0 <= x < cols - 1, 0 <= y < rows - 1.
template <typename T>
inline double SampleInside(const cv::Mat& image, double x, double y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double fx = x - x0, fy = y - y0;
  const T* row0 = image.ptr<T>(y0) + x0;
  const T* row1 = image.ptr<T>(y0 + 1) + x0;
  const double top = row0[0] + fx * (double(row0[1]) - row0[0]);
  const double bottom = row1[0] + fx * (double(row1[1]) - row1[0]);
  return top + fy * (bottom - top);
}

bool Inside(const cv::Mat& image, const Eigen::Vector2d& p) {
  return p.x() >= 0 && p.y() >= 0 && p.x() < image.cols - 1 &&
         p.y() < image.rows - 1;
}

template <typename T>
bool CrossesTile(const cv::Mat& image, const Eigen::Vector2d& a,
                 const Eigen::Vector2d& b, int n, double fraction) {
  const int third = std::max(n / 3, 1);
  double sum = 0, first = 0, last = 0;
  // Both ends inside: every sample between them is (no clamping needed).
  const bool inside = Inside(image, a) && Inside(image, b);
  const Eigen::Vector2d step = (b - a) / n;
  Eigen::Vector2d p = a + 0.5 * step;
  for (int s = 0; s < n; ++s, p += step) {
    const double v = inside ? SampleInside<T>(image, p.x(), p.y())
                            : SampleBilinear<T>(image, p.x(), p.y());
    sum += v;
    if (s < third) first += v;
    if (s >= n - third) last += v;
  }
  const double mean = sum / n;
  return std::abs(first - last) / third > fraction * mean;
}

template <typename T>
bool SidesFlip(const cv::Mat& image, const Eigen::Vector2d& a,
               const Eigen::Vector2d& b, double offset_fraction,
               double min_contrast) {
  const Eigen::Vector2d along = b - a;
  const Eigen::Vector2d side =
      offset_fraction * Eigen::Vector2d(-along.y(), along.x());
  double difference[2], sum = 0;
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector2d p = a + along * (k == 0 ? 0.25 : 0.75);
    const Eigen::Vector2d l = p + side, r = p - side;
    const double left = SampleBilinear<T>(image, l.x(), l.y());
    const double right = SampleBilinear<T>(image, r.x(), r.y());
    difference[k] = left - right;
    sum += left + right;
  }
  const double threshold = min_contrast * sum / 4;
  return difference[0] * difference[1] < 0 &&
         std::abs(difference[0]) > threshold &&
         std::abs(difference[1]) > threshold;
}

}  // namespace

bool EdgeSidesFlip(const cv::Mat& image, const Eigen::Vector2d& a,
                   const Eigen::Vector2d& b, double offset_fraction,
                   double min_contrast) {
  switch (image.type()) {
    case CV_8UC1:
      return SidesFlip<uint8_t>(image, a, b, offset_fraction, min_contrast);
    case CV_16UC1:
      return SidesFlip<uint16_t>(image, a, b, offset_fraction, min_contrast);
    case CV_32FC1:
      return SidesFlip<float>(image, a, b, offset_fraction, min_contrast);
    default:
      return false;
  }
}

bool IsSupportedGridImage(const cv::Mat& image) {
  return !image.empty() && image.dims == 2 &&
         (image.type() == CV_8UC1 || image.type() == CV_16UC1 ||
          image.type() == CV_32FC1);
}

bool EdgeCrossesTile(const cv::Mat& image, const Eigen::Vector2d& a,
                     const Eigen::Vector2d& b, int num_samples,
                     double fraction) {
  if (num_samples < 3) return false;
  switch (image.type()) {
    case CV_8UC1:
      return CrossesTile<uint8_t>(image, a, b, num_samples, fraction);
    case CV_16UC1:
      return CrossesTile<uint16_t>(image, a, b, num_samples, fraction);
    case CV_32FC1:
      return CrossesTile<float>(image, a, b, num_samples, fraction);
    default:
      return false;
  }
}

}  // namespace puzzlecal
