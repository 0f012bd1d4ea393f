#include "pipeline/rig_video.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>
#include <utility>

#include "util/failure.h"
#include "util/parallel_for.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

std::string FileName(const std::string& path) {
  return fs::path(path).filename().string();
}

int CamerasSeeing(const RigFrameOutlines& frame) {
  return static_cast<int>(
      std::count(frame.seen.begin(), frame.seen.end(), true));
}

// The joint distance of two rig frames (see ChooseRigFrames).
double JointDistance(const RigFrameOutlines& a, const RigFrameOutlines& b,
                     const std::vector<double>& diagonals) {
  double sum = 0;
  int cameras = 0;
  for (size_t c = 0; c < diagonals.size(); ++c) {
    if (!a.seen[c] && !b.seen[c]) continue;
    ++cameras;
    sum += a.seen[c] && b.seen[c]
               ? OutlineDistance(a.outlines[c], b.outlines[c]) / diagonals[c]
               : 1.0;
  }
  return cameras > 0 ? sum / cameras : 0.0;
}

// The time between frames of the reference video: its stated rate, or the
// median step of its time stamps.
double FramePeriodMs(const VideoFrames& reference) {
  if (reference.fps > 0) return 1000.0 / reference.fps;
  std::vector<double> steps;
  for (size_t i = 1; i < reference.frames.size(); ++i) {
    steps.push_back(reference.frames[i].time_ms -
                    reference.frames[i - 1].time_ms);
  }
  if (steps.empty()) return 0;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2,
                   steps.end());
  return steps[steps.size() / 2];
}

}  // namespace

bool RigVideoOptions::Check(std::string* why) const {
  if (!(max_time_difference_ms >= 0) ||
      !std::isfinite(max_time_difference_ms)) {
    return Fail(
        "max_time_difference_ms must be >= 0 (0: a quarter of the "
        "reference video's frame period)",
        why);
  }
  return true;
}

std::vector<TimePairing> PairFramesByTime(
    const std::vector<double>& reference_ms,
    const std::vector<double>& times_ms, double tolerance_ms) {
  std::vector<TimePairing> pairings(times_ms.size());
  // Per reference frame, the frame nearest to it so far (position).
  std::vector<int> claimed_by(reference_ms.size(), -1);
  for (size_t i = 0; i < times_ms.size(); ++i) {
    TimePairing& p = pairings[i];
    if (reference_ms.empty()) continue;
    const double t = times_ms[i];
    const size_t after = static_cast<size_t>(
        std::lower_bound(reference_ms.begin(), reference_ms.end(), t) -
        reference_ms.begin());
    int nearest = static_cast<int>(std::min(after, reference_ms.size() - 1));
    if (after > 0 && (after == reference_ms.size() ||
                      t - reference_ms[after - 1] <= reference_ms[after] - t)) {
      nearest = static_cast<int>(after - 1);  // ties: the earlier
    }
    p.nearest = nearest;
    p.difference_ms = t - reference_ms[nearest];
    if (!(std::abs(p.difference_ms) <= tolerance_ms)) continue;
    int& holder = claimed_by[nearest];
    if (holder >= 0 &&
        std::abs(pairings[holder].difference_ms) <= std::abs(p.difference_ms)) {
      p.taken = true;  // an earlier frame is at least as near
      continue;
    }
    if (holder >= 0) {
      pairings[holder].reference = -1;
      pairings[holder].taken = true;
    }
    holder = static_cast<int>(i);
    p.reference = nearest;
  }
  return pairings;
}

