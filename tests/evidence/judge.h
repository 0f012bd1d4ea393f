#ifndef PUZZLECAL_TESTS_EVIDENCE_JUDGE_H_
#define PUZZLECAL_TESTS_EVIDENCE_JUDGE_H_

// The judging tests' common steps: rendered views of a tilted board, and a
// calibration judged (evidence, verdict) the way `puzzlecal calibrate` does.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "evidence/evidence.h"
#include "evidence/model_advice.h"
#include "evidence/verdict.h"
#include "sim/synthetic_views.h"

namespace puzzlecal {
namespace testing_judge {

// Views of `camera`: boards turned up to 40 deg from the axis, each at least
// 60 % inside the image, corners with Gaussian noise of `noise_px`.
inline sim::SyntheticScene TiltedScene(const Camera& camera, int num_views,
                                       double noise_px, unsigned seed) {
  sim::SyntheticScene scene;
  scene.camera = camera;
  scene.num_views = num_views;
  scene.noise_px = noise_px;
  scene.seed = seed;
  scene.max_direction_deg = 40;
  scene.min_visible_fraction = 0.6;
  return scene;
}

// One calibration and its judgement.
struct Judged {
  bool calibrated = false;  // false: `error` says why, the rest is empty
  std::string error;
  CalibrationResult result;
  Evidence evidence;
  Verdict verdict;
};

// Calibrates `views` with `model`, then its evidence and verdict with the
// default options. With `check_model_advice`, a richer model is advised only
// after it has won on held-out views, as the program does.
inline Judged Judge(const std::vector<CalibrationView>& views,
                    CameraModelId model, int width, int height,
                    const CalibrationOptions& options = CalibrationOptions(),
                    bool check_model_advice = false) {
  Judged judged;
  judged.calibrated = Calibrate(views, model, width, height, options,
                                &judged.result, &judged.error);
  if (!judged.calibrated) return judged;
  const EvidenceOptions evidence_options;
  judged.evidence =
      ComputeEvidence(views, judged.result, options, evidence_options);
  judged.verdict = MakeVerdict(judged.result, judged.evidence, evidence_options,
                               VerdictOptions());
  if (check_model_advice) {
    CheckModelAdvice(views, judged.result, options, ModelSelectionOptions(),
                     nullptr, &judged.verdict);
  }
  return judged;
}

// The rendered views judged as the program judges them, with the truth's
// model; a failed calibration fails the test.
inline Judged JudgeAsTheProgram(const sim::SyntheticData& data,
                                const Camera& truth) {
  Judged judged = Judge(data.views, truth.model, truth.width, truth.height,
                        CalibrationOptions(), /*check_model_advice=*/true);
  EXPECT_TRUE(judged.calibrated) << judged.error;
  return judged;
}

}  // namespace testing_judge
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_EVIDENCE_JUDGE_H_
