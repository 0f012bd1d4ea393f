#ifndef PUZZLECAL_CAMERA_CAMERA_MODELS_H_
#define PUZZLECAL_CAMERA_CAMERA_MODELS_H_

// Camera models: stateless structs with a fixed parameter count, named
// parameters, their facts (name, family, central or not, far-field model,
// the field radius and where the distortion stops being monotonic), a
// templated Project (double and ceres::Jet) and an iterative Unproject. One
// closed list of models (CameraModelList) and one dispatch point
// (DispatchCameraModel). A new model is its struct, its CameraModelId and
// its entry in CameraModelList; everything else reads the struct.
//
// Conventions (shared with OpenCV, so results can be checked against
// cv::projectPoints / cv::fisheye::projectPoints):
// - camera frame: x right, y down, z forward;
// - pixels: the centre of the top-left pixel is (0, 0);
// - every model's parameters start with fx fy cx cy; the rest is distortion.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace puzzlecal {

enum class CameraModelId {
  kPinholeRadtan,
  kPinholeRational,
  kKannalaBrandt,
  kKannalaBrandtNoncentral,
  kKannalaBrandtSplined,
  kKannalaBrandtSplinedNoncentral,
};

// How a model maps the field angle to the image: pinhole models through the
// radius in the normalised image plane (tan of the angle; points must be in
// front of the camera), fisheye models through the angle itself (rays
// beyond 90 degrees too).
enum class CameraFamily {
  kPinhole,
  kFisheye,
};

// Parameter groups, the same index ranges for every model.
inline constexpr int kFocalLengthBegin = 0;     // fx fy
inline constexpr int kPrincipalPointBegin = 2;  // cx cy
inline constexpr int kDistortionBegin = 4;      // model-specific
// kannala-brandt-noncentral only: e1 e2, the entrance pupil's shift along the
// optical axis (metres), after the radial coefficients k1..k4.
inline constexpr int kPupilBegin = 8;

// A viewing ray: the points origin + s * direction for s >= 0 (camera frame,
// metres; direction a unit vector). Central models put every origin at 0.
struct ViewingRay {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
};

// Why Unproject did not return a ray.
struct UnprojectStatus {
  bool converged = false;  // the iteration met its tolerance
  int iterations = 0;      // iterations used
  double residual_px = 0;  // |Project(ray) - pixel| at the end, in pixels
};

namespace internal {

// The plain value of a double or of a ceres::Jet (its scalar part `a`).
inline double ScalarPart(double x) { return x; }
template <typename T>
double ScalarPart(const T& x) {
  return x.a;
}

// Pinhole with OpenCV's rational radial + tangential distortion. `Rational`
// selects the 12-parameter form (k4 k5 k6 in the denominator).
template <bool Rational>
struct PinholeDistorted {
  static constexpr CameraFamily kFamily = CameraFamily::kPinhole;

  // The radius the distortion is a function of, for a ray in the camera
  // frame: |(x, y)| / z (infinity behind the camera).
  static double FieldRadius(const double* ray) {
    if (!(ray[2] > 0)) return std::numeric_limits<double>::infinity();
    return std::sqrt(ray[0] * ray[0] + ray[1] * ray[1]) / ray[2];
  }

  // The field radius up to which the distorted radius r * radial(r) keeps
  // growing (beyond it the image folds over), scanned up to a 89.9-degree
  // ray.
  static double MaxMonotonicRadius(const double* p) {
    auto distorted = [&](double r) {
      const double r2 = r * r, r4 = r2 * r2, r6 = r4 * r2;
      double radial = 1 + p[4] * r2 + p[5] * r4 + p[8] * r6;
      if constexpr (Rational) radial /= 1 + p[9] * r2 + p[10] * r4 + p[11] * r6;
      return r * radial;
    };
    constexpr double kMaxRadius = 572.0;  // tan(89.9 degrees)
    constexpr int kSteps = 20000;
    double previous = 0.0;
    for (int i = 1; i <= kSteps; ++i) {
      // Finer steps near the centre, where lenses live.
      const double r =
          kMaxRadius * std::pow(static_cast<double>(i) / kSteps, 3);
      const double value = distorted(r);
      if (!(value > previous)) {
        return kMaxRadius * std::pow(static_cast<double>(i - 1) / kSteps, 3);
      }
      previous = value;
    }
    return kMaxRadius;
  }

