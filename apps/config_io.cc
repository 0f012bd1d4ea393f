#include "apps/config_io.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>

namespace puzzlecal {
namespace {

// Reads typed fields out of one YAML file and records the first error as
// "FILE: field 'PATH': PROBLEM".
class FieldReader {
 public:
  FieldReader(std::string file, std::string* error)
      : file_(std::move(file)), error_(error) {}

  bool ok() const { return ok_; }

  bool Fail(const std::string& field, const std::string& problem) {
    if (ok_ && error_ != nullptr) {
      *error_ = field.empty() ? file_ + ": " + problem
                              : file_ + ": field '" + field + "': " + problem;
    }
    ok_ = false;
    return false;
  }

  // Fails on keys of `map` outside `allowed`.
  bool OnlyKeys(const YAML::Node& map, const std::string& path,
                const std::set<std::string>& allowed) {
    if (!map.IsMap()) {
      return Fail(path, "must be a map of fields");
    }
    for (auto it = map.begin(); it != map.end(); ++it) {
      const std::string key = it->first.Scalar();
      if (allowed.count(key) == 0) {
        std::string names;
        for (const std::string& name : allowed) {
          names += (names.empty() ? "" : ", ") + name;
        }
        return Fail(Join(path, key),
                    "unknown field (expected one of: " + names + ")");
      }
    }
    return true;
  }

  static std::string Join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  // Scalars. `required` fields must be present; others keep *out.
  bool Int(const YAML::Node& map, const std::string& path,
           const std::string& key, bool required, int* out) {
    const YAML::Node node = map[key];
    if (!node) return required ? Fail(Join(path, key), "missing") : true;
    try {
      if (!node.IsScalar()) throw YAML::Exception(YAML::Mark(), "");
      *out = node.as<int>();
    } catch (const YAML::Exception&) {
      return Fail(Join(path, key),
                  "must be an integer, got '" + Text(node) + "'");
    }
    return true;
  }

  bool Uint64(const YAML::Node& map, const std::string& path,
              const std::string& key, bool required, uint64_t* out) {
    const YAML::Node node = map[key];
    if (!node) return required ? Fail(Join(path, key), "missing") : true;
    try {
      if (!node.IsScalar() || node.Scalar().find('-') != std::string::npos) {
        throw YAML::Exception(YAML::Mark(), "");
      }
      *out = node.as<uint64_t>();
    } catch (const YAML::Exception&) {
      return Fail(Join(path, key),
                  "must be a non-negative integer, got '" + Text(node) + "'");
    }
    return true;
  }

  bool Double(const YAML::Node& map, const std::string& path,
              const std::string& key, bool required, double* out) {
    const YAML::Node node = map[key];
    if (!node) return required ? Fail(Join(path, key), "missing") : true;
    double value = 0;
    try {
      if (!node.IsScalar()) throw YAML::Exception(YAML::Mark(), "");
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      return Fail(Join(path, key),
                  "must be a number, got '" + Text(node) + "'");
    }
    if (!std::isfinite(value)) {
      return Fail(Join(path, key), "must be a finite number");
    }
    *out = value;
    return true;
  }

  bool Bool(const YAML::Node& map, const std::string& path,
            const std::string& key, bool* out) {
    const YAML::Node node = map[key];
    if (!node) return true;
    try {
      if (!node.IsScalar()) throw YAML::Exception(YAML::Mark(), "");
      *out = node.as<bool>();
    } catch (const YAML::Exception&) {
      return Fail(Join(path, key),
                  "must be true or false, got '" + Text(node) + "'");
    }
    return true;
  }

  bool String(const YAML::Node& map, const std::string& path,
              const std::string& key, bool required, std::string* out) {
    const YAML::Node node = map[key];
    if (!node) return required ? Fail(Join(path, key), "missing") : true;
    if (!node.IsScalar()) return Fail(Join(path, key), "must be a string");
    *out = node.Scalar();
    return true;
  }

