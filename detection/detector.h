#ifndef PUZZLECAL_DETECTION_DETECTOR_H_
#define PUZZLECAL_DETECTION_DETECTOR_H_

// Checkerboard saddle-point detector.
//
// Pipeline (the thesis's Hessian detector, extended):
//  1. grey normalisation (divide by the image maximum) and Gaussian blur;
//  2. per pyramid level, the response S = det(H) + k trace(H)^2 on the
//     axis-aligned and on the diagonal second derivatives (k = 0.5); the
//     corner response is the product of -S and -S_d where both are positive;
//  3. non-maximum suppression with a radius in level pixels (so it scales with
//     the level), above an absolute and a noise-adaptive threshold; the
//     response is streamed row by row into the suppression, never stored;
//  4. the thesis's corner mask (junction kernels beat edge kernels) and a
//     ring test around the response centroid (the grey values on a circle
//     must be centrally symmetric, dominated by the second angular harmonic,
//     above the noise, with the centre half-way between dark and bright);
//  5. sub-pixel refinement at full resolution: by default a saddle-point fit
//     (quadratic in a Gaussian window sized from the distance to the nearest
//     neighbour corner, on the input grey values, re-centred on its own
//     solution); gradient orthogonality and the thesis's squared-response
//     centroid are the alternatives;
//  6. orientation = angle of the first Hessian eigenvector (the one of the
//     positive eigenvalue: along the diagonal through the bright tiles), in
//     (-pi/2, pi/2] since an eigenvector has no sign; taken from the saddle
//     fit's Hessian, or from the second angular harmonic of a circle for the
//     other refinements.

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detection/corner.h"

namespace puzzlecal {

enum class SubpixelMethod {
  kNone,      // integer peak positions (at the detection level, scaled)
  kCentroid,  // the thesis: squared-response centroid over the 3x3 peak
  kGradientOrthogonality,  // edge-gradient least squares, iterated
  kSaddleFit,  // quadratic fit of the grey values, Gaussian window (default)
};

struct DetectorOptions {
  // --- preprocessing ---
  // Divide the grey image by its maximum (the thesis). When false, 8-bit and
  // 16-bit images are divided by 255 / 65535 and float images are used as-is
  // (non-finite pixels read as 0, magnitudes capped at 1e6).
  bool normalize_by_max = true;
  // Standard deviation (pixels) of the Gaussian blur applied before the
  // derivatives; the thesis uses 1 with a 5x5 kernel. >= 0.
  double blur_sigma_px = 1.0;
  // Number of pyramid levels searched (level l has 2^-l of the resolution,
  // made by cv::pyrDown); coarser levels catch large, blurry corners. 1..6.
  int num_levels = 2;
  // Levels finer than this are skipped for detection (but sub-pixel
  // refinement still runs at full resolution); 0 = detect from full
  // resolution. Raising it trades small-tile recall for speed.
  int first_level = 0;

  // --- Hessian response ---
  // Weight of the trace term in S = det(H) + k trace(H)^2 (thesis: 0.5).
  // Edges (one non-zero eigenvalue) get a negative -S with k > 0. >= 0.
  double trace_weight_k = 0.5;
  // Absolute threshold on the corner response sqrt(max(-S,0) max(-S_d,0))
  // (grey normalised to [0,1]; a sharp corner of contrast c blurred with
  // sigma s gives about 32 (c / (pi s^2))^2). > 0.
  double min_response = 5e-4;
  // Noise-adaptive threshold: the response must also exceed this multiple of
  // the median response of the level (sampled on a sparse grid). >= 0; 0 off.
  double noise_response_factor = 8.0;

  // --- non-maximum suppression ---
  // Radius (level pixels) of the square window in which a candidate must be
  // the maximum, at full resolution and at the coarser levels. The thesis
  // uses 10 px at one scale; 2 keeps neighbour corners of 4-5 px tiles
  // apart (3 lost a third of them at 5 px); the coarser levels see only
  // larger tiles, where 3 gives fewer duplicate peaks. 1..50.
  int nms_radius_px = 2;
  int nms_radius_coarse_px = 3;

