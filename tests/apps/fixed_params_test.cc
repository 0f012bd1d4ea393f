// Parameters held fixed and a known start (issue: workflows users expect):
// `--fix`, the options file's calibration.fixed_params, `--initial`, and
// calibrate-rig with known cameras fitting only the rig's poses. Rendered
// with truth (the sample scene, sim's stereo rig).

#include "apps/fixed_params.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "formats/camera_yaml.h"
#include "sim/rig_scenes.h"
#include "target/board.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using testing_program::ProgramRun;
using testing_program::Quote;

TEST(FixedParams, NamesAndGroupsExpandForTheModel) {
  std::vector<std::string> names;
  std::string error;
  ASSERT_TRUE(ExpandFixedParams("k3, p1,p2", CameraModelId::kPinholeRadtan,
                                &names, &error));
  EXPECT_EQ(names, (std::vector<std::string>{"k3", "p1", "p2"}));
  ASSERT_TRUE(ExpandFixedParams("distortion,focal",
                                CameraModelId::kKannalaBrandt, &names, &error));
  EXPECT_EQ(names,
            (std::vector<std::string>{"k1", "k2", "k3", "k4", "fx", "fy"}));
  ASSERT_TRUE(ExpandFixedParams("all,cx", CameraModelId::kPinholeRational,
                                &names, &error));
  EXPECT_EQ(names, CameraModelParamNames(CameraModelId::kPinholeRational));
  ASSERT_TRUE(
      ExpandFixedParams("", CameraModelId::kPinholeRadtan, &names, &error));
  EXPECT_TRUE(names.empty());
  EXPECT_FALSE(
      ExpandFixedParams("p1", CameraModelId::kKannalaBrandt, &names, &error));
  EXPECT_NE(error.find("'p1' is not a parameter of kannala-brandt"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("fx fy cx cy k1 k2 k3 k4"), std::string::npos) << error;
}

class FixedParamsRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ =
        new fs::path(fs::temp_directory_path() /
                     ("puzzlecal_fixed_params_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    const ProgramRun render = Run("render --scene sample --out " +
                                  Quote((*root_ / "images").string()));
    ASSERT_EQ(render.exit_code, 0) << render.all();
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  static ProgramRun Run(const std::string& arguments) {
    return testing_program::RunProgram(arguments, *root_ / "scratch");
  }
  // calibrate on the sample's photos into root/NAME.yaml with `extra`.
  static ProgramRun Calibrate(const std::string& name,
                              const std::string& extra) {
    return Run("calibrate --images " + Quote((*root_ / "images").string()) +
               " --board configs/boards/puzzleboard_23x16_30mm.yaml --out " +
               Quote(File(name)) + " --quiet " + extra);
  }
  static std::string File(const std::string& name) {
    return (*root_ / (name + ".yaml")).string();
  }
  static YAML::Node Load(const std::string& name) {
    return YAML::LoadFile(File(name));
  }
  static fs::path* root_;
};
fs::path* FixedParamsRun::root_ = nullptr;

TEST_F(FixedParamsRun, FixHoldsTheNamedParametersAtTheirStart) {
  const ProgramRun run = Calibrate("fix", "--fix k3,p1,p2");
  ASSERT_EQ(run.exit_code, 0) << run.all();
  const YAML::Node camera = Load("fix");
  for (const char* name : {"p1", "p2", "k3"}) {
    EXPECT_EQ(camera["parameters"][name].as<double>(), 0.0) << name;
    EXPECT_EQ(camera["parameter_stddev"][name].as<double>(), 0.0) << name;
  }
  // The free ones still move (the sample's k1 is -0.2).
  EXPECT_NEAR(camera["parameters"]["k1"].as<double>(), -0.2, 0.01);
  EXPECT_GT(camera["parameter_stddev"]["k1"].as<double>(), 0.0);

  // The options file's list does the same.
  const std::string options = (*root_ / "options.yaml").string();
  {
    std::ofstream out(options);
    out << "calibration:\n  fixed_params: [k3]\n";
  }
  const ProgramRun from_file =
      Calibrate("from_file", "--options " + Quote(options));
  ASSERT_EQ(from_file.exit_code, 0) << from_file.all();
  const YAML::Node held = Load("from_file");
  EXPECT_EQ(held["parameters"]["k3"].as<double>(), 0.0);
  EXPECT_NE(held["parameters"]["p1"].as<double>(), 0.0);
}

TEST_F(FixedParamsRun, InitialStartsFromAFileAndFixKeepsItsValues) {
  ASSERT_EQ(Calibrate("first", "").exit_code, 0);
  const YAML::Node first = Load("first");
  const ProgramRun run =
      Calibrate("second", "--initial " + Quote(File("first")) +
                              " --fix focal,principal-point");
  ASSERT_EQ(run.exit_code, 0) << run.all();
  const YAML::Node second = Load("second");
  for (const char* name : {"fx", "fy", "cx", "cy"}) {
    EXPECT_EQ(second["parameters"][name].as<double>(),
              first["parameters"][name].as<double>())
        << name;
  }
  EXPECT_GT(second["parameter_stddev"]["k1"].as<double>(), 0.0);
}

TEST_F(FixedParamsRun, BadRequestsAreUsageErrorsThatSayWhy) {
  ProgramRun run = Calibrate("bad", "--fix k9");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("'k9' is not a parameter of pinhole-radtan"),
            std::string::npos)
      << run.all();
  run = Calibrate("bad", "--fix all");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("nothing to calibrate"), std::string::npos)
      << run.all();
  ASSERT_EQ(Calibrate("start", "").exit_code, 0);
  run = Calibrate(
      "bad", "--initial " + Quote(File("start")) + " --model kannala-brandt");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("holds a pinhole-radtan camera"), std::string::npos)
      << run.all();
  run = Calibrate("bad", "--initial " + Quote(File("no_such_file")));
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_NE(run.err.find("no_such_file"), std::string::npos) << run.all();
  EXPECT_FALSE(fs::exists(File("bad")));
}

