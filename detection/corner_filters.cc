#include "detection/corner_filters.h"

#include <algorithm>
#include <cmath>

namespace puzzlecal {

bool PassesCornerMask(const cv::Mat& image, int x, int y) {
  if (x < 2 || y < 2 || x >= image.cols - 2 || y >= image.rows - 2) {
    return false;
  }
  // The 16 points of the 5x5 ring in angular order, starting at (2, 0).
  static const int kRing[16][2] = {{2, 0},  {2, 1},   {2, 2},   {1, 2},
                                   {0, 2},  {-1, 2},  {-2, 2},  {-2, 1},
                                   {-2, 0}, {-2, -1}, {-2, -2}, {-1, -2},
                                   {0, -2}, {1, -2},  {2, -2},  {2, -1}};
  float v[16];
  for (int i = 0; i < 16; ++i) {
    v[i] = image.ptr<float>(y + kRing[i][1])[x + kRing[i][0]];
  }
  // Edge kernels: a ring point minus the opposite one (8 distinct pairs).
  float edge = 0.0f;
  for (int i = 0; i < 8; ++i) edge = std::max(edge, std::abs(v[i] - v[i + 8]));
  // Junction kernels: the pair (i, i+8) against the pair rotated by 90
  // degrees (i+4, i+12); the thesis's three kernels are i = 0, 2, 3 (and
  // i = 1 is the mirror image of i = 3).
  float junction = 0.0f;
  for (int i = 0; i < 4; ++i) {
    junction = std::max(
        junction, std::abs(v[i] + v[i + 8] - v[i + 4] - v[(i + 12) % 16]));
  }
  return junction > edge;
}

RingSampler::RingSampler(int samples)
    : samples_(std::clamp(samples / 4 * 4, 8, 64)) {
  const double step = 2.0 * M_PI / samples_;
  for (int i = 0; i < samples_; ++i) {
    cos_[i] = std::cos(i * step);
    sin_[i] = std::sin(i * step);
  }
}

RingMeasure RingSampler::Measure(const cv::Mat& image, double x, double y,
                                 double radius) const {
  RingMeasure m;
  if (!(x - radius >= 0.0 && y - radius >= 0.0 &&
        x + radius < image.cols - 1.0 && y + radius < image.rows - 1.0)) {
    return m;
  }
  m.inside = true;
  const int samples = samples_;
  const double* table_cos = cos_;
  const double* table_sin = sin_;
  float v[64];
  double mean = 0.0;
  for (int i = 0; i < samples; ++i) {
    v[i] = SampleBilinear(image, x + radius * table_cos[i],
                          y + radius * table_sin[i]);
    mean += v[i];
  }
  mean /= samples;
  const int half = samples / 2;
  double even_energy = 0.0, odd_energy = 0.0, re2 = 0.0, im2 = 0.0;
  for (int i = 0; i < half; ++i) {
    const double even = 0.5 * (v[i] + v[i + half]) - mean;
    const double odd = 0.5 * (v[i] - v[i + half]);
    even_energy += even * even;
    odd_energy += odd * odd;
    // cos(2a), sin(2a) of sample i are the table entries of sample 2i.
    re2 += even * table_cos[(2 * i) % samples];
    im2 += even * table_sin[(2 * i) % samples];
  }
  // Second-harmonic amplitude of the symmetric part (cos 2a, sin 2a).
  const double amplitude = 2.0 * std::hypot(re2, im2) / half;
  m.contrast = 2.0 * amplitude;
  m.centre_offset =
      m.contrast > 0.0
          ? std::abs(SampleBilinear(image, x, y) - mean) / m.contrast
          : 1e9;
  m.asymmetry = even_energy > 0.0 ? std::sqrt(odd_energy / even_energy) : 1e9;
  m.second_harmonic_share =
      even_energy > 0.0 ? 0.5 * amplitude * amplitude / (even_energy / half)
                        : 0.0;
  return m;
}

RingMeasure MeasureRing(const cv::Mat& image, double x, double y, double radius,
                        int samples) {
  return RingSampler(samples).Measure(image, x, y, radius);
}

}  // namespace puzzlecal