  template <typename T>
  static void Distort(const T* params, const T& x, const T& y, T* xd, T* yd) {
    const T& k1 = params[4];
    const T& k2 = params[5];
    const T& p1 = params[6];
    const T& p2 = params[7];
    const T& k3 = params[8];
    const T r2 = x * x + y * y;
    const T r4 = r2 * r2;
    const T r6 = r4 * r2;
    T radial = T(1) + k1 * r2 + k2 * r4 + k3 * r6;
    if constexpr (Rational) {
      const T& k4 = params[9];
      const T& k5 = params[10];
      const T& k6 = params[11];
      radial = radial / (T(1) + k4 * r2 + k5 * r4 + k6 * r6);
    }
    const T xy = x * y;
    *xd = x * radial + T(2) * p1 * xy + p2 * (r2 + T(2) * x * x);
    *yd = y * radial + p1 * (r2 + T(2) * y * y) + T(2) * p2 * xy;
  }

  // point_cam: 3 coordinates in the camera frame; pixel: 2 outputs. Returns
  // false for points on or behind the image plane (z <= 0).
  template <typename T>
  static bool Project(const T* params, const T* point_cam, T* pixel) {
    if (!(point_cam[2] > T(0))) return false;
    const T x = point_cam[0] / point_cam[2];
    const T y = point_cam[1] / point_cam[2];
    T xd, yd;
    Distort(params, x, y, &xd, &yd);
    pixel[0] = params[0] * xd + params[2];
    pixel[1] = params[1] * yd + params[3];
    return true;
  }

  // Gauss-Newton on the normalised image plane with a numeric 2x2 Jacobian,
  // started at the distorted point. ray: unit vector with z > 0.
  static UnprojectStatus Unproject(const double* params, const double* pixel,
                                   double* ray) {
    UnprojectStatus status;
    const double xd = (pixel[0] - params[2]) / params[0];
    const double yd = (pixel[1] - params[3]) / params[1];
    double x = xd, y = yd;
    constexpr int kMaxIterations = 50;
    constexpr double kStep = 1e-7;
    for (int it = 0; it < kMaxIterations; ++it) {
      status.iterations = it + 1;
      double fx, fy, fx_dx, fy_dx, fx_dy, fy_dy;
      Distort(params, x, y, &fx, &fy);
      Distort(params, x + kStep, y, &fx_dx, &fy_dx);
      Distort(params, x, y + kStep, &fx_dy, &fy_dy);
      const double ex = fx - xd, ey = fy - yd;
      const double j00 = (fx_dx - fx) / kStep, j10 = (fy_dx - fy) / kStep;
      const double j01 = (fx_dy - fx) / kStep, j11 = (fy_dy - fy) / kStep;
      const double det = j00 * j11 - j01 * j10;
      if (!std::isfinite(det) || std::abs(det) < 1e-12) break;
      const double dx = (j11 * ex - j01 * ey) / det;
      const double dy = (-j10 * ex + j00 * ey) / det;
      x -= dx;
      y -= dy;
      if (!std::isfinite(x) || !std::isfinite(y)) break;
      if (std::hypot(dx, dy) < 1e-14 * (1.0 + std::hypot(x, y))) break;
    }
    double fx, fy, fx_dx, fy_dx, fx_dy, fy_dy;
    Distort(params, x, y, &fx, &fy);
    Distort(params, x + kStep, y, &fx_dx, &fy_dx);
    Distort(params, x, y + kStep, &fx_dy, &fy_dy);
    status.residual_px =
        std::hypot((fx - xd) * params[0], (fy - yd) * params[1]);
    // A solution past the fold of the distortion (where the mapping turns
    // back, Jacobian determinant <= 0) is not the lens' ray for this pixel.
    const double det =
        (fx_dx - fx) * (fy_dy - fy) - (fx_dy - fx) * (fy_dx - fy);
    // The same holds for a solution on the far side of the centre (the
    // radial factor turned negative).
    const bool same_side = x * xd + y * yd >= 0;
    status.converged = std::isfinite(status.residual_px) &&
                       status.residual_px < 1e-6 && det > 0 && same_side;
    const double norm = std::sqrt(x * x + y * y + 1.0);
    ray[0] = x / norm;
    ray[1] = y / norm;
    ray[2] = 1.0 / norm;
    return status;
  }
};

}  // namespace internal

