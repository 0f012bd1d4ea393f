#ifndef PUZZLECAL_EVIDENCE_VERDICT_H_
#define PUZZLECAL_EVIDENCE_VERDICT_H_

// One verdict on a calibration, made from its result and its evidence
// (evidence/evidence.h): good, inconsistent-views (the photos do not share
// one camera: the focal length changed between them), model-error (the
// model cannot follow the lens:
// the two halves of the views disagree far beyond their uncertainty, or the
// residuals keep a systematic part), insufficient-data (the views do not
// determine the model well enough) or bad-detections (outliers or a few
// views far worse than the rest). Each comes with the reason and the next
// step, e.g. the model to try.
//
//   verdict: model-error — <reason> — <next step>

#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"

namespace puzzlecal {

enum class VerdictKind {
  kGood,
  kModelError,
  kInsufficientData,
  kBadDetections,
  kInconsistentViews,
  kViewErrors
};

// "good", "model-error", "insufficient-data", "bad-detections",
// "inconsistent-views", "view-errors".
const char* VerdictKindName(VerdictKind kind);

struct VerdictOptions {
  // --- model error ---
  // The halves disagree when, in a field-angle band with at least
  // EvidenceOptions::min_bin_count samples, the median difference exceeds
  // halves_factor times the median difference the two halves' covariances
  // predict, and halves_floor_px. Noise alone gives ratios near 1 or
  // below (the median length of a 2-D Gaussian vector is 0.83 times its
  // RMS, and the fitted rotation takes out a little more). Defaults 2.5 and
  // 0.1 px.
  double halves_factor = 2.5;
  double halves_floor_px = 0.1;
  // The covariance assumes independent corner errors; errors shared by the
  // corners of a view (its pose, the print, blur, a slightly bent board) do
  // not average out over a view's corners, so real halves differ by more
  // than it predicts, by about the same factor in every band. A model error
  // instead leaves bands where the model fits. So, with at least
  // halves_min_bands judged bands, the prediction is first scaled by the
  // smallest ratio (difference / prediction) of any judged band, when that
  // exceeds 1, and the halves_factor test applies to the scaled
  // prediction. 0 turns the scaling off. Default 3.
  int halves_min_bands = 3;
  // How far that excuse goes. Corner errors shared within views inflate the
  // halves' difference by a factor of about 1.5-2.5 on real photo sets
  // that calibrate well (1.66 on the 256-photo deltille fisheye set, 2.15
  // on a 26-photo 180-degree fisheye), and up to about 10 on renders, whose
  // corners are so exact (0.03 px) that the differences stay under 0.1 px.
  // An excess above halves_max_scale in every band, with the best-agreeing
  // band's median difference above halves_uniform_floor_px, is no shared
  // corner error: the halves do not see one camera (focus, zoom or the
  // board changed between photos), an inconsistent-views finding. Defaults
  // 4 and 0.25 px.
  double halves_max_scale = 4.0;
  double halves_uniform_floor_px = 0.25;
  // A band's excess is judged a model error only when the halves' free
  // intrinsics as a whole also differ by more than their covariances allow:
  // the chi-square of their difference (CrossValidation::intrinsics_chi2),
  // divided by the square of the prediction's scale above, as a standard
  // normal quantile (ChiSquareZ) above halves_min_z. One poorly determined
  // parameter can lift the medians of the bands where it dominates (every
  // pixel of a band shares the one draw of the parameters) without the
  // parameters differing significantly. Default 3.1 (a false alarm about
  // once in a thousand runs); 0 or less turns the test off.
  double halves_min_z = 3.1;
  // A residual bin (min_bin_count corners or more) is systematic when its
  // mean radial or tangential component is more than residual_se_factor
  // standard errors and more than residual_floor_px from zero. The standard
  // error treats corners as independent; corners of one view share a pose
  // error, hence the floor. Defaults 5 and 0.05 px.
  double residual_se_factor = 5.0;
  double residual_floor_px = 0.05;
  // The errors depend on closeness when the nearest distance bin's residual
  // mean is systematic (see residual_se_factor) or its residual RMS
  // exceeds closeness_rms_ratio times that of the farthest bin. With
  // another model-error finding this points to a non-central lens; the RMS
  // ratio alone is a model error only when the nearest bin's RMS is also
  // above closeness_floor_px. Defaults 1.5 and 0.3 px.
  double closeness_rms_ratio = 1.5;
  double closeness_floor_px = 0.3;
  // The conventional field of a pinhole lens (degrees off the axis). A
  // pinhole model whose corners reach beyond it is on a lens wider than it
  // is meant for: the next step is kannala-brandt. A lens whose corners
  // stay within it is never called a fisheye: the model to try is a
  // pinhole one (pinhole-rational), or none. Default 55.
  double pinhole_max_field_deg = 55.0;

  // --- bad detections ---
  // More rejected corners than this fraction of all corners of the used
  // views. Default 0.05.
  double max_outlier_fraction = 0.05;
  // A view stands out when the RMS of its inlier corners exceeds
  // view_rms_factor times the median view's (and view_rms_floor_px), when
  // more than max_view_outlier_fraction of its corners were rejected, or
  // when the rejection emptied it. A view with a few rejected corners and
  // inliers that fit does not: the rejection handled them (an isolated
  // false corner), and the verdict lists them as a note. At most
  // max_bad_view_fraction of the views standing out is "a few views" (more
  // is the model's or the data's doing as a whole). Defaults 3, 0.2 px,
  // 0.2 and 0.2.
  double view_rms_factor = 3.0;
  double view_rms_floor_px = 0.2;
  double max_view_outlier_fraction = 0.2;
  double max_bad_view_fraction = 0.2;

