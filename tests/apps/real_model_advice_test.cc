// On real photo sets: `--model auto` picks a pinhole model for the pinhole
// cameras, and the verdict never recommends a model that the held-out
// comparison rejected (for whatever model the user calibrated with). The
// sets: BoofCV-Data's sony compact camera, each camera of the bb2 stereo
// head and the bfish fisheye (../shared/real, README there), and the
// deltille fisheye photos. Each skips when its photos are absent.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/model_advice.h"
#include "evidence/model_selection.h"
#include "evidence/verdict.h"
#include "formats/board_file.h"
#include "formats/image_io.h"
#include "pipeline/pipeline.h"
#include "tests/support/deltille_data.h"
#include "tests/support/shared_data.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

struct RealSet {
  std::string name;
  std::string images;  // folder
  std::string board;   // board file
  bool pinhole = false;
};

std::vector<RealSet> RealSets() {
  std::vector<RealSet> sets;
  const std::string real = testing_data::SharedFolder("real");
  if (!real.empty()) {
    sets.push_back(
        {"sony", real + "/sony/images", real + "/sony/board.yaml", true});
    sets.push_back(
        {"bb2 cam0", real + "/bb2/rig/cam0", real + "/bb2/board.yaml", true});
    sets.push_back(
        {"bb2 cam1", real + "/bb2/rig/cam1", real + "/bb2/board.yaml", true});
    sets.push_back(
        {"bfish", real + "/bfish/images", real + "/bfish/board.yaml", false});
  }
  const std::string deltille = testing_data::DeltilleFolder();
  if (!deltille.empty()) {
    sets.push_back({"deltille", deltille,
                    "configs/boards/deltille_checkerboard_11x8_20mm.yaml",
                    false});
  }
  return sets;
}

bool LoadViews(const RealSet& set, std::vector<CalibrationView>* views,
               int* width, int* height, std::string* error) {
  Board board;
  ImageListing listing;
  if (!LoadBoardFile(set.board, &board, error) ||
      !ListImages(set.images, &listing, error)) {
    return false;
  }
  std::vector<ImageResult> images =
      ProcessImageFiles(listing.images, board, PipelineOptions(), 0);
  *views = MakeCalibrationViews(board, &images, width, height);
  return !views->empty();
}

// The verdict on `result` as `calibrate` gives it: the evidence, the
// verdict and its model advice checked on held-out views (`selection`:
// the auto run's comparison, or null to compare the two models afresh).
Verdict JudgedVerdict(const std::vector<CalibrationView>& views,
                      const CalibrationResult& result,
                      const CalibrationOptions& calibration,
                      const ModelSelectionOptions& selection_options,
                      const ModelSelection* selection) {
  const EvidenceOptions evidence_options;
  Verdict verdict = MakeVerdict(
      result, ComputeEvidence(views, result, calibration, evidence_options),
      evidence_options, VerdictOptions());
  CheckModelAdvice(views, result, calibration, selection_options, selection,
                   &verdict);
  return verdict;
}

TEST(RealSets, AutoPicksPinholeForPinholeCamerasAndAdviceFollowsHeldOut) {
  const std::vector<RealSet> sets = RealSets();
  if (sets.empty()) {
    PUZZLECAL_SKIP_WITHOUT_DATA(
        std::string("no real photo set found (../shared/real; ") +
        testing_data::DeltilleHowToGet() + ")");
  }
  for (const RealSet& set : sets) {
    SCOPED_TRACE(set.name);
    std::vector<CalibrationView> views;
    int width = 0, height = 0;
    std::string error;
    ASSERT_TRUE(LoadViews(set, &views, &width, &height, &error)) << error;
    const CalibrationOptions calibration;
    const ModelSelectionOptions selection_options;
    ModelSelection selection;
    ASSERT_TRUE(SelectModel(views, width, height, calibration,
                            selection_options, &selection, &error))
        << error;
    const ModelCandidate& chosen = selection.candidates[selection.chosen];
    EXPECT_EQ(CameraModelIsPinhole(chosen.model), set.pinhole)
        << selection.Table();
    // Whatever model the user calibrates with: a model the verdict still
    // recommends must beat it on the held-out views.
    for (const ModelCandidate& current : selection.candidates) {
      if (!current.ok) continue;
      SCOPED_TRACE(CameraModelName(current.model));
      CalibrationResult result;
      if (!Calibrate(views, current.model, width, height, calibration, &result,
                     &error)) {
        continue;
      }
      const bool auto_run = current.model == chosen.model;
      const Verdict verdict =
          JudgedVerdict(views, result, calibration, selection_options,
                        auto_run ? &selection : nullptr);
      if (verdict.suggested_model.empty()) continue;
      CameraModelId suggested;
      ASSERT_TRUE(CameraModelIdFromName(verdict.suggested_model, &suggested));
      const ModelCandidate* challenger = selection.Find(suggested);
      ASSERT_NE(challenger, nullptr) << verdict.Line();
      EXPECT_TRUE(BeatsOnHeldOutViews(*challenger, current, selection_options))
          << verdict.Line() << "\n"
          << selection.Table();
      // The model auto chose is never sent on to another.
      EXPECT_FALSE(auto_run) << verdict.Line() << "\n" << selection.Table();
      // A lens within the conventional field is never called a fisheye.
      if (set.pinhole) {
        EXPECT_TRUE(CameraModelIsPinhole(suggested)) << verdict.Line();
      }
    }
    // A pinhole model the comparison could not even fit (corners beyond
    // its field): when a calibration with it is written at all, its
    // verdict names the fisheye model that fits the held-out views, and
    // does not blame the photos (bfish with pinhole-radtan said
    // inconsistent-views: "retake").
    for (const ModelCandidate& current : selection.candidates) {
      if (current.ok || !CameraModelIsPinhole(current.model)) continue;
      SCOPED_TRACE(CameraModelName(current.model));
      CalibrationResult result;
      if (!Calibrate(views, current.model, width, height, calibration, &result,
                     &error)) {
        continue;
      }
      const Verdict verdict =
          JudgedVerdict(views, result, calibration, selection_options, nullptr);
      EXPECT_EQ(verdict.kind, VerdictKind::kModelError) << verdict.Line();
      CameraModelId suggested;
      ASSERT_TRUE(CameraModelIdFromName(verdict.suggested_model, &suggested))
          << verdict.Line();
      EXPECT_FALSE(CameraModelIsPinhole(suggested)) << verdict.Line();
      const ModelCandidate* fitted = selection.Find(suggested);
      ASSERT_NE(fitted, nullptr);
      EXPECT_TRUE(fitted->ok) << selection.Table();
    }
  }
}

}  // namespace
}  // namespace puzzlecal
