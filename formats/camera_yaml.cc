#include "formats/camera_yaml.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "formats/camera_file_formats.h"
#include "formats/yaml_emit.h"
#include "util/atomic_file.h"
#include "util/enum_names.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

bool CheckCamera(const Camera& camera, std::string* error) {
  if (static_cast<int>(camera.params.size()) !=
      CameraModelNumParams(camera.model)) {
    return Fail(std::string("the camera has ") +
                    std::to_string(camera.params.size()) + " parameters, " +
                    CameraModelName(camera.model) + " needs " +
                    std::to_string(CameraModelNumParams(camera.model)),
                error);
  }
  for (double v : camera.params) {
    if (!std::isfinite(v))
      return Fail("the camera has non-finite parameters", error);
  }
  if (camera.width <= 0 || camera.height <= 0) {
    return Fail("the camera has no image size", error);
  }
  return true;
}
// The root of a camera file's text. yaml-cpp does not know OpenCV's
// "%YAML:1.0" directive: it becomes a comment (so line numbers stay right),
// and `opencv_header` says it was there.
bool ParseCameraText(const std::string& text, const std::string& source,
                     YAML::Node* root, bool* opencv_header,
                     std::string* error) {
  *opencv_header = text.rfind("%YAML:", 0) == 0;
  return ParseYaml(*opencv_header ? "#" + text.substr(1) : text, source, root,
                   error);
}

}  // namespace

bool ParseCameraNode(const YAML::Node& node, const std::string& path,
                     bool opencv_header, FieldReader* reader, Camera* camera,
                     CameraFileFormat* format) {
  FieldReader& r = *reader;
  if (!r.Map(node, path)) return false;
  Camera parsed;
  CameraFileFormat found;
  bool ok;
  if (node["format"] || node["parameters"]) {
    found = CameraFileFormat::kPuzzlecal;
    ok = camera_file::ParsePuzzlecal(node, path, r, &parsed);
  } else if (node["cam0"]) {
    found = CameraFileFormat::kKalibr;
    ok = camera_file::ParseKalibr(node, path, r, &parsed);
  } else if (node["distortion_model"] && !opencv_header) {
    found = CameraFileFormat::kRos;
    ok = camera_file::ParseOpenCvOrRos(node, path, /*ros=*/true, r, &parsed);
  } else if (opencv_header || node["camera_matrix"]) {
    found = CameraFileFormat::kOpenCv;
    ok = camera_file::ParseOpenCvOrRos(node, path, /*ros=*/false, r, &parsed);
  } else {
    return r.Fail(path,
                  "not a camera file in any known format (puzzlecal, opencv, "
                  "ros, kalibr): no 'parameters', 'camera_matrix' or 'cam0'");
  }
  if (!ok) return false;
  if (CameraModelIsSplined(parsed.model) &&
      static_cast<int>(parsed.params.size()) ==
          CameraModelNumParams(parsed.model) &&
      !(parsed.params[KannalaBrandtSplinedModel::kGridRadiusIndex] > 0 &&
        std::isfinite(
            parsed.params[KannalaBrandtSplinedModel::kGridRadiusIndex]))) {
    return r.Fail(path + ".parameters.grid_radius",
                  "must be a positive number (the spline grid's half width, "
                  "radians)");
  }
  *camera = parsed;
  if (format != nullptr) *format = found;
  return true;
}

const char* RosDistortionModel(CameraModelId id) {
  switch (id) {
    case CameraModelId::kPinholeRadtan:
      return "plumb_bob";
    case CameraModelId::kPinholeRational:
      return "rational_polynomial";
    case CameraModelId::kKannalaBrandt:
    case CameraModelId::kKannalaBrandtNoncentral:  // its far-field part
    // The best-fitting kannala-brandt (CameraForFormat).
    case CameraModelId::kKannalaBrandtSplined:
    case CameraModelId::kKannalaBrandtSplinedNoncentral:
      return "equidistant";
  }
  return "plumb_bob";
}

constexpr EnumName<CameraFileFormat> kCameraFileFormatNames[] = {
    {CameraFileFormat::kPuzzlecal, "puzzlecal"},
    {CameraFileFormat::kOpenCv, "opencv"},
    {CameraFileFormat::kRos, "ros"},
    {CameraFileFormat::kKalibr, "kalibr"},
};

