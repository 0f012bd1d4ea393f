#include "pipeline/rig_run.h"

#include <algorithm>
#include <filesystem>
#include <utility>

#include "util/failure.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// The first few file names of a listing, for messages.
std::string SomeNames(const ImageListing& listing) {
  std::string names;
  for (size_t i = 0; i < listing.images.size() && i < 3; ++i) {
    names +=
        (i > 0 ? ", " : "") + fs::path(listing.images[i]).filename().string();
  }
  return names + (listing.images.size() > 3 ? ", ..." : "");
}

bool MatchByOrder(const std::vector<std::string>& camera_names,
                  const std::vector<ImageListing>& listings, RigFrames* frames,
                  std::string* error) {
  for (size_t c = 0; c < listings.size(); ++c) {
    if (listings[c].images.size() != listings[0].images.size()) {
      return Fail("--match_by_order: camera '" + camera_names[c] + "' has " +
                      std::to_string(listings[c].images.size()) +
                      " images, camera '" + camera_names[0] + "' " +
                      std::to_string(listings[0].images.size()) +
                      "; pairing by order needs the same number in every "
                      "folder.",
                  error);
    }
    for (size_t i = 0; i < listings[c].images.size(); ++i) {
      frames->frame_of_file[c][listings[c].images[i]] = static_cast<int>(i);
    }
  }
  frames->num_frames = static_cast<int>(listings[0].images.size());
  return true;
}

// Two cameras never take byte-identical photos: a camera folder whose
// photos are copies of another's (one folder copied for the other) would
// be calibrated as two cameras in one place, a rig with a baseline of 0.
// False naming both cameras when any frame's files of two cameras hold the
// same bytes (files are read only where their sizes agree).
bool RefuseCopiedCameraPhotos(const std::vector<std::string>& camera_names,
                              const std::vector<ImageListing>& listings,
                              const RigFrames& frames, std::string* error) {
  // Per camera, the file of each frame ("" where none).
  std::vector<std::vector<std::string>> file_of_frame(listings.size());
  for (size_t c = 0; c < listings.size(); ++c) {
    file_of_frame[c].assign(frames.num_frames, "");
    for (const auto& [file, frame] : frames.frame_of_file[c]) {
      file_of_frame[c][frame] = file;
    }
  }
  for (size_t a = 0; a < listings.size(); ++a) {
    for (size_t b = a + 1; b < listings.size(); ++b) {
      int both = 0;
      std::vector<std::string> same;
      for (int f = 0; f < frames.num_frames; ++f) {
        const std::string& file_a = file_of_frame[a][f];
        const std::string& file_b = file_of_frame[b][f];
        if (file_a.empty() || file_b.empty()) continue;
        ++both;
        if (FilesHoldSameBytes(file_a, file_b)) {
          same.push_back(fs::path(file_b).filename().string());
        }
      }
      if (same.empty()) continue;
      std::string which;
      if (static_cast<int>(same.size()) < both) {
        which = ": ";
        for (size_t k = 0; k < same.size() && k < 3; ++k) {
          which += (k > 0 ? ", " : "") + same[k];
        }
        if (same.size() > 3) which += ", ...";
      }
      return Fail(
          StringPrintf("cameras '%s' and '%s' hold the same photos (%zu of %d "
                       "byte-identical%s): a rig needs one folder per camera, "
                       "each holding that camera's own photos",
                       camera_names[a].c_str(), camera_names[b].c_str(),
                       same.size(), both, which.c_str()) +
              (static_cast<int>(same.size()) == both
                   ? " (is '" + camera_names[b] + "' a copy of '" +
                         camera_names[a] + "'?)"
                   : "; replace the copies with the photos '" +
                         camera_names[b] + "' took, or remove them"),
          error);
    }
  }
  return true;
}

