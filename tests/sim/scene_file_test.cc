#include "sim/scene_file.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "formats/board_file.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// A scratch folder removed at the end of the test.
class ConfigIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("puzzlecal_scene_file_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  fs::path dir_;
};

TEST_F(ConfigIoTest, AllShippedBoardFilesLoad) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator("configs/boards")) {
    if (entry.path().extension() != ".yaml") continue;
    Board board;
    std::string error;
    EXPECT_TRUE(LoadBoardFile(entry.path().string(), &board, &error)) << error;
    ++count;
  }
  EXPECT_GE(count, 4);
  Board board;
  std::string error;
  ASSERT_TRUE(LoadBoardFile("configs/boards/puzzleboard_23x16_30mm.yaml",
                            &board, &error))
      << error;
  EXPECT_EQ(board.type, BoardType::kPuzzleBoard);
  EXPECT_EQ(board.cols, 23);
  EXPECT_EQ(board.rows, 16);
  EXPECT_EQ(board.origin, Eigen::Vector2i(50, 100));
  EXPECT_DOUBLE_EQ(board.tile_size_m, 0.03);
  ASSERT_TRUE(LoadBoardFile(
      "configs/boards/deltille_checkerboard_11x8_20mm.yaml", &board, &error))
      << error;
  EXPECT_EQ(board.type, BoardType::kCheckerboard);
  EXPECT_EQ(board.cols, 11);
  EXPECT_EQ(board.rows, 8);
  EXPECT_DOUBLE_EQ(board.tile_size_m, 0.02);
}

TEST_F(ConfigIoTest, BrokenBoardFilesNameFileAndField) {
  struct Case {
    std::string text;
    std::string field;
  };
  const std::vector<Case> cases = {
      {"type: puzzle\ncols: 11\nrows: 8\ntile_size_m: 0.06\n", "type"},
      {"cols: 11\nrows: 8\ntile_size_m: 0.06\n", "type"},
      {"type: puzzleboard\ncols: eleven\nrows: 8\ntile_size_m: 0.06\n", "cols"},
      {"type: puzzleboard\ncols: 11\ntile_size_m: 0.06\n", "rows"},
      {"type: puzzleboard\ncols: 11\nrows: 8\ntile_size_m: -1\n",
       "tile_size_m"},
      {"type: puzzleboard\ncols: 11\nrows: 8\ntile_size_m: .nan\n",
       "tile_size_m"},
      {"type: puzzleboard\ncols: 11\nrows: 8\norigin: [0]\n"
       "tile_size_m: 0.06\n",
       "origin"},
      {"type: puzzleboard\ncols: 11\nrows: 8\norigin: [600, 0]\n"
       "tile_size_m: 0.06\n",
       "origin"},
      {"type: checkerboard\ncols: 11\nrows: 8\norigin: [1, 0]\n"
       "tile_size_m: 0.06\n",
       "origin"},
      {"type: puzzleboard\ncols: 1\nrows: 8\ntile_size_m: 0.06\n", "cols"},
      {"type: puzzleboard\ncols: 11\nrows: 8\ntile_size: 0.06\n", "tile_size"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string path =
        Write("board_" + std::to_string(i) + ".yaml", cases[i].text);
    Board board;
    std::string error;
    EXPECT_FALSE(LoadBoardFile(path, &board, &error)) << cases[i].text;
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find(cases[i].field), std::string::npos)
        << "case " << i << ": " << error;
  }
  Board board;
  std::string error;
  const std::string missing = (dir_ / "missing.yaml").string();
  EXPECT_FALSE(LoadBoardFile(missing, &board, &error));
  EXPECT_NE(error.find(missing), std::string::npos) << error;
  const std::string bad = Write("bad.yaml", "type: [unclosed\n");
  EXPECT_FALSE(LoadBoardFile(bad, &board, &error));
  EXPECT_NE(error.find(bad), std::string::npos) << error;
  const std::string empty = Write("empty.yaml", "");
  EXPECT_FALSE(LoadBoardFile(empty, &board, &error));
  EXPECT_NE(error.find(empty), std::string::npos) << error;
}