const char* CameraFileFormatName(CameraFileFormat format) {
  return NameOf(kCameraFileFormatNames, format, "puzzlecal");
}

bool CameraFileFormatFromName(const std::string& name,
                              CameraFileFormat* format) {
  return ValueOf(kCameraFileFormatNames, name, format);
}

bool CameraFormatFixedParams(CameraFileFormat format, CameraModelId model,
                             std::vector<std::string>* fixed,
                             std::string* error) {
  fixed->clear();
  if (format != CameraFileFormat::kKalibr) return true;
  if (model == CameraModelId::kPinholeRadtan) {
    fixed->push_back("k3");  // Kalibr's radtan: k1 k2 p1 p2
    return true;
  }
  // equidistant; a non-central camera is written as its far-field part
  // (see DescribeCameraFileOmission).
  if (CameraModelIsFisheye(model)) return true;
  return Fail(std::string("the kalibr format cannot hold a ") +
                  CameraModelName(model) +
                  " camera (its camchain has pinhole-radtan with k3 = 0 and "
                  "kannala-brandt only): choose one of those models, or the "
                  "opencv or ros format",
              error);
}

double FarFieldErrorPx(const Camera& camera, double distance_m,
                       double max_field_angle_deg) {
  if (CameraModelIsCentral(camera.model) || !(distance_m > 0)) return 0;
  const Camera far = FarFieldCamera(camera);
  const double max_angle = max_field_angle_deg > 0
                               ? max_field_angle_deg * M_PI / 180.0
                               : std::numeric_limits<double>::infinity();
  double worst = 0;
  auto visit = [&](double x, double y) {
    const Eigen::Vector2d pixel(x, y);
    ViewingRay ray;
    if (!camera.UnprojectRay(pixel, &ray).converged) return;
    const Eigen::Vector3d& d = ray.direction;
    if (!(std::atan2(d.head<2>().norm(), d.z()) <= max_angle)) return;
    // The point on the ray at distance_m from the camera origin.
    const double b = ray.origin.dot(d);
    const double disc =
        b * b - ray.origin.squaredNorm() + distance_m * distance_m;
    if (!(disc >= 0)) return;
    const Eigen::Vector3d point = ray.origin + (-b + std::sqrt(disc)) * d;
    Eigen::Vector2d seen;
    if (!camera.Project(point, &seen) || !far.Project(point, &seen)) return;
    worst = std::max(worst, (seen - pixel).norm());
  };
  constexpr int kStep = 8;
  for (int y = 0; y < camera.height; y += kStep) {
    for (int x = 0; x < camera.width; x += kStep) visit(x, y);
    visit(camera.width - 1, y);
  }
  for (int x = 0; x < camera.width; x += kStep) visit(x, camera.height - 1);
  visit(camera.width - 1, camera.height - 1);
  return worst;
}

Camera CameraForFormat(const Camera& camera, CameraFileFormat format,
                       const CameraFileStats& stats, CameraFitReport* fit) {
  CameraFitReport report;
  if (format == CameraFileFormat::kPuzzlecal) return camera;
  const Camera far = FarFieldCamera(camera);
  if (!CameraModelIsSplined(far.model)) return far;
  CameraFitOptions options;
  // The observed field, or else the circle the spline's grid covers.
  options.max_field_angle_deg =
      stats.max_field_angle_deg > 0
          ? stats.max_field_angle_deg
          : far.params[KannalaBrandtSplinedModel::kGridRadiusIndex] * 180 /
                M_PI;
  const Camera fitted = FitCameraModel(far, CameraModelId::kKannalaBrandt,
                                       options, fit != nullptr ? fit : &report);
  return fitted;
}

