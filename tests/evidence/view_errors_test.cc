// View-level errors: a board bent by a few mm in two photos (sim/
// view_faults.h, with truth) is named as a view-level error of those
// photos, not as outliers or a model error; the clean scene is good.

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/model_advice.h"
#include "evidence/verdict.h"
#include "evidence/view_consistency.h"
#include "sim/synthetic_views.h"
#include "sim/view_faults.h"
#include "tests/evidence/judge.h"

namespace puzzlecal {
namespace {

using sim::SyntheticData;
using sim::SyntheticScene;
using testing_judge::JudgeAsTheProgram;
using testing_judge::Judged;
using testing_judge::TiltedScene;

TEST(ViewErrors, CleanSceneIsGood) {
  const SyntheticScene scene = TiltedScene(sim::TruthRadtan(), 24, 0.15, 7);
  const Judged judged =
      JudgeAsTheProgram(sim::MakeSyntheticData(scene), scene.camera);
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kGood) << judged.verdict.Line();
}

// Two photos of a board bent by 4 mm (a bowl; a twist): view-errors naming
// exactly those photos; no bad-detections finding for their corners.
TEST(ViewErrors, BentBoardInTwoPhotosIsAViewLevelError) {
  for (const sim::BoardWarp warp :
       {sim::BoardWarp::kBowl, sim::BoardWarp::kTwist}) {
    SCOPED_TRACE(warp == sim::BoardWarp::kBowl ? "bowl" : "twist");
    const SyntheticScene scene = TiltedScene(sim::TruthRadtan(), 24, 0.15, 7);
    SyntheticData data = sim::MakeSyntheticData(scene);
    const std::vector<int> bent = {5, 17};
    sim::ApplyBoardBend(scene, warp, 0.004, bent, &data);
    const Judged judged = JudgeAsTheProgram(data, scene.camera);
    std::printf("%s\n", judged.verdict.Line().c_str());
    EXPECT_EQ(judged.verdict.kind, VerdictKind::kViewErrors)
        << judged.verdict.Line() << "\n"
        << EvidenceText(judged.evidence);
    for (int v : bent) {
      EXPECT_NE(judged.verdict.reason.find(data.views[v].name + " ("),
                std::string::npos)
          << judged.verdict.reason;
    }
    for (int v = 0; v < static_cast<int>(data.views.size()); ++v) {
      if (v == bent[0] || v == bent[1]) continue;
      EXPECT_EQ(judged.verdict.reason.find(data.views[v].name + " ("),
                std::string::npos)
          << data.views[v].name << ": " << judged.verdict.reason;
    }
    for (const std::string& finding : judged.verdict.findings) {
      EXPECT_EQ(finding.find("rejected as outliers (limit"), std::string::npos)
          << finding;
    }
    EXPECT_NE(judged.verdict.next_step.find("retake"), std::string::npos);
  }
}

}  // namespace
}  // namespace puzzlecal