// fx fy cx cy k1 k2 p1 p2 k3: OpenCV's 5-coefficient model (plumb_bob).
struct PinholeRadtanModel : internal::PinholeDistorted<false> {
  static constexpr CameraModelId kId = CameraModelId::kPinholeRadtan;
  static constexpr const char* kName = "pinhole-radtan";
  static constexpr bool kCentral = true;  // every ray starts at the origin
  static constexpr CameraModelId kFarFieldId = kId;
  static constexpr int kNumParams = 9;
  static constexpr std::array<const char*, kNumParams> kParamNames = {
      "fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};
};

// fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6: OpenCV's rational model
// (CALIB_RATIONAL_MODEL, ROS rational_polynomial).
struct PinholeRationalModel : internal::PinholeDistorted<true> {
  static constexpr CameraModelId kId = CameraModelId::kPinholeRational;
  static constexpr const char* kName = "pinhole-rational";
  static constexpr bool kCentral = true;  // every ray starts at the origin
  static constexpr CameraModelId kFarFieldId = kId;
  static constexpr int kNumParams = 12;
  static constexpr std::array<const char*, kNumParams> kParamNames = {
      "fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"};
};

// fx fy cx cy k1 k2 k3 k4: Kannala-Brandt / OpenCV fisheye (equidistant).
// theta = atan2(|(x, y)|, z), so rays beyond 90 degrees from the axis project
// as well (OpenCV's version divides by z first and cannot).
struct KannalaBrandtModel {
  static constexpr CameraModelId kId = CameraModelId::kKannalaBrandt;
  static constexpr const char* kName = "kannala-brandt";
  static constexpr CameraFamily kFamily = CameraFamily::kFisheye;
  static constexpr bool kCentral = true;  // every ray starts at the origin
  static constexpr CameraModelId kFarFieldId = kId;
  static constexpr int kNumParams = 8;
  static constexpr std::array<const char*, kNumParams> kParamNames = {
      "fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"};

  // The angle theta the distortion is a function of, for a ray in the
  // camera frame.
  static double FieldRadius(const double* ray) {
    return std::atan2(std::sqrt(ray[0] * ray[0] + ray[1] * ray[1]), ray[2]);
  }

  // The angle up to which theta_d(theta) keeps growing (beyond it the image
  // folds over), at most pi: the first angle where
  // d theta_d / d theta = 1 + 3 k1 t^2 + 5 k2 t^4 + 7 k3 t^6 + 9 k4 t^8
  // stops being positive.
  static double MaxMonotonicRadius(const double* p) {
    constexpr int kSteps = 4000;
    for (int i = 1; i <= kSteps; ++i) {
      const double t = M_PI * i / kSteps;
      const double t2 = t * t, t4 = t2 * t2, t6 = t4 * t2, t8 = t4 * t4;
      const double slope =
          1 + 3 * p[4] * t2 + 5 * p[5] * t4 + 7 * p[6] * t6 + 9 * p[7] * t8;
      if (!(slope > 0)) return M_PI * (i - 1) / kSteps;
    }
    return M_PI;
  }

  template <typename T>
  static T DistortTheta(const T* params, const T& theta) {
    const T t2 = theta * theta;
    const T t4 = t2 * t2;
    const T t6 = t4 * t2;
    const T t8 = t4 * t4;
    return theta * (T(1) + params[4] * t2 + params[5] * t4 + params[6] * t6 +
                    params[7] * t8);
  }