CameraFileOmission DescribeCameraFileOmission(const Camera& camera,
                                              CameraFileFormat format,
                                              const CameraFileStats& stats) {
  CameraFileOmission omission;
  if (format == CameraFileFormat::kPuzzlecal ||
      (CameraModelIsCentral(camera.model) &&
       !CameraModelIsSplined(camera.model)) ||
      static_cast<int>(camera.params.size()) !=
          CameraModelNumParams(camera.model)) {
    return omission;
  }
  omission.lossy = true;
  const Camera far = FarFieldCamera(camera);
  const std::vector<std::string> names = CameraModelParamNames(camera.model);
  char buffer[160];
  for (size_t k = far.params.size(); k < names.size(); ++k) {
    std::snprintf(buffer, sizeof(buffer), "%s%s = %.6g m",
                  omission.left_out.empty() ? "" : ", ", names[k].c_str(),
                  camera.params[k]);
    omission.left_out += buffer;
  }
  omission.distance_m = stats.closest_board_distance_m;
  omission.max_field_angle_deg = stats.max_field_angle_deg;
  std::string note = std::string("the ") + CameraFileFormatName(format) +
                     " format has no " + CameraModelName(camera.model) +
                     " model: it holds ";
  if (CameraModelIsSplined(camera.model)) {
    CameraFitReport fit;
    omission.held = CameraForFormat(camera, format, stats, &fit);
    omission.fitted = fit.ok;
    omission.fit_rms_px = fit.rms_px;
    omission.fit_max_px = fit.max_px;
    if (fit.ok) {
      std::snprintf(buffer, sizeof(buffer),
                    "the best-fitting kannala-brandt, off from the splined "
                    "far-field projection by up to %.2f px (RMS %.2f px)",
                    fit.max_px, fit.rms_px);
    } else {
      std::snprintf(buffer, sizeof(buffer),
                    "kannala-brandt's part of it without the spline (no "
                    "kannala-brandt could be fitted: %s)",
                    fit.error.c_str());
    }
    note += buffer;
    if (omission.max_field_angle_deg > 0) {
      std::snprintf(buffer, sizeof(buffer), " over field angles up to %.0f deg",
                    omission.max_field_angle_deg);
      note += buffer;
    }
    if (CameraModelIsCentral(camera.model)) {
      omission.note = note;
      return omission;
    }
    note += ", and";
  } else {
    omission.held = far;
    note +=
        std::string("the far-field part (") + CameraModelName(far.model) + ")";
  }
  note += " without the entrance pupil shift " + omission.left_out;
  if (omission.distance_m > 0) {
    omission.max_error_px = FarFieldErrorPx(camera, omission.distance_m,
                                            omission.max_field_angle_deg);
    std::snprintf(buffer, sizeof(buffer),
                  "; for points %.3g m away it is off by up to %.2f px",
                  omission.distance_m, omission.max_error_px);
    note += buffer;
    if (omission.distance_m < 1.0) {
      std::snprintf(buffer, sizeof(buffer), ", %.2f px at 1 m",
                    FarFieldErrorPx(camera, 1.0, omission.max_field_angle_deg));
      note += buffer;
    }
    if (omission.max_field_angle_deg > 0) {
      std::snprintf(buffer, sizeof(buffer), " (field angles up to %.0f deg)",
                    omission.max_field_angle_deg);
      note += buffer;
    }
  }
  omission.note = note;
  return omission;
}

