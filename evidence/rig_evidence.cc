#include "evidence/rig_evidence.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "util/angles.h"
#include "util/failure.h"
#include "util/statistics.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

// The robust centre of relative poses: the rotation closest to all others
// (least summed angle) and the per-axis median translation.
Eigen::Isometry3d RobustCentre(const std::vector<Eigen::Isometry3d>& samples) {
  size_t best = 0;
  double best_sum = -1;
  for (size_t i = 0; i < samples.size(); ++i) {
    double sum = 0;
    for (const Eigen::Isometry3d& other : samples) {
      sum += RotationDifferenceDeg(samples[i].linear(), other.linear());
    }
    if (best_sum < 0 || sum < best_sum) {
      best_sum = sum;
      best = i;
    }
  }
  Eigen::Isometry3d centre = Eigen::Isometry3d::Identity();
  centre.linear() = samples[best].linear();
  for (int k = 0; k < 3; ++k) {
    std::vector<double> values;
    for (const Eigen::Isometry3d& s : samples) {
      values.push_back(s.translation()(k));
    }
    centre.translation()(k) = Median(values);
  }
  return centre;
}

// A camera's view of a frame in the rig's labels.
std::vector<Eigen::Vector3d> RigLabels(const RigCameraInput& input,
                                       const RigCalibrationResult& result,
                                       size_t c, size_t f) {
  std::vector<Eigen::Vector3d> points = input.frames[f].board_points;
  if (result.cameras[c].relabelled[f]) {
    for (Eigen::Vector3d& p : points) p = result.half_turn * p;
  }
  return points;
}

// Sum of squared pixel differences of `camera`'s corners predicted with
// cam_from_board, and their number.
void TransferSum(const Camera& camera, const Eigen::Isometry3d& cam_from_board,
                 const std::vector<Eigen::Vector3d>& points,
                 const std::vector<Eigen::Vector2d>& pixels, double* sum2,
                 int* count) {
  for (size_t i = 0; i < points.size() && i < pixels.size(); ++i) {
    Eigen::Vector2d predicted;
    if (!camera.Project(cam_from_board * points[i], &predicted) ||
        !predicted.allFinite()) {
      continue;
    }
    *sum2 += (predicted - pixels[i]).squaredNorm();
    ++*count;
  }
}

// Median distance (pixels of camera b) of b's corner rays from the
// epipolar planes of a's, with the rig's intrinsics and extrinsics.
double EpipolarError(const std::vector<RigCameraInput>& inputs,
                     const RigCalibrationResult& result, size_t a, size_t b,
                     size_t f) {
  const Camera cam_a = FarFieldCamera(result.cameras[a].camera);
  const Camera cam_b = FarFieldCamera(result.cameras[b].camera);
  const Eigen::Isometry3d b_from_a =
      result.cameras[b].cam_from_rig * result.cameras[a].cam_from_rig.inverse();
  const std::vector<Eigen::Vector3d> pa = RigLabels(inputs[a], result, a, f);
  const std::vector<Eigen::Vector3d> pb = RigLabels(inputs[b], result, b, f);
  std::vector<double> distances;
  for (size_t i = 0; i < pa.size(); ++i) {
    for (size_t j = 0; j < pb.size(); ++j) {
      if ((pa[i] - pb[j]).norm() > 1e-9) continue;
      Eigen::Vector3d ray_a, ray_b;
      if (!cam_a.Unproject(inputs[a].frames[f].image_points[i], &ray_a)
               .converged ||
          !cam_b.Unproject(inputs[b].frames[f].image_points[j], &ray_b)
               .converged) {
        break;
      }
      const Eigen::Vector3d normal =
          b_from_a.translation().cross(b_from_a.linear() * ray_a);
      if (!(normal.norm() > 0)) break;
      const double sine = std::abs(normal.normalized().dot(ray_b.normalized()));
      distances.push_back(std::asin(std::min(1.0, sine)) * cam_b.params[0]);
      break;
    }
  }
  return distances.empty() ? 0.0 : Median(distances);
}

}  // namespace

bool RigEvidenceOptions::Check(std::string* why) const {
  if (!(moved_factor > 1)) return Fail("moved_factor must be > 1", why);
  if (!(min_moved_px > 0)) return Fail("min_moved_px must be > 0", why);
  if (!(max_joint_over_alone > 1)) {
    return Fail("max_joint_over_alone must be > 1", why);
  }
  return true;
}

std::string RigVerdict::Line() const {
  return "rig: verdict: " + kind + " \u2014 " + reason + " \u2014 " + next_step;
}