// A view whose labels are relative (part of a plain checkerboard) is
// labelled from its own first corner: the same corner of the board carries
// other labels in the other cameras' views of the frame, so the joint solve
// would tie wrong corners together (one camera of a pair partly covered in
// 6 of 11 frames: transfer errors of 2.6-61 px and a focal length of 199 px
// for 523). A single camera's calibration can use such a view (its pose
// absorbs the shift); a rig cannot.
void LeaveOutRelativeLabels(std::vector<ImageResult>* results) {
  for (ImageResult& image : *results) {
    if (image.outcome != ImageOutcome::kUsable || image.decode.absolute_ids) {
      continue;
    }
    image.outcome = ImageOutcome::kPartialBoard;
    image.reason =
        std::to_string(image.decode.observation.id.size()) +
        " corners of a plain checkerboard not seen whole: a part cannot be "
        "matched with the other cameras' views of the frame";
  }
}

// The rig's evidence and verdict, and the rig file's record of them.
void JudgeRig(const std::vector<RigCameraInput>& inputs,
              const RigEvidenceOptions& rig_options,
              const std::vector<std::vector<std::string>>& frame_files,
              JudgedRig* judged) {
  const RigCalibrationResult& result = judged->result;
  judged->rig = ComputeRigEvidence(inputs, result, rig_options);
  judged->rig_verdict = MakeRigVerdict(result, judged->rig, judged->verdicts,
                                       RigFrameNames(frame_files), rig_options);
  RigFileJudgement& file = judged->file;
  file.verdict_kind = judged->rig_verdict.kind;
  file.verdict_reason = judged->rig_verdict.reason;
  file.verdict_next_step = judged->rig_verdict.next_step;
  for (size_t f = 0; f < judged->rig.frames.size(); ++f) {
    const RigFrameEvidence& frame = judged->rig.frames[f];
    RigFileFrame out;
    for (size_t c = 0; c < result.cameras.size(); ++c) {
      const RigFrameCamera& view = frame.cameras[c];
      out.files.push_back(f < frame_files[c].size() ? frame_files[c][f] : "");
      std::string use = view.used ? "used" : "";
      if (!view.note.empty()) {
        use = view.used ? "used; " + view.note : view.note;
      } else if (!view.used) {
        const std::vector<std::string>& unusable =
            inputs[c].frame_unusable_reason;
        use = out.files.back().empty() ? "not used: no image"
              : view.has_view          ? "not used"
              : f < unusable.size() && !unusable[f].empty()
                  ? "not used: " + unusable[f]
                  : "not used: the board was not found";
      }
      out.use.push_back(use);
      out.rms_px.push_back(view.rms_px);
    }
    out.compared = frame.compared;
    out.transfer_px = frame.transfer_px;
    out.pose_difference_mm = frame.pose_difference_mm;
    out.epipolar_px = frame.epipolar_px;
    out.moved = frame.moved;
    file.frames.push_back(out);
  }
}

}  // namespace

bool ListRigCameraFolders(const std::string& root,
                          std::vector<std::string>* folders,
                          std::string* error) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) {
    return Fail(root + ": not a folder (expected one subfolder per camera)",
                error);
  }
  std::vector<fs::path> found;
  for (fs::directory_iterator it(root, ec), end; !ec && it != end;
       it.increment(ec)) {
    // Hidden folders (".report.partial", ".git", ...) are no cameras.
    const std::string name = it->path().filename().string();
    if (it->is_directory(ec) && !name.empty() && name[0] != '.') {
      found.push_back(it->path());
    }
  }
  if (ec) {
    return Fail(root + ": cannot read the folder (" + ec.message() + ")",
                error);
  }
  std::sort(found.begin(), found.end());
  if (found.size() < 2) {
    return Fail(root + ": " + std::to_string(found.size()) +
                    " camera subfolder" + (found.size() == 1 ? "" : "s") +
                    " (a rig needs one per camera, at least two)",
                error);
  }
  folders->clear();
  for (const fs::path& path : found) folders->push_back(path.string());
  return true;
}

