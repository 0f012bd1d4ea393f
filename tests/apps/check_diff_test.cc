// `puzzlecal check` and `puzzlecal diff` end to end on renders with known
// truth: a calibration re-checked on new photos of the same lens (still
// valid) and of the lens with its focal length changed by 0.5 % (drifted,
// by what the truth implies); two calibrations compared against the
// difference of their truths; a comparison across models and formats; and
// the refusals of bad input. The program is the one built beside this test
// (<build>/apps/puzzlecal).

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "apps/subcommand.h"
#include "evidence/evidence.h"
#include "formats/camera_yaml.h"
#include "formats/png_writer.h"
#include "sim/scenes.h"
#include "tests/support/files.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace check_diff_test {
namespace {

namespace fs = std::filesystem;
using testing_program::ProgramRun;
using testing_program::Quote;

constexpr double kFocalChange = 1.005;

fs::path Scratch() {
  return fs::temp_directory_path() /
         ("puzzlecal_check_diff_test_" + std::to_string(getpid()));
}

[[maybe_unused]] const ::testing::Environment* const kCleanup =
    ::testing::AddGlobalTestEnvironment(
        new testing_program::RemoveAtEnd(Scratch()));

ProgramRun RunPuzzlecal(const std::string& arguments) {
  const ProgramRun run = testing_program::RunProgram(arguments, Scratch());
  std::cout << "$ puzzlecal " << arguments << "\n" << run.all();
  return run;
}

// The wide pinhole lens (100 deg, barrel distortion) at 640 x 480, its
// focal lengths scaled by `focal_scale`, `count` random views drawn with
// `seed`.
SceneSpec LensScene(double focal_scale, int count, uint64_t seed) {
  SceneSpec scene = WidePinholeScene(640, 480);
  scene.camera.params[0] *= focal_scale;
  scene.camera.params[1] *= focal_scale;
  scene.random_views.count = count;
  scene.random_views.seed = seed;
  scene.random_views.occluders_per_view = 1;
  return scene;
}

// Renders the scene's views into `dir` as PNG files.
void RenderInto(const SceneSpec& scene, const fs::path& dir) {
  fs::create_directories(dir);
  std::string error;
  const std::vector<SceneView> views = RenderScene(scene, &error);
  ASSERT_FALSE(views.empty()) << error;
  for (const SceneView& view : views) {
    ASSERT_TRUE(
        WritePngFile((dir / (view.name + ".png")).string(), view.image, &error))
        << error;
  }
}

// One band row of the program's projection-difference table.
struct BandRow {
  double lo = 0, hi = 0, median = 0, p95 = 0, max = 0;
  double expected_median = -1, expected_p95 = -1;  // -1: not printed
};

// The band rows of the program's output, by their lower edge.
std::map<int, BandRow> ParseBands(const std::string& text) {
  std::map<int, BandRow> rows;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    BandRow row;
    const int read =
        std::sscanf(line.c_str(), " %lf-%lf deg %lf %lf %lf %lf %lf", &row.lo,
                    &row.hi, &row.median, &row.p95, &row.max,
                    &row.expected_median, &row.expected_p95);
    if (read >= 5) rows[static_cast<int>(std::lround(row.lo))] = row;
  }
  return rows;
}

Camera ReadCamera(const fs::path& path, CameraFileStats* stats) {
  Camera camera;
  std::string error;
  EXPECT_TRUE(ReadCameraFile(path.string(), &camera, &error, stats)) << error;
  return camera;
}

// The photo sets and camera files the cases use, made on first use in this
// test process's folder (ctest runs every case as a process of its own, so
// each makes only what it needs): the original photos and their calibration
// (pinhole-radtan; kannala-brandt in the opencv format), new photos of the
// same lens, and photos of the lens with the focal length changed, with
// their calibration.
class CheckDiffTest : public ::testing::Test {
 protected:
  static const fs::path& Root() {
    static const fs::path root = Scratch() / "sets";
    return root;
  }
  static Camera Truth() { return LensScene(1.0, 14, 11).camera; }

  // The quoted path of `name` in the sets folder, made if missing.
  static std::string Path(const std::string& name) {
    const fs::path path = Root() / name;
    if (!fs::exists(path)) Make(name, path);
    return Quote(path.string());
  }
  static std::string Check(const std::string& camera, const std::string& set,
                           const std::string& extra = "") {
    return "check --camera " + Path(camera) + " --images " + Path(set) +
           " --board " + Path("board.yaml") + extra;
  }