// Whether two scenes agree in everything that matters for rendering: the
// camera, the board, the render options, and every view (explicit and
// generated: name, pose, occluders), up to `tol` (0: exactly).
void ExpectSameScene(const SceneSpec& a, const SceneSpec& b, double tol,
                     const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.camera.model, b.camera.model);
  EXPECT_EQ(a.camera.width, b.camera.width);
  EXPECT_EQ(a.camera.height, b.camera.height);
  ASSERT_EQ(a.camera.params.size(), b.camera.params.size());
  for (size_t i = 0; i < a.camera.params.size(); ++i) {
    EXPECT_NEAR(a.camera.params[i], b.camera.params[i], tol) << "param " << i;
  }
  EXPECT_EQ(a.board.type, b.board.type);
  EXPECT_EQ(a.board.cols, b.board.cols);
  EXPECT_EQ(a.board.rows, b.board.rows);
  EXPECT_EQ(a.board.origin, b.board.origin);
  EXPECT_EQ(a.board.tile_size_m, b.board.tile_size_m);
  const RenderOptions& ra = a.render;
  const RenderOptions& rb = b.render;
  EXPECT_EQ(ra.supersampling, rb.supersampling);
  EXPECT_NEAR(ra.blur_sigma_px, rb.blur_sigma_px, tol);
  EXPECT_NEAR(ra.black_level, rb.black_level, tol);
  EXPECT_NEAR(ra.white_level, rb.white_level, tol);
  EXPECT_NEAR(ra.background_level, rb.background_level, tol);
  EXPECT_NEAR(ra.paper_margin_tiles, rb.paper_margin_tiles, tol);
  EXPECT_NEAR(ra.lighting_gradient, rb.lighting_gradient, tol);
  EXPECT_NEAR(ra.vignetting, rb.vignetting, tol);
  EXPECT_NEAR(ra.gamma, rb.gamma, tol);
  EXPECT_NEAR(ra.noise_sigma, rb.noise_sigma, tol);
  EXPECT_EQ(ra.seed, rb.seed);
  EXPECT_NEAR(ra.field_of_view_deg, rb.field_of_view_deg, tol);
  EXPECT_EQ(ra.occluders.size(), rb.occluders.size());
  EXPECT_EQ(ra.variant.random_code_seed, rb.variant.random_code_seed);
  EXPECT_EQ(ra.variant.mirrored, rb.variant.mirrored);
  EXPECT_EQ(ra.variant.inverted, rb.variant.inverted);
  EXPECT_EQ(a.views.size(), b.views.size());
  EXPECT_EQ(a.random_views.count, b.random_views.count);
  EXPECT_EQ(a.tilt_series.view_angles_deg.size(),
            b.tilt_series.view_angles_deg.size());
  EXPECT_EQ(a.tile_size_series.tile_px.size(),
            b.tile_size_series.tile_px.size());
  // The generated views: the random draws and the series, pose by pose.
  const std::vector<SceneViewSpec> va = SceneViewSpecs(a);
  const std::vector<SceneViewSpec> vb = SceneViewSpecs(b);
  ASSERT_EQ(va.size(), vb.size());
  for (size_t i = 0; i < va.size(); ++i) {
    EXPECT_EQ(va[i].name, vb[i].name);
    EXPECT_LE((va[i].cam_from_board.matrix() - vb[i].cam_from_board.matrix())
                  .cwiseAbs()
                  .maxCoeff(),
              tol)
        << "view " << va[i].name;
    ASSERT_EQ(va[i].occluders.size(), vb[i].occluders.size());
    for (size_t k = 0; k < va[i].occluders.size(); ++k) {
      EXPECT_LE((va[i].occluders[k].center_px - vb[i].occluders[k].center_px)
                    .cwiseAbs()
                    .maxCoeff(),
                tol);
      EXPECT_NEAR(va[i].occluders[k].radius_px, vb[i].occluders[k].radius_px,
                  tol);
      EXPECT_NEAR(va[i].occluders[k].grey, vb[i].occluders[k].grey, tol);
    }
  }
}

// View `i` of a scene as RenderScene renders it.
cv::Mat RenderOneView(const SceneSpec& scene, size_t i) {
  const std::vector<SceneViewSpec> specs = SceneViewSpecs(scene);
  RenderOptions options = scene.render;
  options.seed = scene.render.seed + i;
  options.occluders.insert(options.occluders.end(), specs[i].occluders.begin(),
                           specs[i].occluders.end());
  return RenderBoard(scene.board, scene.camera, specs[i].cam_from_board,
                     options);
}

