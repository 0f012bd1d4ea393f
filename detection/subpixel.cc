#include "detection/subpixel.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <vector>

#include "detection/corner_filters.h"

namespace puzzlecal {

namespace {

// Central-difference gradients of a square patch of the image, computed once
// per corner and reused by every solve.
class GradientPatch {
 public:
  explicit GradientPatch(GradientRefineScratch* scratch)
      : gxx_(scratch->gxx), gxy_(scratch->gxy), gyy_(scratch->gyy) {}

  // Fills the patch of radius `radius` around (cx, cy); false when it does
  // not fit into the image (with one pixel for the differences).
  bool Fill(const cv::Mat& image, int cx, int cy, int radius) {
    // Shrink (down to `radius - 3`) to stay inside the image.
    const int room =
        std::min({cx - 1, cy - 1, image.cols - 2 - cx, image.rows - 2 - cy});
    radius = std::max(std::min(radius, room), radius - 3);
    if (cx - radius < 1 || cy - radius < 1 || cx + radius > image.cols - 2 ||
        cy + radius > image.rows - 2) {
      return false;
    }
    x0_ = cx - radius;
    y0_ = cy - radius;
    size_ = 2 * radius + 1;
    // Rows padded to a multiple of kLanes (zero products) for the solve.
    stride_ = (size_ + kLanes - 1) / kLanes * kLanes;
    const size_t n = static_cast<size_t>(stride_) * size_;
    gxx_.assign(n, 0.0f);
    gxy_.assign(n, 0.0f);
    gyy_.assign(n, 0.0f);
    for (int j = 0; j < size_; ++j) {
      const int y = y0_ + j;
      const float* up = image.ptr<float>(y - 1);
      const float* row = image.ptr<float>(y);
      const float* down = image.ptr<float>(y + 1);
      const size_t offset = static_cast<size_t>(j) * stride_;
      for (int i = 0; i < size_; ++i) {
        const int x = x0_ + i;
        const float gx = 0.5f * (row[x + 1] - row[x - 1]);
        const float gy = 0.5f * (down[x] - up[x]);
        gxx_[offset + i] = gx * gx;
        gxy_[offset + i] = gx * gy;
        gyy_[offset + i] = gy * gy;
      }
    }
    return true;
  }

  // True when the disc of radius h around p lies inside the patch.
  bool Covers(const Eigen::Vector2d& p, double h) const {
    return p.x() - h >= x0_ && p.y() - h >= y0_ &&
           p.x() + h <= x0_ + size_ - 1 && p.y() + h <= y0_ + size_ - 1;
  }

