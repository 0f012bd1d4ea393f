// The options file (apps/options_io.h): the written defaults read back as
// the defaults, a field set in the file changes that field and no other,
// bad files are refused with the file and the field named, and
// `puzzlecal calibrate --options` runs with what the file says (the program
// is the one built beside this test, run on testdata/sample).

#include "apps/options_io.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "apps/subcommand.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;
using testing_files::ReadFile;
using testing_files::WriteFile;
using testing_program::ProgramPath;
using testing_program::ProgramRun;
using testing_program::RunProgram;

class OptionsIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("puzzlecal_options_" + std::to_string(::getpid()) + "_" +
            info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // Writes `text` to NAME in the test folder; returns its path.
  std::string File(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    WriteFile(path, text);
    return path.string();
  }

  fs::path dir_;
};

// Options with a field of every group away from its default.
RunOptions Perturbed() {
  RunOptions o;
  o.pipeline.detector.num_levels = 3;
  o.pipeline.detector.subpixel = SubpixelMethod::kCentroid;
  o.pipeline.grid.merge.kruskal_passes = 3;
  o.pipeline.grid.off_lattice.enabled = false;
  o.pipeline.decode.bits.min_confidence = 0.25;
  o.pipeline.load.max_pixels = 1000;
  o.pipeline.min_corners = 9;
  o.calibration.outlier_k = 0;
  o.calibration.loss = RobustLoss::kCauchy;
  o.calibration.initialization.focal_search_steps = 30;
  o.evidence.report_angles_deg = {10.0, 20.0};
  o.verdict.min_views = 5;
  o.model_selection.candidates = {"kannala-brandt"};
  o.rig.min_shared_frames = 2;
  return o;
}

// The same fields as an options file.
constexpr char kPerturbedFile[] =
    "detector: {num_levels: 3, subpixel: centroid}\n"
    "grid:\n"
    "  merge: {kruskal_passes: 3}\n"
    "  off_lattice: {enabled: false}\n"
    "decode: {bits: {min_confidence: 0.25}}\n"
    "load: {max_pixels: 1000}\n"
    "pipeline: {min_corners: 9}\n"
    "calibration:\n"
    "  outlier_k: 0\n"
    "  loss: cauchy\n"
    "  initialization: {focal_search_steps: 30}\n"
    "evidence: {report_angles_deg: [10, 20]}\n"
    "verdict: {min_views: 5}\n"
    "model_selection: {candidates: [kannala-brandt]}\n"
    "rig: {min_shared_frames: 2}\n";

TEST_F(OptionsIoTest, WrittenDefaultsReadBackAsTheDefaults) {
  const RunOptions defaults;
  const std::string text = OptionsYaml(defaults);
  EXPECT_EQ(text, OptionsYaml(RunOptions()));  // the same text twice
  // Read over options that differ from the defaults: every field the
  // defaults file holds must be set by it.
  RunOptions read = Perturbed();
  std::string error;
  ASSERT_TRUE(LoadOptionsFile(File("defaults.yaml", text), &read, &error))
      << error;
  EXPECT_EQ(OptionsYaml(read), text);
  EXPECT_EQ(read.pipeline.detector.num_levels,
            defaults.pipeline.detector.num_levels);
  EXPECT_EQ(read.pipeline.detector.subpixel,
            defaults.pipeline.detector.subpixel);
  EXPECT_EQ(read.pipeline.detector.min_response,
            defaults.pipeline.detector.min_response);
  EXPECT_EQ(read.pipeline.grid.merge.kruskal_passes,
            defaults.pipeline.grid.merge.kruskal_passes);
  EXPECT_EQ(read.pipeline.grid.off_lattice.enabled,
            defaults.pipeline.grid.off_lattice.enabled);
  // 1/12 is not a short decimal: the writer's digits must read back exactly.
  EXPECT_EQ(read.pipeline.decode.bits.disc_sample_offset,
            defaults.pipeline.decode.bits.disc_sample_offset);
  EXPECT_EQ(read.pipeline.decode.bits.min_confidence,
            defaults.pipeline.decode.bits.min_confidence);
  EXPECT_EQ(read.pipeline.load.max_pixels, defaults.pipeline.load.max_pixels);
  EXPECT_EQ(read.pipeline.min_corners, defaults.pipeline.min_corners);
  EXPECT_EQ(read.calibration.outlier_k, defaults.calibration.outlier_k);
  EXPECT_EQ(read.calibration.loss, defaults.calibration.loss);
  EXPECT_EQ(read.calibration.initialization.focal_search_steps,
            defaults.calibration.initialization.focal_search_steps);
  EXPECT_EQ(read.evidence.report_angles_deg,
            defaults.evidence.report_angles_deg);
  EXPECT_EQ(read.verdict.min_views, defaults.verdict.min_views);
  EXPECT_EQ(read.model_selection.candidates,
            defaults.model_selection.candidates);
  EXPECT_EQ(read.rig.min_shared_frames, defaults.rig.min_shared_frames);
  // The fields that are flags only are not in the file.
  EXPECT_EQ(text.find("num_threads"), std::string::npos);
  EXPECT_EQ(text.find("run_decode"), std::string::npos);
  // The fixed parameters are the file's to set (--fix adds to them).
  EXPECT_NE(text.find("fixed_params: []"), std::string::npos);
  EXPECT_EQ(read.calibration.fixed_params, defaults.calibration.fixed_params);
}

