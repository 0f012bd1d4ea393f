#include "detection/grey_blur.h"

#include <algorithm>
#include <cstdint>

#include "detection/vector_clones.h"

#ifdef PUZZLECAL_AVX2_INTRINSICS
#include <immintrin.h>
#endif

namespace puzzlecal {

namespace {

// The three distinct taps of a symmetric 5-tap kernel: outer, inner, middle.
struct Taps {
  float outer, inner, middle;
};

Taps TapsOf(const cv::Mat& kernel) {
  const float* k = kernel.ptr<float>();
  return {k[0], k[1], k[2]};
}

// The reference arithmetic of one output value (vertical pass: integer
// pixel sums; horizontal pass: float sums); the vector code does the same
// operations lane by lane.
inline float Combine(const Taps& t, float outer_sum, float inner_sum,
                     float middle) {
  return t.outer * outer_sum + (t.inner * inner_sum + t.middle * middle);
}

// Vertical pass of pixels [begin, width) of five rows into `out`.
void VerticalScalar(const uint8_t* const rows[5], int begin, int width,
                    const Taps& taps, float* out) {
  for (int x = begin; x < width; ++x) {
    out[x] = Combine(taps, static_cast<float>(rows[0][x] + rows[4][x]),
                     static_cast<float>(rows[1][x] + rows[3][x]),
                     static_cast<float>(rows[2][x]));
  }
}

// The two values before the first and after the last of a row of `width`
// (the horizontal pass's replicated border).
inline void ReplicateBorder(float* t, int width) {
  t[-2] = t[-1] = t[0];
  t[width] = t[width + 1] = t[width - 1];
}

// Horizontal pass of pixels [begin, width) of `in` (two replicated values
// before its first and after its last pixel) into `out`.
void HorizontalScalar(const float* in, int begin, int width, const Taps& taps,
                      float* out) {
  for (int x = begin; x < width; ++x) {
    out[x] = Combine(taps, in[x - 2] + in[x + 2], in[x - 1] + in[x + 1], in[x]);
  }
}

#ifdef PUZZLECAL_AVX2_INTRINSICS
__attribute__((target("avx2"))) inline __m256 CombineAvx2(
    __m256 outer, __m256 inner, __m256 middle, __m256 outer_sum,
    __m256 inner_sum, __m256 centre) {
  return _mm256_add_ps(_mm256_mul_ps(outer, outer_sum),
                       _mm256_add_ps(_mm256_mul_ps(inner, inner_sum),
                                     _mm256_mul_ps(middle, centre)));
}

// Eight int16 lanes (the low or high half of a vector) as floats.
__attribute__((target("avx2"))) inline __m256 LowToFloat(__m256i v) {
  return _mm256_cvtepi32_ps(_mm256_cvtepi16_epi32(_mm256_castsi256_si128(v)));
}
__attribute__((target("avx2"))) inline __m256 HighToFloat(__m256i v) {
  return _mm256_cvtepi32_ps(
      _mm256_cvtepi16_epi32(_mm256_extracti128_si256(v, 1)));
}

__attribute__((target("avx2"))) void BlurRowAvx2(const uint8_t* const rows[5],
                                                 int width, const Taps& ty,
                                                 const Taps& tx, float* padded,
                                                 float* out) {
  const __m256 a0 = _mm256_set1_ps(ty.outer), a1 = _mm256_set1_ps(ty.inner),
               a2 = _mm256_set1_ps(ty.middle);
  float* t = padded + 2;
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    __m256i p[5];
    for (int k = 0; k < 5; ++k) {
      p[k] = _mm256_cvtepu8_epi16(
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(rows[k] + x)));
    }
    const __m256i outer = _mm256_add_epi16(p[0], p[4]);
    const __m256i inner = _mm256_add_epi16(p[1], p[3]);
    _mm256_storeu_ps(t + x, CombineAvx2(a0, a1, a2, LowToFloat(outer),
                                        LowToFloat(inner), LowToFloat(p[2])));
    _mm256_storeu_ps(t + x + 8,
                     CombineAvx2(a0, a1, a2, HighToFloat(outer),
                                 HighToFloat(inner), HighToFloat(p[2])));
  }
  VerticalScalar(rows, x, width, ty, t);
  ReplicateBorder(t, width);
  const __m256 b0 = _mm256_set1_ps(tx.outer), b1 = _mm256_set1_ps(tx.inner),
               b2 = _mm256_set1_ps(tx.middle);
  x = 0;
  for (; x + 8 <= width; x += 8) {
    const __m256 outer =
        _mm256_add_ps(_mm256_loadu_ps(t + x - 2), _mm256_loadu_ps(t + x + 2));
    const __m256 inner =
        _mm256_add_ps(_mm256_loadu_ps(t + x - 1), _mm256_loadu_ps(t + x + 1));
    _mm256_storeu_ps(
        out + x, CombineAvx2(b0, b1, b2, outer, inner, _mm256_loadu_ps(t + x)));
  }
  HorizontalScalar(t, x, width, tx, out);
}
#endif

void BlurRowScalar(const uint8_t* const rows[5], int width, const Taps& ty,
                   const Taps& tx, float* padded, float* out) {
  float* t = padded + 2;
  VerticalScalar(rows, 0, width, ty, t);
  ReplicateBorder(t, width);
  HorizontalScalar(t, 0, width, tx, out);
}

}  // namespace

bool IsSymmetricKernel5(const cv::Mat& kernel) {
  if (kernel.type() != CV_32FC1 || kernel.total() != 5 ||
      !kernel.isContinuous()) {
    return false;
  }
  const float* k = kernel.ptr<float>();
  return k[0] == k[4] && k[1] == k[3];
}

void BlurGreyRows5(const cv::Mat& image, int first, int last,
                   const cv::Mat& kernel_x, const cv::Mat& kernel_y,
                   std::vector<float>* row, cv::Mat* out) {
  CV_Assert(image.type() == CV_8UC1 && IsSymmetricKernel5(kernel_x) &&
            IsSymmetricKernel5(kernel_y) && 0 <= first && first <= last &&
            last <= image.rows && out->type() == CV_32FC1 &&
            out->cols == image.cols && out->rows >= last - first);
  const int width = image.cols;
  const Taps ty = TapsOf(kernel_y), tx = TapsOf(kernel_x);
  row->resize(static_cast<size_t>(width) + 4);
#ifdef PUZZLECAL_AVX2_INTRINSICS
  const bool avx2 = CpuHasAvx2();
#endif
  for (int y = first; y < last; ++y) {
    const uint8_t* rows[5];
    for (int k = 0; k < 5; ++k) {
      rows[k] = image.ptr<uint8_t>(std::clamp(y + k - 2, 0, image.rows - 1));
    }
    float* o = out->ptr<float>(y - first);
#ifdef PUZZLECAL_AVX2_INTRINSICS
    if (avx2) {
      BlurRowAvx2(rows, width, ty, tx, row->data(), o);
      continue;
    }
#endif
    BlurRowScalar(rows, width, ty, tx, row->data(), o);
  }
}

}  // namespace puzzlecal