  // Returns false only for the camera centre itself.
  template <typename T>
  static bool Project(const T* params, const T* point_cam, T* pixel) {
    using std::atan2;
    using std::sqrt;
    const T& x = point_cam[0];
    const T& y = point_cam[1];
    const T& z = point_cam[2];
    const T r2 = x * x + y * y;
    T mx, my;
    // Near the optical axis theta_d / r -> 1 / z; use the limit there so the
    // Jet derivative of sqrt(r2) at 0 is never taken.
    if (r2 < T(1e-20) * z * z && z > T(0)) {
      mx = x / z;
      my = y / z;
    } else {
      if (!(r2 > T(0))) return false;
      const T r = sqrt(r2);
      const T theta = atan2(r, z);
      const T scale = DistortTheta(params, theta) / r;
      mx = x * scale;
      my = y * scale;
    }
    pixel[0] = params[0] * mx + params[2];
    pixel[1] = params[1] * my + params[3];
    return true;
  }

  // Newton on theta_d(theta) = |m|, theta in [0, pi].
  static UnprojectStatus Unproject(const double* params, const double* pixel,
                                   double* ray) {
    UnprojectStatus status;
    const double mx = (pixel[0] - params[2]) / params[0];
    const double my = (pixel[1] - params[3]) / params[1];
    const double theta_d = std::hypot(mx, my);
    double theta = std::min(theta_d, M_PI);
    constexpr int kMaxIterations = 50;
    for (int it = 0; it < kMaxIterations; ++it) {
      status.iterations = it + 1;
      const double t2 = theta * theta, t4 = t2 * t2, t6 = t4 * t2, t8 = t4 * t4;
      const double f = DistortTheta(params, theta) - theta_d;
      const double df = 1.0 + 3.0 * params[4] * t2 + 5.0 * params[5] * t4 +
                        7.0 * params[6] * t6 + 9.0 * params[7] * t8;
      if (!std::isfinite(df) || std::abs(df) < 1e-12) break;
      const double step = f / df;
      theta = std::clamp(theta - step, 0.0, M_PI);
      if (std::abs(step) < 1e-15) break;
    }
    const double f_end = DistortTheta(params, theta) - theta_d;
    status.residual_px =
        std::abs(f_end) * std::max(std::abs(params[0]), std::abs(params[1]));
    // Past the turning point of theta_d(theta) the solution is not the ray.
    const double t2 = theta * theta, t4 = t2 * t2, t6 = t4 * t2, t8 = t4 * t4;
    const double slope = 1.0 + 3.0 * params[4] * t2 + 5.0 * params[5] * t4 +
                         7.0 * params[6] * t6 + 9.0 * params[7] * t8;
    status.converged = std::isfinite(status.residual_px) &&
                       status.residual_px < 1e-6 && slope > 0;
    const double s = std::sin(theta);
    if (theta_d > 0) {
      ray[0] = s * mx / theta_d;
      ray[1] = s * my / theta_d;
    } else {
      ray[0] = ray[1] = 0.0;
    }
    ray[2] = std::cos(theta);
    return status;
  }
};

// fx fy cx cy k1 k2 k3 k4 e1 e2: kannala-brandt with an entrance pupil that
// moves along the optical axis with the field angle, a non-central camera.
// The ray that leaves the lens at the angle theta from the axis starts at
// (0, 0, z0(theta)), z0 = e1 theta^2 + e2 theta^4 (e1, e2 in metres), and
// meets the image where kannala-brandt puts theta: radius theta_d(theta).
// Wide fisheyes have such a pupil; a central model fitted to close views
// absorbs it into a wrong focal length and leaves errors that grow with the
// field angle and shrink as z0 / distance. For far points (and for
// e1 = e2 = 0) the model is kannala-brandt with the same parameters: that is
// its far-field part.
struct KannalaBrandtNoncentralModel {
  static constexpr CameraModelId kId = CameraModelId::kKannalaBrandtNoncentral;
  static constexpr const char* kName = "kannala-brandt-noncentral";
  static constexpr CameraFamily kFamily = CameraFamily::kFisheye;
  static constexpr bool kCentral = false;
  // Far points see kannala-brandt with the first 8 parameters (no e1 e2).
  static constexpr CameraModelId kFarFieldId = CameraModelId::kKannalaBrandt;
  static constexpr int kNumParams = 10;
  static constexpr std::array<const char*, kNumParams> kParamNames = {
      "fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4", "e1", "e2"};
  // Newton steps of SolveTheta on the plain values at most. Newton starts at
  // the central angle atan2(r, z), off by about z0 sin(theta) / distance,
  // and the error then squares each step. In the hardest case
  // noncentral_test checks (twice the measured deltille shift, points 3 cm
  // away, up to 110 degrees) the start is 0.8 rad off and the steps leave
  // 0.24, 0.03, 5e-4, 2e-7, 4e-14, 2e-15 rad: seven leave the value
  // converged, and one more step in T carries the derivatives. The steps
  // stop early once one is below kThetaConvergedStep: the error left is
  // then about its square, below the last bit (on the deltille photos,
  // 2-5 steps instead of 7). Either way the result is a fixed function of
  // the input, wherever it is evaluated.
  static constexpr int kThetaIterations = 7;
  static constexpr double kThetaConvergedStep = 1e-9;