  // --- candidate filters ---
  // The thesis's corner mask: at a candidate, the strongest junction kernel
  // (5x5 ring of radius 2) must beat the strongest edge kernel.
  bool use_corner_mask = true;
  // Ring test: grey values are sampled on a circle around the candidate; a
  // checkerboard corner gives a centrally symmetric ring signal whose energy
  // is mostly in the second angular harmonic.
  bool use_ring_test = true;
  // Ring radius in level pixels. >= 1.5.
  double ring_radius_px = 2.5;
  // Samples on the ring (multiple of 4, 8..64).
  int ring_samples = 16;
  // Minimum grey contrast of the ring (peak-to-peak amplitude of its second
  // harmonic, grey normalised to [0,1]). >= 0.
  double min_ring_contrast = 0.02;
  // Maximum ratio rms(antisymmetric part) / rms(symmetric part) of the ring
  // signal (0 for an ideal corner, about 1 and more for an edge or a
  // T-junction). > 0.
  double max_ring_asymmetry = 0.5;
  // A larger asymmetry, up to this bound, passes when the symmetric part is
  // a clean second harmonic (share >= the second bound) and the contrast is
  // at least the third bound times the contrast threshold: PuzzleBoard
  // corners of 6-10 px tiles reach 0.5-0.9 as the ring meets the discs, and
  // strongly curved fisheye corners about 0.6, with shares of 0.97 and more
  // and full contrast; clutter in that band (wall texture, spots between
  // discs) has lower shares or faint contrast. > 0; [0, 1]; >= 1.
  double max_ring_asymmetry_clean = 0.8;
  double min_ring_second_harmonic_clean = 0.95;
  double min_contrast_factor_clean = 3.0;
  // Minimum share of the symmetric ring energy in the second harmonic (0.81
  // for an ideal square-wave corner, lower for blobs and lines). In [0, 1].
  double min_ring_second_harmonic = 0.5;
  // Maximum |centre grey - ring mean| / ring contrast (0 at a corner). Drops
  // saddle-like spots inside a tile between two PuzzleBoard discs. > 0.
  double max_ring_centre_offset = 0.35;
  // The ring contrast must also exceed this multiple of the pixel noise of
  // the input (robust estimate from differences to the 4-neighbour mean,
  // grey normalised like the image): faint saddle-shaped noise inside
  // bright tiles stays out. >= 0; 0 off.
  double ring_noise_factor = 3.0;

  // --- sub-pixel refinement (always at full resolution) ---
  SubpixelMethod subpixel = SubpixelMethod::kSaddleFit;
  // Gradient orthogonality: half-size of its window as a fraction of the
  // distance to the nearest other corner (a tile edge); clamped to the two
  // bounds below. This window also bounds how far any refinement may move a
  // corner (max_shift_fraction). > 0.
  double window_fraction_of_neighbor = 0.3;
  // Bounds of the window half-size in full-resolution pixels; the upper one is
  // also used for a corner without neighbours. 2 <= min <= max <= 64.
  int min_window_px = 4;
  int max_window_px = 12;
  // Saddle fit (on the input grey values, not the blurred ones): standard
  // deviation of its Gaussian window as a fraction of the distance to the
  // nearest other corner, in (0, 1], clamped to the two bounds below
  // (full-resolution pixels, 0.5 <= min <= max <= 16). PuzzleBoard discs
  // start a third of a tile from the corner: above about 0.14 their
  // Gaussian tail pulls the fit by tenths of a pixel; on strongly curved
  // fisheye corners larger windows also lose the point symmetry the fit
  // relies on (deltille photos: calibration RMS 0.41 px at 0.1, 0.45 at 0.3).
  // The lower bound holds where the fraction would give a window of a few
  // pixels (a clutter corner beside a board corner, the image border): there
  // six quadratic coefficients fit little more than noise. At 1.0 instead of
  // 0.7 the deltille halves agree to 0.091 px instead of 0.110 px at
  // 90-100 degrees (RMS 0.153 px either way) and the demo PuzzleBoard's
  // 8-12 px tiles gain accuracy (p99 0.135 -> 0.128 px).
  double saddle_sigma_fraction = 0.1;
  double min_saddle_sigma_px = 1.0;
  double max_saddle_sigma_px = 6.0;
  // Re-centrings of the saddle fit (each moves the window to the last
  // solution; from the response centroid one or two suffice) and the step
  // length (pixels) below which it stops: each re-centring shrinks the
  // remaining offset about tenfold, so 0.05 leaves well under 0.01 px.
  // 1..100; > 0.
  int saddle_max_iterations = 4;
  double saddle_convergence_px = 0.05;
  // Newton iterations of the gradient-orthogonality fixed point. >= 1.
  int max_iterations = 6;
  // Gradient orthogonality stops when the update is shorter than this
  // (pixels). > 0.
  double convergence_px = 0.005;
  // Drop a corner whose refined position moved more than this fraction of the
  // window half-size from its start (a failed refinement). > 0.
  double max_shift_fraction = 0.75;
  // Corners closer than this (pixels) after refinement are merged (the
  // stronger one stays). >= 0.
  double merge_distance_px = 1.5;