namespace {

// `text` as comment lines ("# " before each of its lines).
std::string CommentLines(const std::string& text) {
  std::string comment;
  size_t begin = 0;
  while (begin <= text.size()) {
    size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    comment += "# " + text.substr(begin, end - begin) + "\n";
    begin = end + 1;
  }
  return comment;
}

// The text of `camera` in `format`, nothing added.
bool FormatBody(const Camera& camera, const CameraFileStats& stats,
                CameraFileFormat format, std::string* text, std::string* error,
                const CameraFileNames& names) {
  switch (format) {
    case CameraFileFormat::kPuzzlecal:
      *text = camera_file::FormatPuzzlecal(camera, stats);
      return true;
    case CameraFileFormat::kOpenCv:
      *text = camera_file::FormatOpenCv(camera);
      return true;
    case CameraFileFormat::kRos:
      *text = camera_file::FormatRos(camera, names.camera_name);
      return true;
    case CameraFileFormat::kKalibr:
      return camera_file::FormatKalibr(camera, names.rostopic, text, error);
  }
  return Fail("unknown camera file format", error);
}

// The file's text for `camera` whose omission in `format` is `omission`
// (DescribeCameraFileOmission, computed once: a splined camera's costs a
// fit), a camera CheckCamera accepts: when lossy, the camera the format holds
// (omission.held). The opencv, ros and kalibr formats have no field for the
// verdict or for what is missing: comment lines at the top carry them (the
// readers of these formats skip comments), after OpenCV's "%YAML:1.0" line,
// which must come first. The puzzlecal format has a `verdict` field.
bool FormatWithOmission(const Camera& camera, const CameraFileStats& stats,
                        CameraFileFormat format,
                        const CameraFileOmission& omission, std::string* text,
                        std::string* error, const CameraFileNames& names) {
  std::string body;
  if (omission.lossy) {
    if (!CheckCamera(omission.held, error) ||
        !FormatBody(omission.held, stats, format, &body, error, names)) {
      return false;
    }
  } else if (!FormatBody(camera, stats, format, &body, error, names)) {
    return false;
  }
  std::string comment;
  if (format != CameraFileFormat::kPuzzlecal && !stats.verdict.empty()) {
    comment += CommentLines(stats.verdict);
  }
  if (omission.lossy) comment += CommentLines(omission.note);
  const size_t line_end = body.find('\n');
  if (format == CameraFileFormat::kOpenCv && body.rfind("%YAML", 0) == 0 &&
      line_end != std::string::npos) {
    *text = body.substr(0, line_end + 1) + comment + body.substr(line_end + 1);
  } else {
    *text = comment + body;
  }
  return true;
}

}  // namespace

bool FormatCameraFile(const Camera& camera, const CameraFileStats& stats,
                      CameraFileFormat format, std::string* text,
                      std::string* error, const CameraFileNames& names) {
  if (!CheckCamera(camera, error)) return false;
  return FormatWithOmission(camera, stats, format,
                            DescribeCameraFileOmission(camera, format, stats),
                            text, error, names);
}

bool WriteCameraFile(const std::string& path, CameraFileFormat format,
                     const Camera& camera, const CameraFileStats& stats,
                     std::string* error, std::string* note,
                     const CameraFileNames& names) {
  std::string text, why;
  const bool valid = CheckCamera(camera, &why);
  const CameraFileOmission omission =
      valid ? DescribeCameraFileOmission(camera, format, stats)
            : CameraFileOmission();
  if (!valid || !FormatWithOmission(camera, stats, format, omission, &text,
                                    &why, names)) {
    return Fail("cannot write '" + path + "' (" + CameraFileFormatName(format) +
                    " format): " + why,
                error);
  }
  if (!WriteFileAtomically(path, text, error)) return false;
  if (note != nullptr) *note = omission.note;
  return true;
}

CalibrationRange MeasureCalibrationRange(
    const std::vector<CalibrationView>& views,
    const CalibrationResult& result) {
  CalibrationRange range;
  double closest = std::numeric_limits<double>::infinity();
  double widest = 0;
  for (size_t v = 0; v < views.size() && v < result.view_used.size(); ++v) {
    if (!result.view_used[v] || v >= result.cam_from_board.size()) continue;
    for (size_t i = 0; i < views[v].board_points.size(); ++i) {
      if (v < result.inlier.size() && i < result.inlier[v].size() &&
          !result.inlier[v][i]) {
        continue;
      }
      const Eigen::Vector3d p =
          result.cam_from_board[v] * views[v].board_points[i];
      if (!p.allFinite()) continue;
      closest = std::min(closest, p.norm());
      widest = std::max(widest, std::atan2(p.head<2>().norm(), p.z()));
    }
  }
  if (std::isfinite(closest)) {
    range.closest_board_distance_m = closest;
    range.max_field_angle_deg = widest * 180.0 / M_PI;
  }
  return range;
}

CameraFileStats CalibrationFileStats(const CalibrationResult& result,
                                     const std::vector<CalibrationView>& views,
                                     const std::vector<std::string>& view_files,
                                     const Eigen::Vector3d& first_corner_m,
                                     const std::string& verdict_line) {
  CameraFileStats stats =
      CameraFileStatsOfResult(result, view_files, first_corner_m);
  stats.verdict = verdict_line;
  const CalibrationRange range = MeasureCalibrationRange(views, result);
  stats.closest_board_distance_m = range.closest_board_distance_m;
  stats.max_field_angle_deg = range.max_field_angle_deg;
  return stats;
}

