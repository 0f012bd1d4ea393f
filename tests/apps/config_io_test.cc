#include "apps/config_io.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// A scratch folder removed at the end of the test.
class ConfigIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("puzzlecal_config_io_" + std::to_string(::getpid()) + "_" +
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

// Every shipped recipe loads and equals its C++ factory at the recipe's size.
TEST_F(ConfigIoTest, ShippedScenesEqualTheirFactories) {
  int count = 0;
  std::vector<fs::path> recipes = {"testdata/sample_scene.yaml"};
  for (const auto& entry : fs::directory_iterator("configs/scenes")) {
    recipes.push_back(entry.path());
  }
  std::sort(recipes.begin(), recipes.end());
  for (const fs::path& path : recipes) {
    const fs::directory_entry entry(path);
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    SceneSpec loaded;
    std::string error;
    ASSERT_TRUE(LoadSceneFile(entry.path().string(), &loaded, &error)) << error;
    SceneSpec factory;
    if (loaded.name == "sample") {
      factory = SampleScene(loaded.camera.width, loaded.camera.height);
    } else {
      ASSERT_TRUE(MakeStandardScene(loaded.name, loaded.camera.width,
                                    loaded.camera.height, &factory))
          << entry.path() << ": no factory named " << loaded.name;
    }
    EXPECT_EQ(loaded.camera.model, factory.camera.model);
    ASSERT_EQ(loaded.camera.params.size(), factory.camera.params.size());
    for (size_t i = 0; i < factory.camera.params.size(); ++i) {
      EXPECT_NEAR(loaded.camera.params[i], factory.camera.params[i], 1e-9)
          << entry.path() << " param " << i;
    }
    EXPECT_EQ(loaded.board.type, factory.board.type);
    EXPECT_EQ(loaded.board.cols, factory.board.cols);
    EXPECT_EQ(loaded.board.origin, factory.board.origin);
    EXPECT_DOUBLE_EQ(loaded.board.tile_size_m, factory.board.tile_size_m);
    const RenderOptions& a = loaded.render;
    const RenderOptions& b = factory.render;
    EXPECT_EQ(a.supersampling, b.supersampling);
    EXPECT_DOUBLE_EQ(a.blur_sigma_px, b.blur_sigma_px) << entry.path();
    EXPECT_DOUBLE_EQ(a.black_level, b.black_level);
    EXPECT_DOUBLE_EQ(a.white_level, b.white_level);
    EXPECT_DOUBLE_EQ(a.background_level, b.background_level);
    EXPECT_DOUBLE_EQ(a.lighting_gradient, b.lighting_gradient);
    EXPECT_DOUBLE_EQ(a.vignetting, b.vignetting);
    EXPECT_DOUBLE_EQ(a.noise_sigma, b.noise_sigma);
    EXPECT_DOUBLE_EQ(a.field_of_view_deg, b.field_of_view_deg);
    const std::vector<SceneViewSpec> va = SceneViewSpecs(loaded);
    const std::vector<SceneViewSpec> vb = SceneViewSpecs(factory);
    ASSERT_EQ(va.size(), vb.size()) << entry.path();
    for (size_t i = 0; i < va.size(); ++i) {
      EXPECT_EQ(va[i].name, vb[i].name);
      EXPECT_LT((va[i].cam_from_board.matrix() - vb[i].cam_from_board.matrix())
                    .norm(),
                1e-9)
          << entry.path() << " view " << va[i].name;
      EXPECT_EQ(va[i].occluders.size(), vb[i].occluders.size());
    }
  }
  EXPECT_GE(count, 6);
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
