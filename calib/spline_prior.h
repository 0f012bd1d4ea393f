#ifndef PUZZLECAL_CALIB_SPLINE_PRIOR_H_
#define PUZZLECAL_CALIB_SPLINE_PRIOR_H_

// The prior on a splined model's correction surface (camera/splined_model.h)
// that the solvers add to the corners' residuals:
//  - smoothness: the second difference of the control values along every
//    row and every column of the grid, weighted so that a second difference
//    of 1 px costs as much as a corner 1 px off (times smoothness_weight):
//    where no corner was seen the surface continues as a plane, and where
//    corners are dense they decide;
//  - a weak pull of every control value towards zero (zero_weight): the
//    surface can shift, scale and bend the image as fx fy cx cy and k1..k4
//    do, and the pull leaves those to kannala-brandt's own parameters, so
//    that the solve has one answer and kannala-brandt's part stays the best
//    kannala-brandt.
// Residuals in pixels: the control values (radians of the equidistant
// image) times fx (du) or fy (dv) at the prior's construction; all du rows,
// then all dv rows.

#include <ceres/cost_function.h>
#include <ceres/problem.h>

#include <Eigen/Core>
#include <string>

#include "camera/camera_models.h"

namespace puzzlecal {

struct SplinePriorOptions {
  // Weight of each second difference, in pixels of residual per pixel of
  // second difference. Default 0.1. Measured on sim::TruthBumpyFisheye (30
  // views, 0.1 px noise): at 1 the prior flattened the lens' bump and the
  // far-field error was 3-9 times the stated uncertainty (0.26-1.0 px); at
  // 0.1 it is within it in every 10-degree band (0.03-0.16 px), and at
  // 0.01 no better. > 0.
  double smoothness_weight = 0.1;
  // Weight of each control value's pull towards zero, pixels per pixel.
  // Default 0.01: a correction of 1 px costs as much as a corner off by
  // 0.01 px, against the thousands of corners a calibration has. At 1e-4
  // the solve no longer converged within 200 iterations (the directions
  // the spline shares with fx fy cx cy are then nearly free). > 0.
  double zero_weight = 0.01;

  bool Check(std::string* why) const;
};

// The residuals of the prior: 2 components x (2 K (K - 2) second
// differences + K^2 values), K = kSplineKnots.
int SplinePriorResidualCount();

// The prior as a cost on a splined model's whole intrinsics block (only the
// correction values' columns of its Jacobian are non-zero).
ceres::CostFunction* CreateSplinePriorCost(CameraModelId model, double fx,
                                           double fy,
                                           const SplinePriorOptions& options);

// Adds the prior on `intrinsics` to `problem` when `model` is splined
// (nothing otherwise), with fx fy read from `intrinsics` now.
void AddSplinePrior(CameraModelId model, double* intrinsics,
                    const SplinePriorOptions& options, ceres::Problem* problem);
// The same on the knot rows' blocks: intrinsics + kSplineBegin + 2 K row,
// each a parameter block of 2 K values in `problem` (K = kSplineKnots), the
// single-camera solve's layout (calib/splined_reprojection.h): the same
// residuals, split into small residual blocks along the rows.
void AddSplinePriorOnKnots(CameraModelId model, double* intrinsics,
                           const SplinePriorOptions& options,
                           ceres::Problem* problem);

// The prior's information on the whole intrinsics vector of `model` (n x n,
// n its parameter count): W' W, W the prior's Jacobian (the prior is linear
// in the control values, so W is the same everywhere), in the units of the
// corners' residuals (pixels), as a solve's normal equations hold it. Zero
// for a model without a spline. For code that predicts a calibration's
// uncertainty without a solve (the capture advice).
Eigen::MatrixXd SplinePriorInformation(CameraModelId model, double fx,
                                       double fy,
                                       const SplinePriorOptions& options);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_SPLINE_PRIOR_H_