bool MatchRigFrames(const std::vector<std::string>& camera_names,
                    const std::vector<ImageListing>& listings, bool by_order,
                    RigFrames* frames, std::string* error) {
  const size_t num_cameras = listings.size();
  if (camera_names.size() != num_cameras || num_cameras < 2) {
    return Fail(std::to_string(num_cameras) + " image listings for " +
                    std::to_string(camera_names.size()) +
                    " camera names (a rig needs one per camera, at least two)",
                error);
  }
  frames->num_frames = 0;
  frames->frame_of_file.assign(num_cameras, {});
  if (by_order) {
    return MatchByOrder(camera_names, listings, frames, error) &&
           RefuseCopiedCameraPhotos(camera_names, listings, *frames, error);
  }
  std::map<std::string, int> frame_of_name;
  std::map<std::string, int> cameras_with_name;
  for (const ImageListing& listing : listings) {
    for (const std::string& file : listing.images) {
      const std::string name = fs::path(file).filename().string();
      frame_of_name.emplace(name, 0);
      ++cameras_with_name[name];
    }
  }
  for (size_t c = 0; c < num_cameras; ++c) {
    const ImageListing& listing = listings[c];
    const bool shares = std::any_of(
        listing.images.begin(), listing.images.end(),
        [&](const std::string& file) {
          return cameras_with_name[fs::path(file).filename().string()] > 1;
        });
    if (shares || listing.images.empty()) continue;
    const size_t other = c == 0 ? 1 : 0;
    return Fail(
        "camera '" + camera_names[c] +
            "' shares no frame with another camera: none of its file names (" +
            SomeNames(listing) + ") is in another camera's folder ('" +
            camera_names[other] + "': " + SomeNames(listings[other]) +
            "). Frames are matched by file name: the same name in every "
            "camera folder is the same instant. If these are the same "
            "instants under other names, rename the files so that they "
            "match, or pass --match_by_order to pair the n-th image (sorted "
            "by name) of every folder; otherwise take photos in which it and "
            "a neighbouring camera see the board together.",
        error);
  }
  int index = 0;
  for (auto& [name, frame] : frame_of_name) frame = index++;
  for (size_t c = 0; c < num_cameras; ++c) {
    for (const std::string& file : listings[c].images) {
      frames->frame_of_file[c][file] =
          frame_of_name.at(fs::path(file).filename().string());
    }
  }
  frames->num_frames = index;
  return RefuseCopiedCameraPhotos(camera_names, listings, *frames, error);
}

int MakeRigCameraViews(const Board& board,
                       const std::vector<std::string>& files,
                       const std::map<std::string, int>& frame_of_file,
                       int num_frames, const PipelineOptions& options,
                       int num_threads, RigCameraInput* input,
                       std::vector<std::string>* frame_files,
                       std::vector<ImageResult>* images) {
  input->frames.assign(num_frames, CalibrationView());
  input->frame_unusable_reason.assign(num_frames, "");
  frame_files->assign(num_frames, "");
  std::vector<ImageResult> results =
      ProcessImageFiles(files, board, options, num_threads);
  LeaveOutRelativeLabels(&results);
  std::vector<CalibrationView> views =
      MakeCalibrationViews(board, &results, &input->width, &input->height);
  int usable = 0;
  for (const ImageResult& image : results) {
    const int frame = frame_of_file.at(image.file);
    (*frame_files)[frame] = image.file;
    if (image.view_index < 0) {
      input->frame_unusable_reason[frame] =
          std::string(ImageOutcomeName(image.outcome)) +
          (image.reason.empty() ? "" : " (" + image.reason + ")");
      continue;
    }
    input->frames[frame] = std::move(views[image.view_index]);
    ++usable;
  }
  if (images != nullptr) *images = std::move(results);
  return usable;
}