TEST_F(OptionsIoTest, AFileChangesExactlyTheFieldsItSets) {
  RunOptions read;
  std::string error;
  ASSERT_TRUE(LoadOptionsFile(File("some.yaml", kPerturbedFile), &read, &error))
      << error;
  // The writer writes every field, so equal texts mean equal options.
  EXPECT_EQ(OptionsYaml(read), OptionsYaml(Perturbed()));
  EXPECT_NE(OptionsYaml(read), OptionsYaml(RunOptions()));
  EXPECT_EQ(read.pipeline.detector.subpixel, SubpixelMethod::kCentroid);
  EXPECT_EQ(read.pipeline.load.max_pixels, 1000);
  // A rig's cameras are calibrated with the calibration section.
  EXPECT_EQ(read.rig.camera.outlier_k, 0.0);
  EXPECT_EQ(read.rig.camera.initialization.focal_search_steps, 30);
  // Empty files and empty sections change nothing.
  RunOptions empty;
  ASSERT_TRUE(LoadOptionsFile(File("empty.yaml", ""), &empty, &error));
  ASSERT_TRUE(LoadOptionsFile(File("null.yaml", "grid:\n"), &empty, &error));
  EXPECT_EQ(OptionsYaml(empty), OptionsYaml(RunOptions()));
}

// Each refusal: false, the message names the file and the field, and the
// options are left as they were.
void ExpectRefused(const std::string& path, const std::string& field,
                   const std::string& also) {
  RunOptions options = Perturbed();
  std::string error;
  EXPECT_FALSE(LoadOptionsFile(path, &options, &error)) << path;
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find(field), std::string::npos) << error;
  EXPECT_NE(error.find(also), std::string::npos) << error;
  EXPECT_EQ(OptionsYaml(options), OptionsYaml(Perturbed()));
}

TEST_F(OptionsIoTest, BadFilesAreRefusedNamingTheFileAndTheField) {
  // Unknown keys, with the allowed names.
  ExpectRefused(File("typo.yaml", "grid:\n  merge:\n    kruskal_pases: 2\n"),
                "'grid.merge.kruskal_pases'", "kruskal_passes");
  ExpectRefused(File("section.yaml", "detection: {num_levels: 2}\n"),
                "'detection'", "detector");
  ExpectRefused(File("flag_only.yaml", "calibration: {num_threads: 4}\n"),
                "'calibration.num_threads'", "outlier_k");
  // Values of the wrong type.
  ExpectRefused(File("type.yaml", "calibration:\n  outlier_k: many\n"),
                "'calibration.outlier_k'", "many");
  ExpectRefused(File("int.yaml", "detector: {num_levels: 2.5}\n"),
                "'detector.num_levels'", "2.5");
  ExpectRefused(File("enum.yaml", "detector: {subpixel: fast}\n"),
                "'detector.subpixel'", "saddle-fit");
  ExpectRefused(File("group.yaml", "grid: {merge: 3}\n"), "'grid.merge'",
                "map");
  ExpectRefused(File("list.yaml", "evidence: {report_angles_deg: 30}\n"),
                "'evidence.report_angles_deg'", "list");
  // Values Check() refuses, with the section.
  ExpectRefused(File("range.yaml", "detector: {num_levels: 9}\n"),
                "section 'detector'", "num_levels");
  ExpectRefused(File("grid_range.yaml", "grid: {merge: {kruskal_passes: 0}}\n"),
                "section 'grid'", "kruskal_passes");
  ExpectRefused(
      File("calib_range.yaml",
           "calibration: {initialization: {max_focal_aspect: 0.5}}\n"),
      "section 'calibration'", "max_focal_aspect");
  ExpectRefused(
      File("model.yaml", "model_selection: {candidates: [fisheye]}\n"),
      "section 'model_selection'", "fisheye");
  // Not a file of fields at all.
  ExpectRefused(File("scalar.yaml", "42\n"), "", "map");
  ExpectRefused((dir_ / "missing.yaml").string(), "", "cannot open");
}

