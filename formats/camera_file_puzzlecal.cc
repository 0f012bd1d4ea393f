// The puzzlecal camera format: the model by name, the parameters by name
// with their 1-sigma, the calibration's statistics, views and verdict.

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "formats/camera_file_formats.h"
#include "formats/yaml_emit.h"
#include "formats/yaml_fields.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

constexpr const char* kPuzzlecalFormatTag = "puzzlecal-camera";
// One entry of the puzzlecal format's `views`.
void EmitView(const CameraFileView& view, YAML::Emitter& out) {
  out << YAML::BeginMap;
  out << YAML::Key << "file" << YAML::Value << view.file;
  out << YAML::Key << "cam_from_board" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "R" << YAML::Value;
  EmitRows(out, view.cam_from_board.linear());
  out << YAML::Key << "t" << YAML::Value;
  EmitFlow(out, RowMajor(view.cam_from_board.translation()));
  out << YAML::EndMap;
  out << YAML::Key << "rms_px" << YAML::Value << view.rms_px;
  out << YAML::Key << "corners" << YAML::Value << view.corners;
  out << YAML::EndMap;
}

}  // namespace

namespace camera_file {

std::string FormatPuzzlecal(const Camera& camera,
                            const CameraFileStats& stats) {
  const std::vector<std::string> names = CameraModelParamNames(camera.model);
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << kPuzzlecalFormatTag;
  out << YAML::Key << "model" << YAML::Value << CameraModelName(camera.model);
  out << YAML::Key << "image_width" << YAML::Value << camera.width;
  out << YAML::Key << "image_height" << YAML::Value << camera.height;
  EmitNamedValues(out, "parameters", names, camera.params);
  if (stats.has_stats) {
    if (stats.param_stddev.size() == names.size()) {
      EmitNamedValues(out, "parameter_stddev", names, stats.param_stddev);
    }
    const Eigen::Index n = static_cast<Eigen::Index>(names.size());
    if (stats.covariance.rows() == n && stats.covariance.cols() == n) {
      out << YAML::Key << "parameter_covariance" << YAML::Value;
      EmitRows(out, stats.covariance);
    }
    out << YAML::Key << "rms_px" << YAML::Value << stats.rms_px;
    out << YAML::Key << "views_used" << YAML::Value << stats.num_views_used;
    out << YAML::Key << "corners_used" << YAML::Value << stats.num_corners_used;
    out << YAML::Key << "outliers" << YAML::Value << stats.num_outliers;
    if (stats.max_field_angle_deg > 0) {
      out << YAML::Key << "max_field_angle_deg" << YAML::Value
          << stats.max_field_angle_deg;
    }
    if (!stats.verdict.empty()) {
      out << YAML::Key << "verdict" << YAML::Value << stats.verdict;
    }
    if (!stats.views.empty()) {
      out << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
      for (const CameraFileView& view : stats.views) EmitView(view, out);
      out << YAML::EndSeq;
    }
  }
  out << YAML::EndMap;
  return std::string("# puzzlecal camera calibration\n") + out.c_str() + "\n";
}
bool ParsePuzzlecal(const YAML::Node& map, const std::string& path,
                    FieldReader& r, Camera* camera) {
  CameraModelId id;
  if (!ReadModel(map, path, r, &id)) return false;
  ResetCamera(id, camera);
  if (!ReadImageSize(map, path, r, camera)) return false;
  YAML::Node params;
  if (!r.Child(map, path, "parameters", kRequired, &params)) return false;
  const std::string params_path = FieldReader::Join(path, "parameters");
  const std::vector<std::string> names = CameraModelParamNames(id);
  for (size_t k = 0; k < names.size(); ++k) {
    if (!r.Double(params, params_path, names[k], kRequired,
                  &camera->params[k])) {
      return false;
    }
  }
  if (!(camera->params[0] > 0) || !(camera->params[1] > 0)) {
    return r.Fail(FieldReader::Join(params_path, "fx"),
                  "focal lengths must be positive");
  }
  return true;
}
bool ParseViews(const YAML::Node& root, FieldReader& r,
                std::vector<CameraFileView>* views) {
  views->clear();
  YAML::Node list;
  if (!r.List(root, "", "views", Presence::kOptional, &list)) return false;
  for (size_t v = 0; v < list.size(); ++v) {
    const std::string path = FieldReader::Index("views", v);
    const std::string pose_path = FieldReader::Join(path, "cam_from_board");
    CameraFileView view;
    YAML::Node pose;
    Eigen::Matrix3d rotation;
    std::vector<double> t;
    if (!r.String(list[v], path, "file", kRequired, &view.file) ||
        !r.Child(list[v], path, "cam_from_board", kRequired, &pose) ||
        !r.Rows3x3(pose, pose_path, "R", kRequired, &rotation)) {
      return false;
    }
    if (!((rotation.transpose() * rotation - Eigen::Matrix3d::Identity())
              .cwiseAbs()
              .maxCoeff() < 1e-6) ||
        !(rotation.determinant() > 0)) {
      return r.Fail(FieldReader::Join(pose_path, "R"), "not a rotation matrix");
    }
    if (!r.Doubles(pose, pose_path, "t", kRequired, 3, &t) ||
        !r.Double(list[v], path, "rms_px", kRequired, &view.rms_px) ||
        !r.Int(list[v], path, "corners", kRequired, &view.corners)) {
      return false;
    }
    view.cam_from_board.linear() = rotation;
    view.cam_from_board.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
    views->push_back(view);
  }
  return true;
}

bool ParseStats(const YAML::Node& root, const Camera& camera, FieldReader& r,
                CameraFileStats* stats) {
  *stats = CameraFileStats();
  if (!root["rms_px"]) return true;
  stats->has_stats = true;
  const std::vector<std::string> names = CameraModelParamNames(camera.model);
  const int n = static_cast<int>(names.size());
  YAML::Node stddev, covariance;
  if (!r.Double(root, "", "rms_px", kRequired, &stats->rms_px) ||
      !r.Int(root, "", "views_used", Presence::kOptional,
             &stats->num_views_used) ||
      !r.Int(root, "", "corners_used", Presence::kOptional,
             &stats->num_corners_used) ||
      !r.Int(root, "", "outliers", Presence::kOptional, &stats->num_outliers) ||
      !r.Double(root, "", "max_field_angle_deg", Presence::kOptional,
                &stats->max_field_angle_deg) ||
      !r.String(root, "", "verdict", Presence::kOptional, &stats->verdict) ||
      !r.Child(root, "", "parameter_stddev", Presence::kOptional, &stddev) ||
      !r.List(root, "", "parameter_covariance", Presence::kOptional,
              &covariance)) {
    return false;
  }
  if (stddev) {
    stats->param_stddev.assign(n, 0.0);
    for (int k = 0; k < n; ++k) {
      if (!r.Double(stddev, "parameter_stddev", names[k], kRequired,
                    &stats->param_stddev[k])) {
        return false;
      }
    }
  }
  if (covariance) {
    const std::string field = "parameter_covariance";
    if (static_cast<int>(covariance.size()) != n) {
      return r.Fail(field, "expected " + std::to_string(n) + " rows for " +
                               CameraModelName(camera.model) + ", got " +
                               std::to_string(covariance.size()));
    }
    stats->covariance.resize(n, n);
    for (int i = 0; i < n; ++i) {
      std::vector<double> row;
      if (!r.Numbers(covariance[i], FieldReader::Index(field, i), n, &row)) {
        return false;
      }
      for (int j = 0; j < n; ++j) stats->covariance(i, j) = row[j];
    }
    const double asymmetry = (stats->covariance - stats->covariance.transpose())
                                 .cwiseAbs()
                                 .maxCoeff();
    if (!(asymmetry <= 1e-9 * stats->covariance.cwiseAbs().maxCoeff()) ||
        !(stats->covariance.diagonal().minCoeff() >= 0)) {
      return r.Fail(field,
                    "not a covariance (symmetric, with a diagonal >= 0)");
    }
  }
  return ParseViews(root, r, &stats->views);
}

}  // namespace camera_file
}  // namespace puzzlecal
