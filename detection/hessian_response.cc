#include "detection/hessian_response.h"

#include <algorithm>

namespace puzzlecal {

void ComputeSaddleResponse(const cv::Mat& blurred, float trace_weight_k,
                           cv::Mat* response) {
  CV_Assert(blurred.type() == CV_32FC1);
  const int width = blurred.cols;
  const int height = blurred.rows;
  response->create(height, width, CV_32FC1);
  response->setTo(0.0f);
  if (width < 5 || height < 5) return;
  const float k = trace_weight_k;
  for (int y = 2; y < height - 2; ++y) {
    const float* __restrict rm2 = blurred.ptr<float>(y - 2);
    const float* __restrict rm1 = blurred.ptr<float>(y - 1);
    const float* __restrict r0 = blurred.ptr<float>(y);
    const float* __restrict rp1 = blurred.ptr<float>(y + 1);
    const float* __restrict rp2 = blurred.ptr<float>(y + 2);
    float* __restrict out = response->ptr<float>(y);
    for (int x = 2; x < width - 2; ++x) {
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
      out[x] = a * b;
    }
  }
}

float SampledMedian(const cv::Mat& response, int step,
                    std::vector<float>* scratch) {
  scratch->clear();
  step = std::max(step, 1);
  for (int y = step / 2; y < response.rows; y += step) {
    const float* row = response.ptr<float>(y);
    for (int x = step / 2; x < response.cols; x += step) {
      scratch->push_back(row[x]);
    }
  }
  if (scratch->empty()) return 0.0f;
  auto middle = scratch->begin() + scratch->size() / 2;
  std::nth_element(scratch->begin(), middle, scratch->end());
  return *middle;
}

int FindResponsePeaks(const cv::Mat& response, float threshold, int radius,
                      std::vector<ResponsePeak>* peaks) {
  const int width = response.cols;
  const int height = response.rows;
  int above = 0;
  radius = std::max(radius, 1);
  for (int y = 1; y < height - 1; ++y) {
    const float* up = response.ptr<float>(y - 1);
    const float* row = response.ptr<float>(y);
    const float* down = response.ptr<float>(y + 1);
    for (int x = 1; x < width - 1; ++x) {
      const float v = row[x];
      if (!(v > threshold)) continue;
      ++above;
      // Cheap 3x3 test first: earlier pixels in scan order must be smaller,
      // later ones not larger.
      if (up[x - 1] >= v || up[x] >= v || up[x + 1] >= v || row[x - 1] >= v ||
          row[x + 1] > v || down[x - 1] > v || down[x] > v || down[x + 1] > v) {
        continue;
      }
      bool is_max = true;
      if (radius > 1) {
        const int y0 = std::max(y - radius, 0);
        const int y1 = std::min(y + radius, height - 1);
        const int x0 = std::max(x - radius, 0);
        const int x1 = std::min(x + radius, width - 1);
        for (int yy = y0; yy <= y1 && is_max; ++yy) {
          const float* r = response.ptr<float>(yy);
          for (int xx = x0; xx <= x1; ++xx) {
            const bool earlier = yy < y || (yy == y && xx < x);
            if (earlier ? r[xx] >= v : r[xx] > v) {
              is_max = false;
              break;
            }
          }
        }
      }
      if (is_max) peaks->push_back({x, y, v});
    }
  }
  return above;
}

}  // namespace puzzlecal