// Every built-in scene written out as a recipe loads back as exactly that
// scene, and its recipe renders the same image (the last view: a generated
// one wherever the scene generates views).
TEST_F(ConfigIoTest, BuiltInScenesRoundTripThroughTheirRecipes) {
  const std::vector<std::string> names = BuiltInSceneNames();
  ASSERT_GE(names.size(), 8u);
  for (const std::string& name : names) {
    SceneSpec built_in;
    ASSERT_TRUE(MakeBuiltInScene(name, 0, 0, &built_in)) << name;
    const std::string path = Write(name + ".yaml", SceneRecipeYaml(built_in));
    SceneSpec loaded;
    std::string error;
    ASSERT_TRUE(LoadSceneFile(path, &loaded, &error)) << error;
    ExpectSameScene(loaded, built_in, 0.0, name);
    const size_t last = SceneViewSpecs(built_in).size() - 1;
    const cv::Mat a = RenderOneView(built_in, last);
    const cv::Mat b = RenderOneView(loaded, last);
    ASSERT_FALSE(a.empty()) << name;
    ASSERT_EQ(a.size(), b.size()) << name;
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0) << name;
    EXPECT_GT(cv::countNonZero(a != a.at<uchar>(0, 0)), 0)
        << name << ": a blank image proves nothing";
  }
  // Another size renders another camera; unknown names are refused.
  SceneSpec small, unknown;
  ASSERT_TRUE(MakeBuiltInScene("wide_pinhole", 320, 240, &small));
  EXPECT_EQ(small.camera.width, 320);
  EXPECT_FALSE(MakeBuiltInScene("wide_pinhol", 0, 0, &unknown));
}

// A scene with every field the recipe writes away from its default (the
// built-ins leave some at theirs), so a field the writer forgot would show.
TEST_F(ConfigIoTest, EveryRecipeFieldRoundTrips) {
  SceneSpec scene = WidePinholeScene(96, 72);
  scene.name = "every: \"field\" #";
  scene.board.origin = Eigen::Vector2i(11, 13);
  RenderOptions& o = scene.render;
  o.supersampling = 3;
  o.blur_sigma_px = 0.9;
  o.black_level = 0.11;
  o.white_level = 0.87;
  o.background_level = 0.31;
  o.paper_margin_tiles = 0.6;
  o.lighting_gradient = 0.2;
  o.vignetting = 0.25;
  o.gamma = 1.7;
  o.noise_sigma = 0.01;
  o.seed = 12345678901234ull;
  o.field_of_view_deg = 120.0 / 7.0 * 7.0 + 1.0 / 3.0;
  o.occluders = {{Eigen::Vector2d(10.1, 20.2), 3.3, 0.25}};
  o.motion_blur = {3.25, 17.0 / 3.0};
  o.variant.random_code_seed = 99;
  o.variant.mirrored = true;
  o.variant.inverted = true;
  SceneViewSpec view;
  view.name = "explicit";
  view.cam_from_board.linear() =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  view.cam_from_board.translation() = Eigen::Vector3d(-0.3, -0.2, 0.9);
  view.occluders = {{Eigen::Vector2d(40.0 / 3.0, 7.0), 5.0, 0.75}};
  view.motion_blur = {7.5, -40};  // this view's own, over the scene's
  scene.views = {view};
  RandomViews& rv = scene.random_views;
  rv.count = 2;
  rv.seed = 77;
  rv.min_distance_m = 0.7;
  rv.max_distance_m = 1.1;
  rv.min_view_angle_deg = 50;
  rv.max_view_angle_deg = 80;
  rv.max_roll_deg = 25;
  rv.max_off_axis_deg = 10;
  rv.target_margin_tiles = 1.5;
  rv.occluders_per_view = 2;
  rv.min_occluder_radius_px = 3;
  rv.max_occluder_radius_px = 6;
  scene.tilt_series = {{90, 70}, 0.95, 30};
  scene.tile_size_series = {{6, 9}, 80, 12};
  ASSERT_TRUE(scene.Check());

  const std::string text = SceneRecipeYaml(scene);
  SceneSpec loaded;
  std::string error;
  ASSERT_TRUE(LoadSceneFile(Write("every.yaml", text), &loaded, &error))
      << error << "\n"
      << text;
  ExpectSameScene(loaded, scene, 0.0, "every field");
  EXPECT_EQ(loaded.tilt_series.view_angles_deg,
            scene.tilt_series.view_angles_deg);
  EXPECT_EQ(loaded.tile_size_series.tile_px, scene.tile_size_series.tile_px);
  const size_t n = SceneViewSpecs(scene).size();
  ASSERT_EQ(n, 7u);
  for (size_t i = 0; i < n; ++i) {
    EXPECT_EQ(cv::norm(RenderOneView(scene, i), RenderOneView(loaded, i),
                       cv::NORM_INF),
              0)
        << "view " << i;
  }
}

