// Inconsistent views: a focal length change between photos (autofocus,
// zoom) rendered with truth (sim/view_faults.h) gives the inconsistent-views
// verdict naming the changed photos; the clean scene does not.

#include "evidence/view_consistency.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/model_advice.h"
#include "evidence/verdict.h"
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

TEST(ViewConsistencyOptions, CheckRejectsBadValues) {
  ViewConsistencyOptions options;
  EXPECT_TRUE(options.Check());
  options.min_corners = 6;
  EXPECT_FALSE(options.Check());
  options = ViewConsistencyOptions();
  options.max_iterations = 0;
  EXPECT_FALSE(options.Check());
}

// One camera: the views' focal lengths agree within their sigma (chi-square
// near its degrees of freedom) and nothing is said.
TEST(ViewConsistency, CleanViewsAgree) {
  const SyntheticScene scene = TiltedScene(sim::TruthRadtan(), 24, 0.2, 3);
  const SyntheticData data = sim::MakeSyntheticData(scene);
  const Judged judged = JudgeAsTheProgram(data, scene.camera);
  const ViewConsistency& vc = judged.evidence.view_consistency;
  ASSERT_TRUE(vc.ok) << vc.error;
  EXPECT_EQ(vc.views.size(), data.views.size());
  EXPECT_LT(vc.spread_ratio, 1.6) << EvidenceText(judged.evidence);
  EXPECT_NEAR(vc.mean_scale, 1.0, 0.002);
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kGood) << judged.verdict.Line();
}

// A third of the photos taken at a 2 % longer focal length (autofocus):
// inconsistent-views, naming changed photos first, with the next step about
// focus; their own focal lengths come out near the truth.
TEST(ViewConsistency, FocalChangeBetweenPhotosIsNamed) {
  const SyntheticScene scene = TiltedScene(sim::TruthRadtan(), 24, 0.2, 5);
  SyntheticData data = sim::MakeSyntheticData(scene);
  std::vector<int> changed;
  for (int v = 1; v < static_cast<int>(data.views.size()); v += 3) {
    changed.push_back(v);
  }
  sim::ApplyFocalChange(scene.camera, 1.02, changed, &data);
  const Judged judged = JudgeAsTheProgram(data, scene.camera);
  const ViewConsistency& vc = judged.evidence.view_consistency;
  ASSERT_TRUE(vc.ok) << vc.error;
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kInconsistentViews)
      << judged.verdict.Line() << "\n"
      << EvidenceText(judged.evidence);
  EXPECT_NE(judged.verdict.next_step.find("autofocus"), std::string::npos);
  for (const ViewFocal& f : MostInconsistentViews(vc, 3)) {
    EXPECT_NE(std::find(changed.begin(), changed.end(), f.view), changed.end())
        << f.name;
    EXPECT_NE(judged.verdict.reason.find(f.name), std::string::npos)
        << judged.verdict.reason;
  }
  // The changed views' focal lengths against the others': 2 % apart.
  double changed_sum = 0, kept_sum = 0;
  int changed_n = 0, kept_n = 0;
  for (const ViewFocal& f : vc.views) {
    if (std::find(changed.begin(), changed.end(), f.view) != changed.end()) {
      changed_sum += f.scale;
      ++changed_n;
    } else {
      kept_sum += f.scale;
      ++kept_n;
    }
  }
  ASSERT_GT(changed_n, 0);
  ASSERT_GT(kept_n, 0);
  EXPECT_NEAR((changed_sum / changed_n) / (kept_sum / kept_n), 1.02, 0.005);
}

// The same scene without the change: no such finding (the scene, not the
// seed, makes the difference).
TEST(ViewConsistency, SameSceneWithoutTheChangeIsGood) {
  const SyntheticScene scene = TiltedScene(sim::TruthRadtan(), 24, 0.2, 5);
  const SyntheticData data = sim::MakeSyntheticData(scene);
  const Judged judged = JudgeAsTheProgram(data, scene.camera);
  EXPECT_EQ(judged.verdict.kind, VerdictKind::kGood) << judged.verdict.Line();
}

}  // namespace
}  // namespace puzzlecal