CameraFileStats CameraFileStatsOfResult(
    const CalibrationResult& result, const std::vector<std::string>& view_files,
    const Eigen::Vector3d& first_corner_m) {
  CameraFileStats stats;
  stats.has_stats = true;
  stats.param_stddev = result.param_stddev;
  if (result.covariance_ok) stats.covariance = result.covariance;
  stats.rms_px = result.rms_px;
  stats.num_views_used = result.num_views_used;
  stats.num_corners_used = result.num_corners_used;
  stats.num_outliers = result.num_outliers;
  for (size_t v = 0; v < result.view_used.size(); ++v) {
    if (!result.view_used[v]) continue;
    CameraFileView view;
    view.file = v < view_files.size() ? view_files[v] : "";
    // P_cam = R (P_file + c) + t with P_file = P_board - c.
    view.cam_from_board = result.cam_from_board[v];
    view.cam_from_board.translation() +=
        result.cam_from_board[v].linear() * first_corner_m;
    if (v < result.view_rms_px.size()) view.rms_px = result.view_rms_px[v];
    if (v < result.inlier.size()) {
      view.corners = static_cast<int>(
          std::count(result.inlier[v].begin(), result.inlier[v].end(), true));
    }
    stats.views.push_back(view);
  }
  return stats;
}

bool WriteCameraFile(const std::string& path, CameraFileFormat format,
                     const CalibrationResult& result, std::string* error,
                     const CalibrationRange& range, std::string* note,
                     const CameraFileNames& names) {
  CameraFileStats stats;
  stats.has_stats = true;
  stats.param_stddev = result.param_stddev;
  if (result.covariance_ok) stats.covariance = result.covariance;
  stats.rms_px = result.rms_px;
  stats.num_views_used = result.num_views_used;
  stats.num_corners_used = result.num_corners_used;
  stats.num_outliers = result.num_outliers;
  stats.closest_board_distance_m = range.closest_board_distance_m;
  stats.max_field_angle_deg = range.max_field_angle_deg;
  return WriteCameraFile(path, format, result.camera, stats, error, note,
                         names);
}

bool ParseCameraFile(const std::string& text, const std::string& source,
                     Camera* camera, CameraFileFormat* format,
                     std::string* error, CameraFileStats* stats) {
  YAML::Node root;
  bool opencv_header = false;
  if (!ParseCameraText(text, source, &root, &opencv_header, error)) {
    return false;
  }
  if (!root.IsMap()) {
    return Fail(source + ": not a camera file (expected a YAML map)", error);
  }
  FieldReader reader(source, error);
  try {
    Camera parsed;
    CameraFileFormat found;
    CameraFileStats read;
    if (!ParseCameraNode(root, "", opencv_header, &reader, &parsed, &found) ||
        (stats != nullptr && found == CameraFileFormat::kPuzzlecal &&
         !camera_file::ParseStats(root, parsed, reader, &read))) {
      return false;
    }
    *camera = parsed;
    if (format != nullptr) *format = found;
    if (stats != nullptr) *stats = read;
    return true;
  } catch (const YAML::Exception& e) {
    return Fail(source + ": " + e.what(), error);
  }
}

bool ReadCameraFile(const std::string& path, Camera* camera, std::string* error,
                    CameraFileStats* stats) {
  std::string text;
  if (!ReadTextFile(path, &text, error)) return false;
  return ParseCameraFile(text, path, camera, nullptr, error, stats);
}

bool ReadCameraFileViews(const std::string& path,
                         std::vector<CameraFileView>* views,
                         std::string* error) {
  std::string text;
  YAML::Node root;
  bool opencv_header = false;
  if (!ReadTextFile(path, &text, error) ||
      !ParseCameraText(text, path, &root, &opencv_header, error)) {
    return false;
  }
  if (!root.IsMap()) return Fail(path + ": not a camera file", error);
  FieldReader reader(path, error);
  try {
    return camera_file::ParseViews(root, reader, views);
  } catch (const YAML::Exception& e) {
    return Fail(path + ": " + e.what(), error);
  }
}

}  // namespace puzzlecal
