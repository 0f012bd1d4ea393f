#ifndef PUZZLECAL_EVIDENCE_EVIDENCE_H_
#define PUZZLECAL_EVIDENCE_EVIDENCE_H_

// Evidence on a finished calibration: is the model right for the lens and do
// the views determine it?
// - cross-validation: the used views split into two disjoint halves
//   (alternating by position, or several splits fixed by the views'
//   contents), each half calibrated on its own; the far-field
//   projection difference between the two solutions over the image, after
//   the best-fit rotation between their camera frames, compared with what
//   the two solutions' own uncertainties predict;
// - projection uncertainty: the parameter covariance propagated to the
//   projection of a far point at each pixel;
// - systematic residuals: the inlier residuals split into a radial and a
//   tangential component about the principal point, binned by field angle
//   and by the corner's distance from the camera, with means and standard
//   errors. A right model leaves means near zero in every bin.
// evidence/verdict.h turns these facts into one verdict.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "camera/calibration_view.h"
#include "camera/camera_models.h"
#include "evidence/view_consistency.h"

namespace puzzlecal {

struct EvidenceOptions {
  // Largest spacing in pixels of the grid on which the maps are computed.
  // Default 40. >= 1.
  int grid_step_px = 40;
  // The grid is made finer than grid_step_px until it holds at least this
  // many samples, so that the field-angle bands are judged on any image
  // size (a fixed 40 px grid left 8 of 10 bands of a 640 x 720 fisheye
  // under min_bin_count). Default 10000 (640 x 480: 5 px; 1600 x 1200:
  // 13 px). 0: grid_step_px as it is.
  int grid_min_samples = 10000;
  // Width of the field-angle bands of the summaries and of the residual
  // bins, degrees. Default 10. > 0.
  double band_width_deg = 10.0;
  // Bins of the residuals against board distance; their edges are quantiles
  // of the corner distances, so every bin holds about the same count.
  // Default 6. >= 1.
  int distance_bins = 6;
  // A band or bin with fewer samples than this is listed but not judged.
  // Default 30. >= 1.
  int min_bin_count = 30;
  // Run the cross-validation (two extra calibrations per split). Default
  // true.
  bool cross_validation = true;
  // Splits of the used views into two halves. 1: one split, alternating
  // by position; the verdict's thresholds (VerdictOptions::halves_*) were
  // set on it. It compares near-twin halves when the photos are in capture
  // order (neighbouring photos share the board's bend, the light, the
  // blur), and it depends on that order: the same 13 photos of a compact
  // camera in 8 file orders gave 2 verdicts, and leaving out one photo of
  // 26 of a 180-degree fisheye turned its verdict from good to model-error
  // in 16 of the 26 cases. More than 1: every split orders the views by a
  // hash of their corners, salted by the split, and alternates; the band
  // figures are the median split's. The verdict then depends on no order,
  // and leaving out one fisheye photo turned it in 3 of 26 cases, but
  // those halves differ more (the fisheye's excess in every band 3.45
  // times their uncertainty, against 2.14; 1.6-2.2x in the rim bands of
  // 64 photos of another fisheye), beyond what the thresholds were set
  // for: its fit with the noncentral model, good on one split, is
  // model-error on five. Default 1.
  // 1-16.
  int cross_validation_splits = 1;
  // Field angles (degrees) at which the projection uncertainty is reported,
  // besides the centre and the rim (the widest observed field angle).
  // Default 30, 60, 90. Angles the image does not reach are reported as
  // such.
  std::vector<double> report_angles_deg = {30.0, 60.0, 90.0};
  // Azimuths sampled around the axis for each report angle. Default 16. >= 1.
  int report_azimuths = 16;
  // The per-view focal lengths (evidence/view_consistency.h).
  ViewConsistencyOptions view_consistency;

