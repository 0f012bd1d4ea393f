#include "detection/detector.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detection/corner_filters.h"
#include "detection/hessian_response.h"
#include "detection/subpixel.h"

namespace puzzlecal {

bool DetectorOptions::Check(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why != nullptr) *why = text;
    return false;
  };
  if (!(blur_sigma_px >= 0.0 && blur_sigma_px <= 20.0)) {
    return fail("blur_sigma_px must be in [0, 20]");
  }
  if (num_levels < 1 || num_levels > 6) return fail("num_levels must be 1..6");
  if (first_level < 0 || first_level >= num_levels) {
    return fail("first_level must be in [0, num_levels)");
  }
  if (!(trace_weight_k >= 0.0 && std::isfinite(trace_weight_k))) {
    return fail("trace_weight_k must be >= 0");
  }
  if (!(min_response > 0.0 && std::isfinite(min_response))) {
    return fail("min_response must be > 0");
  }
  if (!(noise_response_factor >= 0.0 && std::isfinite(noise_response_factor))) {
    return fail("noise_response_factor must be >= 0");
  }
  if (nms_radius_px < 1 || nms_radius_px > 50) {
    return fail("nms_radius_px must be in [1, 50]");
  }
  if (nms_radius_coarse_px < 1 || nms_radius_coarse_px > 50) {
    return fail("nms_radius_coarse_px must be in [1, 50]");
  }
  if (!(ring_radius_px >= 1.5 && ring_radius_px <= 20.0)) {
    return fail("ring_radius_px must be in [1.5, 20]");
  }
  if (ring_samples < 8 || ring_samples > 64 || ring_samples % 4 != 0) {
    return fail("ring_samples must be a multiple of 4 in [8, 64]");
  }
  if (!(min_ring_contrast >= 0.0))
    return fail("min_ring_contrast must be >= 0");
  if (!(max_ring_asymmetry > 0.0))
    return fail("max_ring_asymmetry must be > 0");
  if (!(min_contrast_factor_clean >= 1.0)) {
    return fail("min_contrast_factor_clean must be >= 1");
  }
  if (!(max_ring_asymmetry_clean > 0.0)) {
    return fail("max_ring_asymmetry_clean must be > 0");
  }
  if (!(min_ring_second_harmonic_clean >= 0.0 &&
        min_ring_second_harmonic_clean <= 1.0)) {
    return fail("min_ring_second_harmonic_clean must be in [0, 1]");
  }
  if (!(min_ring_second_harmonic >= 0.0 && min_ring_second_harmonic <= 1.0)) {
    return fail("min_ring_second_harmonic must be in [0, 1]");
  }
  if (!(ring_noise_factor >= 0.0 && std::isfinite(ring_noise_factor))) {
    return fail("ring_noise_factor must be >= 0");
  }
  if (!(max_ring_centre_offset > 0.0)) {
    return fail("max_ring_centre_offset must be > 0");
  }
  if (!(window_fraction_of_neighbor > 0.0 &&
        window_fraction_of_neighbor <= 1.0)) {
    return fail("window_fraction_of_neighbor must be in (0, 1]");
  }
  if (min_window_px < 2 || max_window_px > 64 ||
      min_window_px > max_window_px) {
    return fail("need 2 <= min_window_px <= max_window_px <= 64");
  }
  if (!(saddle_sigma_fraction > 0.0 && saddle_sigma_fraction <= 1.0)) {
    return fail("saddle_sigma_fraction must be in (0, 1]");
  }
  if (!(min_saddle_sigma_px >= 0.5 &&
        min_saddle_sigma_px <= max_saddle_sigma_px &&
        max_saddle_sigma_px <= 16.0)) {
    return fail("need 0.5 <= min_saddle_sigma_px <= max_saddle_sigma_px <= 16");
  }
  if (saddle_max_iterations < 1 || saddle_max_iterations > 100) {
    return fail("saddle_max_iterations must be in [1, 100]");
  }
  if (!(saddle_convergence_px > 0.0)) {
    return fail("saddle_convergence_px must be > 0");
  }
  if (max_iterations < 1 || max_iterations > 100) {
    return fail("max_iterations must be in [1, 100]");
  }
  if (!(convergence_px > 0.0)) return fail("convergence_px must be > 0");
  if (!(max_shift_fraction > 0.0))
    return fail("max_shift_fraction must be > 0");
  if (!(merge_distance_px >= 0.0))
    return fail("merge_distance_px must be >= 0");
  if (!(orientation_spacing_fraction > 0.0)) {
    return fail("orientation_spacing_fraction must be > 0");
  }
  return true;
}

