#include "report/rig_report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <vector>

#include "formats/image_io.h"
#include "formats/png_writer.h"
#include "pipeline/video_frames.h"
#include "report/html.h"
#include "report/overlay.h"
#include "report/plot.h"
#include "util/atomic_file.h"
#include "util/failure.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// The charts written for one camera and, when there are none, why.
struct CameraCharts {
  std::vector<std::string> files;
  std::string missing;
};

// The frame both first cameras saw with the most corners between them, -1
// when there is none (or the calibration failed).
int PairFrame(const RigReportInput& input) {
  if (!input.calibration_ok || input.result == nullptr ||
      input.result->cameras.size() < 2 || input.files.size() < 2) {
    return -1;
  }
  const RigCalibrationResult& result = *input.result;
  int best = -1, best_corners = 0;
  for (size_t f = 0; f < result.frame_used.size(); ++f) {
    if (f >= input.files[0].size() || f >= input.files[1].size()) break;
    if (!result.cameras[0].frame_used[f] || !result.cameras[1].frame_used[f]) {
      continue;
    }
    const int corners = static_cast<int>(result.cameras[0].inlier[f].size() +
                                         result.cameras[1].inlier[f].size());
    if (corners > best_corners) {
      best_corners = corners;
      best = static_cast<int>(f);
    }
  }
  return best;
}

bool HasEvidence(const RigReportInput& input) {
  return input.calibration_ok && input.result != nullptr &&
         !input.evidence.empty();
}

// The evidence charts of every camera, drawn by the single-camera report's
// code. A camera whose charts cannot be drawn (no chart library, an
// invalid image size) gets the reason instead; a file that cannot be
// written is an error.
bool WriteAllCameraCharts(const std::string& dir, const RigReportInput& input,
                          const RigReportOptions& options,
                          std::vector<CameraCharts>* charts,
                          std::string* error) {
  charts->assign(input.evidence.size(), CameraCharts());
  std::string why;
  const bool available = plot::ChartsAvailable(&why);
  for (size_t c = 0; c < input.evidence.size(); ++c) {
    const Camera& camera = input.result->cameras[c].camera;
    if (!available) {
      (*charts)[c].missing = "no charts: " + why;
      continue;
    }
    if (camera.width <= 0 || camera.height <= 0) {
      (*charts)[c].missing =
          StringPrintf("no charts: the image size %d x %d is not valid",
                       camera.width, camera.height);
      continue;
    }
    if (!WriteEvidenceCharts(dir, RigChartPrefix(input.result->cameras[c].name),
                             camera.width, camera.height, *input.evidence[c],
                             options.charts, &(*charts)[c].files, error)) {
      return false;
    }
  }
  return true;
}

// The rig's residuals for the camera beside its own calibration's.
std::string CameraFiguresTable(const RigCameraResult& cam) {
  std::ostringstream md;
  md << "| | rig (joint solve) | own calibration |\n|---|---:|---:|\n";
  md << StringPrintf(
      "| RMS reprojection error (px per coordinate) | %.4f | "
      "%.4f |\n",
      cam.rms_px, cam.single_rms_px);
  md << StringPrintf("| corners used | %d | %d |\n", cam.num_corners_used,
                     cam.single.num_corners_used);
  md << StringPrintf("| outliers | %d | %d |\n", cam.num_outliers,
                     cam.single.num_outliers);
  md << StringPrintf("| frames used (own calibration: views) | %d | %d |\n\n",
                     cam.num_frames_used, cam.single_views_used);
  return md.str();
}

// One camera's section: verdict, figures, evidence and its charts.
std::string CameraSection(const RigCameraResult& cam, const Evidence* evidence,
                          const Verdict* verdict, const CameraCharts* charts) {
  std::ostringstream md;
  md << "## Camera " << cam.name << "\n\n";
  md << "Model **" << CameraModelName(cam.camera.model) << "**, image "
     << cam.camera.width << " x " << cam.camera.height << " px.\n\n";
  if (verdict != nullptr) {
    md << "**" << RigVerdictLine(cam.name, *verdict) << "**\n\n";
  }
  md << CameraFiguresTable(cam);
  if (evidence == nullptr) return md.str();
  md << "Evidence and verdict judge the camera's own calibration, as "
        "`puzzlecal calibrate` judges one camera.\n\n";
  md << EvidenceMarkdown(*evidence, verdict, 3);
  md << "### Charts\n\n";
  if (charts->files.empty()) {
    md << (charts->missing.empty() ? std::string("No charts were drawn.")
                                   : charts->missing)
       << "\n\n";
  }
  const std::string prefix = RigChartPrefix(cam.name);
  for (const std::string& file : charts->files) {
    md << "- `" << file
       << "`: " << EvidenceChartDescription(file.substr(prefix.size()))
       << "\n\n  ![" << file << "](" << file << ")\n\n";
  }
  return md.str();
}