  // A list of numbers; `size` >= 0 demands that many.
  bool Doubles(const YAML::Node& map, const std::string& path,
               const std::string& key, bool required, int size,
               std::vector<double>* out) {
    const YAML::Node node = map[key];
    if (!node) return required ? Fail(Join(path, key), "missing") : true;
    if (!node.IsSequence()) {
      return Fail(Join(path, key), "must be a list of numbers like [1, 2]");
    }
    if (size >= 0 && static_cast<int>(node.size()) != size) {
      return Fail(Join(path, key), "must hold " + std::to_string(size) +
                                       " numbers, got " +
                                       std::to_string(node.size()));
    }
    std::vector<double> values;
    for (size_t i = 0; i < node.size(); ++i) {
      double value = 0;
      try {
        if (!node[i].IsScalar()) throw YAML::Exception(YAML::Mark(), "");
        value = node[i].as<double>();
      } catch (const YAML::Exception&) {
        return Fail(Join(path, key) + "[" + std::to_string(i) + "]",
                    "must be a number, got '" + Text(node[i]) + "'");
      }
      if (!std::isfinite(value)) {
        return Fail(Join(path, key) + "[" + std::to_string(i) + "]",
                    "must be finite");
      }
      values.push_back(value);
    }
    *out = values;
    return true;
  }

 private:
  static std::string Text(const YAML::Node& node) {
    if (node.IsScalar()) return node.Scalar();
    if (node.IsSequence()) return "a list";
    if (node.IsMap()) return "a map";
    return "nothing";
  }

