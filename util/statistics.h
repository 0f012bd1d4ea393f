#ifndef PUZZLECAL_UTIL_STATISTICS_H_
#define PUZZLECAL_UTIL_STATISTICS_H_

// Small order statistics shared by the libraries and the benches.

#include <cstddef>
#include <vector>

namespace puzzlecal {

// The upper median (element n/2 of the sorted values); 0 for no values.
double Median(std::vector<double> values);

// The value below which `fraction` (in [0, 1]) of the values lie, by linear
// interpolation between order statistics; 0 for no values.
double Quantile(std::vector<double> values, double fraction);

// 1.4826 * median(|v - median(v)|): the standard deviation of Gaussian values,
// estimated robustly; 0 for no values.
double MedianAbsoluteDeviationSigma(const std::vector<double>& values);

// 1.4826 * median(|v|): the same about zero, for values whose mean is zero
// by construction (residual coordinates) or that are non-negative errors;
// 0 for no values.
double RobustSigmaAboutZero(std::vector<double> values);

// An evenly spread sample of at most `max_count` of the indices 0 .. count-1
// (k * count / max_count for k = 0 .. max_count-1); all of them, in order,
// when count <= max_count.
std::vector<size_t> EvenlySpreadIndices(size_t count, size_t max_count);

}  // namespace puzzlecal

#endif  // PUZZLECAL_UTIL_STATISTICS_H_