// The frames: per camera whether it was used (or why not) and its rig
// RMS, the frame's transfer error, pose difference and epipolar error;
// frames that look moved are marked.
std::string FramesTable(const RigReportInput& input) {
  const RigCalibrationResult& result = *input.result;
  const RigEvidence& evidence = *input.rig_evidence;
  std::ostringstream md;
  md << "## Frames\n\nPer frame: each camera's image, whether the rig used "
        "it and its residual RMS in the rig (px); the transfer error (the "
        "board as one camera posed it alone, moved through the rig to the "
        "other: RMS px), how far the frame's relative pose is from the "
        "rig's, and the epipolar error (median, px). "
     << StringPrintf("Frames whose transfer error exceeds %.2f px ",
                     evidence.moved_limit_px)
     << "(typical " << StringPrintf("%.2f", evidence.median_transfer_px)
     << " px) look unsynchronised or moved: **moved**.\n\n| frame |";
  for (const RigCameraResult& cam : result.cameras) {
    md << " " << cam.name << " |";
  }
  md << " transfer (px) | pose difference | epipolar (px) | |\n|---|";
  for (size_t c = 0; c < result.cameras.size(); ++c) md << "---|";
  md << "---:|---:|---:|---|\n";
  for (size_t f = 0; f < evidence.frames.size(); ++f) {
    const RigFrameEvidence& frame = evidence.frames[f];
    std::string name;
    for (size_t c = 0; c < input.files.size() && name.empty(); ++c) {
      if (f < input.files[c].size() && !input.files[c][f].empty()) {
        name = fs::path(input.files[c][f]).filename().string();
      }
    }
    md << "| " << (name.empty() ? std::to_string(f + 1) : name) << " |";
    for (const RigFrameCamera& view : frame.cameras) {
      std::string cell = !view.has_view ? "-"
                         : view.used    ? StringPrintf("%.3f", view.rms_px)
                                        : "not used";
      if (!view.note.empty()) {
        cell = view.used ? cell + " (" + view.note + ")" : view.note;
      }
      std::replace(cell.begin(), cell.end(), '|', '/');
      md << " " << cell << " |";
    }
    if (frame.compared) {
      md << StringPrintf(" %.3f | %.2f mm, %.3f deg | %.3f | %s |\n",
                         frame.transfer_px, frame.pose_difference_mm,
                         frame.pose_difference_deg, frame.epipolar_px,
                         frame.moved ? "**moved**" : "");
    } else {
      md << " | | | |\n";
    }
  }
  md << "\n";
  return md.str();
}

std::string RigSummary(const RigReportInput& input,
                       const std::vector<CameraCharts>& charts, bool pair,
                       const std::string& rect_note) {
  std::ostringstream md;
  md << "# Rig calibration report\n\n";
  const bool evidence = HasEvidence(input);
  if (input.rig_verdict != nullptr) {
    md << "**" << input.rig_verdict->Line() << "**\n\n";
  }
  if (evidence) {
    for (size_t c = 0; c < input.verdicts.size(); ++c) {
      md << "- "
         << RigVerdictLine(input.result->cameras[c].name, *input.verdicts[c])
         << "\n";
    }
    md << "\n";
  }
  if (!input.calibration_ok) {
    md << "> **Calibration failed:** " << input.calibration_error << "\n\n";
  } else if (input.result != nullptr && !input.result->cameras.empty()) {
    md << "## Rig\n\n```\n" << RigCalibrationReport(*input.result) << "```\n\n";
    if (input.rig_evidence != nullptr) md << FramesTable(input);
    for (size_t c = 0; c < input.result->cameras.size(); ++c) {
      md << CameraSection(input.result->cameras[c],
                          evidence ? input.evidence[c] : nullptr,
                          evidence ? input.verdicts[c] : nullptr,
                          evidence ? &charts[c] : nullptr);
    }
  }
  if (pair) {
    md << "## Rectified pair\n\n`rectified_pair.png`: one frame of the "
          "first two cameras, rectified side by side with horizontal lines; "
          "after a good calibration every board corner lies on the same row "
          "in both halves. "
       << rect_note << "\n\n![rectified_pair.png](rectified_pair.png)\n\n";
  }
  md << "## Time\n\n"
     << StringPrintf("%.2f s on %d threads (images %.2f s).\n",
                     input.seconds_total, input.threads, input.seconds_images);
  return md.str();
}

}  // namespace

