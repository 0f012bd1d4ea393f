#include "camera/model_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

namespace puzzlecal {
namespace {

struct RayPixel {
  Eigen::Vector3d ray;
  Eigen::Vector2d pixel;
};

// The grid pixels of `camera` within the field, with their rays.
std::vector<RayPixel> SamplePixels(const Camera& camera,
                                   const CameraFitOptions& options) {
  const double max_angle = options.max_field_angle_deg > 0
                               ? options.max_field_angle_deg * M_PI / 180.0
                               : M_PI;
  std::vector<RayPixel> samples;
  for (int y = 0; y < camera.height; y += options.step_px) {
    for (int x = 0; x < camera.width; x += options.step_px) {
      RayPixel sample;
      sample.pixel = Eigen::Vector2d(x, y);
      if (!camera.Unproject(sample.pixel, &sample.ray).converged) continue;
      const double angle =
          std::atan2(sample.ray.head<2>().norm(), sample.ray.z());
      if (!(angle <= max_angle)) continue;
      samples.push_back(sample);
    }
  }
  return samples;
}

// Residuals fit(ray) - pixel (2 per sample); false when a ray does not
// project.
bool Residuals(CameraModelId model, const std::vector<double>& params,
               const std::vector<RayPixel>& samples, Eigen::VectorXd* r) {
  r->resize(2 * samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    Eigen::Vector2d pixel;
    if (!ProjectPoint(model, params.data(), samples[i].ray, &pixel) ||
        !pixel.allFinite()) {
      return false;
    }
    r->segment<2>(2 * i) = pixel - samples[i].pixel;
  }
  return true;
}

}  // namespace

bool CameraFitOptions::Check(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why != nullptr) *why = text;
    return false;
  };
  if (step_px < 1) return fail("step_px must be >= 1");
  if (!(max_field_angle_deg >= 0)) {
    return fail("max_field_angle_deg must be >= 0");
  }
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  return true;
}

Camera FitCameraModel(const Camera& source, CameraModelId target,
                      const CameraFitOptions& options,
                      CameraFitReport* report) {
  *report = CameraFitReport();
  Camera fit;
  fit.model = target;
  fit.width = source.width;
  fit.height = source.height;
  const std::vector<std::string> names = CameraModelParamNames(target);
  const std::vector<std::string> source_names =
      CameraModelParamNames(source.model);
  fit.params.assign(names.size(), 0.0);
  for (size_t k = 0; k < names.size(); ++k) {
    const auto found =
        std::find(source_names.begin(), source_names.end(), names[k]);
    if (found != source_names.end()) {
      fit.params[k] = source.params[found - source_names.begin()];
    }
  }
  std::string why;
  if (!options.Check(&why)) {
    report->error = "fit options: " + why;
    return fit;
  }
  const std::vector<RayPixel> samples =
      SamplePixels(FarFieldCamera(source), options);
  const int n = static_cast<int>(fit.params.size());
  if (static_cast<int>(samples.size()) < n) {
    report->error = "too few pixels of the source camera to fit " +
                    std::string(CameraModelName(target)) + " to (" +
                    std::to_string(samples.size()) + ")";
    return fit;
  }
  Eigen::VectorXd r;
  if (!Residuals(target, fit.params, samples, &r)) {
    report->error = "the start does not project every compared ray";
    return fit;
  }
  // Levenberg-Marquardt with central-difference Jacobians (a few thousand
  // rays, a dozen parameters: no solver library needed).
  double lambda = 1e-3;
  double cost = r.squaredNorm();
  Eigen::MatrixXd jacobian(r.size(), n);
  for (int it = 0; it < options.max_iterations; ++it) {
    report->iterations = it + 1;
    for (int k = 0; k < n; ++k) {
      const double step = 1e-7 * std::max(1.0, std::abs(fit.params[k]));
      std::vector<double> plus = fit.params, minus = fit.params;
      plus[k] += step;
      minus[k] -= step;
      Eigen::VectorXd r_plus, r_minus;
      if (!Residuals(target, plus, samples, &r_plus) ||
          !Residuals(target, minus, samples, &r_minus)) {
        r_plus = r_minus = r;
      }
      jacobian.col(k) = (r_plus - r_minus) / (2 * step);
    }
    const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    const Eigen::VectorXd gradient = jacobian.transpose() * r;
    bool improved = false;
    for (int attempt = 0; attempt < 20 && !improved; ++attempt) {
      Eigen::MatrixXd damped = normal;
      damped.diagonal() += lambda * normal.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd delta = damped.ldlt().solve(-gradient);
      std::vector<double> next = fit.params;
      for (int k = 0; k < n; ++k) next[k] += delta[k];
      Eigen::VectorXd r_next;
      if (delta.allFinite() && Residuals(target, next, samples, &r_next) &&
          r_next.squaredNorm() < cost) {
        const double gain = cost - r_next.squaredNorm();
        fit.params = next;
        r = r_next;
        cost = r.squaredNorm();
        lambda = std::max(1e-9, lambda / 3);
        improved = true;
        if (gain < 1e-12 * cost) it = options.max_iterations;
      } else {
        lambda *= 4;
      }
    }
    if (!improved) break;
  }
  report->num_pixels = static_cast<int>(samples.size());
  report->rms_px = std::sqrt(cost / samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    report->max_px = std::max(report->max_px, r.segment<2>(2 * i).norm());
  }
  report->ok = true;
  return fit;
}

}  // namespace puzzlecal