namespace {

// CPU time of the calling thread: on a shared machine wall time measures
// the neighbours, not the detector.
struct Clock {
  using time_point = double;  // milliseconds
  static time_point now() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
  }
};

double MsSince(Clock::time_point start) { return Clock::now() - start; }

// Buffers reused by consecutive calls on one thread (same-size images then
// cause no allocation and no page faults).
struct Workspace {
  cv::Mat single;                // one-channel input (colour converted)
  cv::Mat finite;                // float input with non-finite pixels zeroed
  std::vector<cv::Mat> blurred;  // per level, CV_32FC1, grey in [0, 1]
  std::vector<float> response_rows;  // ring of response rows
  std::vector<float> row;            // one row of the downsampling
  cv::Mat band;                      // blurred rows of a band of level 0
  std::vector<float> scratch;
};

// Largest pixel value of a one-channel image (a loop the compiler
// vectorises; cv::minMaxLoc also tracks locations).
template <typename Pixel>
double MaxValueOf(const cv::Mat& image) {
  Pixel best = 0;
  for (int y = 0; y < image.rows; ++y) {
    const Pixel* __restrict row = image.ptr<Pixel>(y);
    Pixel row_max = 0;
    for (int x = 0; x < image.cols; ++x) row_max = std::max(row_max, row[x]);
    best = std::max(best, row_max);
  }
  return static_cast<double>(best);
}

double MaxValue(const cv::Mat& image) {
  switch (image.depth()) {
    case CV_8U:
      return MaxValueOf<uint8_t>(image);
    case CV_16U:
      return MaxValueOf<uint16_t>(image);
    default: {
      double max_value = 0.0;
      cv::minMaxLoc(image, nullptr, &max_value);
      return max_value;
    }
  }
}

// Halves the resolution of a CV_32FC1 image: binomial [1 2 1] / 4 in x and
// y at every second pixel (output pixel (i, j) is centred on input pixel
// (2i, 2j); replicated border). Output size as cv::pyrDown's. Lighter than
// pyrDown's 5x5 kernel; the input is already blurred. Writes output rows
// [i0, i1) of `dst` (already of the output size) from `src`, which holds
// input rows [src_first, src_first + src.rows) of an image `height` rows
// high; the input rows 2 i - 1 .. 2 i + 1 (clamped) must be in `src`.
void DownsampleRows(const cv::Mat& src, int src_first, int height, int i0,
                    int i1, std::vector<float>* row, cv::Mat* dst) {
  const int width = src.cols;
  const int out_width = dst->cols;
  row->resize(width);
  float* __restrict tmp = row->data();
  for (int i = i0; i < i1; ++i) {
    const int y = 2 * i;
    const float* __restrict up = src.ptr<float>(std::max(y - 1, 0) - src_first);
    const float* __restrict mid =
        src.ptr<float>(std::min(y, height - 1) - src_first);
    const float* __restrict down =
        src.ptr<float>(std::min(y + 1, height - 1) - src_first);
    for (int x = 0; x < width; ++x) {
      tmp[x] = 0.25f * (up[x] + 2.0f * mid[x] + down[x]);
    }
    float* __restrict out = dst->ptr<float>(i);
    out[0] = 0.25f * (3.0f * tmp[0] + (width > 1 ? tmp[1] : tmp[0]));
    for (int j = 1; j < out_width; ++j) {
      const int x = 2 * j;
      out[j] = 0.25f * (tmp[x - 1] + 2.0f * tmp[std::min(x, width - 1)] +
                        tmp[std::min(x + 1, width - 1)]);
    }
  }
}

void Downsample(const cv::Mat& src, std::vector<float>* row, cv::Mat* dst) {
  dst->create((src.rows + 1) / 2, (src.cols + 1) / 2, CV_32FC1);
  DownsampleRows(src, 0, src.rows, 0, dst->rows, row, dst);
}

// Largest magnitude a float input pixel keeps (grey is normally in [0, 1]).
constexpr float kMaxFloatPixel = 1e6f;