bool RigReportOptions::Check(std::string* why) const {
  if (line_spacing_px < 2) return Fail("line_spacing_px must be >= 2", why);
  std::string charts_why;
  if (!charts.Check(&charts_why)) return Fail("charts: " + charts_why, why);
  return true;
}

std::string RigVerdictLine(const std::string& name, const Verdict& verdict) {
  return name + ": " + verdict.Line();
}

std::string RigChartPrefix(const std::string& name) {
  std::string prefix = name.empty() ? std::string("camera") : name;
  for (char& c : prefix) {
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '-' ||
                    c == '_' || c == '.';
    if (!ok) c = '_';
  }
  return prefix + "_";
}

cv::Mat RectifyImage(const cv::Mat& image, const Camera& lens,
                     const Eigen::Matrix3d& rectified_from_camera,
                     const Eigen::Matrix3d& projection, int width, int height) {
  // The scene is far away compared to the lens: a non-central camera acts
  // as its far-field part (the same camera for central models).
  const Camera camera = FarFieldCamera(lens);
  cv::Mat map_x(height, width, CV_32FC1), map_y(height, width, CV_32FC1);
  const Eigen::Matrix3d camera_from_pixel =
      rectified_from_camera.transpose() * projection.inverse();
  // Beyond the fold of a pinhole's distortion polynomial (where the image
  // radius stops growing with the ray's angle) a ray lands on a pixel that
  // is not its own: black.
  const bool pinhole = CameraModelIsPinhole(camera.model);
  const Eigen::Vector2d centre(camera.params[2], camera.params[3]);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector3d ray = camera_from_pixel * Eigen::Vector3d(u, v, 1);
      Eigen::Vector2d pixel;
      bool valid = camera.Project(ray, &pixel) && pixel.allFinite();
      if (valid && pinhole) {
        Eigen::Vector3d outward = ray;
        outward.head<2>() *= 1.0 + 1e-4;
        Eigen::Vector2d further;
        valid = camera.Project(outward, &further) &&
                (further - centre).norm() > (pixel - centre).norm();
      }
      if (!valid) {
        pixel.setConstant(-1e6);
      }
      map_x.at<float>(v, u) = static_cast<float>(pixel.x());
      map_y.at<float>(v, u) = static_cast<float>(pixel.y());
    }
  }
  cv::Mat rectified;
  cv::remap(image, rectified, map_x, map_y, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  return rectified;
}

StereoRectification ViewingRectification(
    const Camera& first, const Camera& second,
    const Eigen::Isometry3d& second_from_first) {
  const Eigen::Matrix3d r = second_from_first.linear();
  const Eigen::Vector3d centre =
      -(r.transpose() * second_from_first.translation());
  // x along the baseline, turned to the first camera's +x so that the
  // picture stays upright whichever side the second camera is on.
  Eigen::Vector3d x = centre.normalized();
  if (x.x() < 0) x = -x;
  const Eigen::Vector3d axes =
      (Eigen::Vector3d::UnitZ() + r.transpose() * Eigen::Vector3d::UnitZ())
          .normalized();
  const Eigen::Vector3d z = (axes - x * x.dot(axes)).normalized();
  const Eigen::Vector3d y = z.cross(x);
  StereoRectification rect;
  rect.r1.row(0) = x.transpose();
  rect.r1.row(1) = y.transpose();
  rect.r1.row(2) = z.transpose();
  rect.r2 = rect.r1 * r.transpose();
  const double f = std::min(first.params[0], second.params[0]);
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = k(1, 1) = f;
  k(0, 2) = 0.5 * (first.width - 1);
  k(1, 2) = 0.5 * (first.height - 1);
  rect.p1.setZero();
  rect.p1.leftCols<3>() = k;
  rect.p2 = rect.p1;
  rect.p2(0, 3) = -f * (rect.r1 * centre).x();
  rect.width = first.width;
  rect.height = first.height;
  rect.q.setZero();
  rect.essential.setZero();
  rect.fundamental.setZero();
  return rect;
}