 private:
  static void Make(const std::string& name, const fs::path& path) {
    fs::create_directories(Root());
    if (name == "board.yaml") {
      const Board& board = LensScene(1.0, 1, 1).board;
      testing_files::WriteFile(
          path, "type: puzzleboard\ncols: " + std::to_string(board.cols) +
                    "\nrows: " + std::to_string(board.rows) + "\norigin: [" +
                    std::to_string(board.origin.x()) + ", " +
                    std::to_string(board.origin.y()) + "]\ntile_size_m: " +
                    std::to_string(board.tile_size_m) + "\n");
    } else if (name == "original") {
      RenderInto(LensScene(1.0, 14, 11), path);
    } else if (name == "same") {
      RenderInto(LensScene(1.0, 10, 23), path);
    } else if (name == "changed") {
      RenderInto(LensScene(kFocalChange, 14, 23), path);
    } else {
      const std::string set = name == "changed.yaml" ? "changed" : "original";
      const std::string extra = name == "original_kb_opencv.yaml"
                                    ? " --model kannala-brandt --format opencv"
                                    : "";
      const ProgramRun run = RunPuzzlecal(
          "calibrate --quiet --images " + Path(set) + " --board " +
          Path("board.yaml") + " --out " + Quote(path.string()) + extra);
      ASSERT_EQ(run.exit_code, 0) << run.all();
    }
  }
};

TEST_F(CheckDiffTest, CheckOnNewPhotosOfTheSameLensIsStillValid) {
  const ProgramRun run = RunPuzzlecal(Check("original.yaml", "same"));
  EXPECT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_NE(run.out.find("verdict: still-valid"), std::string::npos);
  EXPECT_NE(run.out.find("0 of 10 views (0 %) worse than the stored noise"),
            std::string::npos);
  EXPECT_NE(run.out.find("covariance in the file"), std::string::npos);
}

TEST_F(CheckDiffTest, CheckThatCannotSeeADriftSaysNotEnoughData) {
  // The options file asks for a resolution of 0.001 px, which the ten new
  // photos do not give.
  const fs::path options = Scratch() / "fine.yaml";
  fs::create_directories(Scratch());
  testing_files::WriteFile(options, "check:\n  max_detectable_px: 0.001\n");
  const ProgramRun run = RunPuzzlecal(
      Check("original.yaml", "same", " --options " + Quote(options.string())));
  EXPECT_EQ(run.exit_code, kExitNoResult) << run.all();
  EXPECT_NE(run.out.find("verdict: not-enough-data — the new views "
                         "determine the projection only to"),
            std::string::npos);
}

// The calibration's own photos (the camera file lists them) fit it by
// construction: checked alone they give not-enough-data, saying why; mixed
// with new ones they are counted in the verdict's reason. A link to an own
// photo is that photo.
TEST_F(CheckDiffTest, CheckOnTheCalibrationsOwnPhotosSaysSo) {
  ProgramRun run = RunPuzzlecal(Check("original.yaml", "original"));
  EXPECT_EQ(run.exit_code, kExitNoResult) << run.all();
  EXPECT_NE(run.out.find("verdict: not-enough-data — every photo is one the "
                         "camera file was calibrated from"),
            std::string::npos)
      << run.out;
  const fs::path mixed = Scratch() / "mixed";
  fs::create_directories(mixed);
  const fs::path original = Root() / "original";
  const fs::path same = Root() / "same";
  Path("same");
  int linked = 0;
  for (const auto& entry : fs::directory_iterator(original)) {
    if (entry.path().extension() != ".png" || linked == 3) continue;
    fs::create_symlink(entry.path(),
                       mixed / ("own_" + entry.path().filename().string()));
    ++linked;
  }
  for (const auto& entry : fs::directory_iterator(same)) {
    if (entry.path().extension() != ".png") continue;
    fs::copy_file(entry.path(),
                  mixed / ("new_" + entry.path().filename().string()));
  }
  ASSERT_EQ(linked, 3);
  run = RunPuzzlecal("check --camera " + Path("original.yaml") + " --images " +
                     Quote(mixed.string()) + " --board " + Path("board.yaml"));
  EXPECT_NE(run.out.find("(3 of the 13 views are photos the camera file was "
                         "calibrated from, which cannot show a drift)"),
            std::string::npos)
      << run.out;
}

