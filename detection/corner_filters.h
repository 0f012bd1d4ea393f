#ifndef PUZZLECAL_DETECTION_CORNER_FILTERS_H_
#define PUZZLECAL_DETECTION_CORNER_FILTERS_H_

// Tests that tell checkerboard corners from other response peaks.

#include <opencv2/core.hpp>

namespace puzzlecal {

// The thesis's corner mask at one pixel of `image` (CV_32FC1): the strongest
// of the three 5x5 junction kernels (opposite points on the radius-2 ring
// summed, minus the pair rotated by 90 degrees) must exceed the strongest of
// the eight edge kernels (a point minus its opposite). Both taken in absolute
// value so either corner polarity passes. False within 2 px of the border.
bool PassesCornerMask(const cv::Mat& image, int x, int y);

// Bilinear sample of a CV_32FC1 image; the caller keeps (x, y) at least one
// pixel inside the image.
inline float SampleBilinear(const cv::Mat& image, double x, double y) {
  const int x0 = static_cast<int>(x);
  const int y0 = static_cast<int>(y);
  const float fx = static_cast<float>(x - x0);
  const float fy = static_cast<float>(y - y0);
  const float* r0 = image.ptr<float>(y0) + x0;
  const float* r1 = image.ptr<float>(y0 + 1) + x0;
  return (1.0f - fy) * ((1.0f - fx) * r0[0] + fx * r0[1]) +
         fy * ((1.0f - fx) * r1[0] + fx * r1[1]);
}

// Measurements of the grey values on a circle around a candidate.
struct RingMeasure {
  bool inside = false;     // the ring fitted into the image
  double contrast = 0.0;   // peak-to-peak amplitude of the 2nd harmonic
  double asymmetry = 0.0;  // rms(antisymmetric) / rms(symmetric part)
  double second_harmonic_share = 0.0;  // of the symmetric part's energy
  // |grey at the centre - ring mean| / contrast: 0 at a checkerboard corner
  // (point symmetry puts the centre half-way between dark and bright), large
  // in a bright or dark tile between two structures of the other colour.
  double centre_offset = 0.0;
};

// The ring test's sampler: the unit-circle offsets of `samples` points
// (clamped to a multiple of 4 in 8..64), computed once and shared by every
// measurement.
class RingSampler {
 public:
  explicit RingSampler(int samples);

  // Samples the circle of `radius` around (x, y) of `image` (CV_32FC1,
  // bilinear).
  RingMeasure Measure(const cv::Mat& image, double x, double y,
                      double radius) const;

 private:
  int samples_;
  double cos_[64];
  double sin_[64];
};

// One measurement with a sampler of `samples` points (a multiple of 4, at
// most 64) made for it.
RingMeasure MeasureRing(const cv::Mat& image, double x, double y, double radius,
                        int samples);

}  // namespace puzzlecal

#endif  // PUZZLECAL_DETECTION_CORNER_FILTERS_H_
