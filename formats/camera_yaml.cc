#include "formats/camera_yaml.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "formats/yaml_emit.h"
#include "util/atomic_file.h"
#include "util/enum_names.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

constexpr const char* kPuzzlecalFormatTag = "puzzlecal-camera";

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
    out << YAML::Key << "rms_px" << YAML::Value << stats.rms_px;
    out << YAML::Key << "views_used" << YAML::Value << stats.num_views_used;
    out << YAML::Key << "corners_used" << YAML::Value << stats.num_corners_used;
    out << YAML::Key << "outliers" << YAML::Value << stats.num_outliers;
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

// Key of a kannala-brandt camera's coefficients in the opencv format.
constexpr char kOpenCvFisheyeKey[] = "fisheye_distortion_coefficients";

// OpenCV's FileStorage wants "%YAML:1.0" and its own matrix tag.
std::string FormatOpenCv(const Camera& camera) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "model" << YAML::Value << CameraModelName(camera.model);
  out << YAML::Key << "image_width" << YAML::Value << camera.width;
  out << YAML::Key << "image_height" << YAML::Value << camera.height;
  EmitOpenCvMatrix(out, "camera_matrix", 3, 3,
                   RowMajor(CameraMatrixOf(camera)));
  const std::vector<double> distortion = DistortionOf(camera);
  // A fisheye's k1..k4 under OpenCV's usual key would be read as pinhole
  // k1 k2 p1 p2 by cv::undistort and friends; its own key (the D of
  // cv::fisheye) makes pinhole readers fail loudly instead.
  const bool fisheye = CameraModelIsFisheye(camera.model);
  if (fisheye) {
    out << YAML::Key << "distortion_model" << YAML::Value << "fisheye";
  }
  EmitOpenCvMatrix(out, fisheye ? kOpenCvFisheyeKey : "distortion_coefficients",
                   1, static_cast<int>(distortion.size()), distortion);
  out << YAML::EndMap;
  return std::string("%YAML:1.0\n---\n") + out.c_str() + "\n";
}