RigFrameChoice ChooseRigFrames(const std::vector<RigFrameOutlines>& frames,
                               const std::vector<double>& diagonals,
                               double min_pose_change, int max_frames) {
  const size_t n = frames.size();
  const size_t num_cameras = diagonals.size();
  RigFrameChoice choice;
  choice.duplicate_of.assign(n, -1);
  choice.not_needed.assign(n, false);
  choice.closest.assign(n, -1);
  // Near duplicates, in time order.
  std::vector<int> distinct;
  for (size_t k = 0; k < n; ++k) {
    const RigFrameOutlines& frame = frames[k];
    int similar = -1;
    double similar_distance = std::numeric_limits<double>::infinity();
    for (const int j : distinct) {
      const RigFrameOutlines& other = frames[j];
      double worst = 0;  // the largest change over the cameras, of diagonals
      bool repeats = CamerasSeeing(frame) > 0;
      for (size_t c = 0; c < num_cameras && repeats; ++c) {
        if (!frame.seen[c]) continue;
        if (!other.seen[c]) {
          repeats = false;  // this camera sees the board anew
          break;
        }
        const double change =
            OutlineDistance(frame.outlines[c], other.outlines[c]) /
            diagonals[c];
        repeats = change < min_pose_change;
        worst = std::max(worst, change);
      }
      if (repeats && worst < similar_distance) {
        similar = j;
        similar_distance = worst;
      }
    }
    if (similar >= 0) {
      choice.duplicate_of[k] = similar;
    } else {
      distinct.push_back(static_cast<int>(k));
    }
  }
  if (static_cast<int>(distinct.size()) <= max_frames) {
    choice.kept = distinct;
    return choice;
  }
  // Farthest-point over the joint outlines: first the frame seen by the
  // most cameras (then the most corners, then the earliest), then each
  // time, among the frames seen by the most cameras, the one farthest from
  // all chosen (ties: the earlier).
  const auto better_start = [&](int a, int b) {
    const int ca = CamerasSeeing(frames[a]), cb = CamerasSeeing(frames[b]);
    if (ca != cb) return ca > cb;
    return frames[a].corners > frames[b].corners;
  };
  int next = distinct[0];
  for (const int k : distinct) {
    if (better_start(k, next)) next = k;
  }
  std::map<int, double> distance;  // not chosen yet -> to the chosen
  for (const int k : distinct) {
    distance[k] = std::numeric_limits<double>::infinity();
  }
  std::vector<int> chosen;
  while (static_cast<int>(chosen.size()) < max_frames) {
    chosen.push_back(next);
    distance.erase(next);
    if (distance.empty()) break;
    int best = -1;
    for (auto& [k, d] : distance) {
      d = std::min(d, JointDistance(frames[k], frames[next], diagonals));
      if (best < 0) {
        best = k;
        continue;
      }
      const int ck = CamerasSeeing(frames[k]), cb = CamerasSeeing(frames[best]);
      if (ck > cb || (ck == cb && d > distance[best])) best = k;
    }
    next = best;
  }
  std::sort(chosen.begin(), chosen.end());
  choice.kept = chosen;
  for (const auto& [k, d] : distance) {
    choice.not_needed[k] = true;
    double closest = std::numeric_limits<double>::infinity();
    for (const int j : chosen) {
      const double dj = JointDistance(frames[k], frames[j], diagonals);
      if (dj < closest) {
        closest = dj;
        choice.closest[k] = j;
      }
    }
  }
  return choice;
}

std::string RigVideoFrames::Summary() const {
  std::ostringstream out;
  int seen_by_all = 0;
  for (size_t f = 0; f < (views.empty() ? 0 : views[0].size()); ++f) {
    bool all = true;
    for (const std::vector<ImageResult>& camera : views) {
      all = all && !camera[f].file.empty();
    }
    seen_by_all += all;
  }
  out << "rig: " << matched_frames << " frames of "
      << (videos.empty() ? std::string("the reference video")
                         : FileName(videos[0].file))
      << " paired with every other camera's (|dt| <= "
      << StringPrintf("%.1f", tolerance_ms) << " ms), " << unpaired_frames
      << " frame" << (unpaired_frames == 1 ? "" : "s")
      << " of the other cameras without a partner; " << candidate_frames
      << " rig frames show the board, " << near_duplicates
      << " near duplicates, " << not_needed << " not needed, "
      << (views.empty() ? 0 : views[0].size()) << " kept (" << seen_by_all
      << " seen by all " << views.size() << " cameras)";
  return out.str();
}

