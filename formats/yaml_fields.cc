#include "formats/yaml_fields.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "util/failure.h"

namespace puzzlecal {
namespace {

// What a node holds, for messages: its text, or what kind of node it is.
std::string Text(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a map";
  return "nothing";
}

// Reads a scalar as T; false for lists, maps and text that is no T.
template <typename T>
bool ScalarAs(const YAML::Node& node, T* out) {
  if (!node.IsScalar()) return false;
  try {
    *out = node.as<T>();
  } catch (const YAML::Exception&) {
    return false;
  }
  return true;
}

}  // namespace

bool ReadTextFile(const std::string& path, std::string* text,
                  std::string* error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Fail(path + ": cannot open the file", error);
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) return Fail(path + ": cannot read the file", error);
  *text = contents.str();
  return true;
}

bool ParseYaml(const std::string& text, const std::string& source,
               YAML::Node* root, std::string* error) {
  try {
    *root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return Fail(source + ": not valid YAML (line " +
                    std::to_string(e.mark.line + 1) + "): " + e.msg,
                error);
  }
  return true;
}

bool LoadYaml(const std::string& path, YAML::Node* root, std::string* error) {
  std::string text;
  if (!ReadTextFile(path, &text, error) ||
      !ParseYaml(text, path, root, error)) {
    return false;
  }
  if (!root->IsMap()) return Fail(path + ": must be a map of fields", error);
  return true;
}

FieldReader::FieldReader(std::string source, std::string* error)
    : source_(std::move(source)), error_(error) {}

bool FieldReader::Fail(const std::string& field, const std::string& problem) {
  if (ok_ && error_ != nullptr) {
    *error_ = field.empty() ? source_ + ": " + problem
                            : source_ + ": field '" + field + "': " + problem;
  }
  ok_ = false;
  return false;
}