TEST_F(CheckDiffTest, CheckWithTheFocalLengthChangedHasDriftedByTheTruth) {
  const fs::path out = Scratch() / "check_out";
  const ProgramRun run = RunPuzzlecal(
      Check("original.yaml", "changed", " --out " + Quote(out.string())));
  ASSERT_EQ(run.exit_code, kExitDrifted) << run.all();
  ASSERT_NE(run.out.find("verdict: drifted"), std::string::npos);
  // "moved by up to X px (median of the LO-HI deg band"
  double moved = 0, lo = 0, hi = 0;
  const size_t at = run.out.find("moved by up to");
  ASSERT_NE(at, std::string::npos);
  ASSERT_EQ(std::sscanf(run.out.c_str() + at,
                        "moved by up to %lf px (median of the %lf-%lf deg",
                        &moved, &lo, &hi),
            3);
  // The truth's difference in that band, over the field the program
  // compared (the rows give it).
  const std::map<int, BandRow> rows = ParseBands(run.out);
  ASSERT_FALSE(rows.empty());
  const double field = rows.rbegin()->second.hi;
  Camera changed = Truth();
  changed.params[0] *= kFocalChange;
  changed.params[1] *= kFocalChange;
  const ProjectionDiff truth =
      ProjectionDifference(Truth(), changed, field, EvidenceOptions());
  ASSERT_TRUE(truth.ok) << truth.error;
  const int band = static_cast<int>(std::lround(lo / 10));
  ASSERT_LT(band, static_cast<int>(truth.difference_bands.size()));
  const double expected = truth.difference_bands[band].median;
  // The pixel radius of the band's rim: f x 0.5 % x that radius is about
  // the size of the change.
  std::cout << "drift reported " << moved << " px at " << lo << "-" << hi
            << " deg; the truths differ by " << expected << " px there\n";
  EXPECT_NEAR(moved, expected, 0.2 * expected);
  EXPECT_GT(moved, 0.5);
  EXPECT_TRUE(fs::exists(out / "projection_difference.png"));
  CameraFileStats stats;
  const Camera fresh = ReadCamera(out / "new_camera.yaml", &stats);
  EXPECT_NEAR(fresh.params[0] / changed.params[0], 1.0, 0.001);
  EXPECT_EQ(stats.covariance.rows(), 9);
}

TEST_F(CheckDiffTest, DiffOfACameraWithItselfIsZero) {
  const ProgramRun run = RunPuzzlecal("diff " + Path("original.yaml") + " " +
                                      Path("original.yaml"));
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_NE(run.out.find("rotation between the camera frames 0.0000 deg"),
            std::string::npos);
  const std::map<int, BandRow> rows = ParseBands(run.out);
  ASSERT_GE(rows.size(), 3u);
  for (const auto& [lo, row] : rows) {
    EXPECT_EQ(row.median, 0.0) << lo;
    EXPECT_EQ(row.max, 0.0) << lo;
    EXPECT_GT(row.expected_median, 0.0) << lo;
  }
}

TEST_F(CheckDiffTest, DiffOfTwoCalibrationsIsTheTruthsWithinTheirSigma) {
  const fs::path out = Scratch() / "diff_out";
  const ProgramRun run =
      RunPuzzlecal("diff " + Path("original.yaml") + " " +
                   Path("changed.yaml") + " --out " + Quote(out.string()));
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_TRUE(fs::exists(out / "projection_difference.png"));
  EXPECT_NE(run.out.find("within the field both calibrations observed"),
            std::string::npos);
  CameraFileStats a, b;
  ReadCamera(Root() / "original.yaml", &a);
  ReadCamera(Root() / "changed.yaml", &b);
  Camera changed = Truth();
  changed.params[0] *= kFocalChange;
  changed.params[1] *= kFocalChange;
  const ProjectionDiff truth = ProjectionDifference(
      Truth(), changed, std::min(a.max_field_angle_deg, b.max_field_angle_deg),
      EvidenceOptions());
  ASSERT_TRUE(truth.ok) << truth.error;
  const std::map<int, BandRow> rows = ParseBands(run.out);
  int judged = 0;
  for (const AngleBand& t : truth.difference_bands) {
    const auto it = rows.find(static_cast<int>(std::lround(t.lo_deg)));
    ASSERT_NE(it, rows.end()) << t.lo_deg;
    const BandRow& row = it->second;
    if (t.count < EvidenceOptions().min_bin_count) continue;
    ++judged;
    std::cout << t.lo_deg << " deg: truths " << t.median << " px, files "
              << row.median << " px, expected " << row.expected_median
              << " px\n";
    // Within 3 sigma, and the table's rounding to 0.001 px.
    EXPECT_NEAR(row.median, t.median, 3 * row.expected_median + 0.001)
        << t.lo_deg;
  }
  EXPECT_GE(judged, 3);
}

