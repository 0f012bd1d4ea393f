#include "sim/scene_file.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "formats/board_node.h"
#include "formats/yaml_emit.h"
#include "formats/yaml_fields.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

constexpr Presence kRequired = Presence::kRequired;
constexpr Presence kOptional = Presence::kOptional;

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
  if (!r->String(node, path, "model", kRequired, &model_name)) return false;
  if (!CameraModelIdFromName(model_name, &model)) {
    return r->Fail("camera.model", "unknown model '" + model_name +
                                       "' (known: " + CameraModelNames() + ")");
  }
  if (!r->Int(node, path, "width", kRequired, &width) ||
      !r->Int(node, path, "height", kRequired, &height)) {
    return false;
  }
  if (width < 1 || height < 1 || width > 20000 || height > 20000) {
    return r->Fail("camera.width", "image size must be in [1, 20000]");
  }
  if (node["params"]) {
    std::vector<double> params;
    if (!r->Doubles(node, path, "params", kRequired,
                    CameraModelNumParams(model), &params)) {
      return false;
    }
    camera->model = model;
    camera->params = params;
    camera->width = width;
    camera->height = height;
  } else if (model == CameraModelId::kKannalaBrandt) {
    double fov = 190, circle = 0.96;
    if (!r->Double(node, path, "fov_deg", kOptional, &fov) ||
        !r->Double(node, path, "circle_fraction", kOptional, &circle)) {
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
    if (!r->Double(node, path, "hfov_deg", kOptional, &hfov) ||
        !r->Double(node, path, "k1", kOptional, &k1)) {
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
    if (!r->Doubles(list[i], item, "center_px", kRequired, 2, &center) ||
        !r->Double(list[i], item, "radius_px", kRequired, &o.radius_px) ||
        !r->Double(list[i], item, "grey", kOptional, &o.grey)) {
      return false;
    }
    o.center_px = Eigen::Vector2d(center[0], center[1]);
    occluders->push_back(o);
  }
  return true;
}

// An optional `motion_blur: {length_px, angle_deg}` of `map`.
bool ParseMotionBlur(const YAML::Node& map, const std::string& path,
                     FieldReader* r, MotionBlur* blur) {
  const YAML::Node node = map["motion_blur"];
  if (!node) return true;
  const std::string blur_path = FieldReader::Join(path, "motion_blur");
  return r->OnlyKeys(node, blur_path, {"length_px", "angle_deg"}) &&
         r->Double(node, blur_path, "length_px", kRequired, &blur->length_px) &&
         r->Double(node, blur_path, "angle_deg", kOptional, &blur->angle_deg);
}

bool ParseRender(const YAML::Node& node, FieldReader* r,
                 RenderOptions* options) {
  const std::string path = "render";
  if (!r->OnlyKeys(
          node, path,
          {"supersampling", "blur_sigma_px", "black_level", "white_level",
           "background_level", "paper_margin_tiles", "lighting_gradient",
           "vignetting", "gamma", "noise_sigma", "seed", "field_of_view_deg",
           "motion_blur", "occluders", "variant"})) {
    return false;
  }
  RenderOptions& o = *options;
  if (!r->Int(node, path, "supersampling", kOptional, &o.supersampling) ||
      !r->Double(node, path, "blur_sigma_px", kOptional, &o.blur_sigma_px) ||
      !r->Double(node, path, "black_level", kOptional, &o.black_level) ||
      !r->Double(node, path, "white_level", kOptional, &o.white_level) ||
      !r->Double(node, path, "background_level", kOptional,
                 &o.background_level) ||
      !r->Double(node, path, "paper_margin_tiles", kOptional,
                 &o.paper_margin_tiles) ||
      !r->Double(node, path, "lighting_gradient", kOptional,
                 &o.lighting_gradient) ||
      !r->Double(node, path, "vignetting", kOptional, &o.vignetting) ||
      !r->Double(node, path, "gamma", kOptional, &o.gamma) ||
      !r->Double(node, path, "noise_sigma", kOptional, &o.noise_sigma) ||
      !r->Uint64(node, path, "seed", kOptional, &o.seed) ||
      !r->Double(node, path, "field_of_view_deg", kOptional,
                 &o.field_of_view_deg) ||
      !ParseMotionBlur(node, path, r, &o.motion_blur) ||
      !ParseOccluders(node, path, r, &o.occluders)) {
    return false;
  }
  if (const YAML::Node variant = node["variant"]) {
    const std::string vpath = "render.variant";
    if (!r->OnlyKeys(variant, vpath,
                     {"random_code_seed", "mirrored", "inverted"}) ||
        !r->Uint64(variant, vpath, "random_code_seed", kOptional,
                   &o.variant.random_code_seed) ||
        !r->Bool(variant, vpath, "mirrored", kOptional, &o.variant.mirrored) ||
        !r->Bool(variant, vpath, "inverted", kOptional, &o.variant.inverted)) {
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
  if (!r->Doubles(node, path, "target", kRequired, 2, &target) ||
      !r->Double(node, path, "distance_m", kRequired, &view->distance_m) ||
      !r->Double(node, path, "view_angle_deg", kOptional,
                 &view->view_angle_deg) ||
      !r->Double(node, path, "tilt_direction_deg", kOptional,
                 &view->tilt_direction_deg) ||
      !r->Double(node, path, "roll_deg", kOptional, &view->roll_deg) ||
      !r->Double(node, path, "off_axis_deg", kOptional, &view->off_axis_deg) ||
      !r->Double(node, path, "off_axis_direction_deg", kOptional,
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
    if (!r->OnlyKeys(
            node, path,
            {"name", "pose", "cam_from_board", "occluders", "motion_blur"})) {
      return false;
    }
    SceneViewSpec spec;
    if (!r->String(node, path, "name", kOptional, &spec.name)) return false;
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
          !r->Doubles(pose, ppath, "rotation", kRequired, 9, &rotation) ||
          !r->Doubles(pose, ppath, "translation", kRequired, 3, &translation)) {
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
    if (!ParseOccluders(node, path, r, &spec.occluders) ||
        !ParseMotionBlur(node, path, r, &spec.motion_blur)) {
      return false;
    }
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
         r->Int(node, path, "count", kRequired, &rv->count) &&
         r->Uint64(node, path, "seed", kRequired, &rv->seed) &&
         r->Double(node, path, "min_distance_m", kOptional,
                   &rv->min_distance_m) &&
         r->Double(node, path, "max_distance_m", kOptional,
                   &rv->max_distance_m) &&
         r->Double(node, path, "min_view_angle_deg", kOptional,
                   &rv->min_view_angle_deg) &&
         r->Double(node, path, "max_view_angle_deg", kOptional,
                   &rv->max_view_angle_deg) &&
         r->Double(node, path, "max_roll_deg", kOptional, &rv->max_roll_deg) &&
         r->Double(node, path, "max_off_axis_deg", kOptional,
                   &rv->max_off_axis_deg) &&
         r->Double(node, path, "target_margin_tiles", kOptional,
                   &rv->target_margin_tiles) &&
         r->Int(node, path, "occluders_per_view", kOptional,
                &rv->occluders_per_view) &&
         r->Double(node, path, "min_occluder_radius_px", kOptional,
                   &rv->min_occluder_radius_px) &&
         r->Double(node, path, "max_occluder_radius_px", kOptional,
                   &rv->max_occluder_radius_px);
}

}  // namespace

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
  if (!r.String(root, "", "name", kRequired, &s.name)) return false;
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
  } else if (!ParseBoardNode(board, "board", &r, &s.board)) {
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
        !r.Doubles(tilt, "tilt_series", "view_angles_deg", kRequired, -1,
                   &s.tilt_series.view_angles_deg) ||
        !r.Double(tilt, "tilt_series", "distance_m", kRequired,
                  &s.tilt_series.distance_m) ||
        !r.Double(tilt, "tilt_series", "tilt_direction_deg", kOptional,
                  &s.tilt_series.tilt_direction_deg)) {
      return false;
    }
  }
  if (const YAML::Node tiles = root["tile_size_series"]) {
    const std::string tpath = "tile_size_series";
    if (!r.OnlyKeys(tiles, tpath, {"tile_px", "view_angle_deg", "roll_deg"}) ||
        !r.Doubles(tiles, tpath, "tile_px", kRequired, -1,
                   &s.tile_size_series.tile_px) ||
        !r.Double(tiles, tpath, "view_angle_deg", kOptional,
                  &s.tile_size_series.view_angle_deg) ||
        !r.Double(tiles, tpath, "roll_deg", kOptional,
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

namespace {

void EmitExactField(YAML::Emitter& out, const char* key, double value) {
  out << YAML::Key << key << YAML::Value;
  EmitExact(out, value);
}

void EmitOccluders(YAML::Emitter& out, const std::vector<Occluder>& list) {
  out << YAML::Key << "occluders" << YAML::Value << YAML::BeginSeq;
  for (const Occluder& o : list) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "center_px" << YAML::Value;
    EmitExactFlow(out, {o.center_px.x(), o.center_px.y()});
    EmitExactField(out, "radius_px", o.radius_px);
    EmitExactField(out, "grey", o.grey);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

void EmitMotionBlur(YAML::Emitter& out, const MotionBlur& blur) {
  out << YAML::Key << "motion_blur" << YAML::Value << YAML::Flow
      << YAML::BeginMap;
  EmitExactField(out, "length_px", blur.length_px);
  EmitExactField(out, "angle_deg", blur.angle_deg);
  out << YAML::EndMap;
}

void EmitRender(YAML::Emitter& out, const RenderOptions& o) {
  out << YAML::Key << "render" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "supersampling" << YAML::Value << o.supersampling;
  EmitExactField(out, "blur_sigma_px", o.blur_sigma_px);
  EmitExactField(out, "black_level", o.black_level);
  EmitExactField(out, "white_level", o.white_level);
  EmitExactField(out, "background_level", o.background_level);
  EmitExactField(out, "paper_margin_tiles", o.paper_margin_tiles);
  EmitExactField(out, "lighting_gradient", o.lighting_gradient);
  EmitExactField(out, "vignetting", o.vignetting);
  EmitExactField(out, "gamma", o.gamma);
  EmitExactField(out, "noise_sigma", o.noise_sigma);
  out << YAML::Key << "seed" << YAML::Value << o.seed;
  EmitExactField(out, "field_of_view_deg", o.field_of_view_deg);
  if (o.motion_blur.length_px > 0) EmitMotionBlur(out, o.motion_blur);
  if (!o.occluders.empty()) EmitOccluders(out, o.occluders);
  out << YAML::Key << "variant" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "random_code_seed" << YAML::Value
      << o.variant.random_code_seed;
  out << YAML::Key << "mirrored" << YAML::Value << o.variant.mirrored;
  out << YAML::Key << "inverted" << YAML::Value << o.variant.inverted;
  out << YAML::EndMap;
  out << YAML::EndMap;
}

// A pose as the recipe's views and the truth's views hold it.
void EmitCamFromBoard(YAML::Emitter& out, const Eigen::Isometry3d& pose) {
  out << YAML::Key << "cam_from_board" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "rotation" << YAML::Value;
  EmitExactFlow(out, RowMajor(pose.linear()));
  out << YAML::Key << "translation" << YAML::Value;
  EmitExactFlow(out, RowMajor(pose.translation()));
  out << YAML::EndMap;
}

void EmitRandomViews(YAML::Emitter& out, const RandomViews& rv) {
  out << YAML::Key << "random_views" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "count" << YAML::Value << rv.count;
  out << YAML::Key << "seed" << YAML::Value << rv.seed;
  EmitExactField(out, "min_distance_m", rv.min_distance_m);
  EmitExactField(out, "max_distance_m", rv.max_distance_m);
  EmitExactField(out, "min_view_angle_deg", rv.min_view_angle_deg);
  EmitExactField(out, "max_view_angle_deg", rv.max_view_angle_deg);
  EmitExactField(out, "max_roll_deg", rv.max_roll_deg);
  EmitExactField(out, "max_off_axis_deg", rv.max_off_axis_deg);
  EmitExactField(out, "target_margin_tiles", rv.target_margin_tiles);
  out << YAML::Key << "occluders_per_view" << YAML::Value
      << rv.occluders_per_view;
  EmitExactField(out, "min_occluder_radius_px", rv.min_occluder_radius_px);
  EmitExactField(out, "max_occluder_radius_px", rv.max_occluder_radius_px);
  out << YAML::EndMap;
}

// The camera of a truth file: model, size, parameter names and values.
bool ParseTruthCamera(const YAML::Node& node, FieldReader& r, Camera* camera) {
  const std::string path = "camera";
  std::string model;
  if (!r.String(node, path, "model", kRequired, &model)) return false;
  if (!CameraModelIdFromName(model, &camera->model)) {
    return r.Fail("camera.model", "unknown model '" + model +
                                      "' (known: " + CameraModelNames() + ")");
  }
  return r.Int(node, path, "width", kRequired, &camera->width) &&
         r.Int(node, path, "height", kRequired, &camera->height) &&
         r.Doubles(node, path, "params", kRequired,
                   CameraModelNumParams(camera->model), &camera->params);
}

// One view of a truth file.
bool ParseTruthView(const YAML::Node& node, const std::string& path,
                    FieldReader& r, SceneTruthView* view) {
  const std::string pose_path = FieldReader::Join(path, "cam_from_board");
  YAML::Node pose, corners;
  std::vector<double> rotation, translation;
  if (!r.String(node, path, "file", kRequired, &view->file) ||
      !r.String(node, path, "name", kRequired, &view->name) ||
      !r.Child(node, path, "cam_from_board", kRequired, &pose) ||
      !r.Doubles(pose, pose_path, "rotation", kRequired, 9, &rotation) ||
      !r.Doubles(pose, pose_path, "translation", kRequired, 3, &translation) ||
      !r.List(node, path, "corners", kRequired, &corners)) {
    return false;
  }
  Eigen::Matrix3d rot;
  for (int k = 0; k < 9; ++k) rot(k / 3, k % 3) = rotation[k];
  view->cam_from_board.linear() = rot;
  view->cam_from_board.translation() =
      Eigen::Vector3d(translation[0], translation[1], translation[2]);
  const std::string corners_path = FieldReader::Join(path, "corners");
  for (size_t i = 0; i < corners.size(); ++i) {
    const std::string field = FieldReader::Index(corners_path, i);
    std::vector<double> row;
    if (!r.Numbers(corners[i], field, 5, &row, NonFinite::kAllow)) {
      return false;
    }
    for (int k = 2; k < 5; ++k) {
      if (!(std::abs(row[k]) <= 1e6 && row[k] == std::floor(row[k]))) {
        return r.Fail(field, "col, row and visible must be whole numbers");
      }
    }
    TruthCorner corner;
    corner.xy = Eigen::Vector2d(row[0], row[1]);
    corner.id =
        Eigen::Vector2i(static_cast<int>(row[2]), static_cast<int>(row[3]));
    corner.visible = row[4] != 0;
    view->corners.push_back(corner);
  }
  return true;
}

}  // namespace

std::string SceneTruthYaml(const SceneSpec& scene,
                           const std::vector<SceneView>& views,
                           const std::vector<std::string>& files) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "scene" << YAML::Value << scene.name;
  out << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "model" << YAML::Value
      << CameraModelName(scene.camera.model);
  out << YAML::Key << "width" << YAML::Value << scene.camera.width;
  out << YAML::Key << "height" << YAML::Value << scene.camera.height;
  out << YAML::Key << "param_names" << YAML::Value << YAML::Flow
      << CameraModelParamNames(scene.camera.model);
  out << YAML::Key << "params" << YAML::Value;
  EmitExactFlow(out, scene.camera.params);
  out << YAML::EndMap;
  out << YAML::Key << "board" << YAML::Value;
  EmitBoardNode(out, scene.board);
  out << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
  for (size_t v = 0; v < views.size(); ++v) {
    const RenderTruth& truth = views[v].truth;
    out << YAML::BeginMap;
    out << YAML::Key << "file" << YAML::Value
        << (v < files.size() ? files[v] : views[v].name);
    out << YAML::Key << "name" << YAML::Value << views[v].name;
    EmitCamFromBoard(out, truth.cam_from_board);
    out << YAML::Key << "corners" << YAML::Value << YAML::BeginSeq;
    for (const TruthCorner& c : truth.corners) {
      out << YAML::Flow << YAML::BeginSeq;
      // A corner that cannot be projected has no finite position.
      const double nan = std::numeric_limits<double>::quiet_NaN();
      EmitExact(out, c.xy.allFinite() ? c.xy.x() : nan);
      EmitExact(out, c.xy.allFinite() ? c.xy.y() : nan);
      out << c.id.x() << c.id.y() << (c.visible ? 1 : 0) << YAML::EndSeq;
    }
    out << YAML::EndSeq;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
  return std::string(
             "# Exact geometry of the rendered views. Pixels: the centre of "
             "the\n# top-left pixel is (0, 0). corners rows: [x, y, col, row, "
             "visible]\n# (x, y = .nan when the corner cannot be "
             "projected).\n") +
         out.c_str() + "\n";
}

bool ParseSceneTruth(const std::string& text, const std::string& source,
                     SceneTruth* truth, std::string* error) {
  YAML::Node root;
  if (!ParseYaml(text, source, &root, error)) return false;
  FieldReader r(source, error);
  SceneTruth t;
  YAML::Node camera, board, views;
  if (!r.Map(root, "") || !r.String(root, "", "scene", kRequired, &t.scene) ||
      !r.Child(root, "", "camera", kRequired, &camera) ||
      !ParseTruthCamera(camera, r, &t.camera) ||
      !r.Child(root, "", "board", kRequired, &board) ||
      !ParseBoardNode(board, "board", &r, &t.board) ||
      !r.List(root, "", "views", kRequired, &views)) {
    return false;
  }
  t.views.resize(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    if (!ParseTruthView(views[v], FieldReader::Index("views", v), r,
                        &t.views[v])) {
      return false;
    }
  }
  *truth = t;
  return true;
}

bool ReadSceneTruthFile(const std::string& path, SceneTruth* truth,
                        std::string* error) {
  std::string text;
  if (!ReadTextFile(path, &text, error)) return false;
  return ParseSceneTruth(text, path, truth, error);
}

std::string SceneRecipeYaml(const SceneSpec& scene) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << scene.name;
  out << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "model" << YAML::Value
      << CameraModelName(scene.camera.model);
  out << YAML::Key << "width" << YAML::Value << scene.camera.width;
  out << YAML::Key << "height" << YAML::Value << scene.camera.height;
  out << YAML::Key << "params" << YAML::Value;
  EmitExactFlow(out, scene.camera.params);
  std::string names;
  for (const std::string& name : CameraModelParamNames(scene.camera.model)) {
    names += (names.empty() ? "" : " ") + name;
  }
  out << YAML::Comment(names);
  out << YAML::EndMap;
  out << YAML::Key << "board" << YAML::Value;
  EmitBoardNode(out, scene.board);
  EmitRender(out, scene.render);
  if (!scene.views.empty()) {
    out << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
    for (const SceneViewSpec& view : scene.views) {
      out << YAML::BeginMap;
      out << YAML::Key << "name" << YAML::Value << view.name;
      EmitCamFromBoard(out, view.cam_from_board);
      if (!view.occluders.empty()) EmitOccluders(out, view.occluders);
      if (view.motion_blur.length_px > 0) {
        EmitMotionBlur(out, view.motion_blur);
      }
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  if (scene.random_views.count > 0) EmitRandomViews(out, scene.random_views);
  if (!scene.tilt_series.view_angles_deg.empty()) {
    const TiltSeries& tilt = scene.tilt_series;
    out << YAML::Key << "tilt_series" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "view_angles_deg" << YAML::Value;
    EmitExactFlow(out, tilt.view_angles_deg);
    EmitExactField(out, "distance_m", tilt.distance_m);
    EmitExactField(out, "tilt_direction_deg", tilt.tilt_direction_deg);
    out << YAML::EndMap;
  }
  if (!scene.tile_size_series.tile_px.empty()) {
    const TileSizeSeries& tiles = scene.tile_size_series;
    out << YAML::Key << "tile_size_series" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "tile_px" << YAML::Value;
    EmitExactFlow(out, tiles.tile_px);
    EmitExactField(out, "view_angle_deg", tiles.view_angle_deg);
    EmitExactField(out, "roll_deg", tiles.roll_deg);
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return "# Scene recipe '" + scene.name +
         "' (fields: configs/scenes/README.md).\n" + out.c_str() + "\n";
}

std::vector<std::string> BuiltInSceneNames() {
  std::vector<std::string> names = StandardSceneNames();
  names.push_back(kSampleSceneName);
  return names;
}

bool MakeBuiltInScene(const std::string& name, int width, int height,
                      SceneSpec* scene) {
  if (name == kSampleSceneName) {
    *scene =
        width > 0 && height > 0 ? SampleScene(width, height) : SampleScene();
    return true;
  }
  return MakeStandardScene(name, width, height, scene);
}

bool LoadScene(const std::string& name_or_path, int width, int height,
               SceneSpec* scene, std::string* error) {
  const std::vector<std::string> names = BuiltInSceneNames();
  if (std::find(names.begin(), names.end(), name_or_path) != names.end()) {
    return MakeBuiltInScene(name_or_path, width, height, scene);
  }
  if (width > 0 || height > 0) {
    return Fail(name_or_path +
                    ": an image size is for built-in scenes only (a recipe "
                    "file sets camera.width and camera.height)",
                error);
  }
  return LoadSceneFile(name_or_path, scene, error);
}

}  // namespace puzzlecal