  // One weighted least-squares solve with the window centred on p (weights
  // 1 - r^2 / h^2: zero at the rim so pixels entering or leaving the window
  // do not jump, yet broad enough to use the straight edge arms): returns
  // the point minimising sum w g g^T (q - x) over x. False when the system
  // is ill-conditioned (fewer than two edge directions).
  bool Solve(const Eigen::Vector2d& p, double h,
             Eigen::Vector2d* solution) const {
    // Float sums in kLanes independent lanes so the loop vectorises; the
    // rounding error is far below 0.001 px for windows up to 64 px.
    const float inv_h2 = static_cast<float>(1.0 / (h * h));
    const int j0 = std::max(0, static_cast<int>(std::ceil(p.y() - h)) - y0_);
    const int j1 =
        std::min(size_ - 1, static_cast<int>(std::floor(p.y() + h)) - y0_);
    float dx0[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      dx0[l] = static_cast<float>(x0_ + l - p.x());
    }
    float a00[kLanes] = {}, a01[kLanes] = {}, a11[kLanes] = {};
    float b0[kLanes] = {}, b1[kLanes] = {};
    for (int j = j0; j <= j1; ++j) {
      const float dy = static_cast<float>(y0_ + j - p.y());
      const float dy2 = dy * dy;
      const size_t offset = static_cast<size_t>(j) * stride_;
      for (int i = 0; i < stride_; i += kLanes) {
        const float* gxx = &gxx_[offset + i];
        const float* gxy = &gxy_[offset + i];
        const float* gyy = &gyy_[offset + i];
        for (int l = 0; l < kLanes; ++l) {
          const float dx = dx0[l] + static_cast<float>(i);
          // Weight 1 - r^2 / h^2, zero outside the disc.
          const float w = std::max(0.0f, 1.0f - (dx * dx + dy2) * inv_h2);
          const float wxx = w * gxx[l], wxy = w * gxy[l], wyy = w * gyy[l];
          a00[l] += wxx;
          a01[l] += wxy;
          a11[l] += wyy;
          // Relative to p for numerical range.
          b0[l] += wxx * dx + wxy * dy;
          b1[l] += wxy * dx + wyy * dy;
        }
      }
    }
    double s00 = 0, s01 = 0, s11 = 0, t0 = 0, t1 = 0;
    for (int l = 0; l < kLanes; ++l) {
      s00 += a00[l];
      s01 += a01[l];
      s11 += a11[l];
      t0 += b0[l];
      t1 += b1[l];
    }
    const double det = s00 * s11 - s01 * s01;
    const double trace = s00 + s11;
    if (!(trace > 0.0) || det < 0.05 * trace * trace) return false;
    *solution = p + Eigen::Vector2d((s11 * t0 - s01 * t1) / det,
                                    (s00 * t1 - s01 * t0) / det);
    return std::isfinite(solution->x()) && std::isfinite(solution->y());
  }

 private:
  static constexpr int kLanes = 8;
  int x0_ = 0, y0_ = 0, size_ = 0, stride_ = 0;
  // Gradient products per pixel, rows of `stride_` floats (the caller's
  // scratch).
  std::vector<float>& gxx_;
  std::vector<float>& gxy_;
  std::vector<float>& gyy_;
};
}  // namespace

GradientRefineResult RefineByGradientOrthogonality(
    const cv::Mat& image, const Eigen::Vector2d& start, int half_window,
    int max_iterations, double convergence_px, GradientRefineScratch* scratch) {
  GradientRefineResult result;
  result.xy = start;
  if (!std::isfinite(start.x()) || !std::isfinite(start.y()) ||
      half_window < 1 || std::abs(start.x()) > 1e6 ||
      std::abs(start.y()) > 1e6) {
    return result;
  }
  // Room for the window plus a few pixels of movement.
  GradientRefineScratch local_scratch;
  GradientPatch patch(scratch != nullptr ? scratch : &local_scratch);
  const double h = half_window;
  if (!patch.Fill(image, static_cast<int>(std::lround(start.x())),
                  static_cast<int>(std::lround(start.y())), half_window + 3)) {
    return result;
  }
  // The solve with the window centred on p returns F(p); the corner is the
  // fixed point F(p) = p. Plain iteration p <- F(p) converges slowly when the
  // blur is wide compared with the window (the weights move with p), so we
  // run Newton on G(p) = F(p) - p with a finite-difference Jacobian computed
  // once (chord method).
  constexpr double kStep = 0.25;  // finite-difference step, pixels
  Eigen::Vector2d p = start;
  Eigen::Vector2d f;
  if (!patch.Solve(p, h, &f)) return result;
  Eigen::Vector2d g = f - p;
  Eigen::Matrix2d jacobian;
  for (int axis = 0; axis < 2; ++axis) {
    Eigen::Vector2d shifted = p;
    shifted[axis] += kStep;
    Eigen::Vector2d f_shifted;
    if (!patch.Solve(shifted, h, &f_shifted)) return result;
    jacobian.col(axis) = ((f_shifted - shifted) - g) / kStep;
  }
  // Fall back to plain iteration if the Jacobian is degenerate.
  const bool use_newton = std::abs(jacobian.determinant()) > 1e-3;
  const Eigen::Matrix2d inverse =
      use_newton ? Eigen::Matrix2d(jacobian.inverse())
                 : Eigen::Matrix2d(-Eigen::Matrix2d::Identity());
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    Eigen::Vector2d step = -inverse * g;
    const double length = step.norm();
    if (!std::isfinite(length)) return result;
    if (length > 1.0) step /= length;  // at most one pixel per step
    p += step;
    if ((p - start).norm() > h) return result;
    if (!patch.Covers(p, h) &&
        !patch.Fill(image, static_cast<int>(std::lround(p.x())),
                    static_cast<int>(std::lround(p.y())), half_window + 3)) {
      return result;
    }
    if (!patch.Solve(p, h, &f)) return result;
    g = f - p;
    if (length < convergence_px) break;
  }
  result.ok = true;
  result.xy = p;
  return result;
}

