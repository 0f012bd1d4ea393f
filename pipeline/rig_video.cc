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
  if (!(max_time_difference_ms >= 0) || !std::isfinite(max_time_difference_ms)) {
    return Fail("max_time_difference_ms must be >= 0 (0: a quarter of the "
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
    if (after > 0 &&
        (after == reference_ms.size() ||
         t - reference_ms[after - 1] <= reference_ms[after] - t)) {
      nearest = static_cast<int>(after - 1);  // ties: the earlier
    }
    p.nearest = nearest;
    p.difference_ms = t - reference_ms[nearest];
    if (!(std::abs(p.difference_ms) <= tolerance_ms)) continue;
    int& holder = claimed_by[nearest];
    if (holder >= 0 && std::abs(pairings[holder].difference_ms) <=
                           std::abs(p.difference_ms)) {
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

bool ReadRigVideos(const std::vector<std::string>& videos, const Board& board,
                   const PipelineOptions& pipeline,
                   const VideoFrameOptions& video_options,
                   const RigVideoOptions& options, int num_threads,
                   RigVideoFrames* frames, std::string* error) {
  *frames = RigVideoFrames();
  std::string why;
  if (!video_options.Check(&why)) return Fail("video: " + why, error);
  if (!options.Check(&why)) return Fail("rig_video: " + why, error);
  const size_t num_cameras = videos.size();
  if (num_cameras < 1) return Fail("no video", error);
  // Each video examined by itself; only the corners of the frames that
  // pass are kept.
  std::vector<std::vector<VideoFrameCandidate>> candidates(num_cameras);
  std::vector<std::string> errors(num_cameras);
  std::vector<char> read(num_cameras, 0);
  frames->videos.resize(num_cameras);
  ParallelFor(static_cast<int>(num_cameras), num_threads, [&](int c) {
    read[c] = ExamineVideo(
        videos[c], board, pipeline, video_options,
        [&](VideoFrameCandidate&& candidate) {
          candidates[c].push_back(std::move(candidate));
        },
        &frames->videos[c], &errors[c]);
  });
  for (size_t c = 0; c < num_cameras; ++c) {
    if (!read[c]) return Fail(errors[c], error);
  }
  // Pairing by time stamp with the reference video's examined frames.
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
  // Per camera, per reference position: the record paired with it (-1).
  std::vector<std::vector<int>> partner(
      num_cameras, std::vector<int>(reference_ms.size(), -1));
  for (size_t i = 0; i < reference.frames.size(); ++i) {
    VideoFrameRecord& r = frames->videos[0].frames[i];
    r.reference_frame = r.index;
    partner[0][i] = static_cast<int>(i);
  }
  const std::string reference_name = FileName(reference.file);
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
        partner[c][p.reference] = static_cast<int>(i);
        continue;
      }
      ++frames->unpaired_frames;
      if (r.outcome != VideoFrameOutcome::kKept) continue;
      r.outcome = VideoFrameOutcome::kNoPartner;
      if (p.nearest < 0) {
        r.reason = reference_name + " has no frame";
      } else if (p.taken) {
        r.reason = StringPrintf(
            "%s's frame %d (%+.1f ms) is paired with a nearer frame of this "
            "video",
            reference_name.c_str(), reference.frames[p.nearest].index,
            p.difference_ms);
      } else {
        r.reason = StringPrintf(
            "no frame of %s within %.1f ms (the nearest, frame %d, is %+.1f "
            "ms away)",
            reference_name.c_str(), frames->tolerance_ms,
            reference.frames[p.nearest].index, p.difference_ms);
      }
    }
  }
  for (size_t i = 0; i < reference_ms.size(); ++i) {
    bool all = true;
    for (size_t c = 1; c < num_cameras; ++c) all = all && partner[c][i] >= 0;
    frames->matched_frames += all;
  }
  // The rig frames in which some camera's frame passed: per reference
  // position, per camera the candidate (position in candidates[c]).
  std::vector<std::map<int, int>> candidate_at(num_cameras);  // index -> pos
  for (size_t c = 0; c < num_cameras; ++c) {
    for (size_t k = 0; k < candidates[c].size(); ++k) {
      candidate_at[c][candidates[c][k].index] = static_cast<int>(k);
    }
  }
  std::vector<int> rig_reference;             // rig frame -> reference pos
  std::vector<std::vector<int>> rig_candidate;  // rig frame -> per camera
  std::vector<RigFrameOutlines> outlines;
  for (size_t i = 0; i < reference_ms.size(); ++i) {
    std::vector<int> at(num_cameras, -1);
    RigFrameOutlines frame;
    frame.seen.assign(num_cameras, false);
    frame.outlines.assign(num_cameras, BoardOutline::Zero());
    for (size_t c = 0; c < num_cameras; ++c) {
      if (partner[c][i] < 0) continue;
      const VideoFrameRecord& r = frames->videos[c].frames[partner[c][i]];
      if (r.outcome != VideoFrameOutcome::kKept) continue;
      at[c] = candidate_at[c].at(r.index);
      const VideoFrameCandidate& candidate = candidates[c][at[c]];
      frame.seen[c] = true;
      frame.outlines[c] = candidate.outline;
      frame.corners +=
          static_cast<int>(candidate.result.decode.observation.id.size());
    }
    if (CamerasSeeing(frame) == 0) continue;
    rig_reference.push_back(static_cast<int>(i));
    rig_candidate.push_back(at);
    outlines.push_back(std::move(frame));
  }
  frames->candidate_frames = static_cast<int>(outlines.size());
  std::vector<double> diagonals;
  for (const VideoFrames& video : frames->videos) {
    diagonals.push_back(std::max(1.0, std::hypot(video.width, video.height)));
  }
  const RigFrameChoice choice =
      ChooseRigFrames(outlines, diagonals, video_options.min_pose_change,
                      video_options.max_frames);
  // The outcomes of the candidates' records.
  const auto record_of = [&](size_t c, int rig_frame) -> VideoFrameRecord& {
    return frames->videos[c].frames[partner[c][rig_reference[rig_frame]]];
  };
  const auto index_in = [&](size_t c, int rig_frame) {
    return rig_frame >= 0 && rig_candidate[rig_frame][c] >= 0
               ? record_of(c, rig_frame).index
               : -1;
  };
  for (size_t k = 0; k < outlines.size(); ++k) {
    const int similar = choice.duplicate_of[k] >= 0 ? choice.duplicate_of[k]
                                                    : choice.closest[k];
    if (choice.duplicate_of[k] >= 0) ++frames->near_duplicates;
    if (choice.not_needed[k]) ++frames->not_needed;
    if (similar < 0) continue;  // kept
    for (size_t c = 0; c < num_cameras; ++c) {
      if (rig_candidate[k][c] < 0) continue;
      VideoFrameRecord& r = record_of(c, static_cast<int>(k));
      r.outcome = choice.duplicate_of[k] >= 0
                      ? VideoFrameOutcome::kNearDuplicate
                      : VideoFrameOutcome::kNotNeeded;
      r.similar_frame = index_in(c, similar);
      r.pose_change_px =
          r.similar_frame >= 0
              ? OutlineDistance(outlines[k].outlines[c],
                                outlines[similar].outlines[c])
              : -1;
    }
  }
  // The chosen frames' views and names.
  frames->views.assign(num_cameras, {});
  frames->frame_files.assign(num_cameras, {});
  for (const int k : choice.kept) {
    for (size_t c = 0; c < num_cameras; ++c) {
      const int paired = partner[c][rig_reference[k]];
      frames->frame_files[c].push_back(
          paired < 0 ? std::string()
                     : VideoFrameName(videos[c],
                                      frames->videos[c].frames[paired].index));
      ImageResult view;
      if (rig_candidate[k][c] >= 0) {
        view = std::move(candidates[c][rig_candidate[k][c]].result);
      }
      frames->views[c].push_back(std::move(view));
    }
  }
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