RigEvidence ComputeRigEvidence(const std::vector<RigCameraInput>& inputs,
                               const RigCalibrationResult& result,
                               const RigEvidenceOptions& options) {
  RigEvidence evidence;
  const size_t num_cameras = result.cameras.size();
  const size_t num_frames = result.frame_used.size();
  evidence.frames.assign(num_frames, RigFrameEvidence());
  for (size_t c = 0; c < num_cameras; ++c) {
    const RigCameraResult& cam = result.cameras[c];
    evidence.joint_over_alone.push_back(
        cam.single_rms_px > 0 ? cam.rms_px / cam.single_rms_px : 0.0);
    for (size_t f = 0; f < num_frames; ++f) {
      RigFrameCamera view;
      view.has_view = !inputs[c].frames[f].board_points.empty();
      view.used = cam.frame_used[f];
      view.note = f < cam.frame_note.size() ? cam.frame_note[f] : "";
      double sum2 = 0;
      if (f < cam.residuals.size()) {
        for (const Eigen::Vector2d& r : cam.residuals[f]) {
          if (!r.allFinite() || r.squaredNorm() == 0) continue;
          sum2 += r.squaredNorm();
          ++view.corners;
        }
      }
      view.rms_px =
          view.corners > 0 ? std::sqrt(sum2 / (2.0 * view.corners)) : 0.0;
      evidence.frames[f].cameras.push_back(view);
      if (f < cam.start_disagreement_deg.size()) {
        double& left_out = evidence.frames[f].left_out_deg;
        left_out = std::max(left_out, cam.start_disagreement_deg[f]);
      }
    }
  }
  // Each camera against the camera its start was chained from.
  for (size_t c = 1; c < num_cameras; ++c) {
    const int parent =
        c < result.start_parent.size() ? result.start_parent[c] : 0;
    if (parent < 0) continue;
    const size_t p = static_cast<size_t>(parent);
    const RigCameraResult& cam_c = result.cameras[c];
    const RigCameraResult& cam_p = result.cameras[p];
    std::vector<size_t> frames;
    std::vector<Eigen::Isometry3d> samples;
    for (size_t f = 0; f < num_frames; ++f) {
      if (f < cam_c.alone_posed.size() && cam_c.alone_posed[f] &&
          f < cam_p.alone_posed.size() && cam_p.alone_posed[f]) {
        frames.push_back(f);
        samples.push_back(cam_c.alone_cam_from_board[f] *
                          cam_p.alone_cam_from_board[f].inverse());
      }
    }
    if (samples.empty()) continue;
    const Eigen::Isometry3d centre = RobustCentre(samples);
    for (size_t k = 0; k < frames.size(); ++k) {
      const size_t f = frames[k];
      double sum2 = 0;
      int count = 0;
      TransferSum(cam_c.single.camera, centre * cam_p.alone_cam_from_board[f],
                  RigLabels(inputs[c], result, c, f),
                  inputs[c].frames[f].image_points, &sum2, &count);
      TransferSum(cam_p.single.camera,
                  centre.inverse() * cam_c.alone_cam_from_board[f],
                  RigLabels(inputs[p], result, p, f),
                  inputs[p].frames[f].image_points, &sum2, &count);
      if (count == 0) continue;
      const double transfer = std::sqrt(sum2 / (2.0 * count));
      RigFrameEvidence& frame = evidence.frames[f];
      if (frame.compared && transfer <= frame.transfer_px) continue;
      frame.compared = true;
      frame.transfer_px = transfer;
      frame.pose_difference_mm =
          1000 * (samples[k].translation() - centre.translation()).norm();
      frame.pose_difference_deg =
          RotationDifferenceDeg(samples[k].linear(), centre.linear());
      frame.epipolar_px = EpipolarError(inputs, result, p, c, f);
    }
  }
  for (size_t f = 0; f < num_frames; ++f) {
    if (evidence.frames[f].left_out_deg > 0) {
      evidence.left_out_frames.push_back(static_cast<int>(f));
    }
  }
  std::vector<double> transfers;
  for (const RigFrameEvidence& frame : evidence.frames) {
    if (frame.compared) transfers.push_back(frame.transfer_px);
  }
  if (transfers.empty()) return evidence;
  evidence.median_transfer_px = Median(transfers);
  evidence.moved_limit_px = std::max(
      options.moved_factor * evidence.median_transfer_px, options.min_moved_px);
  for (size_t f = 0; f < num_frames; ++f) {
    RigFrameEvidence& frame = evidence.frames[f];
    frame.moved = frame.compared && frame.transfer_px > evidence.moved_limit_px;
    if (frame.moved) evidence.moved_frames.push_back(static_cast<int>(f));
  }
  return evidence;
}