namespace {

// Per camera, per position in the reference video's examined frames: the
// position of the record paired with it (-1 when none).
using Partners = std::vector<std::vector<int>>;

// The rig frames in which some camera's frame passed the video tests.
struct RigCandidates {
  std::vector<int> reference;               // rig frame -> reference position
  std::vector<std::vector<int>> candidate;  // rig frame -> per camera (-1)
  std::vector<RigFrameOutlines> outlines;   // rig frame -> outlines
};

// Stage 1: each video examined by itself; only the corners of the frames
// that pass are kept (`candidates`, per camera).
bool ExamineRigVideos(const std::vector<std::string>& videos,
                      const Board& board, const PipelineOptions& pipeline,
                      const VideoFrameOptions& video_options, int num_threads,
                      RigVideoFrames* frames,
                      std::vector<std::vector<VideoFrameCandidate>>* candidates,
                      std::string* error) {
  const size_t num_cameras = videos.size();
  candidates->assign(num_cameras, {});
  std::vector<std::string> errors(num_cameras);
  std::vector<char> read(num_cameras, 0);
  frames->videos.resize(num_cameras);
  ParallelFor(static_cast<int>(num_cameras), num_threads, [&](int c) {
    read[c] = ExamineVideo(
        videos[c], board, pipeline, video_options,
        [&](VideoFrameCandidate&& candidate) {
          (*candidates)[c].push_back(std::move(candidate));
        },
        &frames->videos[c], &errors[c]);
  });
  for (size_t c = 0; c < num_cameras; ++c) {
    if (!read[c]) return Fail(errors[c], error);
  }
  return true;
}

// The reason of a kept frame that found no partner in the reference video.
std::string NoPartnerReason(const VideoFrames& reference,
                            const TimePairing& pairing, double tolerance_ms) {
  const std::string reference_name = FileName(reference.file);
  if (pairing.nearest < 0) return reference_name + " has no frame";
  if (pairing.taken) {
    return StringPrintf(
        "%s's frame %d (%+.1f ms) is paired with a nearer frame of this "
        "video",
        reference_name.c_str(), reference.frames[pairing.nearest].index,
        pairing.difference_ms);
  }
  return StringPrintf(
      "no frame of %s within %.1f ms (the nearest, frame %d, is %+.1f ms "
      "away)",
      reference_name.c_str(), tolerance_ms,
      reference.frames[pairing.nearest].index, pairing.difference_ms);
}

// Stage 2: every camera's examined frames paired by time stamp with the
// reference video's (tolerance_ms, unpaired_frames, matched_frames and the
// records' partners and outcomes).
bool PairRigVideos(const RigVideoOptions& options, RigVideoFrames* frames,
                   Partners* partner, std::string* error) {
  const size_t num_cameras = frames->videos.size();
  const VideoFrames& reference = frames->videos[0];
  frames->tolerance_ms = options.max_time_difference_ms > 0
                             ? options.max_time_difference_ms
                             : FramePeriodMs(reference) / 4;
  std::vector<double> reference_ms;
  for (const VideoFrameRecord& r : reference.frames) {
    reference_ms.push_back(r.time_ms);
  }
  if (!std::is_sorted(reference_ms.begin(), reference_ms.end())) {
    return Fail(reference.file + ": its time stamps do not increase", error);
  }
  partner->assign(num_cameras, std::vector<int>(reference_ms.size(), -1));
  for (size_t i = 0; i < reference.frames.size(); ++i) {
    VideoFrameRecord& r = frames->videos[0].frames[i];
    r.reference_frame = r.index;
    (*partner)[0][i] = static_cast<int>(i);
  }
  for (size_t c = 1; c < num_cameras; ++c) {
    std::vector<VideoFrameRecord>& records = frames->videos[c].frames;
    std::vector<double> times;
    for (const VideoFrameRecord& r : records) times.push_back(r.time_ms);
    if (!std::is_sorted(times.begin(), times.end())) {
      return Fail(frames->videos[c].file + ": its time stamps do not increase",
                  error);
    }
    const std::vector<TimePairing> pairings =
        PairFramesByTime(reference_ms, times, frames->tolerance_ms);
    for (size_t i = 0; i < records.size(); ++i) {
      VideoFrameRecord& r = records[i];
      const TimePairing& p = pairings[i];
      if (p.reference >= 0) {
        r.reference_frame = reference.frames[p.reference].index;
        r.time_difference_ms = p.difference_ms;
        (*partner)[c][p.reference] = static_cast<int>(i);
        continue;
      }
      ++frames->unpaired_frames;
      if (r.outcome != VideoFrameOutcome::kKept) continue;
      r.outcome = VideoFrameOutcome::kNoPartner;
      r.reason = NoPartnerReason(reference, p, frames->tolerance_ms);
    }
  }
  for (size_t i = 0; i < reference_ms.size(); ++i) {
    bool all = true;
    for (size_t c = 1; c < num_cameras; ++c) all = all && (*partner)[c][i] >= 0;
    frames->matched_frames += all;
  }
  return true;
}

// Stage 3: the rig frames in which some camera's paired frame passed.
RigCandidates CollectRigCandidates(
    const std::vector<std::vector<VideoFrameCandidate>>& candidates,
    const Partners& partner, const RigVideoFrames& frames) {
  const size_t num_cameras = candidates.size();
  std::vector<std::map<int, int>> candidate_at(num_cameras);  // index -> pos
  for (size_t c = 0; c < num_cameras; ++c) {
    for (size_t k = 0; k < candidates[c].size(); ++k) {
      candidate_at[c][candidates[c][k].index] = static_cast<int>(k);
    }
  }
  RigCandidates rig;
  for (size_t i = 0; i < partner[0].size(); ++i) {
    std::vector<int> at(num_cameras, -1);
    RigFrameOutlines frame;
    frame.seen.assign(num_cameras, false);
    frame.outlines.assign(num_cameras, BoardOutline::Zero());
    for (size_t c = 0; c < num_cameras; ++c) {
      if (partner[c][i] < 0) continue;
      const VideoFrameRecord& r = frames.videos[c].frames[partner[c][i]];
      if (r.outcome != VideoFrameOutcome::kKept) continue;
      at[c] = candidate_at[c].at(r.index);
      const VideoFrameCandidate& candidate = candidates[c][at[c]];
      frame.seen[c] = true;
      frame.outlines[c] = candidate.outline;
      frame.corners +=
          static_cast<int>(candidate.result.decode.observation.id.size());
    }
    if (CamerasSeeing(frame) == 0) continue;
    rig.reference.push_back(static_cast<int>(i));
    rig.candidate.push_back(at);
    rig.outlines.push_back(std::move(frame));
  }
  return rig;
}

// Stage 4: the outcome of every candidate frame that was not chosen (near
// duplicate or not needed, with the chosen frame most like it).
void RecordRigChoice(const RigFrameChoice& choice, const RigCandidates& rig,
                     const Partners& partner, RigVideoFrames* frames) {
  const size_t num_cameras = partner.size();
  const auto record_of = [&](size_t c, int rig_frame) -> VideoFrameRecord& {
    return frames->videos[c].frames[partner[c][rig.reference[rig_frame]]];
  };
  const auto index_in = [&](size_t c, int rig_frame) {
    return rig_frame >= 0 && rig.candidate[rig_frame][c] >= 0
               ? record_of(c, rig_frame).index
               : -1;
  };
  for (size_t k = 0; k < rig.outlines.size(); ++k) {
    const int similar = choice.duplicate_of[k] >= 0 ? choice.duplicate_of[k]
                                                    : choice.closest[k];
    if (choice.duplicate_of[k] >= 0) ++frames->near_duplicates;
    if (choice.not_needed[k]) ++frames->not_needed;
    if (similar < 0) continue;  // kept
    for (size_t c = 0; c < num_cameras; ++c) {
      if (rig.candidate[k][c] < 0) continue;
      VideoFrameRecord& r = record_of(c, static_cast<int>(k));
      r.outcome = choice.duplicate_of[k] >= 0
                      ? VideoFrameOutcome::kNearDuplicate
                      : VideoFrameOutcome::kNotNeeded;
      r.similar_frame = index_in(c, similar);
      r.pose_change_px =
          r.similar_frame >= 0
              ? OutlineDistance(rig.outlines[k].outlines[c],
                                rig.outlines[similar].outlines[c])
              : -1;
    }
  }
}

// Stage 5: the chosen frames' views (moved out of `candidates`) and names.
void TakeChosenViews(const std::vector<int>& kept, const RigCandidates& rig,
                     const Partners& partner,
                     const std::vector<std::string>& videos,
                     std::vector<std::vector<VideoFrameCandidate>>* candidates,
                     RigVideoFrames* frames) {
  const size_t num_cameras = partner.size();
  frames->views.assign(num_cameras, {});
  frames->frame_files.assign(num_cameras, {});
  for (const int k : kept) {
    for (size_t c = 0; c < num_cameras; ++c) {
      const int paired = partner[c][rig.reference[k]];
      frames->frame_files[c].push_back(
          paired < 0 ? std::string()
                     : VideoFrameName(videos[c],
                                      frames->videos[c].frames[paired].index));
      ImageResult view;
      if (rig.candidate[k][c] >= 0) {
        view = std::move((*candidates)[c][rig.candidate[k][c]].result);
      }
      frames->views[c].push_back(std::move(view));
    }
  }
}

}  // namespace