std::string FieldReader::Join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string FieldReader::Index(const std::string& path, size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

bool FieldReader::Map(const YAML::Node& node, const std::string& path) {
  return node.IsMap() ? true : Fail(path, "must be a map of fields");
}

bool FieldReader::OnlyKeys(const YAML::Node& map, const std::string& path,
                           const std::set<std::string>& allowed) {
  if (!Map(map, path)) return false;
  for (auto it = map.begin(); it != map.end(); ++it) {
    const std::string key = it->first.Scalar();
    if (allowed.count(key) != 0) continue;
    std::string names;
    for (const std::string& name : allowed) {
      names += (names.empty() ? "" : ", ") + name;
    }
    return Fail(Join(path, key),
                "unknown field (expected one of: " + names + ")");
  }
  return true;
}

bool FieldReader::Child(const YAML::Node& map, const std::string& path,
                        const std::string& key, Presence presence,
                        YAML::Node* child) {
  if (!Map(map, path)) return false;
  const YAML::Node node = map[key];
  if (!node) {
    if (presence == Presence::kRequired)
      return Fail(Join(path, key), "missing");
    // reset(), not assignment: assigning one node to another would make the
    // node *child held (perhaps part of a document) refer to the new one.
    child->reset(YAML::Node(YAML::NodeType::Undefined));
    return true;
  }
  child->reset(node);
  return true;
}

bool FieldReader::List(const YAML::Node& map, const std::string& path,
                       const std::string& key, Presence presence,
                       YAML::Node* list) {
  YAML::Node node;
  if (!Child(map, path, key, presence, &node)) return false;
  if (!node) {
    // Absent: undefined, whatever *list held (a default YAML::Node is a
    // defined null, which a caller's `if (list)` would take for a list).
    list->reset(YAML::Node(YAML::NodeType::Undefined));
    return true;
  }
  if (!node.IsSequence()) return Fail(Join(path, key), "must be a list");
  list->reset(node);
  return true;
}

template <typename T>
bool FieldReader::Scalar(const YAML::Node& map, const std::string& path,
                         const std::string& key, Presence presence,
                         const char* what, T* out) {
  YAML::Node node;
  if (!Child(map, path, key, presence, &node)) return false;
  if (!node) return true;
  T value;
  if (!ScalarAs(node, &value)) {
    return Fail(Join(path, key),
                std::string("must be ") + what + ", got '" + Text(node) + "'");
  }
  *out = value;
  return true;
}

bool FieldReader::Int(const YAML::Node& map, const std::string& path,
                      const std::string& key, Presence presence, int* out) {
  return Scalar(map, path, key, presence, "an integer", out);
}

bool FieldReader::Uint64(const YAML::Node& map, const std::string& path,
                         const std::string& key, Presence presence,
                         uint64_t* out) {
  YAML::Node node;
  if (!Child(map, path, key, presence, &node)) return false;
  // yaml-cpp reads "-1" as 2^64 - 1.
  if (node && node.IsScalar() && node.Scalar().find('-') != std::string::npos) {
    return Fail(Join(path, key),
                "must be a non-negative integer, got '" + Text(node) + "'");
  }
  return Scalar(map, path, key, presence, "a non-negative integer", out);
}

bool FieldReader::Double(const YAML::Node& map, const std::string& path,
                         const std::string& key, Presence presence,
                         double* out) {
  double value = 0;
  YAML::Node node;
  if (!Child(map, path, key, presence, &node)) return false;
  if (!node) return true;
  if (!Scalar(map, path, key, presence, "a number", &value)) return false;
  if (!std::isfinite(value)) {
    return Fail(Join(path, key), "must be a finite number");
  }
  *out = value;
  return true;
}

bool FieldReader::Bool(const YAML::Node& map, const std::string& path,
                       const std::string& key, Presence presence, bool* out) {
  return Scalar(map, path, key, presence, "true or false", out);
}

bool FieldReader::String(const YAML::Node& map, const std::string& path,
                         const std::string& key, Presence presence,
                         std::string* out) {
  YAML::Node node;
  if (!Child(map, path, key, presence, &node)) return false;
  if (!node) return true;
  if (!node.IsScalar()) {
    return Fail(Join(path, key), "must be a string, got " + Text(node));
  }
  *out = node.Scalar();
  return true;
}

bool FieldReader::Numbers(const YAML::Node& list, const std::string& field,
                          int size, std::vector<double>* out,
                          NonFinite non_finite) {
  if (!list.IsSequence()) {
    return Fail(field, "must be a list of numbers like [1, 2]");
  }
  if (size >= 0 && static_cast<int>(list.size()) != size) {
    return Fail(field, "must hold " + std::to_string(size) + " numbers, got " +
                           std::to_string(list.size()));
  }
  std::vector<double> values;
  for (size_t i = 0; i < list.size(); ++i) {
    double value = 0;
    if (!ScalarAs(list[i], &value)) {
      return Fail(Index(field, i),
                  "must be a number, got '" + Text(list[i]) + "'");
    }
    if (non_finite == NonFinite::kReject && !std::isfinite(value)) {
      return Fail(Index(field, i), "must be a finite number");
    }
    values.push_back(value);
  }
  *out = values;
  return true;
}

bool FieldReader::Doubles(const YAML::Node& map, const std::string& path,
                          const std::string& key, Presence presence, int size,
                          std::vector<double>* out, NonFinite non_finite) {
  YAML::Node node;
  if (!Child(map, path, key, presence, &node)) return false;
  if (!node) return true;
  return Numbers(node, Join(path, key), size, out, non_finite);
}

bool FieldReader::Rows3x3(const YAML::Node& map, const std::string& path,
                          const std::string& key, Presence presence,
                          Eigen::Matrix3d* out) {
  YAML::Node rows;
  if (!Child(map, path, key, presence, &rows)) return false;
  if (!rows) return true;
  const std::string field = Join(path, key);
  if (!rows.IsSequence() || rows.size() != 3) {
    return Fail(field, "must be 3 rows of 3 numbers");
  }
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i) {
    std::vector<double> row;
    if (!Numbers(rows[i], Index(field, i), 3, &row)) return false;
    for (int j = 0; j < 3; ++j) m(i, j) = row[j];
  }
  *out = m;
  return true;
}

bool FieldReader::Matrix(const YAML::Node& map, const std::string& path,
                         const std::string& key, Presence presence, int rows,
                         int cols, std::vector<double>* data) {
  YAML::Node node;
  if (!Child(map, path, key, presence, &node)) return false;
  if (!node) return true;
  const int size = rows > 0 && cols > 0 ? rows * cols : -1;
  return Doubles(node, Join(path, key), "data", Presence::kRequired, size,
                 data);
}

}  // namespace puzzlecal