// By name: a built-in at its own size or another; otherwise a recipe file,
// whose size is its own.
TEST_F(ConfigIoTest, LoadSceneTakesANameOrARecipe) {
  SceneSpec scene;
  std::string error;
  ASSERT_TRUE(LoadScene("dark_fisheye", 0, 0, &scene, &error)) << error;
  EXPECT_EQ(scene.camera.width, 800);
  ASSERT_TRUE(LoadScene("dark_fisheye", 1600, 1200, &scene, &error)) << error;
  EXPECT_EQ(scene.camera.height, 1200);
  ASSERT_TRUE(LoadScene("testdata/sample_scene.yaml", 0, 0, &scene, &error))
      << error;
  EXPECT_EQ(scene.name, "sample");
  EXPECT_FALSE(
      LoadScene("testdata/sample_scene.yaml", 640, 480, &scene, &error));
  EXPECT_NE(error.find("built-in"), std::string::npos) << error;
  EXPECT_FALSE(LoadScene("no_such_scene", 0, 0, &scene, &error));
  EXPECT_NE(error.find("no_such_scene: cannot open"), std::string::npos)
      << error;
}

// The recipes kept as files (those that are not built-ins, and the demo's
// sample recipe) load and equal their C++ definition at their size.
TEST_F(ConfigIoTest, ShippedRecipesEqualTheirBuiltIns) {
  std::vector<fs::path> recipes = {"testdata/sample_scene.yaml"};
  for (const auto& entry : fs::directory_iterator("configs/scenes")) {
    if (entry.path().extension() == ".yaml") recipes.push_back(entry.path());
  }
  int compared = 0;
  for (const fs::path& path : recipes) {
    SceneSpec loaded;
    std::string error;
    ASSERT_TRUE(LoadSceneFile(path.string(), &loaded, &error)) << error;
    SceneSpec built_in;
    if (!MakeBuiltInScene(loaded.name, loaded.camera.width,
                          loaded.camera.height, &built_in)) {
      continue;  // a recipe of its own
    }
    // Hand-written numbers (a focal length from a field of view) agree to
    // the digits the file holds.
    ExpectSameScene(loaded, built_in, 1e-9, path.string());
    ++compared;
  }
  // The sample recipe at least is a built-in's: something was compared.
  EXPECT_GE(compared, 1);
}