  // The radial distortion is kannala-brandt's.
  static double FieldRadius(const double* ray) {
    return KannalaBrandtModel::FieldRadius(ray);
  }
  static double MaxMonotonicRadius(const double* params) {
    return KannalaBrandtModel::MaxMonotonicRadius(params);
  }

  // z0(theta) for the pupil terms `pupil` = (e1, e2).
  template <typename T>
  static T PupilZ(const T* pupil, const T& theta) {
    const T t2 = theta * theta;
    return t2 * (pupil[0] + pupil[1] * t2);
  }

  // d z0 / d theta.
  template <typename T>
  static T PupilZSlope(const T* pupil, const T& theta) {
    const T t2 = theta * theta;
    return theta * (T(2) * pupil[0] + T(4) * pupil[1] * t2);
  }

  // The angle theta of the ray that passes through a point at distance r > 0
  // from the axis and height z, for the pupil terms `pupil` = (e1, e2): the
  // root of h(theta) = theta - atan2(r, z - z0(theta)), by Newton steps on
  // the plain values (see kThetaIterations) and one last step in T. For a
  // ceres::Jet that last step, taken at the root, gives the derivative the
  // implicit function theorem gives (d theta = -dh / h'), so the dual
  // numbers go through one step instead of all of them. `residual` returns
  // |h| and `slope` h' = 1 - r z0' / (r^2 + (z - z0)^2) at the end (plain
  // values: they are only compared); slope <= 0 means the point lies inside
  // the lens' caustic (nearer than any pupil position can be seen from),
  // where no ray reaches it.
  template <typename T>
  static T SolveTheta(const T* pupil, const T& r, const T& z, double* residual,
                      double* slope) {
    using std::atan2;
    const double pupil_value[2] = {internal::ScalarPart(pupil[0]),
                                   internal::ScalarPart(pupil[1])};
    const double r_value = internal::ScalarPart(r);
    const double z_value = internal::ScalarPart(z);
    double theta_value = std::atan2(r_value, z_value);
    for (int it = 0; it < kThetaIterations; ++it) {
      const double w = z_value - PupilZ(pupil_value, theta_value);
      const double h = theta_value - std::atan2(r_value, w);
      const double dh = 1.0 - r_value * PupilZSlope(pupil_value, theta_value) /
                                  (r_value * r_value + w * w);
      const double step = h / dh;
      theta_value -= step;
      if (!(std::abs(step) >= kThetaConvergedStep)) break;
    }
    T theta(theta_value);
    {
      const T w = z - PupilZ(pupil, theta);
      const T h = theta - atan2(r, w);
      const T dh = T(1) - r * PupilZSlope(pupil, theta) / (r * r + w * w);
      theta = theta - h / dh;
    }
    theta_value = internal::ScalarPart(theta);
    const double w = z_value - PupilZ(pupil_value, theta_value);
    *residual = std::abs(theta_value - std::atan2(r_value, w));
    *slope = 1.0 - r_value * PupilZSlope(pupil_value, theta_value) /
                       (r_value * r_value + w * w);
    return theta;
  }