  // --- insufficient data ---
  // Fewer used views than this. Default 8.
  int min_views = 8;
  // Coverage (CalibrationResult::coverage) below this. Default 0.2.
  double min_coverage = 0.2;
  // The median of the projection uncertainty map in a field-angle band
  // within the observed field above this (pixels, per axis). Default
  // 0.25 px.
  double max_uncertainty_px = 0.25;
  // A free focal length or principal point coordinate whose standard
  // deviation exceeds its magnitude is undetermined.
  // check_distortion_determined applies the same test to the distortion
  // coefficients (whose standard deviation must then also exceed
  // min_undetermined_distortion_stddev, as they can be truly near zero).
  // Default false: coupled coefficients (the rational model's numerator
  // and denominator) are individually undetermined while the projection
  // they make is well determined; the projection uncertainty judges them.
  bool check_distortion_determined = false;
  double min_undetermined_distortion_stddev = 0.05;

  // --- inconsistent views ---
  // The views disagree on the focal length (evidence/view_consistency.h:
  // autofocus, zoom, another board) when their own focal lengths spread
  // more than view_focal_spread_factor times their standard deviations
  // (corner errors shared within a view make real sets spread up to about
  // 3 times: 3.2 was measured on a good 64-view fisheye set) and freeing
  // them moves the corners by more than noise predicts plus
  // view_focal_floor_px (RMS over the views). Defaults 3 and 0.05 px.
  double view_focal_spread_factor = 3.0;
  double view_focal_floor_px = 0.05;
  // Views named in a finding, the worst first. Default 5. >= 1.
  int max_named_views = 5;

  // --- view-level errors ---
  // A view's residual field (ViewField: a smooth field across the board
  // fitted to all of its corners' residuals) is a view-level error (a bent
  // board, a focus change, motion) when its RMS exceeds view_field_factor
  // times both what noise gives and the median view's (real views all carry
  // some: 0.1-0.18 px on a good 64-view fisheye set, where noise gives
  // 0.035 px), and view_field_floor_px, and exceeds what it leaves (the
  // view's errors are mostly the field), in at most max_bad_view_fraction
  // of the views (more is the model's doing). Such a view's rejected
  // corners are not counted as outliers. Defaults 3 (as view_rms_factor)
  // and 0.1 px.
  double view_field_factor = 3.0;
  double view_field_floor_px = 0.1;

  bool Check(std::string* why = nullptr) const;
};

// How one view of a calibration stands. This one rule names views in the
// verdict's findings, in the report's table of worst views and in its
// per-view chart.
enum class ViewStanding {
  kNotUsed,    // the calibration did not use it (and not for outliers)
  kFits,       // its corners fit like the other views'
  kHandled,    // a few rejected corners, the rest fits: a note
  kStandsOut,  // bad detections: inliers far above the median view's, too
               // many corners rejected, or the rejection emptied it
  kViewError,  // a smooth residual field across the board (view-level)
};

struct ViewJudgement {
  ViewStanding standing = ViewStanding::kNotUsed;
  double inlier_rms_px = 0;  // RMS per coordinate of its inlier corners
  int corners = 0;           // corners in the calibration, rejected ones too
  int rejected = 0;          // rejected as outliers
  double worst_rejected_px = 0;  // largest error of a rejected corner
  std::string why;  // for kHandled, kStandsOut and kViewError, with figures
};

struct Verdict {
  VerdictKind kind = VerdictKind::kGood;
  std::string reason;     // what the evidence shows, with figures
  std::string next_step;  // what to do
  // Every finding, in the order checked (the verdict names the first one of
  // the highest-ranked kind: model-error, inconsistent-views, view-errors,
  // bad-detections, insufficient-data).
  std::vector<std::string> findings;
  // What was seen and handled, which does not change the verdict: views
  // whose few rejected corners the outlier rejection took out while the
  // rest of the view fits (an isolated false corner); distortion
  // coefficients undetermined one by one (standard deviation above their
  // value and min_undetermined_distortion_stddev) while
  // check_distortion_determined is off.
  std::vector<std::string> notes;
  // A model name the next step suggests ("" if none).
  std::string suggested_model;
  // The inconsistent-views finding and its next step, also when a
  // model-error outranks it ("" if none): a model error and views that
  // disagree on the focal length look alike in the per-view focal lengths
  // (a model that cannot follow the lens is bent differently by each
  // view), so the held-out comparison decides (evidence/model_advice.h):
  // when no richer model wins there, the views are the explanation.
  std::string inconsistent_views;
  std::string inconsistent_views_next_step;
  // The same for the view-level errors finding.
  std::string view_errors;
  std::string view_errors_next_step;
  // Every view of the result, in its order, judged by the rule above; and
  // the rule's figures: the median view's inlier RMS and the limit above
  // which a view's inliers stand out (view_rms_factor times the median,
  // at least view_rms_floor_px). Empty / 0 when the result has no views.
  std::vector<ViewJudgement> views;
  double median_view_rms_px = 0;
  double view_rms_limit_px = 0;

  // "verdict: <kind> — <reason> — <next step>"
  std::string Line() const;
};

// The verdict for a successful calibration (`result`) and its evidence.
// Invalid options give insufficient-data with the options' fault as reason.
Verdict MakeVerdict(const CalibrationResult& result, const Evidence& evidence,
                    const EvidenceOptions& evidence_options,
                    const VerdictOptions& options);

// The model to try after `model` shows a model error (a candidate only:
// evidence/model_advice.h confirms it on held-out views).
// `grows_with_closeness`: the residuals depend on the board distance;
// `max_field_deg`: the widest observed field angle.
std::string NextModel(CameraModelId model, bool grows_with_closeness,
                      double max_field_deg, const VerdictOptions& options);

}  // namespace puzzlecal

#endif  // PUZZLECAL_EVIDENCE_VERDICT_H_