// Picks the one-channel, finite version of the input and the grey value
// that maps to 1.0. Returns false with a reason for unsupported types.
bool PrepareInput(const cv::Mat& image, bool normalize_by_max, Workspace* ws,
                  const cv::Mat** single, double* normalizer,
                  std::string* why) {
  if (image.channels() == 1) {
    *single = &image;
  } else if ((image.channels() == 3 || image.channels() == 4) &&
             (image.depth() == CV_8U || image.depth() == CV_16U ||
              image.depth() == CV_32F)) {
    cv::cvtColor(
        image, ws->single,
        image.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
    *single = &ws->single;
  } else {
    *why = "unsupported number of channels";
    return false;
  }
  double full_scale = 1.0;
  switch ((*single)->depth()) {
    case CV_8U:
      full_scale = 255.0;
      break;
    case CV_16U:
      full_scale = 65535.0;
      break;
    case CV_32F:
      full_scale = 1.0;
      break;
    default:
      *why = "unsupported pixel type (need 8-bit, 16-bit or 32-bit float)";
      return false;
  }
  if ((*single)->depth() == CV_32F) {
    // Non-finite pixels become 0, and magnitudes are capped at
    // kMaxFloatPixel: the response multiplies four second derivatives, which
    // would overflow float for values near its range.
    (*single)->copyTo(ws->finite);
    for (int y = 0; y < ws->finite.rows; ++y) {
      float* row = ws->finite.ptr<float>(y);
      for (int x = 0; x < ws->finite.cols; ++x) {
        if (!std::isfinite(row[x])) {
          row[x] = 0.0f;
        } else {
          row[x] = std::clamp(row[x], -kMaxFloatPixel, kMaxFloatPixel);
        }
      }
    }
    *single = &ws->finite;
  }
  double scale = full_scale;
  if (normalize_by_max) {
    const double max_value = MaxValue(**single);
    if (max_value > 0.0) scale = max_value;
  }
  *normalizer = scale;
  return true;
}

// Robust standard deviation of the pixel noise of `image` (one channel):
// 1.4826 times the median absolute difference between a pixel and the mean
// of its four neighbours (scaled to unit gain for white noise), sampled
// every `step` pixels. Edges and corners are a small share of the samples.
template <typename Pixel>
double NoiseSigmaOf(const cv::Mat& image, int step,
                    std::vector<float>* scratch) {
  scratch->clear();
  for (int y = 1 + step / 2; y < image.rows - 1; y += step) {
    const Pixel* up = image.ptr<Pixel>(y - 1);
    const Pixel* row = image.ptr<Pixel>(y);
    const Pixel* down = image.ptr<Pixel>(y + 1);
    for (int x = 1 + step / 2; x < image.cols - 1; x += step) {
      scratch->push_back(std::abs(
          static_cast<float>(row[x]) -
          0.25f *
              (static_cast<float>(row[x - 1]) + static_cast<float>(row[x + 1]) +
               static_cast<float>(up[x]) + static_cast<float>(down[x]))));
    }
  }
  if (scratch->empty()) return 0.0;
  auto middle = scratch->begin() + scratch->size() / 2;
  std::nth_element(scratch->begin(), middle, scratch->end());
  // For white noise of sigma n the difference has sigma n sqrt(1.25).
  return 1.4826 * *middle / std::sqrt(1.25);
}

double NoiseSigma(const cv::Mat& image, int step, std::vector<float>* scratch) {
  switch (image.depth()) {
    case CV_8U:
      return NoiseSigmaOf<uint8_t>(image, step, scratch);
    case CV_16U:
      return NoiseSigmaOf<uint16_t>(image, step, scratch);
    case CV_32F:
      return NoiseSigmaOf<float>(image, step, scratch);
    default:
      return 0.0;
  }
}

// Suppression radius of pyramid level `level`.
int NmsRadius(const DetectorOptions& options, int level) {
  return level == 0 ? options.nms_radius_px : options.nms_radius_coarse_px;
}

// A verified candidate in full-resolution pixels.
struct Candidate {
  Eigen::Vector2d xy;  // full-resolution position (before refinement)
  int level = 0;
  float response = 0.0f;  // sqrt of the product response at its level
  int peak_x = 0;         // integer peak at its level
  int peak_y = 0;
};

// Buckets of point indices on a square grid, for radius queries.
class PointGrid {
 public:
  PointGrid(double cell, int width, int height)
      : cell_(std::max(cell, 1.0)),
        cols_(static_cast<int>(width / cell_) + 1),
        rows_(static_cast<int>(height / cell_) + 1),
        cells_(static_cast<size_t>(cols_) * rows_) {}

  void Add(const Eigen::Vector2d& p, int index) {
    cells_[static_cast<size_t>(CellOf(p.y(), rows_)) * cols_ +
           CellOf(p.x(), cols_)]
        .push_back(index);
  }

  // Calls f(index) for every stored point in cells within `radius` of p
  // (points outside the image sit in the border cells).
  template <typename F>
  void ForNear(const Eigen::Vector2d& p, double radius, F f) const {
    const int cx0 = CellOf(p.x() - radius, cols_);
    const int cx1 = CellOf(p.x() + radius, cols_);
    const int cy0 = CellOf(p.y() - radius, rows_);
    const int cy1 = CellOf(p.y() + radius, rows_);
    for (int cy = cy0; cy <= cy1; ++cy) {
      for (int cx = cx0; cx <= cx1; ++cx) {
        for (int index : cells_[static_cast<size_t>(cy) * cols_ + cx]) {
          f(index);
        }
      }
    }
  }

 private:
  int CellOf(double v, int count) const {
    const double cell = std::floor(v / cell_);
    if (!(cell >= 0.0)) return 0;  // also NaN
    return cell >= count - 1 ? count - 1 : static_cast<int>(cell);
  }
  double cell_;
  int cols_;
  int rows_;
  std::vector<std::vector<int>> cells_;
};

}  // namespace