  // Returns false for points on the axis at or behind the pupil and for
  // points no ray reaches (see SolveTheta).
  template <typename T>
  static bool Project(const T* params, const T* point_cam, T* pixel) {
    using std::sqrt;
    const T& x = point_cam[0];
    const T& y = point_cam[1];
    const T& z = point_cam[2];
    const T r2 = x * x + y * y;
    T mx, my;
    // On the axis z0(0) = 0, so the limit is kannala-brandt's.
    if (r2 < T(1e-20) * z * z && z > T(0)) {
      mx = x / z;
      my = y / z;
    } else {
      if (!(r2 > T(0))) return false;
      const T r = sqrt(r2);
      double residual, slope;
      const T theta = SolveTheta(params + kPupilBegin, r, z, &residual, &slope);
      if (!(residual < 1e-9) || !(slope > 0)) return false;
      const T scale = KannalaBrandtModel::DistortTheta(params, theta) / r;
      mx = x * scale;
      my = y * scale;
    }
    pixel[0] = params[0] * mx + params[2];
    pixel[1] = params[1] * my + params[3];
    return true;
  }

  // The ray through `pixel`: kannala-brandt's direction (the far-field ray,
  // which is all `direction` returns here) from the origin (0, 0, z0(theta)).
  static UnprojectStatus Unproject(const double* params, const double* pixel,
                                   double* direction) {
    return KannalaBrandtModel::Unproject(params, pixel, direction);
  }
  static UnprojectStatus UnprojectRay(const double* params, const double* pixel,
                                      double* origin, double* direction) {
    const UnprojectStatus status = Unproject(params, pixel, direction);
    const double theta =
        std::atan2(std::hypot(direction[0], direction[1]), direction[2]);
    origin[0] = origin[1] = 0.0;
    origin[2] = PupilZ(params + kPupilBegin, theta);
    return status;
  }
};

}  // namespace puzzlecal

#include "camera/splined_model.h"  // IWYU pragma: export

namespace puzzlecal {

// The one list of models, in the order of CameraModelId.
using CameraModelList =
    std::tuple<PinholeRadtanModel, PinholeRationalModel, KannalaBrandtModel,
               KannalaBrandtNoncentralModel, KannalaBrandtSplinedModel,
               KannalaBrandtSplinedNoncentralModel>;
inline constexpr int kNumCameraModels = std::tuple_size_v<CameraModelList>;

namespace internal {

template <size_t... I>
constexpr std::array<CameraModelId, sizeof...(I)> ModelIds(
    std::index_sequence<I...>) {
  return {std::tuple_element_t<I, CameraModelList>::kId...};
}

template <size_t... I>
constexpr bool IdsFollowTheList(std::index_sequence<I...>) {
  return ((static_cast<size_t>(std::tuple_element_t<I, CameraModelList>::kId) ==
           I) &&
          ...);
}
static_assert(IdsFollowTheList(std::make_index_sequence<kNumCameraModels>()),
              "CameraModelList must list the models in CameraModelId order");

}  // namespace internal

// True for the splined model structs (compile-time CameraModelIsSplined).
template <typename Model>
constexpr bool CameraModelIsSplinedModel() {
  return Model::kId == CameraModelId::kKannalaBrandtSplined ||
         Model::kId == CameraModelId::kKannalaBrandtSplinedNoncentral;
}

// Calls fn(Model{}) with the model struct for `id`; the one dispatch point from
// a runtime model id to the templates above. The switch has no default, so
// the compiler names it when CameraModelId gains a value.
template <typename Fn>
decltype(auto) DispatchCameraModel(CameraModelId id, Fn&& fn) {
  switch (id) {
    case CameraModelId::kPinholeRadtan:
      return fn(std::tuple_element_t<0, CameraModelList>{});
    case CameraModelId::kPinholeRational:
      return fn(std::tuple_element_t<1, CameraModelList>{});
    case CameraModelId::kKannalaBrandt:
      return fn(std::tuple_element_t<2, CameraModelList>{});
    case CameraModelId::kKannalaBrandtNoncentral:
      return fn(std::tuple_element_t<3, CameraModelList>{});
    case CameraModelId::kKannalaBrandtSplined:
      return fn(std::tuple_element_t<4, CameraModelList>{});
    case CameraModelId::kKannalaBrandtSplinedNoncentral:
      return fn(std::tuple_element_t<5, CameraModelList>{});
  }
  return fn(std::tuple_element_t<0, CameraModelList>{});  // invalid ids only
}

// All models, in the order of CameraModelId.
inline constexpr std::array<CameraModelId, kNumCameraModels> kAllCameraModels =
    internal::ModelIds(std::make_index_sequence<kNumCameraModels>());

// "pinhole-radtan", "pinhole-rational", "kannala-brandt",
// "kannala-brandt-noncentral".
const char* CameraModelName(CameraModelId id);
// Parses a model name; false for unknown names.
bool CameraModelIdFromName(const std::string& name, CameraModelId* id);
// Names of all models, comma separated (for messages).
std::string CameraModelNames();
int CameraModelNumParams(CameraModelId id);
std::vector<std::string> CameraModelParamNames(CameraModelId id);
CameraFamily CameraModelFamily(CameraModelId id);
// True for the pinhole models (points must have z > 0).
bool CameraModelIsPinhole(CameraModelId id);
// True for the fisheye models (kannala-brandt and its non-central form:
// the angle theta from the axis, rays beyond 90 degrees).
bool CameraModelIsFisheye(CameraModelId id);
// False for models whose rays do not all start at the camera origin.
bool CameraModelIsCentral(CameraModelId id);
// True for the models with a spline correction (kannala-brandt-splined and
// its non-central form).
bool CameraModelIsSplined(CameraModelId id);
// True for parameter k of a model that shapes the model and is never
// estimated: the spline's grid_radius (set from the observed field before
// a solve, held fixed in it).
bool CameraModelParamIsStructural(CameraModelId id, int k);

// Runtime wrappers around Model::Project / Model::Unproject. `params` must
// hold CameraModelNumParams(id) values.
bool ProjectPoint(CameraModelId id, const double* params,
                  const Eigen::Vector3d& point_cam, Eigen::Vector2d* pixel);
// `ray`: the unit direction; for non-central models the far-field one (the
// direction of the ray, whose origin UnprojectPixelToRay gives).
UnprojectStatus UnprojectPixel(CameraModelId id, const double* params,
                               const Eigen::Vector2d& pixel,
                               Eigen::Vector3d* ray);
// The full ray through `pixel`, origin included (0 for central models).
UnprojectStatus UnprojectPixelToRay(CameraModelId id, const double* params,
                                    const Eigen::Vector2d& pixel,
                                    ViewingRay* ray);

// A camera: a model and its parameters, plus the image size it was made for.
struct Camera {
  CameraModelId model = CameraModelId::kPinholeRadtan;
  std::vector<double> params;  // CameraModelNumParams(model) values
  int width = 0;               // image size in pixels
  int height = 0;

