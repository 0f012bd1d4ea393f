#include "evidence/model_advice.h"

#include "util/string_format.h"

namespace puzzlecal {

ModelAdvice CheckModelAdvice(const std::vector<CalibrationView>& views,
                             const CalibrationResult& result,
                             const CalibrationOptions& calibration,
                             const ModelSelectionOptions& selection_options,
                             const ModelSelection* selection,
                             Verdict* verdict) {
  ModelAdvice advice;
  if (verdict->suggested_model.empty()) return advice;
  advice.suggested = verdict->suggested_model;
  CameraModelId suggested_id;
  if (!CameraModelIdFromName(advice.suggested, &suggested_id)) {
    return advice;
  }
  const CameraModelId current_id = result.camera.model;
  const ModelCandidate* current = nullptr;
  const ModelCandidate* suggested = nullptr;
  // A selection that could not compare (ModelSelection::compared) says
  // nothing of either model; neither does its failure of the calibrated
  // model on a fold.
  if (selection != nullptr && selection->compared) {
    current = selection->Find(current_id);
    suggested = selection->Find(suggested_id);
  }
  ModelSelection own;
  if (current == nullptr || suggested == nullptr || !current->ok) {
    ModelSelectionOptions options = selection_options;
    options.candidates = {CameraModelName(current_id), advice.suggested};
    std::string error;
    if (!SelectModel(views, result.camera.width, result.camera.height,
                     calibration, options, &own, &error)) {
      advice.error = error;
    }
    current = own.Find(current_id);
    suggested = own.Find(suggested_id);
    if (!own.compared) {
      advice.error = own.reason;
      current = suggested = nullptr;
    }
  }
  advice.checked = true;
  if (current != nullptr && suggested != nullptr && current->ok &&
      suggested->ok) {
    advice.current_rms_px = current->holdout_rms_px;
    advice.suggested_rms_px = suggested->holdout_rms_px;
    advice.confirmed =
        BeatsOnHeldOutViews(*suggested, *current, selection_options, &advice.z);
  } else if (current != nullptr && suggested != nullptr && !current->ok &&
             suggested->ok) {
    // The calibrated model cannot even be fitted to the folds (a pinhole
    // model for corners beyond the field it is meant for) while the
    // suggested one fits and predicts the held-out views: that is the
    // comparison's answer, not a failure to compare.
    advice.suggested_rms_px = suggested->holdout_rms_px;
    advice.current_error = current->error;
    advice.confirmed = true;
  } else if (advice.error.empty()) {
    advice.error = suggested != nullptr && !suggested->ok
                       ? advice.suggested + ": " + suggested->error
                       : "the calibrated model could not be refitted";
  }
  const std::string current_name = CameraModelName(current_id);
  if (advice.confirmed) {
    if (!advice.current_error.empty()) {
      // The reason the calibrated model cannot be fitted replaces the
      // verdict's own (a pinhole fit places wide corners at smaller
      // angles than they are).
      verdict->next_step = StringPrintf(
          "calibrate with --model %s; on held-out views it fits %.4f px, "
          "where %s cannot be fitted (%s)",
          advice.suggested.c_str(), advice.suggested_rms_px,
          current_name.c_str(), advice.current_error.c_str());
      return advice;
    }
    verdict->next_step += StringPrintf(
        "; on held-out views it fits %.4f px against %.4f px for %s",
        advice.suggested_rms_px, advice.current_rms_px, current_name.c_str());
    return advice;
  }
  verdict->suggested_model.clear();
  std::string why;
  if (advice.error.empty()) {
    why = StringPrintf(
        "%s does not fit held-out views better than %s (%.4f px against "
        "%.4f px, %.1f standard errors)",
        advice.suggested.c_str(), current_name.c_str(), advice.suggested_rms_px,
        advice.current_rms_px, advice.z);
  } else {
    why = advice.suggested + " could not be compared on held-out views (" +
          advice.error + ")";
  }
  if (verdict->kind == VerdictKind::kModelError &&
      !verdict->inconsistent_views.empty()) {
    // No richer model explains it; the views that disagree on the focal
    // length do.
    verdict->kind = VerdictKind::kInconsistentViews;
    verdict->reason = verdict->inconsistent_views + "; " + verdict->reason;
    verdict->next_step = verdict->inconsistent_views_next_step + " (" + why +
                         ", so the model is not what to change)";
    return advice;
  }
  if (verdict->kind == VerdictKind::kModelError &&
      !verdict->view_errors.empty()) {
    verdict->kind = VerdictKind::kViewErrors;
    verdict->reason = verdict->view_errors + "; " + verdict->reason;
    verdict->next_step = verdict->view_errors_next_step + " (" + why +
                         ", so the model is not what to change)";
    return advice;
  }
  verdict->next_step =
      why +
      ", so no model change is advised: no model tried explains the "
      "finding better. Check that focus and zoom stayed fixed between the "
      "photos, that the "
      "board is flat and its file right, and look at the worst views in the "
      "report; more views at several distances and tilts tell these apart";
  return advice;
}

}  // namespace puzzlecal
