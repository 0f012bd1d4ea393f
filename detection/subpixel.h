#ifndef PUZZLECAL_DETECTION_SUBPIXEL_H_
#define PUZZLECAL_DETECTION_SUBPIXEL_H_

// Sub-pixel refinement and orientation of one corner.

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace puzzlecal {

struct GradientRefineResult {
  bool ok = false;       // converged to a well-conditioned solution
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  int iterations = 0;
};

// Gradient orthogonality: at a corner p every image gradient g(q) in the
// neighbourhood is orthogonal to q - p (q lies on an edge through p, or the
// gradient vanishes). Solves sum w g g^T (q - p) = 0 in least squares with
// weights w = 1 - |q - p|^2 / h^2 of half-size h centred on the estimate;
// the fixed point (window centred on its own solution) is found by Newton
// iterations with a finite-difference Jacobian. `image` is CV_32FC1
// (blurred). Fails when the window leaves the image, the system is
// ill-conditioned (fewer than two edge directions) or the estimate leaves
// the window.
GradientRefineResult RefineByGradientOrthogonality(
    const cv::Mat& image, const Eigen::Vector2d& start, int half_window,
    int max_iterations, double convergence_px);

// The thesis's squared-grey centroid over the 3x3 neighbourhood of the
// integer peak (x, y) of `response` (CV_32FC1, product form). Returns the
// position in the response's pixel frame.
Eigen::Vector2d CentroidOfSquaredResponse(const cv::Mat& response, int x,
                                          int y);

// Angle in (-pi/2, pi/2] of the eigenvector of the larger (positive, at a
// saddle) eigenvalue of the Hessian of `image` at `xy`, estimated at the
// scale `radius` (pixels) from the second angular harmonic of the grey values
// on that circle. It points along the diagonal through the two brighter
// tiles. Returns 0 when the circle leaves the image.
double HessianOrientation(const cv::Mat& image, const Eigen::Vector2d& xy,
                          double radius);

}  // namespace puzzlecal

#endif  // PUZZLECAL_DETECTION_SUBPIXEL_H_
