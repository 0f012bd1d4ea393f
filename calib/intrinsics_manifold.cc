#include "calib/intrinsics_manifold.h"

#include <algorithm>

namespace puzzlecal {

TiedFocalManifold::TiedFocalManifold(int size, const std::vector<bool>& fixed)
    : size_(size) {
  for (int k = 0; k < size; ++k) {
    if (k != 1 && !fixed[k]) tangent_.push_back(k);
  }
}

bool TiedFocalManifold::Plus(const double* x, const double* delta,
                             double* x_plus_delta) const {
  std::copy(x, x + size_, x_plus_delta);
  for (size_t t = 0; t < tangent_.size(); ++t) {
    x_plus_delta[tangent_[t]] += delta[t];
  }
  // fy keeps its offset from fx (0 once tied).
  x_plus_delta[1] = x_plus_delta[0] + (x[1] - x[0]);
  return true;
}

bool TiedFocalManifold::PlusJacobian(const double* /*x*/,
                                     double* jacobian) const {
  const int tangent = TangentSize();
  std::fill(jacobian, jacobian + size_ * tangent, 0.0);
  for (int t = 0; t < tangent; ++t) {
    jacobian[tangent_[t] * tangent + t] = 1.0;
    if (tangent_[t] == 0) jacobian[1 * tangent + t] = 1.0;  // fy with fx
  }
  return true;
}

bool TiedFocalManifold::Minus(const double* y, const double* x,
                              double* y_minus_x) const {
  for (size_t t = 0; t < tangent_.size(); ++t) {
    y_minus_x[t] = y[tangent_[t]] - x[tangent_[t]];
  }
  return true;
}

bool TiedFocalManifold::MinusJacobian(const double* /*x*/,
                                      double* jacobian) const {
  const int tangent = TangentSize();
  std::fill(jacobian, jacobian + tangent * size_, 0.0);
  for (int t = 0; t < tangent; ++t) jacobian[t * size_ + tangent_[t]] = 1.0;
  return true;
}

}  // namespace puzzlecal