  bool Check(std::string* why = nullptr) const;
};

// A quantity sampled on a pixel grid: sample (i, j) is pixel
// (min(i * step_px, width - 1), min(j * step_px, height - 1)). NaN where it is
// not defined (no ray, or outside the observed field for the difference
// map).
struct PixelMap {
  int step_px = 0;
  int cols = 0;
  int rows = 0;
  std::vector<double> values;  // row-major, cols * rows
  std::vector<double>
      angle_deg;  // field angle of each sample's ray (NaN: none)
  double At(int i, int j) const { return values[j * cols + i]; }
};

// Summary of a PixelMap over the samples whose field angle lies in
// [lo_deg, hi_deg).
struct AngleBand {
  double lo_deg = 0;
  double hi_deg = 0;
  int count = 0;
  double median = 0;
  double p95 = 0;
  double max = 0;
};

// "10-20 deg"; a last band cut short by the widest angle seen gets its end
// to a tenth of a degree ("20-20.4 deg", not "20-20 deg").
std::string AngleRangeLabel(double lo_deg, double hi_deg);
std::string BandLabel(const AngleBand& band);

// The far-field projection difference between two cameras of one image
// size (ProjectionDifference): each grid pixel's ray under camera A, turned
// by the rotation b_from_a that best aligns the two cameras' rays, projected
// by camera B, against A's projection of the same ray,
// |project_B(R * ray) - project_A(ray)| (mrcal's projection_diff). The
// rotation is no disagreement about the lens: a camera frame is tied to its
// calibration's board poses only, and turning it with all of them changes
// no projection of the boards.
struct ProjectionDiff {
  bool ok = false;
  std::string error;  // why not, when !ok
  Eigen::Matrix3d b_from_a = Eigen::Matrix3d::Identity();
  double rotation_deg = 0;  // the angle of b_from_a
  // The widest field angle (A's ray) among the compared pixels, degrees.
  double max_angle_deg = 0;
  // The difference in pixels; NaN where not compared (a pixel without a ray
  // in either camera, or beyond the field limit).
  PixelMap difference_px;
  // What the cameras' uncertainties alone would give, sqrt(tr(C_A(p)) +
  // tr(C_B(p))) with each 2 x 2 projection covariance C(p) taken after its
  // own rotation gauge over the compared field (RotationGauge), from the
  // covariances given; `expected_ok` false (and the map empty) when none
  // was given.
  bool expected_ok = false;
  PixelMap expected_px;
  std::vector<AngleBand> difference_bands;
  std::vector<AngleBand> expected_bands;  // empty when !expected_ok
};

// The halves of the used views (EvidenceOptions::cross_validation_splits).
// The first split's halves give the cameras,
// the maps and the rotation; the band figures (per band, the median
// split's) and the chi-square are medians over the splits that could be
// calibrated.
struct CrossValidation {
  bool ok = false;
  std::string error;  // why not, when !ok
  // Splits compared (those whose halves could both be calibrated), of the
  // splits tried.
  int splits = 0;
  int splits_tried = 0;
  int views_a = 0;
  int views_b = 0;
  double rms_a_px = 0;
  double rms_b_px = 0;
  Camera camera_a;
  Camera camera_b;
  // The rotation taking half A's camera frame to half B's that best aligns
  // their rays (the gauge freedom removed before comparing), and its angle.
  Eigen::Matrix3d b_from_a = Eigen::Matrix3d::Identity();
  double rotation_deg = 0;
  // |project_B(R * unproject_A(pixel)) - pixel| in pixels, within the
  // observed field (field angle <= the widest inlier corner's): the halves'
  // ProjectionDifference.
  PixelMap difference_px;
  // What noise alone would give: the RMS length of the difference predicted
  // from the two halves' covariances, sqrt(tr(C_A(p)) + tr(C_B(p))), where
  // C(p) is the 2 x 2 projection covariance at the pixel.
  PixelMap expected_px;
  // Per field-angle band, the figures of the split whose ratio of the
  // difference's median to the expected median is the median over the
  // splits; the count the smallest over them.
  std::vector<AngleBand> difference_bands;
  std::vector<AngleBand> expected_bands;
  // The halves' free intrinsics as a whole: the Mahalanobis distance
  // d' (C_A + C_B)^-1 d of their difference d under the sum of their
  // covariances, chi-square distributed with intrinsics_dof degrees of
  // freedom when the two differ by noise alone. A band median above
  // (difference_bands) can come from one parameter that is poorly
  // determined everywhere in the band (every pixel of a band shares the one
  // draw of the parameters); this figure says whether the difference is
  // larger than the covariances allow at all.
  // (The median over the splits.)
  double intrinsics_chi2 = 0;
  int intrinsics_dof = 0;
  double seconds = 0;  // the calibrations and the comparisons
};

// The standard normal quantile of a chi-square value with `dof` degrees of
// freedom (Wilson-Hilferty: (x/k)^(1/3) is nearly normal with mean
// 1 - 2/(9k) and variance 2/(9k)); 0 for dof < 1.
double ChiSquareZ(double chi2, int dof);

// One field angle at which the uncertainty is reported.
struct UncertaintyPoint {
  std::string label;  // "centre", "30 deg", ..., "rim (74.2 deg)"
  double angle_deg = 0;
  bool in_image = false;  // some azimuth at that angle lands in the image
  double sigma_px = 0;    // the largest over the azimuths that land
  // The same with the ray held fixed in the camera frame (no rotation
  // removed).
  double camera_frame_sigma_px = 0;
};

struct ProjectionUncertainty {
  bool ok = false;  // false when the result has no covariance
  // Per pixel: the 1-sigma of the projection of a far point seen at that
  // pixel, as the RMS over the two image axes of the 2 x 2 projection
  // covariance, sqrt(tr(C) / 2) (comparable with the per-coordinate RMS
  // reprojection error). C = A Sigma A^T, Sigma the intrinsics' covariance
  // marginal over the poses and A = J - G M: J = d pixel / d intrinsics
  // with the ray held fixed, G = d pixel / d rotation of the ray, and
  // M = (sum G^T G)^-1 sum G^T J over the observed field (`gauge`). The
  // G M term removes the part of a parameter change that a common rotation
  // of the camera frame undoes: a shift of cx, cy together with a rotation
  // of every board pose moves no observation, so the camera-frame
  // uncertainty of cx, cy is mostly not an uncertainty of the lens (mrcal
  // reasons the same way). The camera-frame figure is kept in `points`.
  PixelMap sigma_px;
  Eigen::MatrixXd gauge;  // M (3 x n), empty when it could not be formed
  bool rotation_removed = false;
  std::vector<AngleBand> bands;
  std::vector<UncertaintyPoint> points;
};

// Residual means of the inlier corners in one bin.
struct ResidualBin {
  double lo = 0;  // bin edges: degrees (field angle) or metres (distance)
  double hi = 0;
  int count = 0;
  // Means of the residual (projected minus observed) along the direction
  // from the principal point to the observed corner (radial; > 0: the
  // model projects the corner farther out than it was seen) and across it
  // (tangential, counter-clockwise in the image), with their standard
  // errors (standard deviation / sqrt(count)).
  double mean_radial_px = 0;
  double mean_tangential_px = 0;
  double se_radial_px = 0;
  double se_tangential_px = 0;
  // RMS of the residual coordinates, sqrt(sum |r|^2 / 2n).
  double rms_px = 0;
};

struct SystematicResiduals {
  std::vector<ResidualBin> by_angle;     // field angle of the corner's ray
  std::vector<ResidualBin> by_distance;  // |corner| in the camera frame, m
  double max_angle_deg = 0;  // widest field angle of an inlier corner
};

struct Evidence {
  CrossValidation cross_validation;
  ProjectionUncertainty uncertainty;
  SystematicResiduals residuals;
  ViewConsistency view_consistency;
  double seconds = 0;  // all of it
};

// The grid spacing used for `camera` (grid_step_px, finer for
// grid_min_samples).
int GridStep(const Camera& camera, const EvidenceOptions& options);

// The binned residual means of `result` (no solves).
SystematicResiduals ComputeSystematicResiduals(
    const std::vector<CalibrationView>& views, const CalibrationResult& result,
    const EvidenceOptions& options);

// 2 x 2 covariance of the projection of the ray through `pixel` under the
// intrinsics' covariance: with the ray held fixed in the camera frame, or,
// with `gauge` (RotationGauge), after the best-fit common rotation. False
// when the pixel has no ray.
bool ProjectionCovariance(const Camera& camera,
                          const Eigen::MatrixXd& covariance,
                          const Eigen::Vector2d& pixel, Eigen::Matrix2d* cov,
                          const Eigen::MatrixXd* gauge = nullptr);

// The 2 x n Jacobian that ProjectionCovariance propagates the covariance
// with: d pixel / d intrinsics of the far point seen at `pixel`, minus the
// part the rotation `gauge` undoes (when given). False when the pixel has no
// ray.
bool ProjectionJacobian(const Camera& camera, const Eigen::Vector2d& pixel,
                        const Eigen::MatrixXd* gauge,
                        Eigen::MatrixXd* jacobian);

// The two parts of that Jacobian: d pixel / d intrinsics with the ray held
// fixed (2 x n; a splined model's is zero outside the knots around the
// pixel), and d pixel / d omega for a small rotation omega of the ray (2 x
// 3): ProjectionJacobian is jacobian - rotation * gauge. False when the
// pixel has no ray.
bool ProjectionJacobianParts(const Camera& camera, const Eigen::Vector2d& pixel,
                             Eigen::MatrixXd* jacobian,
                             Eigen::Matrix<double, 2, 3>* rotation);

// M = (sum G^T G)^-1 sum G^T J over the grid pixels of `camera` whose ray is
// at most max_angle_deg off the axis (see ProjectionUncertainty): the
// rotation that best undoes a parameter change. Empty when not formed.
Eigen::MatrixXd RotationGauge(const Camera& camera, int step_px,
                              double max_angle_deg);

// The projection uncertainty map and figures of `result` (no solves).
ProjectionUncertainty ComputeProjectionUncertainty(
    const CalibrationResult& result, double max_angle_deg,
    const EvidenceOptions& options);

// The far-field projection difference of camera B against camera A (see
// ProjectionDiff) on A's pixel grid (GridStep(a, options)), over the
// pixels both cameras unproject whose ray under A is at most max_angle_deg
// off the axis (0: no limit). The rotation starts from the better of the
// identity and the least-squares alignment of the two cameras' rays at the
// same pixels (Kabsch), and is refined by Gauss-Newton steps on the pixel
// differences; a camera against itself gives the identity and exactly 0.
// `covariance_a`, `covariance_b` (optional, n x n of the camera's model)
// give the expected difference. Fails (with the reason) on cameras of
// different image sizes, invalid options, or when fewer than 3 pixels can
// be compared.
ProjectionDiff ProjectionDifference(
    const Camera& a, const Camera& b, double max_angle_deg,
    const EvidenceOptions& options,
    const Eigen::MatrixXd* covariance_a = nullptr,
    const Eigen::MatrixXd* covariance_b = nullptr);

// Calibrates the two halves of the used views of `result` in each of
// options.cross_validation_splits splits (see CrossValidation) with
// `calibration` options, started from the full solution, and compares them.
// Fails when no split's halves can both be calibrated (the first split's
// reason).
CrossValidation CrossValidate(const std::vector<CalibrationView>& views,
                              const CalibrationResult& result,
                              const CalibrationOptions& calibration,
                              double max_angle_deg,
                              const EvidenceOptions& options);

// All of the above for a successful Calibrate(views, ...) -> result. Invalid
// options leave everything empty, with the reason in
// cross_validation.error.
Evidence ComputeEvidence(const std::vector<CalibrationView>& views,
                         const CalibrationResult& result,
                         const CalibrationOptions& calibration,
                         const EvidenceOptions& options);

// Summaries of a map by field-angle bands of `band_width_deg` up to
// `max_angle_deg` (samples beyond it are left out).
std::vector<AngleBand> SummarizeByAngle(const PixelMap& map,
                                        double band_width_deg,
                                        double max_angle_deg);

// Readable text of a projection difference: the rotation, then per
// field-angle band the count, median, 95th percentile and maximum, with the
// expected median and 95th percentile when known. `indent` starts every
// line.
std::string ProjectionDifferenceText(const ProjectionDiff& diff,
                                     const std::string& indent = "");

// Readable text of the evidence (tables of the bands, points and bins).
std::string EvidenceText(const Evidence& evidence);

}  // namespace puzzlecal

#endif  // PUZZLECAL_EVIDENCE_EVIDENCE_H_
