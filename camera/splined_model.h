#ifndef PUZZLECAL_CAMERA_SPLINED_MODEL_H_
#define PUZZLECAL_CAMERA_SPLINED_MODEL_H_

// kannala-brandt-splined: kannala-brandt plus a smooth 2-D correction for
// lenses whose projection kannala-brandt's odd polynomial in the field angle
// cannot follow (a bump in the distortion curve, a decentred or tilted
// element, a moulded asphere). The correction is a uniform cubic B-spline
// surface over the equidistant plane e = theta * (x, y) / |(x, y)|, added to
// kannala-brandt's normalised image point before fx fy cx cy:
//
//   u = fx (m_x(theta) + du(e)) + cx,   v = fy (m_y(theta) + dv(e)) + cy,
//
// with du, dv in the units of m (radians of the equidistant image).
// kSplineKnots x kSplineKnots control points per component on a square grid
// over [-R, R]^2, R = grid_radius: the field the calibration observed
// (chosen from the data, never estimated: it fixes the knot spacing
// 2 R / (kSplineKnots - 3)). Beyond the grid the correction keeps its value
// at the grid's edge. The calibration adds a smoothness prior (second
// differences) and a weak pull towards zero (calib/spline_prior.h): the
// surface is then determined where no corner was seen, and kannala-brandt's
// own parameters keep what they can express (the spline can shift, scale
// and bend as they do).
//
// kannala-brandt-splined-noncentral adds kannala-brandt-noncentral's
// entrance pupil (e1 e2, metres) on top, after the spline's parameters, so
// that its first parameters are kannala-brandt-splined's (its far-field
// part).

#include <algorithm>
#include <array>
#include <cmath>

namespace puzzlecal {

// Control points per side of the spline grid (the knot grid has
// kSplineKnots - 3 cells per side). 10: cells of about 25 degrees over a
// 180 degree field, 200 correction values.
inline constexpr int kSplineKnots = 10;
inline constexpr int kSplineValues = kSplineKnots * kSplineKnots;

namespace internal {

// The names of the correction values, knot by knot: du_ROW_COL,
// dv_ROW_COL (row: knot along y, col: knot along x), as text with static
// storage so that kParamNames can point at it.
struct SplineParamText {
  char text[2 * kSplineValues][10] = {};
  constexpr SplineParamText() {
    for (int c = 0; c < 2; ++c) {
      for (int row = 0; row < kSplineKnots; ++row) {
        for (int col = 0; col < kSplineKnots; ++col) {
          char* s = text[2 * (row * kSplineKnots + col) + c];
          int n = 0;
          s[n++] = 'd';
          s[n++] = c == 0 ? 'u' : 'v';
          s[n++] = '_';
          if (row >= 10) s[n++] = static_cast<char>('0' + row / 10);
          s[n++] = static_cast<char>('0' + row % 10);
          s[n++] = '_';
          if (col >= 10) s[n++] = static_cast<char>('0' + col / 10);
          s[n++] = static_cast<char>('0' + col % 10);
          s[n] = '\0';
        }
      }
    }
  }
};
inline constexpr SplineParamText kSplineParamText{};

// Uniform cubic B-spline basis at t in [0, 1]: the weights of the four
// control points around a cell.
template <typename T>
void CubicBSplineWeights(const T& t, T* w) {
  const T t2 = t * t;
  const T t3 = t2 * t;
  const T one_minus = T(1) - t;
  w[0] = one_minus * one_minus * one_minus / T(6);
  w[1] = (T(3) * t3 - T(6) * t2 + T(4)) / T(6);
  w[2] = (T(-3) * t3 + T(3) * t2 + T(3) * t + T(1)) / T(6);
  w[3] = t3 / T(6);
}

// The cell of the grid over [-R, R] (kSplineKnots control points per side)
// that e falls in, clamped to the grid.
template <typename T>
int SplineCell(const T& e, const T& radius) {
  const double s =
      ScalarPart((e + radius) * T(kSplineKnots - 3) / (T(2) * radius));
  constexpr int kLastCell = kSplineKnots - 4;
  if (!(s > 0)) return 0;
  if (!(s < kLastCell + 1)) return kLastCell;
  return std::min(kLastCell, static_cast<int>(s));
}

// The local coordinate of e in `cell`: in [0, 1] inside it; beyond the
// grid's first and last cell clamped to their edge (the surface keeps its
// value there); elsewhere the cell's polynomial continues (a solve that
// fixed the cell before e moved out of it; see calib/splined_reprojection.h).
template <typename T>
T SplineCellCoordinate(const T& e, const T& radius, int cell) {
  const T s = (e + radius) * T(kSplineKnots - 3) / (T(2) * radius);
  const T t = s - T(cell);
  if (cell == 0 && !(t > T(0))) return T(0);
  if (cell == kSplineKnots - 4 && !(t < T(1))) return T(1);
  return t;
}

}  // namespace internal

template <bool kPupil>
struct KannalaBrandtSplinedModelT {
  static constexpr bool kHasPupil = kPupil;
  static constexpr CameraFamily kFamily = CameraFamily::kFisheye;
  static constexpr bool kCentral = !kPupil;
  static constexpr CameraModelId kId =
      kPupil ? CameraModelId::kKannalaBrandtSplinedNoncentral
             : CameraModelId::kKannalaBrandtSplined;
  static constexpr const char* kName =
      kPupil ? "kannala-brandt-splined-noncentral" : "kannala-brandt-splined";
  // Far points see the central splined model: the parameters without e1 e2.
  static constexpr CameraModelId kFarFieldId =
      CameraModelId::kKannalaBrandtSplined;
  // fx fy cx cy k1 k2 k3 k4, then grid_radius, then the correction values.
  static constexpr int kGridRadiusIndex = 8;
  static constexpr int kSplineBegin = 9;
  static constexpr int kPupilIndex = kSplineBegin + 2 * kSplineValues;
  static constexpr int kNumParams = kPupilIndex + (kPupil ? 2 : 0);

