#include "formats/yaml_emit.h"

#include <cstdio>
#include <cstdlib>

namespace puzzlecal {

YAML::Emitter& EmitFlow(YAML::Emitter& out, const std::vector<double>& values) {
  out << YAML::Flow << YAML::BeginSeq;
  for (double v : values) out << v;
  return out << YAML::EndSeq;
}

void EmitNamedValues(YAML::Emitter& out, const std::string& key,
                     const std::vector<std::string>& names,
                     const std::vector<double>& values) {
  out << YAML::Key << key << YAML::Value << YAML::BeginMap;
  for (size_t k = 0; k < names.size() && k < values.size(); ++k) {
    out << YAML::Key << names[k] << YAML::Value << values[k];
  }
  out << YAML::EndMap;
}

void EmitOpenCvMatrix(YAML::Emitter& out, const std::string& key, int rows,
                      int cols, const std::vector<double>& data) {
  out << YAML::Key << key << YAML::Value << YAML::SecondaryTag("opencv-matrix")
      << YAML::BeginMap;
  out << YAML::Key << "rows" << YAML::Value << rows;
  out << YAML::Key << "cols" << YAML::Value << cols;
  out << YAML::Key << "dt" << YAML::Value << "d";
  out << YAML::Key << "data" << YAML::Value;
  EmitFlow(out, data);
  out << YAML::EndMap;
}

void EmitRosMatrix(YAML::Emitter& out, const std::string& key, int rows,
                   int cols, const std::vector<double>& data) {
  out << YAML::Key << key << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "rows" << YAML::Value << rows;
  out << YAML::Key << "cols" << YAML::Value << cols;
  out << YAML::Key << "data" << YAML::Value;
  EmitFlow(out, data);
  out << YAML::EndMap;
}

Eigen::Matrix3d CameraMatrixOf(const Camera& camera) {
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = camera.params[0];
  k(1, 1) = camera.params[1];
  k(0, 2) = camera.params[2];
  k(1, 2) = camera.params[3];
  return k;
}

std::vector<double> DistortionOf(const Camera& camera) {
  return std::vector<double>(camera.params.begin() + kDistortionBegin,
                             camera.params.end());
}

int ExactDigits(double value) {
  // 17 significant digits always read back exactly; 15 mostly do, and keep
  // values such as 0.1 short.
  char text[40];
  std::snprintf(text, sizeof(text), "%.15g", value);
  return std::strtod(text, nullptr) == value ? 15 : 17;
}

YAML::Emitter& EmitExact(YAML::Emitter& out, double value) {
  // The emitter prints with the stream's %g-like default format at this
  // precision, and .nan / .inf for the non-finite values.
  return out << YAML::DoublePrecision(ExactDigits(value)) << value;
}

YAML::Emitter& EmitExactFlow(YAML::Emitter& out,
                             const std::vector<double>& values) {
  out << YAML::Flow << YAML::BeginSeq;
  for (double v : values) EmitExact(out, v);
  return out << YAML::EndSeq;
}

}  // namespace puzzlecal
