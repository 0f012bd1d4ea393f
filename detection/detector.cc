#include "detection/detector.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detection/corner_filters.h"
#include "detection/grey_blur.h"
#include "detection/hessian_response.h"
#include "detection/subpixel.h"
#include "detection/vector_clones.h"

namespace puzzlecal {

namespace {

// The first preprocessing, pyramid, response and suppression field out of
// range, or nullptr.
const char* PyramidResponseError(const DetectorOptions& o) {
  if (!(o.blur_sigma_px >= 0.0 && o.blur_sigma_px <= 20.0)) {
    return "blur_sigma_px must be in [0, 20]";
  }
  if (o.num_levels < 1 || o.num_levels > 6) return "num_levels must be 1..6";
  if (o.first_level < 0 || o.first_level >= o.num_levels) {
    return "first_level must be in [0, num_levels)";
  }
  if (!(o.trace_weight_k >= 0.0 && std::isfinite(o.trace_weight_k))) {
    return "trace_weight_k must be >= 0";
  }
  if (!(o.min_response > 0.0 && std::isfinite(o.min_response))) {
    return "min_response must be > 0";
  }
  if (!(o.noise_response_factor >= 0.0 &&
        std::isfinite(o.noise_response_factor))) {
    return "noise_response_factor must be >= 0";
  }
  if (o.nms_radius_px < 1 || o.nms_radius_px > 50) {
    return "nms_radius_px must be in [1, 50]";
  }
  if (o.nms_radius_coarse_px < 1 || o.nms_radius_coarse_px > 50) {
    return "nms_radius_coarse_px must be in [1, 50]";
  }
  return nullptr;
}

// The first candidate filters field out of range, or nullptr.
const char* FilterError(const DetectorOptions& o) {
  if (!(o.ring_radius_px >= 1.5 && o.ring_radius_px <= 20.0)) {
    return "ring_radius_px must be in [1.5, 20]";
  }
  if (o.ring_samples < 8 || o.ring_samples > 64 || o.ring_samples % 4 != 0) {
    return "ring_samples must be a multiple of 4 in [8, 64]";
  }
  if (!(o.min_ring_contrast >= 0.0)) return "min_ring_contrast must be >= 0";
  if (!(o.max_ring_asymmetry > 0.0)) return "max_ring_asymmetry must be > 0";
  if (!(o.min_contrast_factor_clean >= 1.0)) {
    return "min_contrast_factor_clean must be >= 1";
  }
  if (!(o.max_ring_asymmetry_clean > 0.0)) {
    return "max_ring_asymmetry_clean must be > 0";
  }
  if (!(o.min_ring_second_harmonic_clean >= 0.0 &&
        o.min_ring_second_harmonic_clean <= 1.0)) {
    return "min_ring_second_harmonic_clean must be in [0, 1]";
  }
  if (!(o.min_ring_second_harmonic >= 0.0 &&
        o.min_ring_second_harmonic <= 1.0)) {
    return "min_ring_second_harmonic must be in [0, 1]";
  }
  if (!(o.ring_noise_factor >= 0.0 && std::isfinite(o.ring_noise_factor))) {
    return "ring_noise_factor must be >= 0";
  }
  if (!(o.max_ring_centre_offset > 0.0)) {
    return "max_ring_centre_offset must be > 0";
  }
  return nullptr;
}

// The first sub-pixel refinement and orientation field out of range, or
// nullptr.
const char* RefinementError(const DetectorOptions& o) {
  if (!(o.window_fraction_of_neighbor > 0.0 &&
        o.window_fraction_of_neighbor <= 1.0)) {
    return "window_fraction_of_neighbor must be in (0, 1]";
  }
  if (o.min_window_px < 2 || o.max_window_px > 64 ||
      o.min_window_px > o.max_window_px) {
    return "need 2 <= min_window_px <= max_window_px <= 64";
  }
  if (!(o.saddle_sigma_fraction > 0.0 && o.saddle_sigma_fraction <= 1.0)) {
    return "saddle_sigma_fraction must be in (0, 1]";
  }
  if (!(o.min_saddle_sigma_px >= 0.5 &&
        o.min_saddle_sigma_px <= o.max_saddle_sigma_px &&
        o.max_saddle_sigma_px <= 16.0)) {
    return "need 0.5 <= min_saddle_sigma_px <= max_saddle_sigma_px <= 16";
  }
  if (o.saddle_max_iterations < 1 || o.saddle_max_iterations > 100) {
    return "saddle_max_iterations must be in [1, 100]";
  }
  if (!(o.saddle_convergence_px > 0.0)) {
    return "saddle_convergence_px must be > 0";
  }
  if (o.max_iterations < 1 || o.max_iterations > 100) {
    return "max_iterations must be in [1, 100]";
  }
  if (!(o.convergence_px > 0.0)) return "convergence_px must be > 0";
  if (!(o.max_shift_fraction > 0.0)) return "max_shift_fraction must be > 0";
  if (!(o.merge_distance_px >= 0.0)) return "merge_distance_px must be >= 0";
  if (!(o.orientation_spacing_fraction > 0.0)) {
    return "orientation_spacing_fraction must be > 0";
  }
  return nullptr;
}

}  // namespace

bool DetectorOptions::Check(std::string* why) const {
  for (const char* error : {PyramidResponseError(*this), FilterError(*this),
                            RefinementError(*this)}) {
    if (error != nullptr) {
      if (why != nullptr) *why = error;
      return false;
    }
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
PUZZLECAL_VECTOR_CLONES void DownsampleRows(const cv::Mat& src, int src_first,
                                            int height, int i0, int i1,
                                            std::vector<float>* row,
                                            cv::Mat* dst) {
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
    // Interior outputs (2 j + 1 inside the row) without clamping, so the
    // loop vectorises; the last one or two clamp at the border.
    const int interior_end = std::min(out_width, std::max(1, width / 2));
    for (int j = 1; j < interior_end; ++j) {
      out[j] = 0.25f * (tmp[2 * j - 1] + 2.0f * tmp[2 * j] + tmp[2 * j + 1]);
    }
    for (int j = interior_end; j < out_width; ++j) {
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
// `converted` and `finite` are the buffers of a colour conversion and of
// the cleaned float copy.
bool PrepareInput(const cv::Mat& image, bool normalize_by_max,
                  cv::Mat* converted, cv::Mat* finite, const cv::Mat** single,
                  double* normalizer, std::string* why) {
  if (image.channels() == 1) {
    *single = &image;
  } else if ((image.channels() == 3 || image.channels() == 4) &&
             (image.depth() == CV_8U || image.depth() == CV_16U ||
              image.depth() == CV_32F)) {
    cv::cvtColor(
        image, *converted,
        image.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
    *single = converted;
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
    (*single)->copyTo(*finite);
    for (int y = 0; y < finite->rows; ++y) {
      float* row = finite->ptr<float>(y);
      for (int x = 0; x < finite->cols; ++x) {
        if (!std::isfinite(row[x])) {
          row[x] = 0.0f;
        } else {
          row[x] = std::clamp(row[x], -kMaxFloatPixel, kMaxFloatPixel);
        }
      }
    }
    *single = finite;
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

// Buckets of point indices on a square grid, for radius queries. Each
// cell is a list in the order of Add (flat arrays, kept between uses, so
// a grid of many cells costs no allocation).
class PointGrid {
 public:
  // Empties the grid and sets its cells.
  void Reset(double cell, int width, int height) {
    cell_ = std::max(cell, 1.0);
    cols_ = static_cast<int>(width / cell_) + 1;
    rows_ = static_cast<int>(height / cell_) + 1;
    head_.assign(static_cast<size_t>(cols_) * rows_, -1);
    tail_.assign(head_.size(), -1);
    next_.clear();
    items_.clear();
  }

  void Add(const Eigen::Vector2d& p, int index) {
    const size_t cell = static_cast<size_t>(CellOf(p.y(), rows_)) * cols_ +
                        CellOf(p.x(), cols_);
    const int slot = static_cast<int>(items_.size());
    items_.push_back(index);
    next_.push_back(-1);
    if (tail_[cell] < 0) {
      head_[cell] = slot;
    } else {
      next_[tail_[cell]] = slot;
    }
    tail_[cell] = slot;
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
        for (int slot = head_[static_cast<size_t>(cy) * cols_ + cx]; slot >= 0;
             slot = next_[slot]) {
          f(items_[slot]);
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
  double cell_ = 1.0;
  int cols_ = 1;
  int rows_ = 1;
  std::vector<int> head_;   // per cell: its first slot, -1 when empty
  std::vector<int> tail_;   // per cell: its last slot, -1 when empty
  std::vector<int> next_;   // per slot: the next slot of its cell, or -1
  std::vector<int> items_;  // per slot: the point index
};

// A level-0 peak above the absolute threshold, kept until the
// noise-adaptive threshold (known only after the whole level) decides.
struct Level0Peak {
  float value;    // the response (product form)
  bool masked;    // passed the corner mask
  int candidate;  // index into the candidates, -1 when filtered out
};

}  // namespace

// Buffers of one detection, kept between the images of a CornerDetector
// (same-size images then cause no allocation and no page faults).
struct CornerDetector::Buffers {
  explicit Buffers(int ring_samples) : ring(ring_samples) {}

  RingSampler ring;              // circle offsets of the ring test
  cv::Mat single;                // one-channel input (colour converted)
  cv::Mat finite;                // float input with non-finite pixels zeroed
  std::vector<cv::Mat> blurred;  // per level, CV_32FC1, grey in [0, 1]
  cv::Mat band;                  // blurred rows of a band of level 0
  std::vector<float> response_rows;  // ring of response rows
  std::vector<float> row;            // one row of the downsampling
  std::vector<float> blur_row;       // one row of the 8-bit blur
  std::vector<float> scratch;        // response and noise samples
  std::vector<ResponsePeak> peaks;   // of one band or one level
  GradientRefineScratch gradient;    // gradient-orthogonality patches
  PointGrid grid;                    // of one merging or refinement step
};

namespace {

constexpr int kMinSide = 8;      // smaller images (and levels) have no corners
constexpr int kBandRows = 64;    // level-0 rows streamed at a time
constexpr int kMedianStep = 12;  // sampling of the noise-adaptive threshold

// One detection in one image: the stages in order (input checks,
// preprocessing, per level response + suppression + filters, merging the
// levels, sub-pixel refinement, duplicate removal, final order), sharing
// the options, the buffers, the summary and what earlier stages found.
class DetectionPass {
 public:
  DetectionPass(const DetectorOptions& options,
                CornerDetector::Buffers* buffers, DetectorSummary* summary)
      : options_(options), b_(*buffers), s_(*summary) {}

  std::vector<Corner> Run(const cv::Mat& image);

 private:
  bool AcceptInput(const cv::Mat& image);
  bool Preprocess(const cv::Mat& image);
  int CountLevels() const;
  void MakeBlurKernels();
  void BuildCoarseLevels();
  void BlurRows(int a, int b, cv::Mat* out) const;
  void BlurRowsInto(int a, int first, int last, cv::Mat* out) const;

  void DetectLevel0Streamed();
  void DetectBand(int y0, int y1, int halo, int reach,
                  std::vector<Level0Peak>* kept);
  void ApplyLevel0Threshold(const std::vector<Level0Peak>& kept);
  void DetectLevel(int level);
  bool FilterPeak(const cv::Mat& level_image, int y_offset,
                  const ResponsePeak& peak, int level, bool* masked);
  bool PassesRingTest(const RingMeasure& ring) const;
  Candidate MakeCandidate(const ResponsePeak& peak, int y_offset,
                          int level) const;

  std::vector<Candidate> MergeLevels() const;
  std::vector<Corner> Refine(const std::vector<Candidate>& merged,
                             std::vector<int>* windows);
  bool RefineOne(const Candidate& c, double nearest, Corner* corner,
                 int* window) const;
  std::vector<Corner> DropDuplicates(const std::vector<Corner>& refined,
                                     const std::vector<int>& windows);

  const DetectorOptions& options_;
  CornerDetector::Buffers& b_;
  DetectorSummary& s_;
  int width_ = 0;
  int height_ = 0;
  const cv::Mat* single_ = nullptr;  // one-channel, finite input
  cv::Mat kernel_;                   // Gaussian blur (empty: no blur)
  cv::Mat kernel_scaled_;            // the same divided by the normalizer
  int levels_ = 1;                   // pyramid levels that exist
  // Level 0 is streamed in bands of rows (blur, response, suppression,
  // filters and the next level's rows while the band is in cache) unless a
  // later step needs the whole blurred image (gradient orthogonality and
  // the circle orientation of the other refinements).
  bool stream_level0_ = false;
  double min_contrast_ = 0.0;          // of the ring test, from the pixel noise
  std::vector<Candidate> candidates_;  // verified, ordered by level
};

std::vector<Corner> DetectionPass::Run(const cv::Mat& image) {
  const Clock::time_point t_start = Clock::now();
  if (!AcceptInput(image) || !Preprocess(image)) return {};
  if (stream_level0_) {
    DetectLevel0Streamed();  // also writes level 1
    BuildCoarseLevels();
  }
  for (int l = stream_level0_ ? 1 : options_.first_level; l < levels_; ++l) {
    DetectLevel(l);
  }
  const Clock::time_point t = Clock::now();
  const std::vector<Candidate> merged = MergeLevels();
  std::vector<int> windows;
  const std::vector<Corner> refined = Refine(merged, &windows);
  std::vector<Corner> corners = DropDuplicates(refined, windows);
  // The promise to every caller: finite positions, responses and
  // orientations, whatever the input held; sorted by y, then x.
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
  s_.ms_refine = MsSince(t);
  s_.corners = static_cast<int>(corners.size());
  s_.ok = true;
  s_.ms_total = MsSince(t_start);
  return corners;
}

// False (with the reason in the summary) when there is nothing to detect.
bool DetectionPass::AcceptInput(const cv::Mat& image) {
  std::string why;
  if (!options_.Check(&why)) {
    s_.message = "invalid detector options: " + why;
    return false;
  }
  if (image.empty()) {
    s_.message = "empty image";
    return false;
  }
  if (image.dims != 2) {
    s_.message = "image is not two-dimensional";
    return false;
  }
  s_.width = width_ = image.cols;
  s_.height = height_ = image.rows;
  if (image.cols < kMinSide || image.rows < kMinSide) {
    s_.ok = true;
    s_.message = "image smaller than 8x8 pixels: no corners";
    return false;
  }
  return true;
}

// Grey conversion, normalisation, blur and pyramid (level 0 and the first
// coarse level only when not streamed), pixel noise.
bool DetectionPass::Preprocess(const cv::Mat& image) {
  const Clock::time_point t = Clock::now();
  std::string why;
  if (!PrepareInput(image, options_.normalize_by_max, &b_.single, &b_.finite,
                    &single_, &s_.normalizer, &why)) {
    s_.message = why;
    return false;
  }
  MakeBlurKernels();
  stream_level0_ = options_.first_level == 0 &&
                   options_.subpixel == SubpixelMethod::kSaddleFit;
  levels_ = CountLevels();
  std::vector<cv::Mat>& blurred = b_.blurred;
  blurred.resize(options_.num_levels);
  if (!stream_level0_) {
    BlurRows(0, height_, &blurred[0]);
    for (int l = 1; l < levels_; ++l) {
      Downsample(blurred[l - 1], &b_.row, &blurred[l]);
    }
  } else if (levels_ > 1) {
    blurred[1].create((height_ + 1) / 2, (width_ + 1) / 2, CV_32FC1);
  }
  s_.levels_used = std::max(0, levels_ - options_.first_level);
  // Pixel noise of the input, grey normalised to [0, 1].
  const double noise =
      options_.ring_noise_factor > 0.0
          ? NoiseSigma(*single_, 11, &b_.scratch) / s_.normalizer
          : 0.0;
  s_.noise_sigma = noise;
  min_contrast_ =
      std::max(options_.min_ring_contrast, options_.ring_noise_factor * noise);
  s_.ms_preprocess = MsSince(t);
  return true;
}

// Levels up to options.num_levels while the level above is at least twice
// the minimum side (level sizes as cv::pyrDown's).
int DetectionPass::CountLevels() const {
  int levels = 1;
  int rows = height_, cols = width_;
  for (int l = 1; l < options_.num_levels; ++l) {
    if (cols < 2 * kMinSide || rows < 2 * kMinSide) break;
    levels = l + 1;
    rows = (rows + 1) / 2;
    cols = (cols + 1) / 2;
  }
  return levels;
}

// Levels 2 and coarser from level 1 (after level 0 was streamed).
void DetectionPass::BuildCoarseLevels() {
  const Clock::time_point t = Clock::now();
  for (int l = 2; l < levels_; ++l) {
    Downsample(b_.blurred[l - 1], &b_.row, &b_.blurred[l]);
  }
  s_.ms_preprocess += MsSince(t);
}

void DetectionPass::MakeBlurKernels() {
  if (!(options_.blur_sigma_px > 0.0)) return;
  const int ksize =
      2 * static_cast<int>(std::ceil(2.0 * options_.blur_sigma_px)) + 1;
  kernel_ = cv::getGaussianKernel(ksize, options_.blur_sigma_px, CV_32F);
  kernel_scaled_ = kernel_ * (1.0 / s_.normalizer);
}

// Grey rows [a, b) of the input, normalised and blurred, into `out`: one
// separable pass from the input type straight to float, with the
// normalisation folded into the kernel (grey_blur.h for 8-bit input and
// the default 5-tap kernel, cv::sepFilter2D otherwise). On a band the
// filter reads the input rows around it, so a band equals those rows of
// the whole image.
void DetectionPass::BlurRows(int a, int b, cv::Mat* out) const {
  if (!(options_.blur_sigma_px > 0.0)) {
    single_->rowRange(a, b).convertTo(*out, CV_32F, 1.0 / s_.normalizer);
  } else if (single_->type() == CV_8UC1 && IsSymmetricKernel5(kernel_scaled_) &&
             IsSymmetricKernel5(kernel_)) {
    out->create(b - a, width_, CV_32FC1);
    BlurGreyRows5(*single_, a, b, kernel_scaled_, kernel_, &b_.blur_row, out);
  } else {
    cv::sepFilter2D(single_->rowRange(a, b), *out, CV_32F, kernel_scaled_,
                    kernel_, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  }
}

// The same for rows [first, last) only, into the rows of `out` (already
// holding the band's rows from `a` on) that they occupy there.
void DetectionPass::BlurRowsInto(int a, int first, int last,
                                 cv::Mat* out) const {
  cv::Mat rows = out->rowRange(first - a, last - a);
  const uchar* const data = rows.data;
  BlurRows(first, last, &rows);
  CV_Assert(rows.data == data);  // written in place, not reallocated
}

// Level 0: peaks above the absolute threshold per band, filtered while the
// band is in cache; the noise-adaptive threshold (from the response sampled
// on the way) then only drops weak peaks: a peak of the whole image is a
// peak above the lower threshold that exceeds the higher one.
void DetectionPass::DetectLevel0Streamed() {
  // Rows around a band: response (2) + suppression radius + ring test.
  // They fix the band's first row, the origin of the peaks' float
  // centroids (and so their rounding).
  const int halo =
      2 + std::max(options_.nms_radius_px,
                   static_cast<int>(std::ceil(options_.ring_radius_px)) + 2);
  // Of those, the rows that the band's peaks reach, the only ones blurred:
  // the response's second differences (2) beyond the suppression window,
  // and the ring test (its centre, the centroid, is within 1 px of the
  // peak; its bilinear samples reach one more row), which also needs its
  // circle inside the band for its inside check to agree with the whole
  // image's; the corner mask (2) and the next level's rows (1) reach less.
  const int reach = std::min(
      halo, std::max(options_.nms_radius_px + 2,
                     static_cast<int>(std::ceil(options_.ring_radius_px)) + 2));
  std::vector<Level0Peak> kept;
  b_.scratch.clear();
  for (int y0 = 0; y0 < height_; y0 += kBandRows) {
    DetectBand(y0, std::min(y0 + kBandRows, height_), halo, reach, &kept);
  }
  ApplyLevel0Threshold(kept);
}

// Level-0 rows [y0, y1): blur (of the `reach` rows around, in a band with
// `halo` rows around), the next level's rows, response + suppression,
// filters.
void DetectionPass::DetectBand(int y0, int y1, int halo, int reach,
                               std::vector<Level0Peak>* kept) {
  // Each stage's end is the next one's start (one clock reading each: the
  // thread's CPU clock is a system call).
  const Clock::time_point t_blur = Clock::now();
  const int a = std::max(0, y0 - halo);
  const int b = std::min(height_, y1 + halo);
  b_.band.create(b - a, width_, CV_32FC1);
  BlurRowsInto(a, std::max(0, y0 - reach), std::min(height_, y1 + reach),
               &b_.band);
  if (levels_ > 1) {
    DownsampleRows(b_.band, a, height_, (y0 + 1) / 2, (y1 + 1) / 2, &b_.row,
                   &b_.blurred[1]);
  }
  const Clock::time_point t_response = Clock::now();
  s_.ms_preprocess += t_response - t_blur;

  PeakRows part;
  part.begin = y0 - a;
  part.end = y1 - a;
  part.y_offset = a;
  part.sample_step = kMedianStep;
  part.samples = options_.noise_response_factor > 0.0 ? &b_.scratch : nullptr;
  b_.peaks.clear();
  const float absolute =
      static_cast<float>(options_.min_response * options_.min_response);
  s_.candidates += FindSaddlePeaksInRows(
      b_.band, static_cast<float>(options_.trace_weight_k), absolute,
      options_.nms_radius_px, part, &b_.response_rows, &b_.peaks);
  const Clock::time_point t_filter = Clock::now();
  s_.ms_response += t_filter - t_response;

  for (const ResponsePeak& peak : b_.peaks) {
    const size_t before = candidates_.size();
    bool masked = false;
    const bool passed = FilterPeak(b_.band, a, peak, 0, &masked);
    kept->push_back(
        {peak.value, masked, passed ? static_cast<int>(before) : -1});
  }
  s_.ms_filter += MsSince(t_filter);
}

// The noise-adaptive threshold of level 0 from the sampled response; drops
// the weaker peaks and their candidates.
void DetectionPass::ApplyLevel0Threshold(const std::vector<Level0Peak>& kept) {
  const Clock::time_point t = Clock::now();
  std::vector<float>& samples = b_.scratch;
  double threshold = options_.min_response;
  if (options_.noise_response_factor > 0.0 && !samples.empty()) {
    auto middle = samples.begin() + samples.size() / 2;
    std::nth_element(samples.begin(), middle, samples.end());
    threshold = std::max(threshold,
                         options_.noise_response_factor * std::sqrt(*middle));
  }
  s_.threshold = threshold;
  const float squared = static_cast<float>(threshold * threshold);
  std::vector<Candidate> strong;
  for (const Level0Peak& p : kept) {
    if (!(p.value > squared)) continue;
    ++s_.after_nms;
    s_.after_mask += p.masked ? 1 : 0;
    if (p.candidate >= 0) {
      ++s_.after_ring;
      strong.push_back(candidates_[p.candidate]);
    }
  }
  candidates_ = std::move(strong);
  s_.ms_nms += MsSince(t);
}

// One whole level: noise-adaptive threshold, response + suppression,
// filters.
void DetectionPass::DetectLevel(int level) {
  const cv::Mat& blurred = b_.blurred[level];
  const float k = static_cast<float>(options_.trace_weight_k);
  Clock::time_point t = Clock::now();
  double threshold = options_.min_response;
  if (options_.noise_response_factor > 0.0) {
    const double median =
        SampledResponseMedian(blurred, k, kMedianStep, &b_.scratch);
    threshold =
        std::max(threshold, options_.noise_response_factor * std::sqrt(median));
  }
  if (level == options_.first_level) s_.threshold = threshold;
  s_.ms_nms += MsSince(t);

  t = Clock::now();
  b_.peaks.clear();
  s_.candidates +=
      FindSaddlePeaks(blurred, k, static_cast<float>(threshold * threshold),
                      NmsRadius(options_, level), &b_.response_rows, &b_.peaks);
  s_.after_nms += static_cast<int>(b_.peaks.size());
  s_.ms_response += MsSince(t);

  t = Clock::now();
  for (const ResponsePeak& peak : b_.peaks) {
    bool masked = false;
    const bool passed = FilterPeak(blurred, 0, peak, level, &masked);
    s_.after_mask += masked ? 1 : 0;
    s_.after_ring += passed ? 1 : 0;
  }
  s_.ms_filter += MsSince(t);
}

// The corner mask and the ring test on `level_image` (rows offset by
// `y_offset` from the level's first row); appends a candidate when the peak
// passes. `masked`: it passed the corner mask.
bool DetectionPass::FilterPeak(const cv::Mat& level_image, int y_offset,
                               const ResponsePeak& peak, int level,
                               bool* masked) {
  *masked = false;
  if (options_.use_corner_mask &&
      !PassesCornerMask(level_image, peak.x, peak.y)) {
    return false;
  }
  *masked = true;
  if (options_.use_ring_test &&
      !PassesRingTest(b_.ring.Measure(level_image, peak.centroid_x,
                                      peak.centroid_y,
                                      options_.ring_radius_px))) {
    return false;
  }
  candidates_.push_back(MakeCandidate(peak, y_offset, level));
  return true;
}

bool DetectionPass::PassesRingTest(const RingMeasure& ring) const {
  const DetectorOptions& o = options_;
  const bool clean_second_harmonic =
      ring.asymmetry <= o.max_ring_asymmetry_clean &&
      ring.second_harmonic_share >= o.min_ring_second_harmonic_clean &&
      ring.contrast >= o.min_contrast_factor_clean * min_contrast_;
  return ring.inside && ring.contrast >= min_contrast_ &&
         (ring.asymmetry <= o.max_ring_asymmetry || clean_second_harmonic) &&
         ring.second_harmonic_share >= o.min_ring_second_harmonic &&
         ring.centre_offset <= o.max_ring_centre_offset;
}

// A peak of `level` as a candidate in full-resolution pixels.
Candidate DetectionPass::MakeCandidate(const ResponsePeak& peak, int y_offset,
                                       int level) const {
  const double scale = std::ldexp(1.0, level);
  Candidate c;
  c.level = level;
  c.peak_x = peak.x;
  c.peak_y = peak.y + y_offset;
  c.response = std::sqrt(peak.value);
  c.xy = Eigen::Vector2d(peak.x * scale, c.peak_y * scale);
  // The centroid is also the start of the iterative refinements (closer
  // than the integer peak: fewer iterations).
  if (options_.subpixel != SubpixelMethod::kNone) {
    c.xy = Eigen::Vector2d(peak.centroid_x, peak.centroid_y + y_offset) * scale;
  }
  return c;
}

// The candidates of all levels, finer levels first: a candidate within the
// suppression radius (at its level) of one already taken is dropped.
std::vector<Candidate> DetectionPass::MergeLevels() const {
  std::vector<Candidate> merged;
  PointGrid& grid = b_.grid;
  grid.Reset(8.0 * NmsRadius(options_, 1), width_, height_);
  for (const Candidate& c : candidates_) {  // already ordered by level
    const double radius =
        std::ldexp(1.0, c.level) * NmsRadius(options_, c.level);
    bool taken = false;
    grid.ForNear(c.xy, radius, [&](int index) {
      if ((merged[index].xy - c.xy).norm() <= radius) taken = true;
    });
    if (taken) continue;
    grid.Add(c.xy, static_cast<int>(merged.size()));
    merged.push_back(c);
  }
  s_.after_merge_levels = static_cast<int>(merged.size());
  return merged;
}

// Sub-pixel refinement of every merged candidate at full resolution, with
// the window sized from the distance to its nearest neighbour; `windows`
// gets the window half-size of each refined corner.
std::vector<Corner> DetectionPass::Refine(const std::vector<Candidate>& merged,
                                          std::vector<int>* windows) {
  const double reach =
      options_.max_window_px / options_.window_fraction_of_neighbor;
  PointGrid& neighbours = b_.grid;
  neighbours.Reset(reach, width_, height_);
  for (size_t i = 0; i < merged.size(); ++i) {
    neighbours.Add(merged[i].xy, static_cast<int>(i));
  }
  std::vector<Corner> refined;
  refined.reserve(merged.size());
  for (size_t i = 0; i < merged.size(); ++i) {
    const Candidate& c = merged[i];
    double nearest = std::numeric_limits<double>::infinity();
    neighbours.ForNear(c.xy, reach, [&](int index) {
      if (index == static_cast<int>(i)) return;
      nearest = std::min(nearest, (merged[index].xy - c.xy).norm());
    });
    Corner corner;
    int window = 0;
    if (!RefineOne(c, nearest, &corner, &window)) {
      ++s_.refine_failed;
      continue;
    }
    refined.push_back(corner);
    windows->push_back(window);
  }
  return refined;
}

// One candidate, `nearest` pixels from its nearest neighbour (infinite when
// alone). False when the refinement failed.
bool DetectionPass::RefineOne(const Candidate& c, double nearest,
                              Corner* corner, int* window_out) const {
  int window = options_.max_window_px;
  if (std::isfinite(nearest)) {
    window = static_cast<int>(
        std::floor(options_.window_fraction_of_neighbor * nearest));
  }
  window = std::clamp(window, options_.min_window_px, options_.max_window_px);
  // Near the image border the window shrinks instead of failing.
  const int room = static_cast<int>(std::floor(
                       std::min({c.xy.x(), c.xy.y(), width_ - 1.0 - c.xy.x(),
                                 height_ - 1.0 - c.xy.y()}))) -
                   2;
  window = std::max(options_.min_window_px, std::min(window, room));
  *window_out = window;
  corner->xy = c.xy;
  corner->response = c.response;
  const double max_shift =
      options_.max_shift_fraction * window + std::ldexp(0.5, c.level);
  if (options_.subpixel == SubpixelMethod::kGradientOrthogonality) {
    const GradientRefineResult r = RefineByGradientOrthogonality(
        b_.blurred[0], c.xy, window, options_.max_iterations,
        options_.convergence_px, &b_.gradient);
    if (!r.ok || (r.xy - c.xy).norm() > max_shift) return false;
    corner->xy = r.xy;
  } else if (options_.subpixel == SubpixelMethod::kSaddleFit) {
    double sigma = options_.max_saddle_sigma_px;
    if (std::isfinite(nearest))
      sigma = options_.saddle_sigma_fraction * nearest;
    sigma = std::clamp(sigma, options_.min_saddle_sigma_px,
                       options_.max_saddle_sigma_px);
    // Near the image border the window shrinks instead of failing.
    sigma = std::max(options_.min_saddle_sigma_px,
                     std::min(sigma, (room + 1.0) / 3.0));
    // On the input grey values: the detector's blur would carry the
    // structures around a corner (PuzzleBoard discs) closer to it.
    const SaddleRefineResult r =
        RefineBySaddleFit(*single_, c.xy, sigma, options_.saddle_max_iterations,
                          options_.saddle_convergence_px, max_shift);
    if (!r.ok) return false;
    corner->xy = r.xy;
    corner->orientation = r.orientation;
  }
  return true;
}

// Corners closer than merge_distance_px: the stronger stays. Orientation
// from the circle of the blurred image for the refinements other than the
// saddle fit (which measured its own).
std::vector<Corner> DetectionPass::DropDuplicates(
    const std::vector<Corner>& refined, const std::vector<int>& windows) {
  std::vector<int> order(refined.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return refined[a].response > refined[b].response;
  });
  const double merge = options_.merge_distance_px;
  PointGrid& kept_grid = b_.grid;
  kept_grid.Reset(std::max(merge, 1.0) * 4.0, width_, height_);
  std::vector<Corner> kept;
  for (int index : order) {
    const Corner& c = refined[index];
    bool duplicate = false;
    kept_grid.ForNear(c.xy, merge, [&](int k) {
      if ((kept[k].xy - c.xy).norm() < merge) duplicate = true;
    });
    if (duplicate) {
      ++s_.merged_duplicates;
      continue;
    }
    kept_grid.Add(c.xy, static_cast<int>(kept.size()));
    Corner out = c;
    if (options_.subpixel != SubpixelMethod::kSaddleFit) {
      out.orientation = HessianOrientation(
          b_.blurred[0], c.xy,
          options_.orientation_spacing_fraction * windows[index]);
    }
    kept.push_back(out);
  }
  return kept;
}

}  // namespace

CornerDetector::CornerDetector(const DetectorOptions& options)
    : options_(options),
      buffers_(std::make_unique<Buffers>(options.ring_samples)) {}

CornerDetector::~CornerDetector() = default;
CornerDetector::CornerDetector(CornerDetector&&) noexcept = default;
CornerDetector& CornerDetector::operator=(CornerDetector&&) noexcept = default;

std::vector<Corner> CornerDetector::Detect(const cv::Mat& image,
                                           DetectorSummary* summary) {
  DetectorSummary local_summary;
  DetectorSummary& s = summary != nullptr ? *summary : local_summary;
  s = DetectorSummary();
  if (buffers_ == nullptr) {  // moved from
    buffers_ = std::make_unique<Buffers>(options_.ring_samples);
  }
  DetectionPass pass(options_, buffers_.get(), &s);
  return pass.Run(image);
}

std::vector<Corner> DetectCorners(const cv::Mat& image,
                                  const DetectorOptions& options,
                                  DetectorSummary* summary) {
  CornerDetector detector(options);
  return detector.Detect(image, summary);
}

}  // namespace puzzlecal