TEST_F(CheckDiffTest, DiffAcrossModelsAndFormats) {
  const fs::path out = Scratch() / "diff_models";
  const ProgramRun run = RunPuzzlecal("diff " + Path("original.yaml") + " " +
                                      Path("original_kb_opencv.yaml") +
                                      " --out " + Quote(out.string()));
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_NE(run.out.find("(kannala-brandt, 640 x 480), no uncertainty"),
            std::string::npos);
  EXPECT_NE(run.out.find("from A's covariance alone"), std::string::npos);
  EXPECT_NE(run.out.find("the files do not say where"), std::string::npos);
  const std::map<int, BandRow> rows = ParseBands(run.out);
  ASSERT_GE(rows.size(), 3u);
  // The two models of one lens agree near the axis.
  EXPECT_LT(rows.begin()->second.median, 0.2);
  EXPECT_TRUE(fs::exists(out / "projection_difference.png"));
}

// `text` without the top-level YAML fields `keys` (each with the lines
// indented under it), as a user trims a camera file by hand.
std::string WithoutFields(const std::string& text,
                          const std::vector<std::string>& keys) {
  std::istringstream lines(text);
  std::string out, line;
  bool skipping = false;
  while (std::getline(lines, line)) {
    if (!line.empty() && line[0] != ' ' && line[0] != '-' && line[0] != '#') {
      const std::string key = line.substr(0, line.find(':'));
      skipping = std::find(keys.begin(), keys.end(), key) != keys.end();
    }
    if (!skipping) out += line + "\n";
  }
  return out;
}