  static constexpr std::array<const char*, kNumParams> MakeParamNames() {
    std::array<const char*, kNumParams> names{};
    constexpr const char* kBase[kSplineBegin] = {
        "fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4", "grid_radius"};
    for (int k = 0; k < kSplineBegin; ++k) names[k] = kBase[k];
    for (int k = 0; k < 2 * kSplineValues; ++k) {
      names[kSplineBegin + k] = internal::kSplineParamText.text[k];
    }
    if constexpr (kPupil) {
      names[kPupilIndex] = "e1";
      names[kPupilIndex + 1] = "e2";
    }
    return names;
  }
  static constexpr std::array<const char*, kNumParams> kParamNames =
      MakeParamNames();

  static double FieldRadius(const double* ray) {
    return KannalaBrandtModel::FieldRadius(ray);
  }
  // Where kannala-brandt's part folds over (the spline is taken to stay
  // small against its slope).
  static double MaxMonotonicRadius(const double* params) {
    return KannalaBrandtModel::MaxMonotonicRadius(params);
  }

  // The 4 x 4 control points around the cell (row, col): knot (row + a,
  // col + b) has weight wy[a] * wx[b] at the equidistant point (ex, ey).
  template <typename T>
  static void CellWeights(const T& ex, const T& ey, const T& radius, int row,
                          int col, T* wx, T* wy) {
    internal::CubicBSplineWeights(
        internal::SplineCellCoordinate(ex, radius, col), wx);
    internal::CubicBSplineWeights(
        internal::SplineCellCoordinate(ey, radius, row), wy);
  }

  // The correction of the cell (row, col) at (ex, ey); `knot(k)` returns
  // the (du, dv) pair of knot k (row-major) as a pointer to two values.
  template <typename T, typename KnotFn>
  static void CorrectionInCell(const T& ex, const T& ey, const T& radius,
                               int row, int col, KnotFn knot, T* du, T* dv) {
    T wx[4], wy[4];
    CellWeights(ex, ey, radius, row, col, wx, wy);
    *du = T(0);
    *dv = T(0);
    for (int a = 0; a < 4; ++a) {
      T row_u(0), row_v(0);
      for (int b = 0; b < 4; ++b) {
        const auto* value = knot((row + a) * kSplineKnots + col + b);
        row_u += wx[b] * value[0];
        row_v += wx[b] * value[1];
      }
      *du += wy[a] * row_u;
      *dv += wy[a] * row_v;
    }
  }

  // The correction (du, dv) at the equidistant point (ex, ey).
  template <typename T>
  static void Correction(const T* params, const T& ex, const T& ey, T* du,
                         T* dv) {
    const T& radius = params[kGridRadiusIndex];
    const int col = internal::SplineCell(ex, radius);
    const int row = internal::SplineCell(ey, radius);
    const T* values = params + kSplineBegin;
    CorrectionInCell(
        ex, ey, radius, row, col, [values](int k) { return values + 2 * k; },
        du, dv);
  }

