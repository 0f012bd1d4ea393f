#include "detection/hessian_response.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "detection/vector_clones.h"

#ifdef PUZZLECAL_AVX2_INTRINSICS
#include <immintrin.h>
#endif

namespace puzzlecal {

namespace {

// The response at interior pixel x of row y (2 <= x < width - 2,
// 2 <= y < height - 2), rows given as pointers.
inline float ResponseAt(const float* __restrict rm2,
                        const float* __restrict rm1, const float* __restrict r0,
                        const float* __restrict rp1,
                        const float* __restrict rp2, int x, float k) {
  const float c2 = 2.0f * r0[x];
  // Axis-aligned second differences (spacing 2).
  const float rxx = r0[x + 2] + r0[x - 2] - c2;
  const float ryy = rp2[x] + rm2[x] - c2;
  const float rxy = rp1[x + 1] - rp1[x - 1] - rm1[x + 1] + rm1[x - 1];
  const float trace = rxx + ryy;
  const float s = rxx * ryy - rxy * rxy + k * trace * trace;
  // Diagonal second differences: along (1,1), along (1,-1) and mixed.
  const float rll = rm2[x - 2] + rp2[x + 2] - c2;
  const float rrr = rm2[x + 2] + rp2[x - 2] - c2;
  const float rlr = ryy - rxx;
  const float trace_d = rll + rrr;
  const float s_d = rll * rrr - rlr * rlr + k * trace_d * trace_d;
  const float a = std::max(-s, 0.0f);
  const float b = std::max(-s_d, 0.0f);
  return a * b;
}

}  // namespace

PUZZLECAL_VECTOR_CLONES void ComputeSaddleResponseRow(const cv::Mat& blurred,
                                                      int y,
                                                      float trace_weight_k,
                                                      float* __restrict out) {
  const int width = blurred.cols;
  const int height = blurred.rows;
  if (y < 2 || y >= height - 2 || width < 5) {
    std::fill(out, out + width, 0.0f);
    return;
  }
  const float* rm2 = blurred.ptr<float>(y - 2);
  const float* rm1 = blurred.ptr<float>(y - 1);
  const float* r0 = blurred.ptr<float>(y);
  const float* rp1 = blurred.ptr<float>(y + 1);
  const float* rp2 = blurred.ptr<float>(y + 2);
  out[0] = out[1] = 0.0f;
  out[width - 2] = out[width - 1] = 0.0f;
  for (int x = 2; x < width - 2; ++x) {
    out[x] = ResponseAt(rm2, rm1, r0, rp1, rp2, x, trace_weight_k);
  }
}

void ComputeSaddleResponse(const cv::Mat& blurred, float trace_weight_k,
                           cv::Mat* response) {
  CV_Assert(blurred.type() == CV_32FC1);
  response->create(blurred.rows, blurred.cols, CV_32FC1);
  for (int y = 0; y < blurred.rows; ++y) {
    ComputeSaddleResponseRow(blurred, y, trace_weight_k,
                             response->ptr<float>(y));
  }
}

float SampledResponseMedian(const cv::Mat& blurred, float trace_weight_k,
                            int step, std::vector<float>* scratch) {
  scratch->clear();
  step = std::max(step, 1);
  const int width = blurred.cols;
  const int height = blurred.rows;
  for (int y = step / 2; y < height; y += step) {
    const bool inside_y = y >= 2 && y < height - 2;
    for (int x = step / 2; x < width; x += step) {
      if (!inside_y || x < 2 || x >= width - 2) {
        scratch->push_back(0.0f);
        continue;
      }
      scratch->push_back(
          ResponseAt(blurred.ptr<float>(y - 2), blurred.ptr<float>(y - 1),
                     blurred.ptr<float>(y), blurred.ptr<float>(y + 1),
                     blurred.ptr<float>(y + 2), x, trace_weight_k));
    }
  }
  if (scratch->empty()) return 0.0f;
  auto middle = scratch->begin() + scratch->size() / 2;
  std::nth_element(scratch->begin(), middle, scratch->end());
  return *middle;
}

int FindSaddlePeaks(const cv::Mat& blurred, float trace_weight_k,
                    float threshold, int radius, std::vector<float>* rows,
                    std::vector<ResponsePeak>* peaks) {
  PeakRows all;
  all.end = blurred.rows;
  return FindSaddlePeaksInRows(blurred, trace_weight_k, threshold, radius, all,
                               rows, peaks);
}

namespace {

// The last 2 radius + 1 response rows, kept in a ring of rows inside the
// caller's buffer, and one row of flags as bits (bit l of byte i: pixel
// 8 i + l; bytes up to a multiple of 8).
class ResponseRing {
 public:
  ResponseRing(int width, int radius, std::vector<float>* buffer)
      : width_(width), ring_(2 * radius + 1) {
    const size_t row_size = static_cast<size_t>(width);
    const size_t bit_bytes = BitBytes(width);
    buffer->resize(ring_ * row_size + bit_bytes / 4);
    response_ = buffer->data();
    bits_ = reinterpret_cast<uint8_t*>(buffer->data() + ring_ * row_size);
  }