  std::string file_;
  std::string* error_;
  bool ok_ = true;
};

bool LoadYaml(const std::string& path, YAML::Node* root, std::string* error) {
  try {
    *root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    if (error != nullptr) *error = path + ": cannot open the file";
    return false;
  } catch (const YAML::Exception& e) {
    if (error != nullptr) {
      *error = path + ": not valid YAML (line " +
               std::to_string(e.mark.line + 1) + "): " + e.msg;
    }
    return false;
  }
  if (!root->IsMap()) {
    if (error != nullptr) *error = path + ": must be a map of fields";
    return false;
  }
  return true;
}

bool ParseBoard(const YAML::Node& node, const std::string& path, FieldReader* r,
                Board* board) {
  if (!r->OnlyKeys(node, path,
                   {"type", "cols", "rows", "origin", "tile_size_m"})) {
    return false;
  }
  Board b;
  std::string type;
  if (!r->String(node, path, "type", true, &type)) return false;
  if (!BoardTypeFromName(type, &b.type)) {
    return r->Fail(FieldReader::Join(path, "type"),
                   "must be puzzleboard or checkerboard, got '" + type + "'");
  }
  if (!r->Int(node, path, "cols", true, &b.cols) ||
      !r->Int(node, path, "rows", true, &b.rows) ||
      !r->Double(node, path, "tile_size_m", true, &b.tile_size_m)) {
    return false;
  }
  std::vector<double> origin = {0, 0};
  if (!r->Doubles(node, path, "origin", false, 2, &origin)) return false;
  for (int i = 0; i < 2; ++i) {
    if (origin[i] != std::floor(origin[i]) || std::abs(origin[i]) > 1e6) {
      return r->Fail(FieldReader::Join(path, "origin"),
                     "must hold two integers");
    }
    b.origin[i] = static_cast<int>(origin[i]);
  }
  std::string why;
  if (!b.Check(&why)) {
    // Board::Check names the field first ("cols and rows must ...").
    const std::string field = why.rfind("tile_size_m", 0) == 0 ? "tile_size_m"
                              : why.rfind("origin", 0) == 0    ? "origin"
                                                               : "cols/rows";
    return r->Fail(FieldReader::Join(path, field), why);
  }
  *board = b;
  return true;
}

std::string Folder(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "" : path.substr(0, slash + 1);
}

bool ParseCamera(const YAML::Node& node, FieldReader* r, Camera* camera) {
  const std::string path = "camera";
  if (!r->OnlyKeys(node, path,
                   {"model", "width", "height", "params", "hfov_deg", "k1",
                    "fov_deg", "circle_fraction"})) {
    return false;
  }
  std::string model_name;
  CameraModelId model;
  int width = 0, height = 0;
  if (!r->String(node, path, "model", true, &model_name)) return false;
  if (!CameraModelIdFromName(model_name, &model)) {
    return r->Fail("camera.model", "unknown model '" + model_name +
                                       "' (known: " + CameraModelNames() + ")");
  }
  if (!r->Int(node, path, "width", true, &width) ||
      !r->Int(node, path, "height", true, &height)) {
    return false;
  }
  if (width < 1 || height < 1 || width > 20000 || height > 20000) {
    return r->Fail("camera.width", "image size must be in [1, 20000]");
  }
  if (node["params"]) {
    std::vector<double> params;
    if (!r->Doubles(node, path, "params", true, CameraModelNumParams(model),
                    &params)) {
      return false;
    }
    camera->model = model;
    camera->params = params;
    camera->width = width;
    camera->height = height;
  } else if (model == CameraModelId::kKannalaBrandt) {
    double fov = 190, circle = 0.96;
    if (!r->Double(node, path, "fov_deg", false, &fov) ||
        !r->Double(node, path, "circle_fraction", false, &circle)) {
      return false;
    }
    if (!(fov > 1 && fov < 360)) {
      return r->Fail("camera.fov_deg", "must be in (1, 360)");
    }
    if (!(circle > 0 && circle < 10)) {
      return r->Fail("camera.circle_fraction", "must be in (0, 10)");
    }
    *camera = FisheyeLensCamera(width, height, fov, circle);
  } else if (model == CameraModelId::kPinholeRadtan) {
    double hfov = 100, k1 = -0.25;
    if (!r->Double(node, path, "hfov_deg", false, &hfov) ||
        !r->Double(node, path, "k1", false, &k1)) {
      return false;
    }
    if (!(hfov > 1 && hfov < 179)) {
      return r->Fail("camera.hfov_deg", "must be in (1, 179)");
    }
    *camera = WidePinholeCamera(width, height, hfov, k1);
  } else {
    return r->Fail("camera.params", "missing (needed for " + model_name + ")");
  }
  std::string why;
  if (!CheckRenderCamera(*camera, &why)) return r->Fail("camera", why);
  return true;
}

bool ParseOccluders(const YAML::Node& map, const std::string& path,
                    FieldReader* r, std::vector<Occluder>* occluders) {
  const YAML::Node list = map["occluders"];
  if (!list) return true;
  const std::string list_path = FieldReader::Join(path, "occluders");
  if (!list.IsSequence()) return r->Fail(list_path, "must be a list");
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string item = list_path + "[" + std::to_string(i) + "]";
    if (!r->OnlyKeys(list[i], item, {"center_px", "radius_px", "grey"})) {
      return false;
    }
    Occluder o;
    std::vector<double> center;
    if (!r->Doubles(list[i], item, "center_px", true, 2, &center) ||
        !r->Double(list[i], item, "radius_px", true, &o.radius_px) ||
        !r->Double(list[i], item, "grey", false, &o.grey)) {
      return false;
    }
    o.center_px = Eigen::Vector2d(center[0], center[1]);
    occluders->push_back(o);
  }
  return true;
}

bool ParseRender(const YAML::Node& node, FieldReader* r,
                 RenderOptions* options) {
  const std::string path = "render";
  if (!r->OnlyKeys(node, path,
                   {"supersampling", "blur_sigma_px", "black_level",
                    "white_level", "background_level", "paper_margin_tiles",
                    "lighting_gradient", "vignetting", "gamma", "noise_sigma",
                    "seed", "field_of_view_deg", "occluders", "variant"})) {
    return false;
  }
  RenderOptions& o = *options;
  if (!r->Int(node, path, "supersampling", false, &o.supersampling) ||
      !r->Double(node, path, "blur_sigma_px", false, &o.blur_sigma_px) ||
      !r->Double(node, path, "black_level", false, &o.black_level) ||
      !r->Double(node, path, "white_level", false, &o.white_level) ||
      !r->Double(node, path, "background_level", false, &o.background_level) ||
      !r->Double(node, path, "paper_margin_tiles", false,
                 &o.paper_margin_tiles) ||
      !r->Double(node, path, "lighting_gradient", false,
                 &o.lighting_gradient) ||
      !r->Double(node, path, "vignetting", false, &o.vignetting) ||
      !r->Double(node, path, "gamma", false, &o.gamma) ||
      !r->Double(node, path, "noise_sigma", false, &o.noise_sigma) ||
      !r->Uint64(node, path, "seed", false, &o.seed) ||
      !r->Double(node, path, "field_of_view_deg", false,
                 &o.field_of_view_deg) ||
      !ParseOccluders(node, path, r, &o.occluders)) {
    return false;
  }
  if (const YAML::Node variant = node["variant"]) {
    const std::string vpath = "render.variant";
    if (!r->OnlyKeys(variant, vpath,
                     {"random_code_seed", "mirrored", "inverted"}) ||
        !r->Uint64(variant, vpath, "random_code_seed", false,
                   &o.variant.random_code_seed) ||
        !r->Bool(variant, vpath, "mirrored", &o.variant.mirrored) ||
        !r->Bool(variant, vpath, "inverted", &o.variant.inverted)) {
      return false;
    }
  }
  std::string why;
  if (!o.Check(&why)) {
    const std::string field = why.substr(0, why.find(' '));
    return r->Fail("render." + field, why);
  }
  return true;
}

bool ParseViewPose(const YAML::Node& node, const std::string& path,
                   FieldReader* r, ViewPose* view) {
  if (!r->OnlyKeys(
          node, path,
          {"target", "distance_m", "view_angle_deg", "tilt_direction_deg",
           "roll_deg", "off_axis_deg", "off_axis_direction_deg"})) {
    return false;
  }
  std::vector<double> target;
  if (!r->Doubles(node, path, "target", true, 2, &target) ||
      !r->Double(node, path, "distance_m", true, &view->distance_m) ||
      !r->Double(node, path, "view_angle_deg", false, &view->view_angle_deg) ||
      !r->Double(node, path, "tilt_direction_deg", false,
                 &view->tilt_direction_deg) ||
      !r->Double(node, path, "roll_deg", false, &view->roll_deg) ||
      !r->Double(node, path, "off_axis_deg", false, &view->off_axis_deg) ||
      !r->Double(node, path, "off_axis_direction_deg", false,
                 &view->off_axis_direction_deg)) {
    return false;
  }
  view->target = Eigen::Vector2d(target[0], target[1]);
  if (!(view->distance_m > 0)) {
    return r->Fail(path + ".distance_m", "must be positive");
  }
  if (!(view->view_angle_deg > 0 && view->view_angle_deg <= 90)) {
    return r->Fail(path + ".view_angle_deg", "must be in (0, 90]");
  }
  return true;
}

bool ParseViews(const YAML::Node& list, FieldReader* r, const Board& board,
                std::vector<SceneViewSpec>* views) {
  if (!list.IsSequence()) return r->Fail("views", "must be a list");
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string path = "views[" + std::to_string(i) + "]";
    const YAML::Node node = list[i];
    if (!r->OnlyKeys(node, path,
                     {"name", "pose", "cam_from_board", "occluders"})) {
      return false;
    }
    SceneViewSpec spec;
    if (!r->String(node, path, "name", false, &spec.name)) return false;
    if (node["pose"]) {
      ViewPose view;
      if (!ParseViewPose(node["pose"], path + ".pose", r, &view)) {
        return false;
      }
      spec.cam_from_board = PoseFromView(board, view);
    } else if (const YAML::Node pose = node["cam_from_board"]) {
      const std::string ppath = path + ".cam_from_board";
      std::vector<double> rotation, translation;
      if (!r->OnlyKeys(pose, ppath, {"rotation", "translation"}) ||
          !r->Doubles(pose, ppath, "rotation", true, 9, &rotation) ||
          !r->Doubles(pose, ppath, "translation", true, 3, &translation)) {
        return false;
      }
      Eigen::Matrix3d rot;
      for (int k = 0; k < 9; ++k) rot(k / 3, k % 3) = rotation[k];
      if ((rot.transpose() * rot - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
          rot.determinant() < 0) {
        return r->Fail(ppath + ".rotation",
                       "must be a rotation matrix (rows, orthonormal, "
                       "determinant +1)");
      }
      spec.cam_from_board.linear() = rot;
      spec.cam_from_board.translation() =
          Eigen::Vector3d(translation[0], translation[1], translation[2]);
    } else {
      return r->Fail(path, "needs 'pose' or 'cam_from_board'");
    }
    if (!ParseOccluders(node, path, r, &spec.occluders)) return false;
    views->push_back(spec);
  }
  return true;
}

bool ParseRandomViews(const YAML::Node& node, FieldReader* r, RandomViews* rv) {
  const std::string path = "random_views";
  return r->OnlyKeys(
             node, path,
             {"count", "seed", "min_distance_m", "max_distance_m",
              "min_view_angle_deg", "max_view_angle_deg", "max_roll_deg",
              "max_off_axis_deg", "target_margin_tiles", "occluders_per_view",
              "min_occluder_radius_px", "max_occluder_radius_px"}) &&
         r->Int(node, path, "count", true, &rv->count) &&
         r->Uint64(node, path, "seed", true, &rv->seed) &&
         r->Double(node, path, "min_distance_m", false, &rv->min_distance_m) &&
         r->Double(node, path, "max_distance_m", false, &rv->max_distance_m) &&
         r->Double(node, path, "min_view_angle_deg", false,
                   &rv->min_view_angle_deg) &&
         r->Double(node, path, "max_view_angle_deg", false,
                   &rv->max_view_angle_deg) &&
         r->Double(node, path, "max_roll_deg", false, &rv->max_roll_deg) &&
         r->Double(node, path, "max_off_axis_deg", false,
                   &rv->max_off_axis_deg) &&
         r->Double(node, path, "target_margin_tiles", false,
                   &rv->target_margin_tiles) &&
         r->Int(node, path, "occluders_per_view", false,
                &rv->occluders_per_view) &&
         r->Double(node, path, "min_occluder_radius_px", false,
                   &rv->min_occluder_radius_px) &&
         r->Double(node, path, "max_occluder_radius_px", false,
                   &rv->max_occluder_radius_px);
}

void AppendDouble(std::ostringstream* out, double value) {
  // The shortest of 15 or 17 digits that reads back exactly.
  char text[40];
  std::snprintf(text, sizeof(text), "%.15g", value);
  if (std::strtod(text, nullptr) != value) {
    std::snprintf(text, sizeof(text), "%.17g", value);
  }
  *out << text;
}

}  // namespace