TEST_F(ConfigIoTest, InlineBoardExplicitPosesAndVariants) {
  const std::string path = Write("scene.yaml", R"(
name: custom
camera: {model: pinhole-rational, width: 64, height: 48,
         params: [50, 50, 31.5, 23.5, 0, 0, 0, 0, 0, 0, 0, 0]}
board: {type: puzzleboard, cols: 5, rows: 4, origin: [10, 20],
        tile_size_m: 0.02}
render:
  supersampling: 2
  variant: {random_code_seed: 7, mirrored: true, inverted: false}
  occluders: [{center_px: [10, 10], radius_px: 3, grey: 0.2}]
views:
  - name: a
    cam_from_board: {rotation: [1, 0, 0, 0, 1, 0, 0, 0, 1],
                     translation: [-0.24, -0.43, 0.3]}
)");
  SceneSpec scene;
  std::string error;
  ASSERT_TRUE(LoadSceneFile(path, &scene, &error)) << error;
  EXPECT_EQ(scene.camera.model, CameraModelId::kPinholeRational);
  EXPECT_EQ(scene.board.origin, Eigen::Vector2i(10, 20));
  EXPECT_EQ(scene.render.variant.random_code_seed, 7u);
  EXPECT_TRUE(scene.render.variant.mirrored);
  ASSERT_EQ(scene.render.occluders.size(), 1u);
  ASSERT_EQ(scene.views.size(), 1u);
  EXPECT_DOUBLE_EQ(scene.views[0].cam_from_board.translation().z(), 0.3);
  const std::vector<SceneView> views = RenderScene(scene, &error);
  ASSERT_EQ(views.size(), 1u) << error;

  // truth.yaml round trip: the corners parse back with their ids.
  const std::string truth = SceneTruthYaml(scene, views, {"custom_a.png"});
  const YAML::Node root = YAML::Load(truth);
  EXPECT_EQ(root["camera"]["model"].as<std::string>(), "pinhole-rational");
  EXPECT_EQ(root["camera"]["params"].size(), 12u);
  const YAML::Node view = root["views"][0];
  EXPECT_EQ(view["file"].as<std::string>(), "custom_a.png");
  EXPECT_EQ(view["cam_from_board"]["rotation"].size(), 9u);
  ASSERT_EQ(view["corners"].size(), 20u);
  const YAML::Node first = view["corners"][0];
  EXPECT_EQ(first[2].as<int>(), 10);
  EXPECT_EQ(first[3].as<int>(), 20);
  EXPECT_NEAR(first[0].as<double>(), views[0].truth.corners[0].xy.x(), 1e-12);
}

// The bits of a double (so -0.0 differs from 0.0 and NaN equals NaN).
uint64_t Bits(double value) {
  uint64_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}

// Names with quotes, colons and '#' (which a hand-written YAML line would
// cut or misread) and doubles that need all 17 digits, -0, a subnormal and
// .nan read back exactly.
TEST_F(ConfigIoTest, TruthReadsBackExactlyWithAwkwardNames) {
  SceneSpec scene;
  scene.name = "it's \"odd\": #1";
  scene.camera.model = CameraModelId::kPinholeRadtan;
  scene.camera.width = 64;
  scene.camera.height = 48;
  scene.camera.params = {100.0 / 3.0, 0.1,   31.5,   23.5,     -0.0,
                         5e-324,      1e300, -1e-17, 0.1 + 0.2};
  scene.board.type = BoardType::kPuzzleBoard;
  scene.board.cols = 3;
  scene.board.rows = 2;
  scene.board.origin = Eigen::Vector2i(7, 9);
  scene.board.tile_size_m = 0.1 + 0.2;
  std::vector<SceneView> views(2);
  views[0].name = "a: \"b\" # c";
  views[1].name = "'single' #";
  views[0].truth.cam_from_board.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())
          .toRotationMatrix();
  views[0].truth.cam_from_board.translation() =
      Eigen::Vector3d(1.0 / 7.0, -2.0 / 3.0, 0.6);
  for (int k = 0; k < 3; ++k) {
    TruthCorner corner;
    corner.id = Eigen::Vector2i(7 + k, 9);
    corner.xy = Eigen::Vector2d(10.0 / (k + 3), M_PI * k);
    corner.visible = k != 1;
    views[0].truth.corners.push_back(corner);
  }
  TruthCorner hidden;
  hidden.xy = Eigen::Vector2d(NAN, NAN);  // behind the camera
  hidden.id = Eigen::Vector2i(8, 10);
  views[1].truth.corners.push_back(hidden);
  const std::vector<std::string> files = {"x'y: \"z\" #0.png", "#: .png"};

  const std::string path =
      Write("truth.yaml", SceneTruthYaml(scene, views, files));
  SceneTruth truth;
  std::string error;
  ASSERT_TRUE(ReadSceneTruthFile(path, &truth, &error)) << error;
  EXPECT_EQ(truth.scene, scene.name);
  EXPECT_EQ(truth.camera.model, scene.camera.model);
  EXPECT_EQ(truth.camera.width, 64);
  ASSERT_EQ(truth.camera.params.size(), scene.camera.params.size());
  for (size_t i = 0; i < scene.camera.params.size(); ++i) {
    EXPECT_EQ(Bits(truth.camera.params[i]), Bits(scene.camera.params[i]))
        << "param " << i << ": " << truth.camera.params[i];
  }
  EXPECT_EQ(truth.board.origin, scene.board.origin);
  EXPECT_EQ(Bits(truth.board.tile_size_m), Bits(scene.board.tile_size_m));
  ASSERT_EQ(truth.views.size(), 2u);
  for (size_t v = 0; v < 2; ++v) {
    EXPECT_EQ(truth.views[v].file, files[v]);
    EXPECT_EQ(truth.views[v].name, views[v].name);
    for (int k = 0; k < 16; ++k) {
      EXPECT_EQ(Bits(truth.views[v].cam_from_board.matrix()(k)),
                Bits(views[v].truth.cam_from_board.matrix()(k)));
    }
    ASSERT_EQ(truth.views[v].corners.size(), views[v].truth.corners.size());
    for (size_t c = 0; c < views[v].truth.corners.size(); ++c) {
      const TruthCorner& read = truth.views[v].corners[c];
      const TruthCorner& written = views[v].truth.corners[c];
      EXPECT_EQ(Bits(read.xy.x()), Bits(written.xy.x()));
      EXPECT_EQ(Bits(read.xy.y()), Bits(written.xy.y()));
      EXPECT_EQ(read.id, written.id);
      EXPECT_EQ(read.visible, written.visible);
    }
  }
  // A broken truth file is named with its field.
  const std::string broken = Write("broken.yaml",
                                   "scene: x\ncamera: {model: pinhole-radtan, "
                                   "width: 64, height: 48, params: [1, 2]}\n");
  EXPECT_FALSE(ReadSceneTruthFile(broken, &truth, &error));
  EXPECT_NE(error.find(broken + ": field 'camera.params': must hold 9"),
            std::string::npos)
      << error;
}