// A puzzlecal camera file trimmed of its covariance (and of every
// statistic: a hand-written camera) is still a camera: check, diff,
// undistort and advise --camera read it as one whose uncertainty is
// unknown, and check says in one line naming the file what that costs.
// (Each refused it before: "field 'parameter_covariance': expected 9 rows
// for pinhole-radtan, got 0".) Check on the changed lens still finds the
// drift, diff of a file with its trimmed copy is 0.
TEST_F(CheckDiffTest, CameraFilesWithoutCovarianceAreReadAsUncertaintyUnknown) {
  Path("original.yaml");
  const std::string written = testing_files::ReadFile(Root() / "original.yaml");
  ASSERT_NE(written.find("\nparameter_covariance:"), std::string::npos);
  const fs::path trimmed = Scratch() / "trimmed";
  fs::create_directories(trimmed);
  const fs::path no_covariance = trimmed / "no_covariance.yaml";
  const fs::path bare = trimmed / "bare.yaml";
  testing_files::WriteFile(no_covariance,
                           WithoutFields(written, {"parameter_covariance"}));
  testing_files::WriteFile(
      bare, WithoutFields(written,
                          {"parameter_stddev", "parameter_covariance", "rms_px",
                           "views_used", "corners_used", "outliers",
                           "max_field_angle_deg", "verdict", "views"}));
  ASSERT_EQ(testing_files::ReadFile(bare).find("rms_px"), std::string::npos);

  // check: still valid on new photos of the same lens, with the note.
  ProgramRun run = RunPuzzlecal(
      "check --camera " + Quote(no_covariance.string()) + " --images " +
      Path("same") + " --board " + Path("board.yaml"));
  EXPECT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_NE(run.out.find("verdict: still-valid"), std::string::npos);
  EXPECT_NE(run.out.find("parameter sigmas but no covariance in the file"),
            std::string::npos);
  EXPECT_NE(run.err.find(no_covariance.string() +
                         " has no parameter_covariance: the check cannot "
                         "judge drift against its uncertainty"),
            std::string::npos)
      << run.err;
  // ... and drifted on the changed lens, by the bare camera too.
  run = RunPuzzlecal("check --camera " + Quote(bare.string()) + " --images " +
                     Path("changed") + " --board " + Path("board.yaml"));
  EXPECT_EQ(run.exit_code, kExitDrifted) << run.all();
  EXPECT_NE(run.out.find("RMS not in the file, no uncertainty in the file"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.err.find(bare.string() + " has no parameter_covariance"),
            std::string::npos)
      << run.err;
  // The file with its covariance needs no note.
  run = RunPuzzlecal(Check("original.yaml", "same"));
  EXPECT_EQ(run.err.find("has no parameter_covariance"), std::string::npos)
      << run.err;

  // diff: the same camera, so 0 everywhere; B's uncertainty is named.
  run = RunPuzzlecal("diff " + Path("original.yaml") + " " +
                     Quote(no_covariance.string()));
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_NE(run.out.find("parameter sigmas without their covariance"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("from A's covariance alone"), std::string::npos);
  std::map<int, BandRow> rows = ParseBands(run.out);
  ASSERT_GE(rows.size(), 3u);
  for (const auto& [lo, row] : rows) EXPECT_EQ(row.max, 0.0) << lo;
  run = RunPuzzlecal("diff " + Quote(bare.string()) + " " +
                     Quote(no_covariance.string()));
  ASSERT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_NE(run.out.find("(pinhole-radtan, 640 x 480), no uncertainty"),
            std::string::npos)
      << run.out;

  // undistort and advise --camera take the camera as it is.
  const fs::path undistorted = Scratch() / "undistorted";
  run =
      RunPuzzlecal("undistort --camera " + Quote(bare.string()) + " --images " +
                   Path("same") + " --out " + Quote(undistorted.string()));
  EXPECT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_TRUE(fs::exists(undistorted / "undistorted_camera.yaml"));
  const fs::path advice = Scratch() / "advice";
  run = RunPuzzlecal("advise --camera " + Quote(no_covariance.string()) +
                     " --images " + Path("same") + " --board " +
                     Path("board.yaml") + " --out " + Quote(advice.string()));
  EXPECT_EQ(run.exit_code, kExitOk) << run.all();
  EXPECT_TRUE(fs::exists(advice / "advice.yaml"));
}

TEST_F(CheckDiffTest, BadInputIsNamedWithTheReason) {
  const fs::path bad = Scratch() / "bad";
  fs::create_directories(bad / "empty");
  testing_files::WriteFile(bad / "broken.yaml", "model: [unclosed\n");
  // An unreadable camera file.
  ProgramRun run = RunPuzzlecal(
      "check --camera " + Quote((bad / "broken.yaml").string()) + " --images " +
      Path("same") + " --board " + Path("board.yaml"));
  EXPECT_EQ(run.exit_code, kExitBadInput);
  EXPECT_NE(run.err.find((bad / "broken.yaml").string()), std::string::npos)
      << run.err;
  // A missing one.
  run = RunPuzzlecal("check --camera " + Quote((bad / "none.yaml").string()) +
                     " --images " + Path("same") + " --board " +
                     Path("board.yaml"));
  EXPECT_EQ(run.exit_code, kExitBadInput);
  EXPECT_NE(run.err.find((bad / "none.yaml").string()), std::string::npos);
  // An empty image folder.
  run = RunPuzzlecal(Check("original.yaml", "same") + " --images " +
                     Quote((bad / "empty").string()));
  EXPECT_EQ(run.exit_code, kExitBadInput);
  EXPECT_NE(run.err.find((bad / "empty").string()), std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("no image"), std::string::npos) << run.err;
  // diff: a broken file, a missing one, one file only.
  run = RunPuzzlecal("diff " + Path("original.yaml") + " " +
                     Quote((bad / "broken.yaml").string()));
  EXPECT_EQ(run.exit_code, kExitBadInput);
  EXPECT_NE(run.err.find((bad / "broken.yaml").string()), std::string::npos);
  run = RunPuzzlecal("diff " + Quote((bad / "none.yaml").string()) + " " +
                     Path("original.yaml"));
  EXPECT_EQ(run.exit_code, kExitBadInput);
  EXPECT_NE(run.err.find((bad / "none.yaml").string()), std::string::npos);
  run = RunPuzzlecal("diff " + Path("original.yaml"));
  EXPECT_EQ(run.exit_code, kExitUsage);
  run = RunPuzzlecal("diff a.yaml b.yaml c.yaml");
  EXPECT_EQ(run.exit_code, kExitUsage);
  EXPECT_NE(run.err.find("unexpected argument 'c.yaml'"), std::string::npos);
}

}  // namespace
}  // namespace check_diff_test
}  // namespace puzzlecal
