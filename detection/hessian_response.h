#ifndef PUZZLECAL_DETECTION_HESSIAN_RESPONSE_H_
#define PUZZLECAL_DETECTION_HESSIAN_RESPONSE_H_

// The thesis's Hessian saddle response on one (blurred) image level, and its
// peaks.

#include <opencv2/core.hpp>
#include <vector>

namespace puzzlecal {

// For every pixel of `blurred` (CV_32FC1), with second differences of
// spacing 2 (the thesis's [-1 0 1] kernel applied twice):
//   S   = rxx ryy - rxy^2 + k (rxx + ryy)^2            (axis-aligned)
//   S_d = rll rrr - rlr^2 + k (rll + rrr)^2            (diagonals)
// and writes max(-S, 0) * max(-S_d, 0) into `response` (CV_32FC1, same size;
// 0 on the 2-pixel border). Positive only where both Hessians see a saddle.
void ComputeSaddleResponse(const cv::Mat& blurred, float trace_weight_k,
                           cv::Mat* response);

// The same response for one row `y` of `blurred` into `out` (width floats).
void ComputeSaddleResponseRow(const cv::Mat& blurred, int y,
                              float trace_weight_k, float* out);

// Median of the response sampled every `step` pixels in x and y (step >= 1,
// starting at step / 2), computed at those pixels only. `scratch` is reused
// between calls.
float SampledResponseMedian(const cv::Mat& blurred, float trace_weight_k,
                            int step, std::vector<float>* scratch);

// An integer local maximum of the response.
struct ResponsePeak {
  int x = 0;
  int y = 0;
  float value = 0.0f;  // the response (product form) at the peak
  // The thesis's sub-pixel step: centroid of the squared response over the
  // 3x3 neighbourhood of the peak.
  float centroid_x = 0.0f;
  float centroid_y = 0.0f;
};

// Pixels whose response exceeds `threshold` (product form) and is the
// maximum of the (2 radius + 1)^2 window around it (clipped to the image).
// Ties are broken by scan order (the first pixel wins), so plateaus yield
// one peak. The response is computed row by row into a ring of 2 radius + 1
// rows (`rows`, reused between calls) and never stored whole. Appends in
// scan order. Returns the number of pixels above the threshold.
int FindSaddlePeaks(const cv::Mat& blurred, float trace_weight_k,
                    float threshold, int radius, std::vector<float>* rows,
                    std::vector<ResponsePeak>* peaks);

// A horizontal band of `blurred` for FindSaddlePeaksInRows: peaks are
// reported for rows [begin, end) only; the rows around them (at least the
// suppression radius + 2) must be real image rows for the result to equal
// the whole image's. Optionally the response is sampled every
// `sample_step` pixels on those rows whose index + `y_offset` (the band's
// first row in the whole image) is sample_step / 2 modulo sample_step, at x
// = sample_step / 2 + i sample_step: the samples of SampledResponseMedian.
struct PeakRows {
  int begin = 0;
  int end = 0;
  int y_offset = 0;
  int sample_step = 1;
  std::vector<float>* samples = nullptr;
};

// FindSaddlePeaks restricted to the rows of `part` (peak rows in the
// coordinates of `blurred`).
int FindSaddlePeaksInRows(const cv::Mat& blurred, float trace_weight_k,
                          float threshold, int radius, const PeakRows& part,
                          std::vector<float>* rows,
                          std::vector<ResponsePeak>* peaks);

}  // namespace puzzlecal

#endif  // PUZZLECAL_DETECTION_HESSIAN_RESPONSE_H_