namespace {

// Moments of one window of the saddle fit: the weights are a separable
// Gaussian on a square window, so the normal matrix is a product of 1-D
// moments and only the right-hand side touches the pixels.
// Gaussian weights exp(-u^2 / 2) at u = u0 + i h for i < n, by the
// recurrence e(i+1) = e(i) g(i), g(i+1) = g(i) exp(-h^2) (three exp calls
// instead of n).
void GaussianRun(double u0, double h, int n, double* out) {
  double e = std::exp(-0.5 * u0 * u0);
  double g = std::exp(-u0 * h - 0.5 * h * h);
  const double c = std::exp(-h * h);
  for (int i = 0; i < n; ++i) {
    out[i] = e;
    e *= g;
    g *= c;
  }
}

constexpr int kLanes = 8;
constexpr int kMaxSide = 2 * 48 + 1;
constexpr int kMaxPadded = (kMaxSide + kLanes - 1) / kLanes * kLanes;

// The weights of one saddle-fit window of `side` = 2 radius + 1 pixels
// centred on the pixel nearest p: 1-D weights and powers of the coordinates
// relative to p, in units of sigma: wu[k][i] = w(u) u^k for k = 0..2 (zero
// in the padding up to `padded`), and the moments sum w u^k for k = 0..4
// for the normal matrix.
struct SaddleWindow {
  int side = 0;
  int padded = 0;
  alignas(32) float wu[3][kMaxPadded] = {};
  float wv[3][kMaxSide];
  double mu[5] = {}, mv[5] = {};
};

void MakeSaddleWindow(const Eigen::Vector2d& p, int cx, int cy, double sigma,
                      int radius, SaddleWindow* w) {
  w->side = 2 * radius + 1;
  w->padded = (w->side + kLanes - 1) / kLanes * kLanes;
  const double inv_s = 1.0 / sigma;
  const double u0 = (cx - radius - p.x()) * inv_s;
  const double v0 = (cy - radius - p.y()) * inv_s;
  double gauss_u[kMaxSide], gauss_v[kMaxSide];
  GaussianRun(u0, inv_s, w->side, gauss_u);
  GaussianRun(v0, inv_s, w->side, gauss_v);
  for (int i = 0; i < w->side; ++i) {
    const double u = u0 + i * inv_s;
    const double v = v0 + i * inv_s;
    // Gaussian tapered smoothly to zero at 3 sigma from p, so the window is
    // symmetric about p whatever its sub-pixel offset.
    const double tu = std::max(0.0, 1.0 - u * u * (1.0 / 9.0));
    const double tv = std::max(0.0, 1.0 - v * v * (1.0 / 9.0));
    const double w_u = gauss_u[i] * tu * tu;
    const double w_v = gauss_v[i] * tv * tv;
    w->wu[0][i] = static_cast<float>(w_u);
    w->wu[1][i] = static_cast<float>(w_u * u);
    w->wu[2][i] = static_cast<float>(w_u * u * u);
    w->wv[0][i] = static_cast<float>(w_v);
    w->wv[1][i] = static_cast<float>(w_v * v);
    w->wv[2][i] = static_cast<float>(w_v * v * v);
    double pu = w_u, pv = w_v;
    for (int k = 0; k < 5; ++k) {
      w->mu[k] += pu;
      w->mv[k] += pv;
      pu *= u;
      pv *= v;
    }
  }
}

// Right-hand side of the fit: sum w u^a v^b I for (a, b) in the basis
// 1, u, v, u^2, u v, v^2, over the window whose top-left pixel is (x0, y0).
// Rows in kLanes independent float lanes so the loop vectorises.
template <typename Pixel>
Eigen::Matrix<double, 6, 1> SaddleRightHandSide(const cv::Mat& image, int x0,
                                                int y0, const SaddleWindow& w) {
  alignas(32) float values[kMaxPadded] = {};
  double r00 = 0, r10 = 0, r01 = 0, r20 = 0, r11 = 0, r02 = 0;
  for (int j = 0; j < w.side; ++j) {
    const Pixel* row = image.ptr<Pixel>(y0 + j) + x0;
    for (int i = 0; i < w.side; ++i) values[i] = static_cast<float>(row[i]);
    float s0[kLanes] = {}, s1[kLanes] = {}, s2[kLanes] = {};
    for (int i = 0; i < w.padded; i += kLanes) {
      for (int l = 0; l < kLanes; ++l) {
        const float value = values[i + l];
        s0[l] += w.wu[0][i + l] * value;
        s1[l] += w.wu[1][i + l] * value;
        s2[l] += w.wu[2][i + l] * value;
      }
    }
    float t0 = 0.0f, t1 = 0.0f, t2 = 0.0f;
    for (int l = 0; l < kLanes; ++l) {
      t0 += s0[l];
      t1 += s1[l];
      t2 += s2[l];
    }
    r00 += w.wv[0][j] * t0;
    r10 += w.wv[0][j] * t1;
    r20 += w.wv[0][j] * t2;
    r01 += w.wv[1][j] * t0;
    r11 += w.wv[1][j] * t1;
    r02 += w.wv[2][j] * t0;
  }
  Eigen::Matrix<double, 6, 1> right;
  right << r00, r10, r01, r20, r11, r02;
  return right;
}

// Solves the fit and returns the step (pixels) to its stationary point and
// the orientation of its Hessian; false when the fit is no saddle.
bool SolveSaddle(const SaddleWindow& w,
                 const Eigen::Matrix<double, 6, 1>& right, double sigma,
                 Eigen::Vector2d* step, double* orientation) {
  // Normal matrix: entry (A, B) = mu[a_A + a_B] * mv[b_A + b_B].
  static const int kPowU[6] = {0, 1, 0, 2, 1, 0};
  static const int kPowV[6] = {0, 0, 1, 0, 1, 2};
  Eigen::Matrix<double, 6, 6> normal;
  for (int a = 0; a < 6; ++a) {
    for (int b = 0; b < 6; ++b) {
      normal(a, b) = w.mu[kPowU[a] + kPowU[b]] * w.mv[kPowV[a] + kPowV[b]];
    }
  }
  const Eigen::Matrix<double, 6, 1> q = normal.ldlt().solve(right);
  // Gradient (q1, q2) and Hessian [[2 q3, q4], [q4, 2 q5]] at p.
  const double hxx = 2.0 * q[3], hxy = q[4], hyy = 2.0 * q[5];
  const double det = hxx * hyy - hxy * hxy;
  // A saddle has an indefinite Hessian; a near-degenerate one (a ridge or
  // an edge) gives no stable stationary point.
  if (!(det < -0.05 * (hxx * hxx + hyy * hyy + 2.0 * hxy * hxy))) {
    return false;
  }
  // Eigenvector of the larger eigenvalue of [[hxx, hxy], [hxy, hyy]].
  double angle = 0.5 * std::atan2(2.0 * hxy, hxx - hyy);
  if (angle <= -M_PI / 2) angle += M_PI;
  *orientation = angle;
  *step = sigma * Eigen::Vector2d((-hyy * q[1] + hxy * q[2]) / det,
                                  (hxy * q[1] - hxx * q[2]) / det);
  return std::isfinite(step->x()) && std::isfinite(step->y());
}

// One step of the saddle fit with the window centred on p.
template <typename Pixel>
bool SaddleStep(const cv::Mat& image, const Eigen::Vector2d& p, double sigma,
                int radius, Eigen::Vector2d* step, double* orientation) {
  const int cx = static_cast<int>(std::floor(p.x() + 0.5));
  const int cy = static_cast<int>(std::floor(p.y() + 0.5));
  if (cx - radius < 0 || cy - radius < 0 || cx + radius >= image.cols ||
      cy + radius >= image.rows) {
    return false;
  }
  SaddleWindow window;
  MakeSaddleWindow(p, cx, cy, sigma, radius, &window);
  return SolveSaddle(
      window,
      SaddleRightHandSide<Pixel>(image, cx - radius, cy - radius, window),
      sigma, step, orientation);
}

}  // namespace

