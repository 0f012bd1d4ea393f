#include "evidence/judgement.h"

#include "util/failure.h"

namespace puzzlecal {

bool JudgementOptions::Check(std::string* why) const {
  std::string reason;
  if (!evidence.Check(&reason)) return Fail("evidence: " + reason, why);
  if (!verdict.Check(&reason)) return Fail("verdict: " + reason, why);
  if (!model_selection.Check(&reason)) {
    return Fail("model_selection: " + reason, why);
  }
  return true;
}

Judgement JudgeCalibration(const std::vector<CalibrationView>& views,
                           const CalibrationResult& result,
                           const CalibrationOptions& calibration,
                           const JudgementOptions& options,
                           const ModelSelection* selection) {
  Judgement judgement;
  judgement.evidence =
      ComputeEvidence(views, result, calibration, options.evidence);
  judgement.verdict = MakeVerdict(result, judgement.evidence, options.evidence,
                                  options.verdict);
  judgement.advice =
      CheckModelAdvice(views, result, calibration, options.model_selection,
                       selection, &judgement.verdict);
  return judgement;
}

bool CalibrateAndJudge(const std::vector<CalibrationView>& views, int width,
                       int height, const std::string& model,
                       const CalibrationOptions& calibration,
                       const JudgementOptions& options, JudgedCalibration* out,
                       std::string* error) {
  std::string why;
  if (!options.Check(&why)) return Fail("invalid options: " + why, error);
  if (views.empty()) return Fail("no views to calibrate from", error);
  JudgedCalibration run;
  run.auto_model = model == "auto";
  CameraModelId id = CameraModelId::kPinholeRadtan;
  if (run.auto_model) {
    if (!SelectModel(views, width, height, calibration, options.model_selection,
                     &run.selection, error)) {
      return false;
    }
    id = run.selection.candidates[run.selection.chosen].model;
  } else if (!CameraModelIdFromName(model, &id)) {
    return Fail("unknown model '" + model + "'; choose one of " +
                    CameraModelNames() + " or auto",
                error);
  }
  if (!Calibrate(views, id, width, height, calibration, &run.result, error)) {
    return false;
  }
  run.judgement = JudgeCalibration(views, run.result, calibration, options,
                                   run.auto_model ? &run.selection : nullptr);
  *out = std::move(run);
  return true;
}

}  // namespace puzzlecal