std::vector<Corner> DetectCorners(const cv::Mat& image,
                                  const DetectorOptions& options,
                                  DetectorSummary* summary) {
  DetectorSummary local_summary;
  DetectorSummary& s = summary != nullptr ? *summary : local_summary;
  s = DetectorSummary();
  const Clock::time_point t_start = Clock::now();
  std::vector<Corner> corners;
  std::string why;
  if (!options.Check(&why)) {
    s.message = "invalid detector options: " + why;
    return corners;
  }
  if (image.empty()) {
    s.message = "empty image";
    return corners;
  }
  if (image.dims != 2) {
    s.message = "image is not two-dimensional";
    return corners;
  }
  s.width = image.cols;
  s.height = image.rows;
  constexpr int kMinSide = 8;
  if (image.cols < kMinSide || image.rows < kMinSide) {
    s.ok = true;
    s.message = "image smaller than 8x8 pixels: no corners";
    return corners;
  }

  // --- preprocessing ---
  Clock::time_point t = Clock::now();
  static thread_local Workspace ws;
  const cv::Mat* single = nullptr;
  if (!PrepareInput(image, options.normalize_by_max, &ws, &single,
                    &s.normalizer, &why)) {
    s.message = why;
    return corners;
  }
  std::vector<cv::Mat>& blurred = ws.blurred;
  blurred.resize(options.num_levels);
  // Grey rows [a, b) of the input, normalised and blurred, into `out`: one
  // separable pass from the input type straight to float, with the
  // normalisation folded into the kernel. On a band the filter reads the
  // input rows around it, so a band equals those rows of the whole image.
  cv::Mat kernel, kernel_scaled;
  if (options.blur_sigma_px > 0.0) {
    const int ksize =
        2 * static_cast<int>(std::ceil(2.0 * options.blur_sigma_px)) + 1;
    kernel = cv::getGaussianKernel(ksize, options.blur_sigma_px, CV_32F);
    kernel_scaled = kernel * (1.0 / s.normalizer);
  }
  auto blur_rows = [&](int a, int b, cv::Mat* out) {
    const cv::Mat band = single->rowRange(a, b);
    if (options.blur_sigma_px > 0.0) {
      cv::sepFilter2D(band, *out, CV_32F, kernel_scaled, kernel,
                      cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
    } else {
      band.convertTo(*out, CV_32F, 1.0 / s.normalizer);
    }
  };
  // Level 0 is streamed in bands of rows (blur, response, suppression,
  // filters and the next level's rows while the band is in cache) unless a
  // later step needs the whole blurred image (gradient orthogonality and
  // the circle orientation of the other refinements).
  const bool stream_level0 = options.first_level == 0 &&
                             options.subpixel == SubpixelMethod::kSaddleFit;
  int levels = 1;
  for (int l = 1; l < options.num_levels; ++l) {
    const int rows = l == 1 ? image.rows : blurred[l - 1].rows;
    const int cols = l == 1 ? image.cols : blurred[l - 1].cols;
    if (cols < 2 * kMinSide || rows < 2 * kMinSide) break;
    levels = l + 1;
  }
  if (!stream_level0) {
    blur_rows(0, image.rows, &blurred[0]);
    for (int l = 1; l < levels; ++l) {
      Downsample(blurred[l - 1], &ws.row, &blurred[l]);
    }
  } else if (levels > 1) {
    blurred[1].create((image.rows + 1) / 2, (image.cols + 1) / 2, CV_32FC1);
  }
  s.levels_used = std::max(0, levels - options.first_level);
  // Pixel noise of the input, grey normalised to [0, 1].
  const double noise = options.ring_noise_factor > 0.0
                           ? NoiseSigma(*single, 11, &ws.scratch) / s.normalizer
                           : 0.0;
  s.noise_sigma = noise;
  s.ms_preprocess = MsSince(t);

  // --- per level: response, threshold, NMS, filters ---
  std::vector<Candidate> candidates;
  std::vector<float>& scratch = ws.scratch;
  std::vector<ResponsePeak> peaks;
  const float k = static_cast<float>(options.trace_weight_k);
  const double min_contrast =
      std::max(options.min_ring_contrast, options.ring_noise_factor * noise);
  constexpr int kMedianStep = 12;  // sampling of the noise-adaptive threshold
  // The corner mask and the ring test on `level_image` (rows offset by
  // `y_offset` from the level's first row); appends a candidate in
  // full-resolution pixels when the peak passes.
  auto filter_peak = [&](const cv::Mat& level_image, int y_offset,
                         const ResponsePeak& peak, int l, bool* masked) {
    *masked = false;
    if (options.use_corner_mask &&
        !PassesCornerMask(level_image, peak.x, peak.y)) {
      return false;
    }
    *masked = true;
    if (options.use_ring_test) {
      const RingMeasure ring =
          MeasureRing(level_image, peak.centroid_x, peak.centroid_y,
                      options.ring_radius_px, options.ring_samples);
      const bool passes =
          ring.inside && ring.contrast >= min_contrast &&
          (ring.asymmetry <= options.max_ring_asymmetry ||
           (ring.asymmetry <= options.max_ring_asymmetry_clean &&
            ring.second_harmonic_share >=
                options.min_ring_second_harmonic_clean &&
            ring.contrast >=
                options.min_contrast_factor_clean * min_contrast)) &&
          ring.second_harmonic_share >= options.min_ring_second_harmonic &&
          ring.centre_offset <= options.max_ring_centre_offset;
      if (!passes) return false;
    }
    const double scale = std::ldexp(1.0, l);
    Candidate c;
    c.level = l;
    c.peak_x = peak.x;
    c.peak_y = peak.y + y_offset;
    c.response = std::sqrt(peak.value);
    c.xy = Eigen::Vector2d(peak.x * scale, c.peak_y * scale);
    // The centroid is also the start of the iterative refinements (closer
    // than the integer peak: fewer iterations).
    if (options.subpixel != SubpixelMethod::kNone) {
      c.xy =
          Eigen::Vector2d(peak.centroid_x, peak.centroid_y + y_offset) * scale;
    }
    candidates.push_back(c);
    return true;
  };

  if (stream_level0) {
    // Peaks above the absolute threshold per band, filtered while the band
    // is in cache; the noise-adaptive threshold (from the response sampled
    // on the way) then only drops weak peaks: a peak of the whole image is
    // a peak above the lower threshold that exceeds the higher one.
    constexpr int kBand = 64;
    // Rows around a band: response (2) + suppression radius + ring test.
    const int halo =
        2 + std::max(options.nms_radius_px,
                     static_cast<int>(std::ceil(options.ring_radius_px)) + 2);
    struct Kept {
      float value;
      bool masked;
      int candidate;  // index into candidates, -1 when filtered out
    };
    std::vector<Kept> kept;
    scratch.clear();
    const float absolute =
        static_cast<float>(options.min_response * options.min_response);
    for (int y0 = 0; y0 < image.rows; y0 += kBand) {
      t = Clock::now();
      const int y1 = std::min(y0 + kBand, image.rows);
      const int a = std::max(0, y0 - halo);
      const int b = std::min(image.rows, y1 + halo);
      blur_rows(a, b, &ws.band);
      if (levels > 1) {
        DownsampleRows(ws.band, a, image.rows, (y0 + 1) / 2, (y1 + 1) / 2,
                       &ws.row, &blurred[1]);
      }
      s.ms_preprocess += MsSince(t);

      t = Clock::now();
      PeakRows part;
      part.begin = y0 - a;
      part.end = y1 - a;
      part.y_offset = a;
      part.sample_step = kMedianStep;
      part.samples = options.noise_response_factor > 0.0 ? &scratch : nullptr;
      peaks.clear();
      s.candidates +=
          FindSaddlePeaksInRows(ws.band, k, absolute, options.nms_radius_px,
                                part, &ws.response_rows, &peaks);
      s.ms_response += MsSince(t);

      t = Clock::now();
      for (const ResponsePeak& peak : peaks) {
        const size_t before = candidates.size();
        bool masked = false;
        const bool passed = filter_peak(ws.band, a, peak, 0, &masked);
        kept.push_back(
            {peak.value, masked, passed ? static_cast<int>(before) : -1});
      }
      s.ms_filter += MsSince(t);
    }
    t = Clock::now();
    double threshold = options.min_response;
    if (options.noise_response_factor > 0.0 && !scratch.empty()) {
      auto middle = scratch.begin() + scratch.size() / 2;
      std::nth_element(scratch.begin(), middle, scratch.end());
      threshold = std::max(threshold,
                           options.noise_response_factor * std::sqrt(*middle));
    }
    s.threshold = threshold;
    const float squared = static_cast<float>(threshold * threshold);
    std::vector<Candidate> strong;
    for (const Kept& p : kept) {
      if (!(p.value > squared)) continue;
      ++s.after_nms;
      s.after_mask += p.masked ? 1 : 0;
      if (p.candidate >= 0) {
        ++s.after_ring;
        strong.push_back(candidates[p.candidate]);
      }
    }
    candidates = std::move(strong);
    s.ms_nms += MsSince(t);
  }

  for (int l = stream_level0 ? 1 : options.first_level; l < levels; ++l) {
    t = Clock::now();
    double threshold = options.min_response;
    if (options.noise_response_factor > 0.0) {
      const double median =
          SampledResponseMedian(blurred[l], k, kMedianStep, &scratch);
      threshold = std::max(threshold,
                           options.noise_response_factor * std::sqrt(median));
    }
    if (l == options.first_level) s.threshold = threshold;
    s.ms_nms += MsSince(t);

    t = Clock::now();
    peaks.clear();
    s.candidates += FindSaddlePeaks(
        blurred[l], k, static_cast<float>(threshold * threshold),
        NmsRadius(options, l), &ws.response_rows, &peaks);
    s.after_nms += static_cast<int>(peaks.size());
    s.ms_response += MsSince(t);

    t = Clock::now();
    for (const ResponsePeak& peak : peaks) {
      bool masked = false;
      const bool passed = filter_peak(blurred[l], 0, peak, l, &masked);
      s.after_mask += masked ? 1 : 0;
      s.after_ring += passed ? 1 : 0;
    }
    s.ms_filter += MsSince(t);
  }

  // --- merge levels (finer levels first), refine at full resolution ---
  t = Clock::now();
  std::vector<Candidate> merged;
  {
    PointGrid grid(8.0 * NmsRadius(options, 1), image.cols, image.rows);
    for (const Candidate& c : candidates) {  // already ordered by level
      const double radius =
          std::ldexp(1.0, c.level) * NmsRadius(options, c.level);
      bool taken = false;
      grid.ForNear(c.xy, radius, [&](int index) {
        if ((merged[index].xy - c.xy).norm() <= radius) taken = true;
      });
      if (taken) continue;
      grid.Add(c.xy, static_cast<int>(merged.size()));
      merged.push_back(c);
    }
  }
  s.after_merge_levels = static_cast<int>(merged.size());

  // Window half-size from the distance to the nearest other candidate.
  const double reach =
      options.max_window_px / options.window_fraction_of_neighbor;
  PointGrid neighbours(reach, image.cols, image.rows);
  for (size_t i = 0; i < merged.size(); ++i) {
    neighbours.Add(merged[i].xy, static_cast<int>(i));
  }
  std::vector<Corner> refined;
  std::vector<int> refined_window;
  refined.reserve(merged.size());
  for (size_t i = 0; i < merged.size(); ++i) {
    const Candidate& c = merged[i];
    double nearest = std::numeric_limits<double>::infinity();
    neighbours.ForNear(c.xy, reach, [&](int index) {
      if (index == static_cast<int>(i)) return;
      nearest = std::min(nearest, (merged[index].xy - c.xy).norm());
    });
    int window = options.max_window_px;
    if (std::isfinite(nearest)) {
      window = static_cast<int>(
          std::floor(options.window_fraction_of_neighbor * nearest));
    }
    window = std::clamp(window, options.min_window_px, options.max_window_px);
    // Near the image border the window shrinks instead of failing.
    const int room = static_cast<int>(std::floor(std::min(
                         {c.xy.x(), c.xy.y(), image.cols - 1.0 - c.xy.x(),
                          image.rows - 1.0 - c.xy.y()}))) -
                     2;
    window = std::max(options.min_window_px, std::min(window, room));
    Corner corner;
    corner.xy = c.xy;
    corner.response = c.response;
    if (options.subpixel == SubpixelMethod::kGradientOrthogonality) {
      const GradientRefineResult r = RefineByGradientOrthogonality(
          blurred[0], c.xy, window, options.max_iterations,
          options.convergence_px);
      if (!r.ok || (r.xy - c.xy).norm() > options.max_shift_fraction * window +
                                              std::ldexp(0.5, c.level)) {
        ++s.refine_failed;
        continue;
      }
      corner.xy = r.xy;
    } else if (options.subpixel == SubpixelMethod::kSaddleFit) {
      double sigma = options.max_saddle_sigma_px;
      if (std::isfinite(nearest)) {
        sigma = options.saddle_sigma_fraction * nearest;
      }
      sigma = std::clamp(sigma, options.min_saddle_sigma_px,
                         options.max_saddle_sigma_px);
      // Near the image border the window shrinks instead of failing.
      sigma = std::max(options.min_saddle_sigma_px,
                       std::min(sigma, (room + 1.0) / 3.0));
      // On the input grey values: the detector's blur would carry the
      // structures around a corner (PuzzleBoard discs) closer to it.
      const SaddleRefineResult r = RefineBySaddleFit(
          *single, c.xy, sigma, options.saddle_max_iterations,
          options.saddle_convergence_px,
          options.max_shift_fraction * window + std::ldexp(0.5, c.level));
      if (!r.ok) {
        ++s.refine_failed;
        continue;
      }
      corner.xy = r.xy;
      corner.orientation = r.orientation;
    }
    refined.push_back(corner);
    refined_window.push_back(window);
  }

  // Merge duplicates (strongest first), then orientation and order.
  std::vector<int> order(refined.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return refined[a].response > refined[b].response;
  });
  {
    PointGrid kept_grid(std::max(options.merge_distance_px, 1.0) * 4.0,
                        image.cols, image.rows);
    std::vector<Corner> kept_corners;
    for (int index : order) {
      const Corner& c = refined[index];
      bool duplicate = false;
      kept_grid.ForNear(c.xy, options.merge_distance_px, [&](int k) {
        if ((kept_corners[k].xy - c.xy).norm() < options.merge_distance_px) {
          duplicate = true;
        }
      });
      if (duplicate) {
        ++s.merged_duplicates;
        continue;
      }
      kept_grid.Add(c.xy, static_cast<int>(kept_corners.size()));
      Corner out = c;
      if (options.subpixel != SubpixelMethod::kSaddleFit) {
        out.orientation = HessianOrientation(
            blurred[0], c.xy,
            options.orientation_spacing_fraction * refined_window[index]);
      }
      kept_corners.push_back(out);
    }
    corners = std::move(kept_corners);
  }
  // The promise to every caller: finite positions, responses and
  // orientations, whatever the input held.
  corners.erase(std::remove_if(corners.begin(), corners.end(),
                               [](const Corner& c) {
                                 return !c.xy.allFinite() ||
                                        !std::isfinite(c.response) ||
                                        !std::isfinite(c.orientation);
                               }),
                corners.end());
  std::sort(corners.begin(), corners.end(),
            [](const Corner& a, const Corner& b) {
              if (a.xy.y() != b.xy.y()) return a.xy.y() < b.xy.y();
              return a.xy.x() < b.xy.x();
            });
  s.ms_refine = MsSince(t);
  s.corners = static_cast<int>(corners.size());
  s.ok = true;
  s.ms_total = MsSince(t_start);
  return corners;
}

}  // namespace puzzlecal