SaddleRefineResult RefineBySaddleFit(const cv::Mat& image,
                                     const Eigen::Vector2d& start,
                                     double sigma_px, int max_iterations,
                                     double convergence_px,
                                     double max_shift_px) {
  SaddleRefineResult result;
  result.xy = start;
  if (!std::isfinite(start.x()) || !std::isfinite(start.y()) ||
      !(sigma_px > 0.0) || std::abs(start.x()) > 1e6 ||
      std::abs(start.y()) > 1e6) {
    return result;
  }
  sigma_px = std::min(sigma_px, 16.0);
  const int radius = static_cast<int>(std::ceil(3.0 * sigma_px));
  Eigen::Vector2d p = start;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    Eigen::Vector2d step;
    bool ok = false;
    switch (image.depth()) {
      case CV_8U:
        ok = SaddleStep<uint8_t>(image, p, sigma_px, radius, &step,
                                 &result.orientation);
        break;
      case CV_16U:
        ok = SaddleStep<uint16_t>(image, p, sigma_px, radius, &step,
                                  &result.orientation);
        break;
      case CV_32F:
        ok = SaddleStep<float>(image, p, sigma_px, radius, &step,
                               &result.orientation);
        break;
      default:
        break;
    }
    if (!ok) return result;
    const double length = step.norm();
    const double limit = std::max(1.0, sigma_px);
    if (length > limit) step *= limit / length;
    p += step;
    if ((p - start).norm() > max_shift_px) return result;
    if (length < convergence_px) break;
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
                          double radius) {
  const double r = std::max(radius, 1.0);
  const double x = xy.x(), y = xy.y();
  if (!(x - r >= 0.0 && y - r >= 0.0 && x + r < image.cols - 1.0 &&
        y + r < image.rows - 1.0)) {
    return 0.0;
  }
  // The second angular harmonic of the grey values on a circle: for a
  // quadratic saddle its phase is twice the angle of the eigenvector of the
  // larger Hessian eigenvalue; for a sharp corner it points along the
  // bisector through the bright tiles at any radius (finite differences at a
  // few pixels would quantise the angle to the sampling directions).
  constexpr int kSamples = 32;
  static const struct Table {
    double c[kSamples], s[kSamples];
    Table() {
      for (int i = 0; i < kSamples; ++i) {
        c[i] = std::cos(2.0 * M_PI * i / kSamples);
        s[i] = std::sin(2.0 * M_PI * i / kSamples);
      }
    }
  } table;
  double re = 0.0, im = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const double v =
        SampleBilinear(image, x + r * table.c[i], y + r * table.s[i]);
    const int twice = (2 * i) % kSamples;
    re += v * table.c[twice];
    im += v * table.s[twice];
  }
  double angle = 0.5 * std::atan2(im, re);
  if (angle <= -M_PI / 2) angle += M_PI;
  return angle;
}

}  // namespace puzzlecal
