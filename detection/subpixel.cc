#include "detection/subpixel.h"

#include <algorithm>
#include <cmath>

#include "detection/corner_filters.h"

namespace puzzlecal {

GradientRefineResult RefineByGradientOrthogonality(
    const cv::Mat& image, const Eigen::Vector2d& start, int half_window,
    int max_iterations, double convergence_px) {
  GradientRefineResult result;
  result.xy = start;
  if (!std::isfinite(start.x()) || !std::isfinite(start.y()) ||
      half_window < 1) {
    return result;
  }
  const double h = half_window;
  const double inv_h2 = 1.0 / (h * h);
  Eigen::Vector2d p = start;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    const int cx = static_cast<int>(std::lround(p.x()));
    const int cy = static_cast<int>(std::lround(p.y()));
    // Central differences need one more pixel on each side.
    if (cx - half_window < 1 || cy - half_window < 1 ||
        cx + half_window > image.cols - 2 ||
        cy + half_window > image.rows - 2) {
      return result;
    }
    double a00 = 0, a01 = 0, a11 = 0, b0 = 0, b1 = 0;
    for (int y = cy - half_window; y <= cy + half_window; ++y) {
      const float* up = image.ptr<float>(y - 1);
      const float* row = image.ptr<float>(y);
      const float* down = image.ptr<float>(y + 1);
      const double dy = y - p.y();
      for (int x = cx - half_window; x <= cx + half_window; ++x) {
        const double dx = x - p.x();
        const double r2 = (dx * dx + dy * dy) * inv_h2;
        if (r2 >= 1.0) continue;
        const double w = (1.0 - r2) * (1.0 - r2);
        const double gx = 0.5 * (row[x + 1] - row[x - 1]);
        const double gy = 0.5 * (down[x] - up[x]);
        const double wxx = w * gx * gx, wxy = w * gx * gy, wyy = w * gy * gy;
        a00 += wxx;
        a01 += wxy;
        a11 += wyy;
        b0 += wxx * x + wxy * y;
        b1 += wxy * x + wyy * y;
      }
    }
    const double det = a00 * a11 - a01 * a01;
    const double trace = a00 + a11;
    // Both gradient directions must be present (a corner, not an edge).
    if (!(trace > 0.0) || det < 0.05 * trace * trace) return result;
    const Eigen::Vector2d next((a11 * b0 - a01 * b1) / det,
                               (a00 * b1 - a01 * b0) / det);
    if (!std::isfinite(next.x()) || !std::isfinite(next.y())) return result;
    const double step = (next - p).norm();
    p = next;
    if ((p - start).norm() > h) return result;
    if (step < convergence_px) break;
  }
  result.ok = true;
  result.xy = p;
  return result;
}

Eigen::Vector2d CentroidOfSquaredResponse(const cv::Mat& response, int x,
                                          int y) {
  double sum = 0.0, sx = 0.0, sy = 0.0;
  for (int yy = std::max(y - 1, 0); yy <= std::min(y + 1, response.rows - 1);
       ++yy) {
    const float* row = response.ptr<float>(yy);
    for (int xx = std::max(x - 1, 0); xx <= std::min(x + 1, response.cols - 1);
         ++xx) {
      const double w = static_cast<double>(row[xx]) * row[xx];
      sum += w;
      sx += w * xx;
      sy += w * yy;
    }
  }
  if (!(sum > 0.0)) return Eigen::Vector2d(x, y);
  return Eigen::Vector2d(sx / sum, sy / sum);
}

double HessianOrientation(const cv::Mat& image, const Eigen::Vector2d& xy,
                          double spacing) {
  const double d = std::max(spacing, 1.0);
  const double x = xy.x(), y = xy.y();
  if (!(x - d >= 0.0 && y - d >= 0.0 && x + d < image.cols - 1.0 &&
        y + d < image.rows - 1.0)) {
    return 0.0;
  }
  const double c2 = 2.0 * SampleBilinear(image, x, y);
  const double hxx =
      SampleBilinear(image, x + d, y) + SampleBilinear(image, x - d, y) - c2;
  const double hyy =
      SampleBilinear(image, x, y + d) + SampleBilinear(image, x, y - d) - c2;
  const double hxy = 0.25 * (SampleBilinear(image, x + d, y + d) -
                             SampleBilinear(image, x - d, y + d) -
                             SampleBilinear(image, x + d, y - d) +
                             SampleBilinear(image, x - d, y - d));
  // Eigenvector of the larger eigenvalue of [[hxx, hxy], [hxy, hyy]].
  double angle = 0.5 * std::atan2(2.0 * hxy, hxx - hyy);
  if (angle <= -M_PI / 2) angle += M_PI;
  return angle;
}

}  // namespace puzzlecal
