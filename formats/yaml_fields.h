#ifndef PUZZLECAL_FORMATS_YAML_FIELDS_H_
#define PUZZLECAL_FORMATS_YAML_FIELDS_H_

// Reading puzzlecal's YAML files (camera and rig files, board and scene
// recipes, the truth of a rendered set): one loader and one field reader,
// so that every reader speaks of a bad field the same way:
//
//   FILE: field 'PATH': PROBLEM
//
// PATH is the chain of keys from the root joined by '.', with list entries
// as [i] ("views[2].cam_from_board.R[1]"); PROBLEM says what the field must
// be and what it held ("must be an integer, got 'ten'", "missing").

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

namespace puzzlecal {

// The text of a file ("FILE: cannot open the file" when it cannot be read).
bool ReadTextFile(const std::string& path, std::string* text,
                  std::string* error);
// Parses YAML text; `source` names it in messages ("SOURCE: not valid YAML
// (line N): ..."). An empty text is an empty (null) node.
bool ParseYaml(const std::string& text, const std::string& source,
               YAML::Node* root, std::string* error);
// Reads and parses a file whose root must be a map of fields.
bool LoadYaml(const std::string& path, YAML::Node* root, std::string* error);

// Whether a field must be there. An optional field that is absent leaves
// the output as it was (its default).
enum class Presence { kOptional, kRequired };

// Whether a list of numbers may hold .nan / .inf (the truth of a corner
// that cannot be projected is .nan).
enum class NonFinite { kReject, kAllow };

// Typed fields out of one source, recording the first failure as
// "SOURCE: field 'PATH': PROBLEM". Every getter takes the map that holds the
// field, the map's path ("" for the root) and the key, and returns false on
// failure (then the output is untouched).
class FieldReader {
 public:
  FieldReader(std::string source, std::string* error);

  const std::string& source() const { return source_; }
  bool ok() const { return ok_; }

  // Records the failure (the first one wins) and returns false. An empty
  // field gives "SOURCE: PROBLEM".
  bool Fail(const std::string& field, const std::string& problem);

  // "a" + "b" = "a.b"; "" + "b" = "b".
  static std::string Join(const std::string& path, const std::string& key);
  // "a" + 2 = "a[2]".
  static std::string Index(const std::string& path, size_t index);

  // `node` must be a map ("must be a map of fields").
  bool Map(const YAML::Node& node, const std::string& path);
  // Fails on keys of `map` outside `allowed` (they are usually typos).
  bool OnlyKeys(const YAML::Node& map, const std::string& path,
                const std::set<std::string>& allowed);

  // The node under `key`; absent and optional gives an undefined node
  // (test it with `if (*child)`).
  bool Child(const YAML::Node& map, const std::string& path,
             const std::string& key, Presence presence, YAML::Node* child);
  // As Child, and the node must be a list (absent and optional: an
  // undefined node, of size 0).
  bool List(const YAML::Node& map, const std::string& path,
            const std::string& key, Presence presence, YAML::Node* list);

  // Scalars.
  bool Int(const YAML::Node& map, const std::string& path,
           const std::string& key, Presence presence, int* out);
  bool Uint64(const YAML::Node& map, const std::string& path,
              const std::string& key, Presence presence, uint64_t* out);
  // A finite number.
  bool Double(const YAML::Node& map, const std::string& path,
              const std::string& key, Presence presence, double* out);
  bool Bool(const YAML::Node& map, const std::string& path,
            const std::string& key, Presence presence, bool* out);
  bool String(const YAML::Node& map, const std::string& path,
              const std::string& key, Presence presence, std::string* out);

  // A list of numbers; `size` >= 0 demands that many.
  bool Doubles(const YAML::Node& map, const std::string& path,
               const std::string& key, Presence presence, int size,
               std::vector<double>* out,
               NonFinite non_finite = NonFinite::kReject);
  // The same for a list node itself, named `field`.
  bool Numbers(const YAML::Node& list, const std::string& field, int size,
               std::vector<double>* out,
               NonFinite non_finite = NonFinite::kReject);
  // A 3x3 matrix as 3 rows of 3 numbers ([[a, b, c], [d, e, f], ...]).
  bool Rows3x3(const YAML::Node& map, const std::string& path,
               const std::string& key, Presence presence, Eigen::Matrix3d* out);
  // A matrix as ROS and OpenCV write it: {rows, cols, data: row-major}.
  // `rows` and `cols` > 0 demand that size of `data`; 0 takes any.
  bool Matrix(const YAML::Node& map, const std::string& path,
              const std::string& key, Presence presence, int rows, int cols,
              std::vector<double>* data);

 private:
  // The scalar under `key` as T; `what` names T in the message ("an
  // integer").
  template <typename T>
  bool Scalar(const YAML::Node& map, const std::string& path,
              const std::string& key, Presence presence, const char* what,
              T* out);

  std::string source_;
  std::string* error_;
  bool ok_ = true;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_YAML_FIELDS_H_