std::string FormatRos(const Camera& camera, const std::string& camera_name) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  const auto& p = camera.params;
  out << YAML::BeginMap;
  out << YAML::Key << "image_width" << YAML::Value << camera.width;
  out << YAML::Key << "image_height" << YAML::Value << camera.height;
  out << YAML::Key << "camera_name" << YAML::Value << camera_name;
  EmitRosMatrix(out, "camera_matrix", 3, 3, RowMajor(CameraMatrixOf(camera)));
  out << YAML::Key << "distortion_model" << YAML::Value
      << RosDistortionModel(camera.model);
  const std::vector<double> distortion = DistortionOf(camera);
  EmitRosMatrix(out, "distortion_coefficients", 1,
                static_cast<int>(distortion.size()), distortion);
  EmitRosMatrix(out, "rectification_matrix", 3, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  EmitRosMatrix(out, "projection_matrix", 3, 4,
                {p[0], 0, p[2], 0, 0, p[1], p[3], 0, 0, 0, 1, 0});
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

bool FormatKalibr(const Camera& camera, const std::string& rostopic,
                  std::string* text, std::string* error) {
  const auto& p = camera.params;
  std::vector<double> coeffs;
  const char* model = "radtan";
  switch (camera.model) {
    case CameraModelId::kPinholeRational:
      for (int k = 8; k < 12; ++k) {
        if (p[k] != 0) {
          return Fail("kalibr has no rational distortion model (k" +
                          std::to_string(k - 5) + " = " + std::to_string(p[k]) +
                          "): write the opencv or ros format, or calibrate "
                          "pinhole-radtan with --format kalibr (k3 held at 0)",
                      error);
        }
      }
      [[fallthrough]];
    case CameraModelId::kPinholeRadtan:
      if (p[8] != 0) {
        return Fail(
            "kalibr's radtan model has no k3 (k3 = " + std::to_string(p[8]) +
                "): write the opencv or ros format, or calibrate "
                "with --format kalibr (k3 held at 0)",
            error);
      }
      coeffs = {p[4], p[5], p[6], p[7]};
      break;
    case CameraModelId::kKannalaBrandt:
    case CameraModelId::kKannalaBrandtNoncentral:  // its far-field part
      model = "equidistant";
      coeffs = {p[4], p[5], p[6], p[7]};
      break;
  }
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap << YAML::Key << "cam0" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "camera_model" << YAML::Value << "pinhole";
  out << YAML::Key << "intrinsics" << YAML::Value;
  EmitFlow(out, {p[0], p[1], p[2], p[3]});
  out << YAML::Key << "distortion_model" << YAML::Value << model;
  out << YAML::Key << "distortion_coeffs" << YAML::Value;
  EmitFlow(out, coeffs);
  out << YAML::Key << "resolution" << YAML::Value << YAML::Flow
      << YAML::BeginSeq << camera.width << camera.height << YAML::EndSeq;
  out << YAML::Key << "rostopic" << YAML::Value << rostopic;
  out << YAML::EndMap << YAML::EndMap;
  *text = std::string(out.c_str()) + "\n";
  return true;
}

// ---- reading ----

constexpr Presence kRequired = Presence::kRequired;

void ResetCamera(CameraModelId id, Camera* camera) {
  camera->model = id;
  camera->params.assign(CameraModelNumParams(id), 0.0);
}

bool ReadModel(const YAML::Node& map, const std::string& path, FieldReader& r,
               CameraModelId* id) {
  std::string name;
  if (!r.String(map, path, "model", kRequired, &name)) return false;
  if (!CameraModelIdFromName(name, id)) {
    return r.Fail(
        FieldReader::Join(path, "model"),
        "unknown model '" + name + "' (known: " + CameraModelNames() + ")");
  }
  return true;
}

bool ReadImageSize(const YAML::Node& map, const std::string& path,
                   FieldReader& r, Camera* camera) {
  if (!r.Int(map, path, "image_width", kRequired, &camera->width) ||
      !r.Int(map, path, "image_height", kRequired, &camera->height)) {
    return false;
  }
  if (camera->width <= 0) {
    return r.Fail(FieldReader::Join(path, "image_width"), "must be positive");
  }
  if (camera->height <= 0) {
    return r.Fail(FieldReader::Join(path, "image_height"), "must be positive");
  }
  return true;
}

// fx fy cx cy from a row-major 3x3 camera matrix.
bool SetIntrinsics(const std::vector<double>& k, const std::string& field,
                   FieldReader& r, Camera* camera) {
  if (k[1] != 0) return r.Fail(field, "skew is not supported");
  if (!(k[0] > 0) || !(k[4] > 0)) {
    return r.Fail(field, "focal lengths must be positive");
  }
  camera->params[0] = k[0];
  camera->params[1] = k[4];
  camera->params[2] = k[2];
  camera->params[3] = k[5];
  return true;
}

// Distortion coefficients into camera->params (zero-padded where the
// format allows shorter lists).
bool SetDistortion(const std::vector<double>& d, const std::string& field,
                   size_t min_count, FieldReader& r, Camera* camera) {
  const size_t count = camera->params.size() - kDistortionBegin;
  if (d.size() < min_count || d.size() > count) {
    return r.Fail(field,
                  std::string("expected ") +
                      (min_count == count ? std::to_string(count)
                                          : std::to_string(min_count) + " to " +
                                                std::to_string(count)) +
                      " coefficients for " + CameraModelName(camera->model) +
                      ", got " + std::to_string(d.size()));
  }
  for (size_t i = 0; i < d.size(); ++i) {
    camera->params[kDistortionBegin + i] = d[i];
  }
  return true;
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

bool ParseOpenCvOrRos(const YAML::Node& map, const std::string& path, bool ros,
                      FieldReader& r, Camera* camera) {
  CameraModelId id = CameraModelId::kPinholeRadtan;
  std::vector<double> k, d;
  if (!r.Matrix(map, path, "camera_matrix", kRequired, 3, 3, &k)) {
    return false;
  }
  const std::string distortion_key = !ros && map[kOpenCvFisheyeKey]
                                         ? kOpenCvFisheyeKey
                                         : "distortion_coefficients";
  const std::string distortion_field = FieldReader::Join(path, distortion_key);
  if (!r.Matrix(map, path, distortion_key, kRequired, 0, 0, &d)) return false;
  if (ros) {
    std::string model;
    if (!r.String(map, path, "distortion_model", kRequired, &model)) {
      return false;
    }
    if (model == "plumb_bob") {
      id = CameraModelId::kPinholeRadtan;
    } else if (model == "rational_polynomial") {
      id = CameraModelId::kPinholeRational;
    } else if (model == "equidistant" || model == "fisheye") {
      id = CameraModelId::kKannalaBrandt;
    } else {
      return r.Fail(FieldReader::Join(path, "distortion_model"),
                    "unknown model '" + model +
                        "' (known: plumb_bob, rational_polynomial, "
                        "equidistant)");
    }
  } else if (map["model"]) {
    if (!ReadModel(map, path, r, &id)) return false;
    if (CameraModelIsFisheye(id) != (distortion_key == kOpenCvFisheyeKey)) {
      return r.Fail(
          distortion_field,
          std::string("model ") + CameraModelName(id) +
              (CameraModelIsFisheye(id) ? " keeps its coefficients under "
                                        : " cannot use ") +
              kOpenCvFisheyeKey);
    }
  } else if (distortion_key == kOpenCvFisheyeKey) {
    id = CameraModelId::kKannalaBrandt;
  } else {
    // OpenCV's own files carry no model: tell it by the number of
    // coefficients (4 or 5: plumb_bob, 8: rational).
    if (d.size() == 8)
      id = CameraModelId::kPinholeRational;
    else if (d.size() == 4 || d.size() == 5)
      id = CameraModelId::kPinholeRadtan;
    else {
      return r.Fail(distortion_field,
                    std::to_string(d.size()) +
                        " coefficients without a 'model' field (expected 4, "
                        "5 or 8)");
    }
  }
  ResetCamera(id, camera);
  if (!ReadImageSize(map, path, r, camera)) return false;
  if (!SetIntrinsics(k, FieldReader::Join(path, "camera_matrix.data"), r,
                     camera)) {
    return false;
  }
  const size_t count = camera->params.size() - kDistortionBegin;
  // plumb_bob may omit k3; the other models need all coefficients.
  const size_t min_count = id == CameraModelId::kPinholeRadtan ? 4 : count;
  return SetDistortion(d, FieldReader::Join(distortion_field, "data"),
                       min_count, r, camera);
}

bool ParseKalibr(const YAML::Node& map, const std::string& path, FieldReader& r,
                 Camera* camera) {
  YAML::Node cam;
  if (!r.Child(map, path, "cam0", kRequired, &cam)) return false;
  const std::string cam_path = FieldReader::Join(path, "cam0");
  std::string camera_model, distortion_model;
  if (!r.String(cam, cam_path, "camera_model", kRequired, &camera_model)) {
    return false;
  }
  if (camera_model != "pinhole") {
    return r.Fail(FieldReader::Join(cam_path, "camera_model"),
                  "only 'pinhole' is supported, got '" + camera_model + "'");
  }
  if (!r.String(cam, cam_path, "distortion_model", kRequired,
                &distortion_model)) {
    return false;
  }
  CameraModelId id;
  if (distortion_model == "radtan") {
    id = CameraModelId::kPinholeRadtan;
  } else if (distortion_model == "equidistant") {
    id = CameraModelId::kKannalaBrandt;
  } else {
    return r.Fail(FieldReader::Join(cam_path, "distortion_model"),
                  "unknown model '" + distortion_model +
                      "' (known: radtan, equidistant)");
  }
  ResetCamera(id, camera);
  std::vector<double> intrinsics, coeffs, resolution;
  if (!r.Doubles(cam, cam_path, "intrinsics", kRequired, 4, &intrinsics)) {
    return false;
  }
  if (!(intrinsics[0] > 0) || !(intrinsics[1] > 0)) {
    return r.Fail(FieldReader::Join(cam_path, "intrinsics"),
                  "focal lengths must be positive");
  }
  for (int k = 0; k < 4; ++k) camera->params[k] = intrinsics[k];
  if (!r.Doubles(cam, cam_path, "distortion_coeffs", kRequired, 4, &coeffs)) {
    return false;
  }
  for (int k = 0; k < 4; ++k) camera->params[kDistortionBegin + k] = coeffs[k];
  if (!r.Doubles(cam, cam_path, "resolution", kRequired, 2, &resolution)) {
    return false;
  }
  // Whole numbers in a sane range before the cast (a double beyond int's
  // range would make it undefined).
  if (!std::all_of(resolution.begin(), resolution.end(), [](double v) {
        return v >= 1 && v <= 1e6 && v == std::floor(v);
      })) {
    return r.Fail(FieldReader::Join(cam_path, "resolution"),
                  "must be [width, height], whole numbers in [1, 1000000]");
  }
  camera->width = static_cast<int>(resolution[0]);
  camera->height = static_cast<int>(resolution[1]);
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
    ok = ParsePuzzlecal(node, path, r, &parsed);
  } else if (node["cam0"]) {
    found = CameraFileFormat::kKalibr;
    ok = ParseKalibr(node, path, r, &parsed);
  } else if (node["distortion_model"] && !opencv_header) {
    found = CameraFileFormat::kRos;
    ok = ParseOpenCvOrRos(node, path, /*ros=*/true, r, &parsed);
  } else if (opencv_header || node["camera_matrix"]) {
    found = CameraFileFormat::kOpenCv;
    ok = ParseOpenCvOrRos(node, path, /*ros=*/false, r, &parsed);
  } else {
    return r.Fail(path,
                  "not a camera file in any known format (puzzlecal, opencv, "
                  "ros, kalibr): no 'parameters', 'camera_matrix' or 'cam0'");
  }
  if (!ok) return false;
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
  if (model == CameraModelId::kKannalaBrandt ||
      model == CameraModelId::kKannalaBrandtNoncentral) {
    return true;
  }
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

CameraFileOmission DescribeCameraFileOmission(const Camera& camera,
                                              CameraFileFormat format,
                                              const CameraFileStats& stats) {
  CameraFileOmission omission;
  if (format == CameraFileFormat::kPuzzlecal ||
      CameraModelIsCentral(camera.model) ||
      static_cast<int>(camera.params.size()) !=
          CameraModelNumParams(camera.model)) {
    return omission;
  }
  omission.lossy = true;
  const Camera far = FarFieldCamera(camera);
  const std::vector<std::string> names = CameraModelParamNames(camera.model);
  char buffer[96];
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
                     " model: it holds the far-field part (" +
                     CameraModelName(far.model) +
                     ") without the entrance pupil shift " + omission.left_out;
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

bool FormatCameraFile(const Camera& camera, const CameraFileStats& stats,
                      CameraFileFormat format, std::string* text,
                      std::string* error, const CameraFileNames& names) {
  if (!CheckCamera(camera, error)) return false;
  const CameraFileOmission omission =
      DescribeCameraFileOmission(camera, format, stats);
  if (omission.lossy) {
    // The far-field part in the format, and a comment that says what is
    // missing (after OpenCV's "%YAML:1.0" line, which must come first).
    std::string body;
    if (!FormatCameraFile(FarFieldCamera(camera), stats, format, &body, error,
                          names)) {
      return false;
    }
    const std::string comment = "# " + omission.note + "\n";
    const size_t line_end = body.find('\n');
    if (format == CameraFileFormat::kOpenCv && body.rfind("%YAML", 0) == 0 &&
        line_end != std::string::npos) {
      *text =
          body.substr(0, line_end + 1) + comment + body.substr(line_end + 1);
    } else {
      *text = comment + body;
    }
    return true;
  }
  switch (format) {
    case CameraFileFormat::kPuzzlecal:
      *text = FormatPuzzlecal(camera, stats);
      return true;
    case CameraFileFormat::kOpenCv:
      *text = FormatOpenCv(camera);
      return true;
    case CameraFileFormat::kRos:
      *text = FormatRos(camera, names.camera_name);
      return true;
    case CameraFileFormat::kKalibr:
      return FormatKalibr(camera, names.rostopic, text, error);
  }
  return Fail("unknown camera file format", error);
}

bool WriteCameraFile(const std::string& path, CameraFileFormat format,
                     const Camera& camera, const CameraFileStats& stats,
                     std::string* error, std::string* note,
                     const CameraFileNames& names) {
  std::string text, why;
  if (!FormatCameraFile(camera, stats, format, &text, &why, names)) {
    return Fail("cannot write '" + path + "' (" + CameraFileFormatName(format) +
                    " format): " + why,
                error);
  }
  if (!WriteFileAtomically(path, text, error)) return false;
  if (note != nullptr) {
    *note = DescribeCameraFileOmission(camera, format, stats).note;
  }
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
                     std::string* error) {
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
    return ParseCameraNode(root, "", opencv_header, &reader, camera, format);
  } catch (const YAML::Exception& e) {
    return Fail(source + ": " + e.what(), error);
  }
}

bool ReadCameraFile(const std::string& path, Camera* camera,
                    std::string* error) {
  std::string text;
  if (!ReadTextFile(path, &text, error)) return false;
  return ParseCameraFile(text, path, camera, nullptr, error);
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
    return ParseViews(root, reader, views);
  } catch (const YAML::Exception& e) {
    return Fail(path + ": " + e.what(), error);
  }
}

}  // namespace puzzlecal