  // --- orientation (refinements other than the saddle fit) ---
  // Radius (full-resolution pixels) of the circle on which the orientation
  // is measured (second angular harmonic = Hessian eigenvector at that
  // scale), as a fraction of the refinement window half-size; at least 1 px.
  // > 0.
  double orientation_spacing_fraction = 0.5;

  // False with a reason when a field is out of range.
  bool Check(std::string* why = nullptr) const;
};

// What happened inside one DetectCorners call.
struct DetectorSummary {
  bool ok = false;      // the image could be processed
  std::string message;  // why not, when !ok
  int width = 0;
  int height = 0;
  int levels_used = 0;       // pyramid levels searched
  double normalizer = 0.0;   // grey value mapped to 1.0
  double threshold = 0.0;    // response threshold of level `first_level`
  double noise_sigma = 0.0;  // estimated pixel noise (grey in [0, 1])
  // Pixels above the response threshold, all levels (level 0, streamed in
  // bands, counts those above min_response: the noise-adaptive threshold is
  // applied to its peaks after the pass).
  int candidates = 0;
  int after_nms = 0;           // local maxima
  int after_mask = 0;          // passed the thesis corner mask
  int after_ring = 0;          // passed the ring test
  int after_merge_levels = 0;  // after merging detections of several levels
  int refine_failed = 0;       // dropped because refinement diverged
  int merged_duplicates = 0;   // dropped as duplicates after refinement
  int corners = 0;             // returned
  // CPU time of the calling thread per stage, milliseconds (work done inside
  // OpenCV's own worker threads, if enabled, is not counted).
  double ms_preprocess = 0.0;  // conversion, normalisation, blur, pyramid
  double ms_response = 0.0;    // Hessian responses and non-maximum
                               // suppression (one pass, rows streamed)
  double ms_nms = 0.0;         // noise-adaptive thresholds (sampled)
  double ms_filter = 0.0;      // corner mask and ring test
  double ms_refine = 0.0;      // sub-pixel, orientation, merging, sorting
  double ms_total = 0.0;
};

// Detects checkerboard corners in grey images (CV_8UC1, CV_16UC1 or
// CV_32FC1; a 3- or 4-channel 8-bit image is converted to grey). Holds the
// buffers of a detection (blurred levels, response rows, scratch), so a
// caller that detects in many images of one size keeps one detector and
// pays no allocation after the first image. The corners do not depend on
// what was detected before. One detector serves one thread at a time;
// detectors on different threads share nothing.
class CornerDetector {
 public:
  explicit CornerDetector(const DetectorOptions& options = {});
  ~CornerDetector();
  CornerDetector(CornerDetector&&) noexcept;
  CornerDetector& operator=(CornerDetector&&) noexcept;
  CornerDetector(const CornerDetector&) = delete;
  CornerDetector& operator=(const CornerDetector&) = delete;

  const DetectorOptions& options() const { return options_; }

  // The corners of `image`, sorted by y, then x. Empty, tiny, constant or
  // unsupported images give no corners and a reason in `summary`;
  // non-finite float pixels are treated as 0. Invalid options give no
  // corners (summary->message says why).
  std::vector<Corner> Detect(const cv::Mat& image,
                             DetectorSummary* summary = nullptr);

  struct Buffers;  // defined in detector.cc

 private:
  DetectorOptions options_;
  std::unique_ptr<Buffers> buffers_;
};

// A detection with a detector made for this one call (see CornerDetector).
std::vector<Corner> DetectCorners(const cv::Mat& image,
                                  const DetectorOptions& options = {},
                                  DetectorSummary* summary = nullptr);

}  // namespace puzzlecal

#endif  // PUZZLECAL_DETECTION_DETECTOR_H_
