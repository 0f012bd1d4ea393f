#include "formats/rig_yaml.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

#include "formats/yaml_emit.h"
#include "formats/yaml_fields.h"
#include "util/atomic_file.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

constexpr const char* kRigFormatTag = "puzzlecal-rig";

// Every camera must be one a camera file can hold.
bool CheckCameras(const RigCalibrationResult& result, std::string* error) {
  if (result.cameras.size() < 2) {
    return Fail("a rig file needs at least two cameras", error);
  }
  for (const RigCameraResult& cam : result.cameras) {
    std::string text, why;
    if (!FormatCameraFile(cam.camera, CameraFileStats(),
                          CameraFileFormat::kPuzzlecal, &text, &why)) {
      return Fail("camera '" + cam.name + "': " + why, error);
    }
  }
  return true;
}

void EmitJudgement(YAML::Emitter& out, const RigCalibrationResult& result,
                   const RigFileJudgement& judgement) {
  out << YAML::Key << "verdict" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "kind" << YAML::Value << judgement.verdict_kind;
  out << YAML::Key << "reason" << YAML::Value << judgement.verdict_reason;
  out << YAML::Key << "next_step" << YAML::Value << judgement.verdict_next_step;
  out << YAML::EndMap;
  out << YAML::Key << "frames" << YAML::Value << YAML::BeginSeq;
  for (const RigFileFrame& frame : judgement.frames) {
    out << YAML::BeginMap;
    out << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
    for (size_t c = 0; c < result.cameras.size() && c < frame.files.size();
         ++c) {
      out << YAML::BeginMap;
      out << YAML::Key << "name" << YAML::Value << result.cameras[c].name;
      out << YAML::Key << "file" << YAML::Value << frame.files[c];
      out << YAML::Key << "use" << YAML::Value << frame.use[c];
      if (frame.rms_px[c] > 0) {
        out << YAML::Key << "rms_px" << YAML::Value << frame.rms_px[c];
      }
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
    if (frame.compared) {
      out << YAML::Key << "transfer_px" << YAML::Value << frame.transfer_px;
      out << YAML::Key << "pose_difference_mm" << YAML::Value
          << frame.pose_difference_mm;
      out << YAML::Key << "epipolar_px" << YAML::Value << frame.epipolar_px;
      out << YAML::Key << "moved" << YAML::Value << frame.moved;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

std::string FormatPuzzlecal(const RigCalibrationResult& result,
                            const RigFileJudgement* judgement) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << kRigFormatTag;
  out << YAML::Key << "rig_frame" << YAML::Value << result.cameras[0].name;
  out << YAML::Key << "rms_px" << YAML::Value << result.rms_px;
  out << YAML::Key << "frames_used" << YAML::Value << result.num_frames_used;
  out << YAML::Key << "corners_used" << YAML::Value << result.num_corners_used;
  out << YAML::Key << "outliers" << YAML::Value << result.num_outliers;
  out << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
  for (const RigCameraResult& cam : result.cameras) {
    const std::vector<std::string> names =
        CameraModelParamNames(cam.camera.model);
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << cam.name;
    out << YAML::Key << "model" << YAML::Value
        << CameraModelName(cam.camera.model);
    out << YAML::Key << "image_width" << YAML::Value << cam.camera.width;
    out << YAML::Key << "image_height" << YAML::Value << cam.camera.height;
    EmitNamedValues(out, "parameters", names, cam.camera.params);
    if (result.covariance_ok && cam.param_stddev.size() == names.size()) {
      EmitNamedValues(out, "parameter_stddev", names, cam.param_stddev);
    }
    out << YAML::Key << "cam_from_rig" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "R" << YAML::Value;
    EmitRows(out, cam.cam_from_rig.linear(), YAML::Flow);
    out << YAML::Key << "t" << YAML::Value;
    EmitFlow(out, RowMajor(cam.cam_from_rig.translation()));
    out << YAML::EndMap;
    if (result.covariance_ok) {
      out << YAML::Key << "cam_from_rig_stddev" << YAML::Value
          << YAML::BeginMap;
      out << YAML::Key << "rotation_deg" << YAML::Value
          << cam.rotation_stddev_deg;
      out << YAML::Key << "t" << YAML::Value;
      EmitFlow(out, RowMajor(cam.translation_stddev_m));
      out << YAML::EndMap;
    }
    out << YAML::Key << "baseline_mm" << YAML::Value << 1000 * cam.baseline_m;
    if (result.covariance_ok) {
      out << YAML::Key << "baseline_stddev_mm" << YAML::Value
          << 1000 * cam.baseline_stddev_m;
    }
    out << YAML::Key << "rms_px" << YAML::Value << cam.rms_px;
    out << YAML::Key << "frames_used" << YAML::Value << cam.num_frames_used;
    out << YAML::Key << "corners_used" << YAML::Value << cam.num_corners_used;
    out << YAML::Key << "outliers" << YAML::Value << cam.num_outliers;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  if (judgement != nullptr) EmitJudgement(out, result, *judgement);
  out << YAML::EndMap;
  return std::string("# puzzlecal rig calibration\n") + out.c_str() + "\n";
}

bool FormatOpenCv(const RigCalibrationResult& result, std::string* text,
                  std::string* error) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "num_cameras" << YAML::Value
      << static_cast<int>(result.cameras.size());
  for (size_t c = 0; c < result.cameras.size(); ++c) {
    const RigCameraResult& cam = result.cameras[c];
    const std::string n = std::to_string(c + 1);
    out << YAML::Key << "name" + n << YAML::Value << cam.name;
    out << YAML::Key << "model" + n << YAML::Value
        << CameraModelName(cam.camera.model);
    out << YAML::Key << "image_width" + n << YAML::Value << cam.camera.width;
    out << YAML::Key << "image_height" + n << YAML::Value << cam.camera.height;
    EmitOpenCvMatrix(out, "K" + n, 3, 3, RowMajor(CameraMatrixOf(cam.camera)));
    const std::vector<double> d = DistortionOf(cam.camera);
    EmitOpenCvMatrix(out, "D" + n, 1, static_cast<int>(d.size()), d);
  }
  if (result.cameras.size() == 2) {
    const Camera& first = result.cameras[0].camera;
    const Camera& second = result.cameras[1].camera;
    const Eigen::Isometry3d second_from_first =
        result.cameras[1].cam_from_rig *
        result.cameras[0].cam_from_rig.inverse();
    StereoRectification rect;
    if (!StereoRectify(first, second, second_from_first, &rect, error)) {
      return false;
    }
    EmitOpenCvMatrix(out, "R", 3, 3, RowMajor(second_from_first.linear()));
    EmitOpenCvMatrix(out, "T", 3, 1, RowMajor(second_from_first.translation()));
    EmitOpenCvMatrix(out, "E", 3, 3, RowMajor(rect.essential));
    EmitOpenCvMatrix(out, "F", 3, 3, RowMajor(rect.fundamental));
    EmitOpenCvMatrix(out, "R1", 3, 3, RowMajor(rect.r1));
    EmitOpenCvMatrix(out, "R2", 3, 3, RowMajor(rect.r2));
    EmitOpenCvMatrix(out, "P1", 3, 4, RowMajor(rect.p1));
    EmitOpenCvMatrix(out, "P2", 3, 4, RowMajor(rect.p2));
    EmitOpenCvMatrix(out, "Q", 4, 4, RowMajor(rect.q));
    out << YAML::Key << "rectification" << YAML::Value << YAML::DoubleQuoted
        << rect.Summary();
  } else {
    for (size_t c = 1; c < result.cameras.size(); ++c) {
      const Eigen::Isometry3d from_first =
          result.cameras[c].cam_from_rig *
          result.cameras[0].cam_from_rig.inverse();
      const std::string n = std::to_string(c + 1);
      EmitOpenCvMatrix(out, "R" + n, 3, 3, RowMajor(from_first.linear()));
      EmitOpenCvMatrix(out, "T" + n, 3, 1, RowMajor(from_first.translation()));
    }
  }
  out << YAML::EndMap;
  *text = std::string("%YAML:1.0\n---\n") + out.c_str() + "\n";
  return true;
}

std::string FormatRosCamera(const RigCameraResult& cam,
                            const Eigen::Matrix3d& rectification,
                            const Eigen::Matrix<double, 3, 4>& projection,
                            const std::string& note) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "image_width" << YAML::Value << cam.camera.width;
  out << YAML::Key << "image_height" << YAML::Value << cam.camera.height;
  out << YAML::Key << "camera_name" << YAML::Value << cam.name;
  EmitRosMatrix(out, "camera_matrix", 3, 3,
                RowMajor(CameraMatrixOf(cam.camera)));
  out << YAML::Key << "distortion_model" << YAML::Value
      << RosDistortionModel(cam.camera.model);
  const std::vector<double> d = DistortionOf(cam.camera);
  EmitRosMatrix(out, "distortion_coefficients", 1, static_cast<int>(d.size()),
                d);
  EmitRosMatrix(out, "rectification_matrix", 3, 3, RowMajor(rectification));
  EmitRosMatrix(out, "projection_matrix", 3, 4, RowMajor(projection));
  out << YAML::EndMap;
  return (note.empty() ? std::string() : "# rectification: " + note + "\n") +
         out.c_str() + "\n";
}

bool FormatRos(const RigCalibrationResult& result, const std::string& out_path,
               std::vector<RigFileText>* files, std::string* error) {
  namespace fs = std::filesystem;
  const fs::path out(out_path);
  const std::string stem = out.stem().string();
  const std::string extension =
      out.has_extension() ? out.extension().string() : ".yaml";
  std::vector<Eigen::Matrix3d> rect(result.cameras.size(),
                                    Eigen::Matrix3d::Identity());
  std::vector<Eigen::Matrix<double, 3, 4>> proj(result.cameras.size());
  for (size_t c = 0; c < result.cameras.size(); ++c) {
    proj[c].setZero();
    proj[c].leftCols<3>() = CameraMatrixOf(result.cameras[c].camera);
  }
  std::string note;
  if (result.cameras.size() == 2) {
    StereoRectification r;
    if (!StereoRectify(result.cameras[0].camera, result.cameras[1].camera,
                       result.cameras[1].cam_from_rig *
                           result.cameras[0].cam_from_rig.inverse(),
                       &r, error)) {
      return false;
    }
    note = r.Summary();
    rect[0] = r.r1;
    rect[1] = r.r2;
    proj[0] = r.p1;
    proj[1] = r.p2;
  }
  for (size_t c = 0; c < result.cameras.size(); ++c) {
    RigFileText file;
    file.path =
        (out.parent_path() / (stem + "_" + result.cameras[c].name + extension))
            .string();
    file.text = FormatRosCamera(result.cameras[c], rect[c], proj[c], note);
    files->push_back(file);
  }
  return true;
}

bool FormatKalibr(const RigCalibrationResult& result, std::string* text,
                  std::string* error) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  for (size_t c = 0; c < result.cameras.size(); ++c) {
    const RigCameraResult& cam = result.cameras[c];
    // The single-camera writer knows what Kalibr's models can hold.
    std::string single, why;
    if (!FormatCameraFile(cam.camera, CameraFileStats(),
                          CameraFileFormat::kKalibr, &single, &why)) {
      return Fail("camera '" + cam.name + "': " + why, error);
    }
    const auto& p = cam.camera.params;
    out << YAML::Key << "cam" + std::to_string(c) << YAML::Value
        << YAML::BeginMap;
    if (c > 0) {
      const Eigen::Matrix4d t =
          (cam.cam_from_rig * result.cameras[c - 1].cam_from_rig.inverse())
              .matrix();
      out << YAML::Key << "T_cn_cnm1" << YAML::Value;
      EmitRows(out, t);
    }
    out << YAML::Key << "cam_overlaps" << YAML::Value << YAML::Flow
        << YAML::BeginSeq;
    for (size_t o = 0; o < result.cameras.size(); ++o) {
      if (o != c && result.shared_frames(c, o) > 0) out << static_cast<int>(o);
    }
    out << YAML::EndSeq;
    out << YAML::Key << "camera_model" << YAML::Value << "pinhole";
    out << YAML::Key << "intrinsics" << YAML::Value;
    EmitFlow(out, {p[0], p[1], p[2], p[3]});
    out << YAML::Key << "distortion_model" << YAML::Value
        << (cam.camera.model == CameraModelId::kKannalaBrandt ? "equidistant"
                                                              : "radtan");
    out << YAML::Key << "distortion_coeffs" << YAML::Value;
    EmitFlow(out, {p[4], p[5], p[6], p[7]});
    out << YAML::Key << "resolution" << YAML::Value << YAML::Flow
        << YAML::BeginSeq << cam.camera.width << cam.camera.height
        << YAML::EndSeq;
    out << YAML::Key << "rostopic" << YAML::Value
        << "/" + cam.name + "/image_raw";
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  *text = std::string(out.c_str()) + "\n";
  return true;
}

}  // namespace

bool FormatRigFiles(const RigCalibrationResult& result, CameraFileFormat format,
                    const std::string& out_path,
                    std::vector<RigFileText>* files, std::string* error,
                    const RigFileJudgement* judgement) {
  files->clear();
  if (!CheckCameras(result, error)) return false;
  // opencv, ros and kalibr have no non-central and no splined model: they
  // get each camera's far-field part, a splined one as the best-fitting
  // kannala-brandt (the same camera for the models they have).
  RigCalibrationResult far_field = result;
  for (RigCameraResult& cam : far_field.cameras) {
    cam.camera = CameraForFormat(cam.camera, format, CameraFileStats());
  }
  RigFileText file;
  file.path = out_path;
  switch (format) {
    case CameraFileFormat::kPuzzlecal:
      file.text = FormatPuzzlecal(result, judgement);
      break;
    case CameraFileFormat::kOpenCv:
      if (!FormatOpenCv(far_field, &file.text, error)) return false;
      break;
    case CameraFileFormat::kRos:
      return FormatRos(far_field, out_path, files, error);
    case CameraFileFormat::kKalibr:
      if (!FormatKalibr(far_field, &file.text, error)) return false;
      break;
  }
  files->push_back(file);
  return true;
}

bool WriteRigFiles(const std::string& out_path, CameraFileFormat format,
                   const RigCalibrationResult& result,
                   std::vector<std::string>* written, std::string* error,
                   const RigFileJudgement* judgement) {
  std::vector<RigFileText> files;
  std::string why;
  if (!FormatRigFiles(result, format, out_path, &files, &why, judgement)) {
    return Fail("cannot write '" + out_path + "' (" +
                    CameraFileFormatName(format) + " format): " + why,
                error);
  }
  for (const RigFileText& file : files) {
    if (!WriteFileAtomically(file.path, file.text, error)) return false;
    if (written != nullptr) written->push_back(file.path);
  }
  return true;
}

namespace {

// One entry of a rig file's `cameras`: a camera as a camera file holds it,
// its name and cam_from_rig.
bool ParseRigCamera(const YAML::Node& node, const std::string& path,
                    FieldReader& r, RigFileCamera* camera) {
  const std::string pose_path = FieldReader::Join(path, "cam_from_rig");
  YAML::Node pose;
  Eigen::Matrix3d rotation;
  std::vector<double> t;
  if (!r.String(node, path, "name", Presence::kRequired, &camera->name) ||
      !ParseCameraNode(node, path, /*opencv_header=*/false, &r, &camera->camera,
                       nullptr) ||
      !r.Child(node, path, "cam_from_rig", Presence::kRequired, &pose) ||
      !r.Rows3x3(pose, pose_path, "R", Presence::kRequired, &rotation) ||
      !r.Doubles(pose, pose_path, "t", Presence::kRequired, 3, &t)) {
    return false;
  }
  if (!(rotation * rotation.transpose())
           .isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
      !(rotation.determinant() > 0)) {
    return r.Fail(FieldReader::Join(pose_path, "R"), "not a rotation matrix");
  }
  camera->cam_from_rig.linear() = rotation;
  camera->cam_from_rig.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return true;
}

}  // namespace

bool ParseRigFile(const std::string& text, const std::string& source,
                  std::vector<RigFileCamera>* cameras, std::string* error) {
  YAML::Node root;
  if (!ParseYaml(text, source, &root, error)) return false;
  if (!root.IsMap() || !root["cameras"]) {
    return Fail(source + ": not a puzzlecal rig file (no 'cameras' list)",
                error);
  }
  FieldReader r(source, error);
  YAML::Node list;
  if (!r.List(root, "", "cameras", Presence::kRequired, &list)) return false;
  if (list.size() < 2) {
    return r.Fail("cameras", "must list two or more cameras");
  }
  std::vector<RigFileCamera> parsed(list.size());
  try {
    for (size_t c = 0; c < list.size(); ++c) {
      if (!ParseRigCamera(list[c], FieldReader::Index("cameras", c), r,
                          &parsed[c])) {
        return false;
      }
    }
  } catch (const YAML::Exception& e) {
    return Fail(source + ": " + e.what(), error);
  }
  *cameras = parsed;
  return true;
}

bool ReadRigFile(const std::string& path, std::vector<RigFileCamera>* cameras,
                 std::string* error) {
  std::string text;
  if (!ReadTextFile(path, &text, error)) return false;
  return ParseRigFile(text, path, cameras, error);
}

}  // namespace puzzlecal
