#ifndef PUZZLECAL_EVIDENCE_JUDGEMENT_H_
#define PUZZLECAL_EVIDENCE_JUDGEMENT_H_

// A calibration judged the way `puzzlecal calibrate` judges it, as one
// library call: the model (`auto`: chosen on held-out views,
// model_selection.h), the calibration, its evidence (evidence.h), the
// verdict drawn from it (verdict.h), and a suggested model advised only
// after it has won on held-out views (model_advice.h). The program, other
// programs linking the library and the Python package take the same steps.

#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "camera/calibration_view.h"
#include "evidence/evidence.h"
#include "evidence/model_advice.h"
#include "evidence/model_selection.h"
#include "evidence/verdict.h"

namespace puzzlecal {

struct JudgementOptions {
  EvidenceOptions evidence;               // the evidence's sampling and bands
  VerdictOptions verdict;                 // the verdict's limits
  ModelSelectionOptions model_selection;  // `auto` and the model advice
  // Every group's Check(); `why` names the group first.
  bool Check(std::string* why = nullptr) const;
};

struct Judgement {
  Evidence evidence;
  Verdict verdict;
  ModelAdvice advice;  // what became of the verdict's suggested model
};

// The evidence, the verdict and the model advice for `result`, calibrated
// from `views` with `calibration`. `selection`: the `--model auto`
// comparison that chose the model (reused by the advice), or null.
Judgement JudgeCalibration(const std::vector<CalibrationView>& views,
                           const CalibrationResult& result,
                           const CalibrationOptions& calibration,
                           const JudgementOptions& options,
                           const ModelSelection* selection = nullptr);

struct JudgedCalibration {
  bool auto_model = false;   // the model was chosen (`auto`)
  ModelSelection selection;  // the comparison, when auto_model
  CalibrationResult result;  // the calibration
  Judgement judgement;       // its evidence and verdict
};

// `model`: a model name (CameraModelNames()) or "auto". Chooses the model
// when asked, calibrates and judges. False with a reason (naming the model
// or the views) when the model is unknown, the options are invalid, no
// model could be chosen or the calibration failed.
bool CalibrateAndJudge(const std::vector<CalibrationView>& views, int width,
                       int height, const std::string& model,
                       const CalibrationOptions& calibration,
                       const JudgementOptions& options, JudgedCalibration* out,
                       std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_EVIDENCE_JUDGEMENT_H_
