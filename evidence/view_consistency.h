#ifndef PUZZLECAL_EVIDENCE_VIEW_CONSISTENCY_H_
#define PUZZLECAL_EVIDENCE_VIEW_CONSISTENCY_H_

// Do the views agree on the camera? A focal length fitted per view, with
// the other intrinsics held at the calibration's and the view's pose free:
// when the focal length changed between photos (autofocus, zoom) or the
// board was replaced by one of another size (a scale the pose cannot take
// up once the perspective of a tilted board is seen), the views' focal
// lengths spread far beyond their standard deviations; with one lens and
// one board they agree within them.

#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "camera/calibration_view.h"

namespace puzzlecal {

struct ViewConsistencyOptions {
  // A view takes part with at least this many inlier corners. Default 8.
  // >= 7 (seven parameters are fitted per view).
  int min_corners = 8;
  // Gauss-Newton iterations of each view's fit. Default 20. >= 1.
  int max_iterations = 20;

  bool Check(std::string* why = nullptr) const;
};

// One view's residual field: a smooth field (quadratic in the board
// coordinates, for x and y apart) fitted to the residuals of all of the
// view's corners, rejected ones included. A bent board, a focus change or
// motion during the exposure move a view's corners together: a field
// across the board that noise and isolated false corners do not make.
struct ViewField {
  int view = 0;
  std::string name;
  int corners = 0;
  int outliers = 0;          // of them rejected by the calibration
  double rms_px = 0;         // all corners, per coordinate
  double smooth_rms_px = 0;  // the fitted field, per coordinate
  double rest_rms_px = 0;    // what the field leaves, per coordinate
  // The field's RMS noise alone would give: sigma * sqrt(12 / 2n).
  double expected_smooth_px = 0;
  // The rejected corners the field accounts for: within the calibration's
  // outlier threshold of it.
  int outliers_explained = 0;
};

// One view's focal length.
struct ViewFocal {
  int view = 0;      // index into the calibration views
  std::string name;  // the view's name (its file)
  int corners = 0;
  // The focal scale fitted for the view (fx and fy both times it) and its
  // standard deviation (corner noise: the calibration's RMS per coordinate).
  double scale = 1;
  double scale_sigma = 0;
  // RMS distance of the view's corners from the principal point (pixels): a
  // focal scale change d moves them by about d times it.
  double radius_px = 0;
  // (scale - weighted mean) / scale_sigma.
  double z = 0;
  // What the view's own focal length gains in its fit: sqrt((SSE held -
  // SSE free) / 2n), pixels per coordinate (about sigma / sqrt(2n) for
  // noise alone).
  double gain_px = 0;
};

struct ViewConsistency {
  bool ok = false;  // at least three views were fitted
  std::string error;
  double focal_px = 0;  // the calibration's fx
  std::vector<ViewFocal> views;
  double mean_scale = 1;  // weighted by 1 / sigma^2
  // Sum of z^2 (chi-square with views - 1 degrees of freedom when the views
  // agree up to independent corner noise), and sqrt(chi2 / dof): how many
  // times their standard deviations the focal lengths spread.
  double chi2 = 0;
  int dof = 0;
  double spread_ratio = 0;
  // RMS over the views of gain_px: how much the views' own focal lengths
  // move their corners' projections, pixels.
  double effect_px = 0;
  // What noise alone would give for it: the RMS over the views of
  // sigma / sqrt(2n) (one parameter freed takes one sigma^2 from a view's
  // sum of squares), sigma the calibration's RMS.
  double expected_effect_px = 0;
  // Each view's residual field (ComputeViewFields).
  std::vector<ViewField> fields;
};

// Every used view's residual field (views with at least
// options.min_corners corners). sigma: the calibration's robust noise
// estimate (its RMS without one).
std::vector<ViewField> ComputeViewFields(
    const std::vector<CalibrationView>& views, const CalibrationResult& result,
    const ViewConsistencyOptions& options);

ViewConsistency ComputeViewConsistency(
    const std::vector<CalibrationView>& views, const CalibrationResult& result,
    const ViewConsistencyOptions& options);

// The views sorted by |z|, largest first (at most `count`).
std::vector<ViewFocal> MostInconsistentViews(const ViewConsistency& vc,
                                             int count);

}  // namespace puzzlecal

#endif  // PUZZLECAL_EVIDENCE_VIEW_CONSISTENCY_H_