bool LoadBoardFile(const std::string& path, Board* board, std::string* error) {
  YAML::Node root;
  if (!LoadYaml(path, &root, error)) return false;
  FieldReader reader(path, error);
  return ParseBoard(root, "", &reader, board);
}

bool LoadSceneFile(const std::string& path, SceneSpec* scene,
                   std::string* error) {
  YAML::Node root;
  if (!LoadYaml(path, &root, error)) return false;
  FieldReader r(path, error);
  if (!r.OnlyKeys(root, "",
                  {"name", "camera", "board", "render", "views", "random_views",
                   "tilt_series", "tile_size_series"})) {
    return false;
  }
  SceneSpec s;
  if (!r.String(root, "", "name", true, &s.name)) return false;
  if (!root["camera"]) return r.Fail("camera", "missing");
  if (!ParseCamera(root["camera"], &r, &s.camera)) return false;
  const YAML::Node board = root["board"];
  if (!board) return r.Fail("board", "missing");
  if (board.IsScalar()) {
    std::string board_path = board.Scalar();
    if (!board_path.empty() && board_path[0] != '/') {
      board_path = Folder(path) + board_path;
    }
    std::string why;
    if (!LoadBoardFile(board_path, &s.board, &why)) {
      return r.Fail("board", why);
    }
  } else if (!ParseBoard(board, "board", &r, &s.board)) {
    return false;
  }
  if (root["render"] && !ParseRender(root["render"], &r, &s.render)) {
    return false;
  }
  if (root["views"] && !ParseViews(root["views"], &r, s.board, &s.views)) {
    return false;
  }
  if (root["random_views"] &&
      !ParseRandomViews(root["random_views"], &r, &s.random_views)) {
    return false;
  }
  if (const YAML::Node tilt = root["tilt_series"]) {
    if (!r.OnlyKeys(tilt, "tilt_series",
                    {"view_angles_deg", "distance_m", "tilt_direction_deg"}) ||
        !r.Doubles(tilt, "tilt_series", "view_angles_deg", true, -1,
                   &s.tilt_series.view_angles_deg) ||
        !r.Double(tilt, "tilt_series", "distance_m", true,
                  &s.tilt_series.distance_m) ||
        !r.Double(tilt, "tilt_series", "tilt_direction_deg", false,
                  &s.tilt_series.tilt_direction_deg)) {
      return false;
    }
  }
  if (const YAML::Node tiles = root["tile_size_series"]) {
    const std::string tpath = "tile_size_series";
    if (!r.OnlyKeys(tiles, tpath, {"tile_px", "view_angle_deg", "roll_deg"}) ||
        !r.Doubles(tiles, tpath, "tile_px", true, -1,
                   &s.tile_size_series.tile_px) ||
        !r.Double(tiles, tpath, "view_angle_deg", false,
                  &s.tile_size_series.view_angle_deg) ||
        !r.Double(tiles, tpath, "roll_deg", false,
                  &s.tile_size_series.roll_deg)) {
      return false;
    }
  }
  std::string why;
  if (!s.Check(&why)) {
    const size_t colon = why.find(':');
    const std::string head = why.substr(0, why.find_first_of(" .:"));
    return r.Fail(colon != std::string::npos ? head : "", why);
  }
  *scene = s;
  return true;
}

