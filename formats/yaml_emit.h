#ifndef PUZZLECAL_FORMATS_YAML_EMIT_H_
#define PUZZLECAL_FORMATS_YAML_EMIT_H_

// Writing puzzlecal's YAML files: the pieces the camera, rig and truth
// writers share, all through yaml-cpp's Emitter (so text is quoted and
// escaped where YAML needs it). The camera and rig writers set the
// emitter's precision to 17 digits; the truth of a render writes each
// number with the fewest digits that read back exactly (EmitExact).

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "camera/camera_models.h"

namespace puzzlecal {

// [v0, v1, ...] on one line, with the emitter's precision.
YAML::Emitter& EmitFlow(YAML::Emitter& out, const std::vector<double>& values);

// The entries of a matrix, row by row.
template <typename Derived>
std::vector<double> RowMajor(const Eigen::MatrixBase<Derived>& m) {
  std::vector<double> values;
  values.reserve(m.rows() * m.cols());
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) values.push_back(m(r, c));
  }
  return values;
}

// A matrix as a list of its rows, each row on one line; the list itself is
// a block list (one row per line) or, with YAML::Flow, on one line.
template <typename Derived>
YAML::Emitter& EmitRows(YAML::Emitter& out, const Eigen::MatrixBase<Derived>& m,
                        YAML::EMITTER_MANIP list_style = YAML::Block) {
  out << list_style << YAML::BeginSeq;
  for (int r = 0; r < m.rows(); ++r) EmitFlow(out, RowMajor(m.row(r)));
  return out << YAML::EndSeq;
}

// `key`: a map of named values ({fx: ..., fy: ...}), one per line.
void EmitNamedValues(YAML::Emitter& out, const std::string& key,
                     const std::vector<std::string>& names,
                     const std::vector<double>& values);

// `key`: a matrix as OpenCV's FileStorage writes it (!!opencv-matrix with
// rows, cols, dt: d and the row-major data).
void EmitOpenCvMatrix(YAML::Emitter& out, const std::string& key, int rows,
                      int cols, const std::vector<double>& data);
// `key`: a matrix as ROS camera_info files hold it ({rows, cols, data}).
void EmitRosMatrix(YAML::Emitter& out, const std::string& key, int rows,
                   int cols, const std::vector<double>& data);

// The 3x3 camera matrix K = [fx 0 cx; 0 fy cy; 0 0 1] of a camera.
Eigen::Matrix3d CameraMatrixOf(const Camera& camera);
// The distortion coefficients of a camera (its parameters after fx fy cx
// cy, in the model's order).
std::vector<double> DistortionOf(const Camera& camera);

// The fewest significant digits (15 or 17) that read `value` back
// exactly.
int ExactDigits(double value);
// `value` with ExactDigits (.nan and .inf as YAML spells them).
YAML::Emitter& EmitExact(YAML::Emitter& out, double value);
// [v0, v1, ...] on one line, each with ExactDigits.
YAML::Emitter& EmitExactFlow(YAML::Emitter& out,
                             const std::vector<double>& values);

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_YAML_EMIT_H_
