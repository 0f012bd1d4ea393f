#include "util/statistics.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace puzzlecal {

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

double Quantile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const double position =
      std::clamp(fraction, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const size_t below = static_cast<size_t>(std::floor(position));
  const size_t above = std::min(below + 1, values.size() - 1);
  const double weight = position - static_cast<double>(below);
  return values[below] + weight * (values[above] - values[below]);
}

double MedianAbsoluteDeviationSigma(const std::vector<double>& values) {
  if (values.empty()) return 0;
  const double center = Median(values);
  std::vector<double> deviations(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    deviations[i] = std::abs(values[i] - center);
  }
  return RobustSigmaAboutZero(std::move(deviations));
}

double RobustSigmaAboutZero(std::vector<double> values) {
  for (double& v : values) v = std::abs(v);
  // 1.4826 = 1 / Phi^-1(3/4): for Gaussian values the MAD times this is sigma.
  return 1.4826 * Median(std::move(values));
}

std::vector<size_t> EvenlySpreadIndices(size_t count, size_t max_count) {
  const size_t take = std::min(count, max_count);
  std::vector<size_t> indices(take);
  for (size_t k = 0; k < take; ++k) indices[k] = k * count / take;
  return indices;
}

}  // namespace puzzlecal