bool ChooseRigCameraModel(const RigCameraInput& input,
                          const CalibrationOptions& calibration,
                          const ModelSelectionOptions& options,
                          ModelSelection* selection, std::string* error) {
  std::vector<CalibrationView> views;
  for (const CalibrationView& view : input.frames) {
    if (!view.board_points.empty()) views.push_back(view);
  }
  std::string why;
  if (!SelectModel(views, input.width, input.height, calibration, options,
                   selection, &why) ||
      selection->chosen < 0) {
    return Fail(why.empty() ? selection->reason : why, error);
  }
  return true;
}

RigBoardSymmetry RigSymmetryOf(const Board& board) {
  RigBoardSymmetry symmetry;
  symmetry.half_turn = board.type == BoardType::kCheckerboard;
  symmetry.centre =
      0.5 * (board.Point(board.origin) +
             board.Point(board.origin +
                         Eigen::Vector2i(board.cols - 1, board.rows - 1)));
  return symmetry;
}

std::vector<std::string> RigFrameNames(
    const std::vector<std::vector<std::string>>& frame_files) {
  std::vector<std::string> names(frame_files.empty() ? 0
                                                     : frame_files[0].size());
  for (size_t f = 0; f < names.size(); ++f) {
    for (const std::vector<std::string>& files : frame_files) {
      if (f < files.size() && !files[f].empty()) {
        names[f] = fs::path(files[f]).filename().string();
        break;
      }
    }
  }
  return names;
}

bool RigRunOptions::Check(std::string* why) const {
  std::string reason;
  if (!rig.Check(&reason)) return Fail("rig: " + reason, why);
  if (!evidence.Check(&reason)) return Fail("evidence: " + reason, why);
  if (!verdict.Check(&reason)) return Fail("verdict: " + reason, why);
  if (!rig_evidence.Check(&reason)) {
    return Fail("rig_evidence: " + reason, why);
  }
  return true;
}

namespace {

// Whether every intrinsic of a calibration was held (a known camera).
bool IntrinsicsHeld(const CalibrationResult& result) {
  return !result.param_fixed.empty() &&
         std::all_of(result.param_fixed.begin(), result.param_fixed.end(),
                     [](bool fixed) { return fixed; });
}

// The verdict of a camera whose intrinsics were given and held: nothing of
// the lens was calibrated here, so nothing of it is judged; the rig's
// poses are (the rig verdict).
Verdict HeldIntrinsicsVerdict(const CalibrationResult& result) {
  Verdict verdict;
  verdict.kind = VerdictKind::kGood;
  verdict.reason = StringPrintf(
      "its intrinsics were given and held (every parameter fixed), not "
      "calibrated or judged here; its views fit them with RMS %.3f px",
      result.rms_px);
  verdict.next_step = "none: the rig's poses are judged below";
  return verdict;
}

}  // namespace

bool CalibrateAndJudgeRig(
    const Board& board, const std::vector<RigCameraInput>& inputs,
    const std::vector<std::vector<std::string>>& frame_files,
    const RigRunOptions& options, JudgedRig* out, std::string* error) {
  *out = JudgedRig();
  std::string why;
  if (!options.Check(&why)) return Fail("invalid options: " + why, error);
  if (frame_files.size() != inputs.size()) {
    return Fail(std::to_string(inputs.size()) + " cameras but frame files of " +
                    std::to_string(frame_files.size()),
                error);
  }
  const bool calibrated = CalibrateRig(inputs, RigSymmetryOf(board),
                                       options.rig, &out->result, error);
  if (!calibrated) return false;
  for (size_t c = 0; c < out->result.cameras.size(); ++c) {
    const RigCameraResult& cam = out->result.cameras[c];
    out->evidence.push_back(ComputeEvidence(
        inputs[c].frames, cam.single, options.rig.camera, options.evidence));
    out->verdicts.push_back(IntrinsicsHeld(cam.single)
                                ? HeldIntrinsicsVerdict(cam.single)
                                : MakeVerdict(cam.single, out->evidence.back(),
                                              options.evidence,
                                              options.verdict));
  }
  JudgeRig(inputs, options.rig_evidence, frame_files, out);
  return true;
}

}  // namespace puzzlecal