cv::Mat RectifiedPairImage(const cv::Mat& first, const cv::Mat& second,
                           const Camera& first_camera,
                           const Camera& second_camera,
                           const StereoRectification& rect,
                           const RigReportOptions& options) {
  const Eigen::Matrix3d k1 = rect.p1.leftCols<3>();
  const Eigen::Matrix3d k2 = rect.p2.leftCols<3>();
  const cv::Mat a =
      RectifyImage(first, first_camera, rect.r1, k1, rect.width, rect.height);
  const cv::Mat b =
      RectifyImage(second, second_camera, rect.r2, k2, rect.width, rect.height);
  cv::Mat pair;
  cv::hconcat(a, b, pair);
  Overlay overlay;
  for (int y = options.line_spacing_px / 2; y < pair.rows;
       y += options.line_spacing_px) {
    OverlayMark line;
    line.kind = OverlayMark::Kind::kLine;
    line.at = Eigen::Vector2d(0, y);
    line.to = Eigen::Vector2d(pair.cols - 1, y);
    line.colour = cv::Scalar(0, 200, 0);
    overlay.marks.push_back(line);
  }
  return DrawOverlay(pair, overlay, OverlayOptions());
}

// The first shared frame of a stereo pair, rectified, with horizontal
// lines (rectified_pair.png).
bool WriteRectifiedPair(const std::string& dir, const RigReportInput& input,
                        int pair_frame, const StereoRectification& rect,
                        const RigReportOptions& options, std::string* error) {
  const RigCalibrationResult& result = *input.result;
  cv::Mat first, second;
  // Photos, or frames of the cameras' videos ("cam0.mp4#frame0012").
  if (!LoadFrameImage(input.files[0][pair_frame], &first, error) ||
      !LoadFrameImage(input.files[1][pair_frame], &second, error)) {
    return false;
  }
  const cv::Mat pair =
      RectifiedPairImage(first, second, result.cameras[0].camera,
                         result.cameras[1].camera, rect, options);
  return WritePngFile((fs::path(dir) / "rectified_pair.png").string(), pair,
                      error);
}

bool WriteRigReport(const std::string& dir, const RigReportInput& input,
                    const RigReportOptions& options, std::string* error) {
  std::string why;
  if (!options.Check(&why)) return Fail("rig report options: " + why, error);
  if (HasEvidence(input)) {
    const size_t n = input.result->cameras.size();
    if (input.evidence.size() != n || input.verdicts.size() != n ||
        std::count(input.evidence.begin(), input.evidence.end(), nullptr) ||
        std::count(input.verdicts.begin(), input.verdicts.end(), nullptr)) {
      return Fail(StringPrintf("rig report: %zu cameras, but %zu evidence "
                               "and %zu verdicts (one of each per camera)",
                               n, input.evidence.size(), input.verdicts.size()),
                  error);
    }
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Fail("cannot create '" + dir + "': " + ec.message(), error);
  std::vector<CameraCharts> charts;
  if (HasEvidence(input) &&
      !WriteAllCameraCharts(dir, input, options, &charts, error)) {
    return false;
  }
  const int pair_frame = PairFrame(input);
  StereoRectification rect;
  std::string rect_note;
  if (pair_frame >= 0) {
    const RigCalibrationResult& result = *input.result;
    // The rectification the opencv and ros files hold, so that the picture
    // shows what a user of the files gets; the viewing one where it has
    // none.
    const Eigen::Isometry3d second_from_first =
        result.cameras[1].cam_from_rig *
        result.cameras[0].cam_from_rig.inverse();
    std::string why;
    if (StereoRectify(result.cameras[0].camera, result.cameras[1].camera,
                      second_from_first, &rect, &why)) {
      rect_note =
          "The rectification of the opencv and ros files: " + rect.Summary() +
          ".";
    } else {
      rect = ViewingRectification(result.cameras[0].camera,
                                  result.cameras[1].camera, second_from_first);
      rect_note = "The files hold no rectification (" + why +
                  "); drawn with a viewing rectification.";
    }
  }
  if (!WriteFileAtomically(
          (fs::path(dir) / "summary.md").string(),
          RigSummary(input, charts, pair_frame >= 0, rect_note), error)) {
    return false;
  }
  if (pair_frame >= 0 &&
      !WriteRectifiedPair(dir, input, pair_frame, rect, options, error)) {
    return false;
  }
  // The same as one web page with the pictures inline.
  return WriteHtmlReport(dir, "Rig calibration report", error);
}

}  // namespace puzzlecal