RigVerdict MakeRigVerdict(const RigCalibrationResult& result,
                          const RigEvidence& evidence,
                          const std::vector<Verdict>& camera_verdicts,
                          const std::vector<std::string>& frame_names,
                          const RigEvidenceOptions& options) {
  RigVerdict verdict;
  auto frame_name = [&](int f) {
    return static_cast<size_t>(f) < frame_names.size() &&
                   !frame_names[f].empty()
               ? frame_names[f]
               : "frame " + std::to_string(f + 1);
  };
  std::string why;
  if (!options.Check(&why)) {
    verdict.kind = "insufficient-data";
    verdict.reason = "rig evidence options: " + why;
    verdict.next_step = "fix the options";
    return verdict;
  }
  if (!evidence.moved_frames.empty() || !evidence.left_out_frames.empty()) {
    std::ostringstream reason;
    if (!evidence.moved_frames.empty()) {
      reason << evidence.moved_frames.size() << " of "
             << std::count_if(
                    evidence.frames.begin(), evidence.frames.end(),
                    [](const RigFrameEvidence& f) { return f.compared; })
             << " frames look unsynchronised or moved between the cameras "
                "(their corners move by more than "
             << StringPrintf("%.2f", evidence.moved_limit_px)
             << " px from one camera to the other; typical "
             << StringPrintf("%.2f", evidence.median_transfer_px) << " px): ";
      for (size_t k = 0; k < evidence.moved_frames.size(); ++k) {
        const int f = evidence.moved_frames[k];
        const RigFrameEvidence& frame = evidence.frames[f];
        reason << (k > 0 ? "; " : "") << frame_name(f) << " "
               << StringPrintf("%.2f px, %.1f mm, %.2f deg", frame.transfer_px,
                               frame.pose_difference_mm,
                               frame.pose_difference_deg);
      }
      reason << "; they are kept and bend the rig";
    }
    if (!evidence.left_out_frames.empty()) {
      reason << (evidence.moved_frames.empty() ? "" : "; and ")
             << evidence.left_out_frames.size()
             << " frame(s) show the board at another moment in one camera "
                "(its pose relative to the rig is off by degrees, not "
                "noise): ";
      for (size_t k = 0; k < evidence.left_out_frames.size(); ++k) {
        const int f = evidence.left_out_frames[k];
        reason << (k > 0 ? "; " : "") << frame_name(f) << " "
               << StringPrintf("%.1f deg", evidence.frames[f].left_out_deg);
      }
      reason << "; the rig is made without them";
    }
    verdict.kind = "moved-frames";
    verdict.reason = reason.str();
    verdict.next_step =
        "remove these frames from every camera's folder and run again (or "
        "take the photos with the board held still, or with the cameras "
        "triggered together)";
    return verdict;
  }
  for (size_t c = 0; c < evidence.joint_over_alone.size(); ++c) {
    if (evidence.joint_over_alone[c] > options.max_joint_over_alone) {
      const RigCameraResult& cam = result.cameras[c];
      verdict.kind = "inconsistent";
      verdict.reason = StringPrintf(
          "camera '%s' fits the rig with an RMS of %.3f px, %.1f times its "
          "own calibration's %.3f px",
          cam.name.c_str(), cam.rms_px, evidence.joint_over_alone[c],
          cam.single_rms_px);
      verdict.next_step =
          "check that the folders' frames are the same instants and that the "
          "rig did not move between photos";
      return verdict;
    }
  }
  // The first camera that is not good gives the kind, its reason and next
  // step; every other one is named with its kind, so that a user reading
  // the rig's line does not take them for good.
  std::vector<size_t> not_good;
  for (size_t c = 0; c < camera_verdicts.size() && c < result.cameras.size();
       ++c) {
    if (camera_verdicts[c].kind != VerdictKind::kGood) not_good.push_back(c);
  }
  if (!not_good.empty()) {
    const size_t first = not_good.front();
    verdict.kind = VerdictKindName(camera_verdicts[first].kind);
    verdict.reason = "camera '" + result.cameras[first].name +
                     "': " + camera_verdicts[first].reason;
    for (size_t k = 1; k < not_good.size(); ++k) {
      const size_t c = not_good[k];
      verdict.reason += std::string(k == 1 ? "; and " : ", ") + "camera '" +
                        result.cameras[c].name + "' is " +
                        VerdictKindName(camera_verdicts[c].kind);
    }
    if (not_good.size() > 1) verdict.reason += " (their own verdicts say why)";
    verdict.next_step = camera_verdicts[first].next_step;
    return verdict;
  }
  double worst = 0;
  for (double ratio : evidence.joint_over_alone) worst = std::max(worst, ratio);
  verdict.kind = "good";
  verdict.reason = StringPrintf(
      "every frame agrees between the cameras (corners move by %.2f px "
      "typically, limit %.2f px) and the joint fit is within %.2f times "
      "each camera's own",
      evidence.median_transfer_px, evidence.moved_limit_px, worst);
  verdict.next_step = "ready to use";
  return verdict;
}

}  // namespace puzzlecal