// Known cameras (the render's truth) and --fix all: only the rig's poses
// are fitted; cam_from_rig comes out at the truth, the intrinsics exactly
// as given.
TEST_F(FixedParamsRun, RigWithKnownCamerasFitsOnlyThePoses) {
  const RigSceneSpec scene = StereoPinholeRig();
  const fs::path images = *root_ / "rig";
  RigRenderSummary summary;
  std::string why;
  ASSERT_TRUE(RenderRigScene(scene, images.string(), &summary, &why)) << why;
  const std::string board = (*root_ / "rig_board.yaml").string();
  {
    std::ofstream out(board);
    out << "type: puzzleboard\ncols: " << scene.board.cols
        << "\nrows: " << scene.board.rows << "\norigin: ["
        << scene.board.origin.x() << ", " << scene.board.origin.y()
        << "]\ntile_size_m: " << scene.board.tile_size_m << "\n";
  }
  std::string initial;
  for (const RigSceneCamera& camera : scene.cameras) {
    const std::string file = File("truth_" + camera.name);
    ASSERT_TRUE(WriteCameraFile(file, CameraFileFormat::kPuzzlecal,
                                camera.camera, CameraFileStats(), &why))
        << why;
    initial += (initial.empty() ? "" : ",") + camera.name + "=" + file;
  }
  const std::string out = File("rig_known");
  const ProgramRun run =
      Run("calibrate-rig --images " + Quote(images.string()) + " --board " +
          Quote(board) + " --out " + Quote(out) + " --initial " +
          Quote(initial) + " --fix all");
  ASSERT_EQ(run.exit_code, 0) << run.all();
  EXPECT_NE(run.all().find("its intrinsics were given and held"),
            std::string::npos)
      << run.all();
  const YAML::Node rig = YAML::LoadFile(out);
  ASSERT_EQ(rig["cameras"].size(), scene.cameras.size());
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    const YAML::Node camera = rig["cameras"][c];
    const std::vector<std::string> names =
        CameraModelParamNames(scene.cameras[c].camera.model);
    for (size_t k = 0; k < names.size(); ++k) {
      EXPECT_EQ(camera["parameters"][names[k]].as<double>(),
                scene.cameras[c].camera.params[k])
          << names[k];
    }
    const std::vector<double> t =
        camera["cam_from_rig"]["t"].as<std::vector<double>>();
    const Eigen::Vector3d truth = scene.cameras[c].cam_from_rig.translation();
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(t[k], truth[k], 2e-4) << k;
  }
}

}  // namespace
}  // namespace puzzlecal