TEST_F(ConfigIoTest, BrokenScenesNameFileAndField) {
  struct Case {
    std::string text;
    std::string field;
  };
  const std::string camera =
      "camera: {model: pinhole-radtan, width: 64, height: 48}\n";
  const std::string board = "board: ../no_such_board.yaml\n";
  const std::string inline_board =
      "board: {type: checkerboard, cols: 4, rows: 3, tile_size_m: 0.02}\n";
  const std::string tilt =
      "tilt_series: {view_angles_deg: [90], distance_m: 0.5}\n";
  const std::vector<Case> cases = {
      {camera + inline_board + tilt, "name"},
      {"name: x\n" + inline_board + tilt, "camera"},
      {"name: x\ncamera: {model: pinhole, width: 64, height: 48}\n" +
           inline_board + tilt,
       "camera.model"},
      {"name: x\ncamera: {model: kannala-brandt, width: 64, height: 48, "
       "params: [1, 2]}\n" +
           inline_board + tilt,
       "camera.params"},
      {"name: x\n" + camera + board + tilt, "board"},
      {"name: x\n" + camera + inline_board + "render: {blur_sigma_px: -1}\n" +
           tilt,
       "render.blur_sigma_px"},
      {"name: x\n" + camera + inline_board + "render: {blur: 1}\n" + tilt,
       "render.blur"},
      {"name: x\n" + camera + inline_board, "views"},
      {"name: x\n" + camera + inline_board +
           "tilt_series: {view_angles_deg: [95], distance_m: 0.5}\n",
       "tilt_series"},
      {"name: x\n" + camera + inline_board +
           "views: [{name: a, pose: {target: [1, 1]}}]\n",
       "views[0].pose.distance_m"},
      {"name: x\n" + camera + inline_board +
           "views: [{name: a, cam_from_board: {rotation: [2, 0, 0, 0, 1, 0, "
           "0, 0, 1], translation: [0, 0, 1]}}]\n",
       "views[0].cam_from_board.rotation"},
      {"name: x\n" + camera + inline_board + "random_views: {count: 3}\n",
       "random_views.seed"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string path =
        Write("scene_" + std::to_string(i) + ".yaml", cases[i].text);
    SceneSpec scene;
    std::string error;
    EXPECT_FALSE(LoadSceneFile(path, &scene, &error)) << cases[i].text;
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find(cases[i].field), std::string::npos)
        << "case " << i << ": " << error;
  }
}

}  // namespace
}  // namespace puzzlecal
