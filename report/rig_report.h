#ifndef PUZZLECAL_REPORT_RIG_REPORT_H_
#define PUZZLECAL_REPORT_RIG_REPORT_H_

// The rig calibration report (`puzzlecal calibrate-rig --report DIR`): a
// markdown summary (summary.md) with every camera's verdict on top, the
// rig's figures, and per camera a section with the joint solve's residuals
// for it, its own calibration's RMS and the evidence on that calibration as
// the single-camera report shows it (report/report.h: the same tables, and
// the same charts named <camera>_cross_validation.png, ...); and, for the
// first two cameras, a rectified pair of one frame both saw, side by side
// with horizontal lines (rectified_pair.png): after a good calibration
// every board corner lies on the same row in both halves.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "calib/rig_calibration.h"
#include "camera/camera_models.h"
#include "evidence/evidence.h"
#include "evidence/rig_evidence.h"
#include "evidence/verdict.h"
#include "formats/rig_yaml.h"
#include "report/report.h"

namespace puzzlecal {

struct RigReportOptions {
  // Rows between the horizontal lines of the rectified pair, in pixels.
  // Default 24. >= 2.
  int line_spacing_px = 24;
  // Sizes of the evidence charts (those of the single-camera report).
  ReportOptions charts;
  bool Check(std::string* why) const;
};

struct RigReportInput {
  const RigCalibrationResult* result = nullptr;  // may be partial
  bool calibration_ok = false;
  std::string calibration_error;
  // Per camera, per frame: the image file (empty when the camera has none).
  std::vector<std::vector<std::string>> files;
  // Per camera (the order of result->cameras): the evidence on the camera's
  // own calibration and its verdict, as `calibrate` judges one camera
  // (evidence/evidence.h, evidence/verdict.h). Empty when not computed (a
  // failed calibration); otherwise one non-null entry per camera each.
  std::vector<const Evidence*> evidence;
  std::vector<const Verdict*> verdicts;
  // The rig's per-frame consistency and verdict (evidence/rig_evidence.h);
  // null when not computed.
  const RigEvidence* rig_evidence = nullptr;
  const RigVerdict* rig_verdict = nullptr;
  double seconds_images = 0;  // detection, grid and decode, wall clock
  double seconds_total = 0;
  int threads = 1;
};

// Resamples `image` of `camera` into the rectified view whose pixels are
// `projection` * `rectified_from_camera` * P_cam (3x3 intrinsics of the
// rectified view), of width x height, through the camera model's own
// projection (any model, fisheye too). Pixels without a ray are black.
cv::Mat RectifyImage(const cv::Mat& image, const Camera& camera,
                     const Eigen::Matrix3d& rectified_from_camera,
                     const Eigen::Matrix3d& projection, int width, int height);

// A rectification for viewing a pair whose optical axes may diverge (a
// fisheye next to a pinhole turned 50 degrees): the common rectified z axis
// is the bisector of the two optical axes made orthogonal to the baseline,
// x runs along the baseline, and both views share the intrinsics
// (the smaller focal length, principal point at the first image's centre).
// cv::stereoRectify (the opencv file's R1 R2 P1 P2) keeps each view close
// to its own camera instead, which for diverging cameras leaves little of
// the overlap in the image.
StereoRectification ViewingRectification(
    const Camera& first, const Camera& second,
    const Eigen::Isometry3d& second_from_first);

// The two rectified images side by side (grey in, colour out) with
// horizontal lines every options.line_spacing_px rows.
cv::Mat RectifiedPairImage(const cv::Mat& first, const cv::Mat& second,
                           const Camera& first_camera,
                           const Camera& second_camera,
                           const StereoRectification& rectification,
                           const RigReportOptions& options);

// The line that gives camera `name`'s verdict, in summary.md and on the
// program's output alike: "<name>: verdict: <kind> — <reason> — <next>".
std::string RigVerdictLine(const std::string& name, const Verdict& verdict);

// File name prefix of camera `name`'s charts ("cam0_"; characters other
// than letters, digits, '-', '_' and '.' become '_').
std::string RigChartPrefix(const std::string& name);

// Writes summary.md, the evidence charts of every camera with evidence
// (and rectified_pair.png when the calibration succeeded and the first two
// cameras share a frame) into `dir`, created if needed. The evidence and
// verdicts, when given, must have one entry per camera.
bool WriteRigReport(const std::string& dir, const RigReportInput& input,
                    const RigReportOptions& options, std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_REPORT_RIG_REPORT_H_
