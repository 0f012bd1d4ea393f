#ifndef PUZZLECAL_DETECTION_SUBPIXEL_H_
#define PUZZLECAL_DETECTION_SUBPIXEL_H_

// Sub-pixel refinement and orientation of one corner.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace puzzlecal {

struct GradientRefineResult {
  bool ok = false;  // converged to a well-conditioned solution
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
// `scratch`, when given, holds the gradient products between calls (a
// caller refining many corners saves the allocations).
struct GradientRefineScratch {
  std::vector<float> gxx, gxy, gyy;  // per patch pixel
};
GradientRefineResult RefineByGradientOrthogonality(
    const cv::Mat& image, const Eigen::Vector2d& start, int half_window,
    int max_iterations, double convergence_px,
    GradientRefineScratch* scratch = nullptr);

struct SaddleRefineResult {
  bool ok = false;  // converged to a saddle (Hessian of the fit indefinite)
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  int iterations = 0;
  // Angle in (-pi/2, pi/2] of the eigenvector of the larger (positive)
  // eigenvalue of the last fit's Hessian: along the diagonal through the
  // two brighter tiles (the orientation of DetectCorners).
  double orientation = 0.0;
};

// Saddle-point fit: a quadratic a + b x + c y + d x^2 + e x y + f y^2 is
// fitted in weighted least squares to the grey values around the estimate p
// (Gaussian weights of standard deviation `sigma_px` centred on p, cut at
// 2.5 sigma), and p moves to the stationary point of the fit until the step
// is shorter than `convergence_px`. A checkerboard corner's grey values are
// point-symmetric about it for any blur, so the fixed point (window centred
// on its own solution) is the corner whatever the window size; structures
// further out (PuzzleBoard discs, neighbour corners) enter only through the
// Gaussian tail. `image` is CV_32FC1. Fails when the window leaves the
// image, the fit is no saddle (det of its Hessian >= 0 or too weak), or p
// moves farther than `max_shift_px` from `start`.
SaddleRefineResult RefineBySaddleFit(const cv::Mat& image,
                                     const Eigen::Vector2d& start,
                                     double sigma_px, int max_iterations,
                                     double convergence_px,
                                     double max_shift_px);

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
