#ifndef PUZZLECAL_CALIB_INTRINSICS_MANIFOLD_H_
#define PUZZLECAL_CALIB_INTRINSICS_MANIFOLD_H_

// The intrinsics block's manifold when fy is tied to fx (one focal length,
// square pixels: OpenCV's CALIB_FIX_ASPECT_RATIO with an aspect of 1): the
// tangent space holds every free parameter but fy, and each step moves fy
// with fx. Parameters held fixed are left out of the tangent space as
// ceres::SubsetManifold leaves them out.

#include <ceres/manifold.h>

#include <vector>

namespace puzzlecal {

class TiedFocalManifold : public ceres::Manifold {
 public:
  // `size`: the block's parameter count; `fixed[k]`: parameter k held.
  // Parameter 0 is fx, 1 is fy; fy is never in the tangent space, fx is
  // unless held (then fy is held with it).
  TiedFocalManifold(int size, const std::vector<bool>& fixed);

  int AmbientSize() const override { return size_; }
  int TangentSize() const override { return static_cast<int>(tangent_.size()); }
  bool Plus(const double* x, const double* delta,
            double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x,
             double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

 private:
  int size_;
  std::vector<int> tangent_;  // the block index of each tangent coordinate
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_INTRINSICS_MANIFOLD_H_