std::string SceneTruthYaml(const SceneSpec& scene,
                           const std::vector<SceneView>& views,
                           const std::vector<std::string>& files) {
  std::ostringstream out;
  out << "# Exact geometry of the rendered views. Pixels: the centre of the\n"
         "# top-left pixel is (0, 0). corners rows: [x, y, col, row, "
         "visible]\n"
         "# (x, y = .nan when the corner cannot be projected).\n";
  out << "scene: \"" << scene.name << "\"\n";
  out << "camera:\n  model: " << CameraModelName(scene.camera.model) << "\n";
  out << "  width: " << scene.camera.width << "\n";
  out << "  height: " << scene.camera.height << "\n";
  out << "  param_names: [";
  const std::vector<std::string> names =
      CameraModelParamNames(scene.camera.model);
  for (size_t i = 0; i < names.size(); ++i) {
    out << (i ? ", " : "") << names[i];
  }
  out << "]\n  params: [";
  for (size_t i = 0; i < scene.camera.params.size(); ++i) {
    if (i) out << ", ";
    AppendDouble(&out, scene.camera.params[i]);
  }
  out << "]\n";
  out << "board:\n  type: " << BoardTypeName(scene.board.type) << "\n";
  out << "  cols: " << scene.board.cols << "\n  rows: " << scene.board.rows
      << "\n  origin: [" << scene.board.origin.x() << ", "
      << scene.board.origin.y() << "]\n  tile_size_m: ";
  AppendDouble(&out, scene.board.tile_size_m);
  out << "\nviews:\n";
  for (size_t v = 0; v < views.size(); ++v) {
    const RenderTruth& truth = views[v].truth;
    out << "  - file: \"" << (v < files.size() ? files[v] : views[v].name)
        << "\"\n    name: \"" << views[v].name << "\"\n";
    out << "    cam_from_board:\n      rotation: [";
    const Eigen::Matrix3d rot = truth.cam_from_board.linear();
    for (int k = 0; k < 9; ++k) {
      if (k) out << ", ";
      AppendDouble(&out, rot(k / 3, k % 3));
    }
    out << "]\n      translation: [";
    for (int k = 0; k < 3; ++k) {
      if (k) out << ", ";
      AppendDouble(&out, truth.cam_from_board.translation()[k]);
    }
    out << "]\n    corners:\n";
    for (const TruthCorner& c : truth.corners) {
      out << "      - [";
      if (c.xy.allFinite()) {
        AppendDouble(&out, c.xy.x());
        out << ", ";
        AppendDouble(&out, c.xy.y());
      } else {
        out << ".nan, .nan";
      }
      out << ", " << c.id.x() << ", " << c.id.y() << ", " << (c.visible ? 1 : 0)
          << "]\n";
    }
  }
  return out.str();
}

}  // namespace puzzlecal