bool ReadRigVideos(const std::vector<std::string>& videos, const Board& board,
                   const PipelineOptions& pipeline,
                   const VideoFrameOptions& video_options,
                   const RigVideoOptions& options, int num_threads,
                   RigVideoFrames* frames, std::string* error) {
  *frames = RigVideoFrames();
  std::string why;
  if (!video_options.Check(&why)) return Fail("video: " + why, error);
  if (!options.Check(&why)) return Fail("rig_video: " + why, error);
  if (videos.empty()) return Fail("no video", error);
  std::vector<std::vector<VideoFrameCandidate>> candidates;
  Partners partner;
  if (!ExamineRigVideos(videos, board, pipeline, video_options, num_threads,
                        frames, &candidates, error) ||
      !PairRigVideos(options, frames, &partner, error)) {
    return false;
  }
  const RigCandidates rig = CollectRigCandidates(candidates, partner, *frames);
  frames->candidate_frames = static_cast<int>(rig.outlines.size());
  std::vector<double> diagonals;
  for (const VideoFrames& video : frames->videos) {
    diagonals.push_back(std::max(1.0, std::hypot(video.width, video.height)));
  }
  const RigFrameChoice choice =
      ChooseRigFrames(rig.outlines, diagonals, video_options.min_pose_change,
                      video_options.max_frames);
  RecordRigChoice(choice, rig, partner, frames);
  TakeChosenViews(choice.kept, rig, partner, videos, &candidates, frames);
  return true;
}

int MakeRigVideoCameraViews(const Board& board, size_t c,
                            RigVideoFrames* frames, RigCameraInput* input,
                            std::vector<std::string>* frame_files) {
  std::vector<ImageResult>& views = frames->views[c];
  const size_t num_frames = views.size();
  std::vector<ImageResult> results;
  std::vector<size_t> frame_of;
  for (size_t f = 0; f < num_frames; ++f) {
    if (views[f].file.empty()) continue;
    results.push_back(std::move(views[f]));
    frame_of.push_back(f);
  }
  views.clear();
  input->frames.assign(num_frames, CalibrationView());
  std::vector<CalibrationView> made =
      MakeCalibrationViews(board, &results, &input->width, &input->height);
  if (input->width == 0) {
    input->width = frames->videos[c].width;
    input->height = frames->videos[c].height;
  }
  int count = 0;
  for (size_t k = 0; k < results.size(); ++k) {
    if (results[k].view_index < 0) continue;
    input->frames[frame_of[k]] = std::move(made[results[k].view_index]);
    ++count;
  }
  *frame_files = frames->frame_files[c];
  return count;
}

}  // namespace puzzlecal
