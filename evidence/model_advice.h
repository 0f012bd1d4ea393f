#ifndef PUZZLECAL_EVIDENCE_MODEL_ADVICE_H_
#define PUZZLECAL_EVIDENCE_MODEL_ADVICE_H_

// One source of truth for model advice: the model a verdict suggests
// (NextModel, evidence/verdict.h) is only a candidate until it has been
// fitted and has beaten the calibrated model on held-out views by more than
// noise (BeatsOnHeldOutViews, evidence/model_selection.h). When it has not,
// the suggestion is withdrawn and the next step says what else explains the
// finding. `--model auto`'s comparison is reused when it holds both models;
// otherwise the two are compared here.

#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "camera/calibration_view.h"
#include "evidence/model_selection.h"
#include "evidence/verdict.h"

namespace puzzlecal {

struct ModelAdvice {
  bool checked = false;  // a suggestion was there and was compared
  // It beat the calibrated model on held-out views, or it fits them and the
  // calibrated model cannot be fitted to the folds at all (then
  // current_error says why: a pinhole model for corners beyond its field).
  bool confirmed = false;
  std::string suggested;        // the model that was suggested
  double suggested_rms_px = 0;  // held-out RMS of both (when compared)
  double current_rms_px = 0;
  double z = 0;               // BeatsOnHeldOutViews' standard errors
  std::string error;          // why the comparison could not be made
  std::string current_error;  // why the calibrated model could not be fitted
};

// Checks verdict->suggested_model against `result`'s model on held-out
// views (from `selection` when it holds both as fitted candidates, else by
// SelectModel on the two) and rewrites the verdict's next step: the figures
// when confirmed; the suggestion withdrawn (suggested_model cleared) and
// the other explanations when not: a model-error verdict with an
// inconsistent-views finding becomes inconsistent-views (the views, not
// the model, explain it). Nothing happens without a suggestion.
ModelAdvice CheckModelAdvice(const std::vector<CalibrationView>& views,
                             const CalibrationResult& result,
                             const CalibrationOptions& calibration,
                             const ModelSelectionOptions& selection_options,
                             const ModelSelection* selection, Verdict* verdict);

}  // namespace puzzlecal

#endif  // PUZZLECAL_EVIDENCE_MODEL_ADVICE_H_