// ---- the program ----

class OptionsProgramTest : public OptionsIoTest {
 protected:
  ProgramRun Run(const std::string& arguments) const {
    return RunProgram(arguments, dir_);
  }

  ProgramRun Calibrate(const fs::path& out, const std::string& extra) const {
    return Run(
        "calibrate --images testdata/sample --board "
        "configs/boards/puzzleboard_23x16_30mm.yaml --threads 2 --out '" +
        out.string() + "' " + extra);
  }

  static int Outliers(const std::string& camera_file) {
    const size_t at = camera_file.find("\noutliers: ");
    return at == std::string::npos ? -1
                                   : std::atoi(camera_file.c_str() + at + 11);
  }
};

TEST_F(OptionsProgramTest, PrintsTheDefaultsAsAnOptionsFile) {
  ASSERT_TRUE(fs::exists(ProgramPath())) << ProgramPath();
  const ProgramRun run = Run("options");
  EXPECT_EQ(run.exit_code, kExitOk) << run.err;
  EXPECT_EQ(run.out, OptionsYaml(RunOptions()));
  const ProgramRun bad =
      Run("options --options '" + File("bad.yaml", "verdict: {x: 1}\n") + "'");
  EXPECT_EQ(bad.exit_code, kExitBadInput);
  EXPECT_NE(bad.err.find("'verdict.x'"), std::string::npos) << bad.err;
}

TEST_F(OptionsProgramTest, CalibrateRunsWithTheFilesOptions) {
  ASSERT_TRUE(fs::exists(ProgramPath())) << ProgramPath();
  const fs::path plain = dir_ / "plain.yaml";
  const ProgramRun base = Calibrate(plain, "");
  ASSERT_EQ(base.exit_code, kExitOk) << base.err;
  const std::string plain_camera = ReadFile(plain);
  // The sample set has a few rejected corners with the default outlier_k.
  ASSERT_GT(Outliers(plain_camera), 0) << plain_camera;

  // A file of the defaults: the same camera file, byte for byte.
  const std::string defaults = File("defaults.yaml", OptionsYaml(RunOptions()));
  const fs::path same = dir_ / "same.yaml";
  const ProgramRun with_defaults =
      Calibrate(same, "--options '" + defaults + "'");
  ASSERT_EQ(with_defaults.exit_code, kExitOk) << with_defaults.err;
  EXPECT_EQ(ReadFile(same), plain_camera);

  // outlier_k 0 turns the rejection off: no outliers, another result.
  const std::string no_rejection =
      File("no_rejection.yaml", "calibration: {outlier_k: 0}\n");
  const fs::path changed = dir_ / "changed.yaml";
  const ProgramRun without = Calibrate(changed, "--options " + no_rejection);
  ASSERT_EQ(without.exit_code, kExitOk) << without.err;
  const std::string changed_camera = ReadFile(changed);
  EXPECT_EQ(Outliers(changed_camera), 0) << changed_camera;
  EXPECT_NE(changed_camera, plain_camera);

  // A bad file: exit 3 before any image is read, nothing written.
  const fs::path none = dir_ / "none.yaml";
  const std::string bad = File("bad.yaml", "calibration: {outlier_k: -1}\n");
  const ProgramRun refused = Calibrate(none, "--options " + bad);
  EXPECT_EQ(refused.exit_code, kExitBadInput);
  EXPECT_NE(refused.err.find(bad), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("outlier_k"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(none));
}

TEST_F(OptionsProgramTest, DetectRunsWithTheFilesOptions) {
  ASSERT_TRUE(fs::exists(ProgramPath())) << ProgramPath();
  const std::string image = "testdata/sample/sample_view_000.png";
  const fs::path plain = dir_ / "plain.yaml";
  ASSERT_EQ(Run("detect --images " + image + " --out '" + plain.string() + "'")
                .exit_code,
            kExitOk);
  // A response threshold no corner reaches: no corners.
  const std::string strict =
      File("strict.yaml", "detector: {min_response: 1000}\n");
  const fs::path none = dir_ / "none.yaml";
  const ProgramRun run = Run("detect --images " + image + " --out '" +
                             none.string() + "' --options " + strict);
  ASSERT_EQ(run.exit_code, kExitOk) << run.err;
  EXPECT_NE(ReadFile(plain).find("corners:\n      - ["), std::string::npos);
  EXPECT_NE(ReadFile(none).find("corners:\n      []"), std::string::npos)
      << ReadFile(none);
}

}  // namespace
}  // namespace puzzlecal