  // kannala-brandt's normalised image point (mx, my) of a camera-frame
  // point and its equidistant point (ex, ey), the spline's argument. `params`
  // holds at least fx..k4; `pupil` e1 e2 (the non-central form only).
  // False where the model has no ray to the point.
  template <typename T>
  static bool KannalaBrandtPart(const T* params, const T* pupil,
                                const T* point_cam, T* mx, T* my, T* ex,
                                T* ey) {
    using std::atan2;
    using std::sqrt;
    const T& x = point_cam[0];
    const T& y = point_cam[1];
    const T& z = point_cam[2];
    const T r2 = x * x + y * y;
    if (r2 < T(1e-20) * z * z && z > T(0)) {
      // On the axis theta / r -> 1 / z for both the model and the grid.
      *mx = *ex = x / z;
      *my = *ey = y / z;
      return true;
    }
    if (!(r2 > T(0))) return false;
    const T r = sqrt(r2);
    T theta;
    if constexpr (kPupil) {
      double residual, slope;
      theta = KannalaBrandtNoncentralModel::SolveTheta(pupil, r, z, &residual,
                                                       &slope);
      if (!(residual < 1e-9) || !(slope > 0)) return false;
    } else {
      (void)pupil;
      theta = atan2(r, z);
    }
    const T scale = KannalaBrandtModel::DistortTheta(params, theta) / r;
    *mx = x * scale;
    *my = y * scale;
    *ex = x * (theta / r);
    *ey = y * (theta / r);
    return true;
  }

  template <typename T>
  static bool Project(const T* params, const T* point_cam, T* pixel) {
    T mx, my, ex, ey;
    if (!KannalaBrandtPart(params, params + kPupilIndex, point_cam, &mx, &my,
                           &ex, &ey)) {
      return false;
    }
    T du, dv;
    Correction(params, ex, ey, &du, &dv);
    pixel[0] = params[0] * (mx + du) + params[2];
    pixel[1] = params[1] * (my + dv) + params[3];
    return true;
  }

  // The far-field direction through `pixel`: fixed-point iteration on the
  // correction (it is small and smooth against kannala-brandt's slope),
  // each step a kannala-brandt unprojection of the pixel less the
  // correction at the current ray.
  static UnprojectStatus Unproject(const double* params, const double* pixel,
                                   double* ray) {
    constexpr int kMaxIterations = 100;
    double target[2] = {pixel[0], pixel[1]};
    UnprojectStatus status;
    for (int it = 0; it < kMaxIterations; ++it) {
      status = KannalaBrandtModel::Unproject(params, target, ray);
      status.iterations = it + 1;
      const double r = std::hypot(ray[0], ray[1]);
      const double theta = std::atan2(r, ray[2]);
      const double ex = r > 0 ? ray[0] * theta / r : 0.0;
      const double ey = r > 0 ? ray[1] * theta / r : 0.0;
      double du, dv;
      Correction(params, ex, ey, &du, &dv);
      const double next[2] = {pixel[0] - params[0] * du,
                              pixel[1] - params[1] * dv};
      const double step = std::hypot(next[0] - target[0], next[1] - target[1]);
      target[0] = next[0];
      target[1] = next[1];
      if (step < 1e-10) break;
    }
    status = KannalaBrandtModel::Unproject(params, target, ray);
    // The residual of the whole model, at the ray found.
    double seen[2];
    if (!ProjectCentral(params, ray, seen)) {
      status.converged = false;
      return status;
    }
    status.residual_px = std::hypot(seen[0] - pixel[0], seen[1] - pixel[1]);
    status.converged = status.converged && status.residual_px < 1e-6;
    return status;
  }

  // The central projection (the pupil at rest), double only.
  static bool ProjectCentral(const double* params, const double* ray,
                             double* pixel) {
    return KannalaBrandtSplinedModelT<false>::Project(params, ray, pixel);
  }

  static UnprojectStatus UnprojectRay(const double* params, const double* pixel,
                                      double* origin, double* direction) {
    const UnprojectStatus status = Unproject(params, pixel, direction);
    origin[0] = origin[1] = origin[2] = 0.0;
    if constexpr (kPupil) {
      const double theta =
          std::atan2(std::hypot(direction[0], direction[1]), direction[2]);
      origin[2] =
          KannalaBrandtNoncentralModel::PupilZ(params + kPupilIndex, theta);
    }
    return status;
  }
};

using KannalaBrandtSplinedModel = KannalaBrandtSplinedModelT<false>;
using KannalaBrandtSplinedNoncentralModel = KannalaBrandtSplinedModelT<true>;

}  // namespace puzzlecal

#endif  // PUZZLECAL_CAMERA_SPLINED_MODEL_H_