  bool Project(const Eigen::Vector3d& point_cam, Eigen::Vector2d* pixel) const {
    return ProjectPoint(model, params.data(), point_cam, pixel);
  }
  UnprojectStatus Unproject(const Eigen::Vector2d& pixel,
                            Eigen::Vector3d* ray) const {
    return UnprojectPixel(model, params.data(), pixel, ray);
  }
  UnprojectStatus UnprojectRay(const Eigen::Vector2d& pixel,
                               ViewingRay* ray) const {
    return UnprojectPixelToRay(model, params.data(), pixel, ray);
  }
};

// The field radius of `ray` (camera frame) that the model's distortion is a
// function of: tan of the field angle for pinhole models, the angle for
// fisheye models.
double FieldRadius(const Camera& camera, const Eigen::Vector3d& ray);
// The field radius up to which the camera's distortion is monotonic (the
// image folds over beyond it): pi at most for fisheye models, tan(89.9 deg)
// for pinhole models.
double MaxMonotonicRadius(const Camera& camera);

// The share of the image border (samples_per_side points along each of its
// four sides) whose pixels have no ray: the model's inverse does not
// converge there, or only to a ray beyond the distortion's fold
// (MaxMonotonicRadius). A polynomial distortion fitted to corners near the
// image's centre can fold over before the image's corners; undistorted and
// rectified images are wrong there. 0 when every sample has a ray.
double BorderFractionWithoutRay(const Camera& camera,
                                int samples_per_side = 64);

// The central model whose projection a non-central one approaches for far
// points, and its parameters (the model itself for central ones):
// kannala-brandt-noncentral -> kannala-brandt without e1 e2.
Camera FarFieldCamera(const Camera& camera);

}  // namespace puzzlecal

#endif  // PUZZLECAL_CAMERA_CAMERA_MODELS_H_