  // Bytes of the bit flags of a row: whole 64-pixel words.
  static size_t BitBytes(int width) {
    return (static_cast<size_t>(width) + 63) / 64 * 8;
  }

  float* Row(int y) const { return response_ + Offset(y); }
  uint8_t* Bits() const { return bits_; }

 private:
  size_t Offset(int y) const {
    return static_cast<size_t>(y % ring_) * static_cast<size_t>(width_);
  }
  int width_;
  int ring_;
  float* response_;
  uint8_t* bits_;
};

// Response row `y` into the ring and its samples for the median (see
// PeakRows).
inline void AddResponseRow(const cv::Mat& blurred, int y, float k,
                           const PeakRows& part, int row_begin, int row_end,
                           const ResponseRing& ring) {
  const int width = blurred.cols;
  float* __restrict out = ring.Row(y);
  ComputeSaddleResponseRow(blurred, y, k, out);
  if (part.samples != nullptr && y >= row_begin && y < row_end &&
      (y + part.y_offset) % part.sample_step == part.sample_step / 2) {
    for (int x = part.sample_step / 2; x < width; x += part.sample_step) {
      part.samples->push_back(out[x]);
    }
  }
}

// Whether no pixel of the 3x3 neighbourhood of interior pixel x (rows
// `up`, `row`, `down`), of value v, exceeds it.
inline bool IsMaximumOf3x3(const float* up, const float* row, const float* down,
                           int x, float v) {
  return !(up[x - 1] > v || up[x] > v || up[x + 1] > v || row[x - 1] > v ||
           row[x + 1] > v || down[x - 1] > v || down[x] > v || down[x + 1] > v);
}

// Sets the flag bits (in `bits`, cleared by the caller) of the pixels x in
// [begin, end) of the middle row above the threshold and the maximum of
// their 3x3 neighbourhood (ties included); returns the number above the
// threshold.
// Pixels 0 and width - 1 are never flagged nor counted.
inline int FlagLocalMaximaScalar(const float* up, const float* row,
                                 const float* down, int width, int begin,
                                 int end, float threshold, uint8_t* bits) {
  int count = 0;
  for (int x = std::max(begin, 1); x < std::min(end, width - 1); ++x) {
    const float v = row[x];
    if (!(v > threshold)) continue;
    ++count;
    if (IsMaximumOf3x3(up, row, down, x, v)) {
      bits[x / 8] = static_cast<uint8_t>(bits[x / 8] | (1u << (x % 8)));
    }
  }
  return count;
}

#ifdef PUZZLECAL_AVX2_INTRINSICS
// Flag bits of the 8 pixels from x on (1 <= x, x + 9 <= width), given
// their comparison with the threshold (`v`, `above`).
__attribute__((target("avx2"))) inline uint8_t MaximaOf8(const float* up,
                                                         const float* row,
                                                         const float* down,
                                                         int x, __m256 v,
                                                         int above) {
  __m256 m =
      _mm256_max_ps(_mm256_loadu_ps(up + x - 1), _mm256_loadu_ps(up + x));
  m = _mm256_max_ps(m, _mm256_loadu_ps(up + x + 1));
  m = _mm256_max_ps(m, _mm256_loadu_ps(row + x - 1));
  m = _mm256_max_ps(m, _mm256_loadu_ps(row + x + 1));
  m = _mm256_max_ps(m, _mm256_loadu_ps(down + x - 1));
  m = _mm256_max_ps(m, _mm256_loadu_ps(down + x));
  m = _mm256_max_ps(m, _mm256_loadu_ps(down + x + 1));
  // Not exceeded by any neighbour: v >= their maximum.
  const int is_max = _mm256_movemask_ps(_mm256_cmp_ps(v, m, _CMP_GE_OQ));
  return static_cast<uint8_t>(above & is_max);
}

// The same, 8 pixels per vector comparison, 32 compared before a branch;
// the 3x3 maxima only for the blocks of 32 with a pixel above the
// threshold (nearly all have none). The first 8 pixels and the last ones
// go through the scalar code (their neighbourhoods leave the row).
__attribute__((target("avx2"))) int FlagLocalMaximaAvx2(
    const float* up, const float* row, const float* down, int width,
    float threshold, uint8_t* bits) {
  const __m256 t = _mm256_set1_ps(threshold);
  int count =
      FlagLocalMaximaScalar(up, row, down, width, 0, 8, threshold, bits);
  int x = 8;
  for (; x + 33 <= width; x += 32) {
    __m256 v[4];
    __m256 any = _mm256_setzero_ps();
    __m256 above[4];
    for (int g = 0; g < 4; ++g) {
      v[g] = _mm256_loadu_ps(row + x + 8 * g);
      above[g] = _mm256_cmp_ps(v[g], t, _CMP_GT_OQ);
      any = _mm256_or_ps(any, above[g]);
    }
    if (_mm256_testz_ps(any, any)) continue;
    for (int g = 0; g < 4; ++g) {
      const int mask = _mm256_movemask_ps(above[g]);
      count += __builtin_popcount(mask);
      bits[x / 8 + g] = MaximaOf8(up, row, down, x + 8 * g, v[g], mask);
    }
  }
  for (; x + 9 <= width; x += 8) {
    const __m256 v = _mm256_loadu_ps(row + x);
    const int mask = _mm256_movemask_ps(_mm256_cmp_ps(v, t, _CMP_GT_OQ));
    count += __builtin_popcount(mask);
    bits[x / 8] = MaximaOf8(up, row, down, x, v, mask);
  }
  return count +
         FlagLocalMaximaScalar(up, row, down, width, x, width, threshold, bits);
}

#endif

// The flags of row y as bits (ring.Bits()): pixels above the threshold
// that no pixel of their 3x3 neighbourhood exceeds. Returns the number of
// pixels above the threshold (pixels 0 and width - 1 excepted: they have no
// 3x3 neighbourhood).
inline int FlagLocalMaxima(const ResponseRing& ring, int y, int width,
                           float threshold) {
  uint8_t* bits = ring.Bits();
  std::memset(bits, 0, ResponseRing::BitBytes(width));
  const float* up = ring.Row(y - 1);
  const float* row = ring.Row(y);
  const float* down = ring.Row(y + 1);
#ifdef PUZZLECAL_AVX2_INTRINSICS
  if (CpuHasAvx2()) {
    return FlagLocalMaximaAvx2(up, row, down, width, threshold, bits);
  }
#endif
  return FlagLocalMaximaScalar(up, row, down, width, 0, width, threshold, bits);
}

// Whether the flagged pixel (x, y) of value v is the maximum of its
// (2 radius + 1)^2 window (clipped to the image); ties go to the first
// pixel in scan order.
inline bool IsWindowMaximum(const ResponseRing& ring, int x, int y, float v,
                            int radius, int width, int height) {
  const float* up = ring.Row(y - 1);
  const float* row = ring.Row(y);
  // Ties in the 3x3 neighbourhood: earlier pixels in scan order must be
  // smaller, later ones not larger.
  if (up[x - 1] >= v || up[x] >= v || up[x + 1] >= v || row[x - 1] >= v) {
    return false;
  }
  if (radius <= 1) return true;
  const int ya = std::max(y - radius, 0);
  const int yb = std::min(y + radius, height - 1);
  const int xa = std::max(x - radius, 0);
  const int xb = std::min(x + radius, width - 1);
  for (int yy = ya; yy <= yb; ++yy) {
    const float* r = ring.Row(yy);
    for (int xx = xa; xx <= xb; ++xx) {
      const bool earlier = yy < y || (yy == y && xx < x);
      if (earlier ? r[xx] >= v : r[xx] > v) return false;
    }
  }
  return true;
}

// The peak at (x, y) with the thesis's centroid of the squared response
// over its 3x3 neighbourhood.
inline ResponsePeak PeakAt(const ResponseRing& ring, int x, int y, float v) {
  ResponsePeak peak;
  peak.x = x;
  peak.y = y;
  peak.value = v;
  double sum = 0.0, sx = 0.0, sy = 0.0;
  for (int dy = -1; dy <= 1; ++dy) {
    const float* r = ring.Row(y + dy);
    for (int dx = -1; dx <= 1; ++dx) {
      const double w = static_cast<double>(r[x + dx]) * r[x + dx];
      sum += w;
      sx += w * dx;
      sy += w * dy;
    }
  }
  peak.centroid_x = static_cast<float>(x + (sum > 0.0 ? sx / sum : 0.0));
  peak.centroid_y = static_cast<float>(y + (sum > 0.0 ? sy / sum : 0.0));
  return peak;
}

}  // namespace

PUZZLECAL_VECTOR_CLONES int FindSaddlePeaksInRows(
    const cv::Mat& blurred, float trace_weight_k, float threshold, int radius,
    const PeakRows& part, std::vector<float>* rows,
    std::vector<ResponsePeak>* peaks) {
  CV_Assert(blurred.type() == CV_32FC1);
  const int width = blurred.cols;
  const int height = blurred.rows;
  const int row_begin = std::max(part.begin, 0);
  const int row_end = std::min(part.end, height);
  radius = std::max(radius, 1);
  const ResponseRing ring(width, radius, rows);
  const uint8_t* bits = ring.Bits();
  const int bit_bytes = static_cast<int>(ResponseRing::BitBytes(width));
  // Only the response rows that the windows of rows [row_begin, row_end)
  // reach are computed (a band's halo rows beyond them are not).
  const int first_row = std::max(0, row_begin - radius);
  const int last_row = std::min(height, std::max(row_end, 0) + radius);
  int above = 0;
  for (int y_new = first_row; y_new < last_row + radius; ++y_new) {
    if (y_new < last_row) {
      AddResponseRow(blurred, y_new, trace_weight_k, part, row_begin, row_end,
                     ring);
    }
    const int y = y_new - radius;  // the row whose window is complete
    if (y < 1 || y > height - 2 || y < row_begin || y >= row_end) continue;
    above += FlagLocalMaxima(ring, y, width, threshold);
    const float* row = ring.Row(y);
    for (int i0 = 0; i0 < bit_bytes; i0 += 8) {
      // Skip 64 flags at once (almost all are zero); then the flagged
      // pixels in scan order.
      uint64_t word;
      std::memcpy(&word, bits + i0, sizeof word);
      if (word == 0) continue;
      for (int i = i0; i < i0 + 8; ++i) {
        for (unsigned byte = bits[i]; byte != 0; byte &= byte - 1) {
          const int x = 8 * i + __builtin_ctz(byte);
          if (IsWindowMaximum(ring, x, y, row[x], radius, width, height)) {
            peaks->push_back(PeakAt(ring, x, y, row[x]));
          }
        }
      }
    }
  }
  return above;
}

}  // namespace puzzlecal
