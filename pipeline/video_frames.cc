#include "pipeline/video_frames.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>

#include "calib/initialization.h"
#include "formats/image_io.h"
#include "formats/video_io.h"
#include "util/enum_names.h"
#include "util/failure.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

constexpr EnumName<VideoFrameOutcome> kOutcomeNames[] = {
    {VideoFrameOutcome::kKept, "kept"},
    {VideoFrameOutcome::kNoBoard, "no board"},
    {VideoFrameOutcome::kFewCorners, "few corners"},
    {VideoFrameOutcome::kBlurred, "blurred"},
    {VideoFrameOutcome::kNearDuplicate, "near duplicate"},
    {VideoFrameOutcome::kNotNeeded, "not needed"},
    {VideoFrameOutcome::kNoPartner, "no partner"},
};

// Bilinear grey level at (x, y); false outside the image.
bool SampleGrey(const cv::Mat& grey, double x, double y, double* value) {
  if (!(x >= 0 && y >= 0 && x < grey.cols - 1 && y < grey.rows - 1)) {
    return false;
  }
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double fx = x - x0, fy = y - y0;
  const uchar* row0 = grey.ptr<uchar>(y0) + x0;
  const uchar* row1 = grey.ptr<uchar>(y0 + 1) + x0;
  *value = (1 - fy) * ((1 - fx) * row0[0] + fx * row0[1]) +
           fy * ((1 - fx) * row1[0] + fx * row1[1]);
  return true;
}

// Grey level averaged over a small cross of points around `p` (radius
// `r` pixels); false outside the image.
bool MeanGrey(const cv::Mat& grey, const Eigen::Vector2d& p, double r,
              double* value) {
  const Eigen::Vector2d offsets[] = {
      {0, 0}, {r, 0}, {-r, 0}, {0, r}, {0, -r}};
  double sum = 0;
  for (const Eigen::Vector2d& offset : offsets) {
    double v = 0;
    if (!SampleGrey(grey, p.x() + offset.x(), p.y() + offset.y(), &v)) {
      return false;
    }
    sum += v;
  }
  *value = sum / 5;
  return true;
}

// The width of the tile edge from corner `a` along the lattice step `along`
// to its neighbour, in pixels across the edge: the contrast between the two
// tiles beside it (at their centres, where the grey is plain however long
// the edge's ramp) over the steepest slope of the grey across the edge
// (pixels: 0.8 of it is a linear ramp's 10 %-90 % rise, 1.0 a Gaussian
// edge's). Contrast over slope needs no flat stretch beside the edge, so it
// measures ramps as long as half a tile. The slope is taken on profiles
// along the other lattice step `across` (not along the edge's normal: in a
// slanted view the normal leaves the two tiles beside the edge) at 22-28 %
// of the way along the edge, reaching 30 % of the step across to each side:
// there they stay clear of a PuzzleBoard's bit discs (diameter 1/3 step,
// centred on the edge midpoints: this edge's at 50 % of the way, the
// crossing edges' at 0 % and half a step to each side) and of the crossing
// edge through the corner. The width along the profile is scaled by the
// sine of the angle between the steps. -1 when a step is under 10 px
// (too few pixels to tell), the lattice is nearly edge-on, a sample leaves
// the image or the tiles differ too little (a streak along the edge mixes
// in the colours beyond the corner).
double EdgeWidth(const cv::Mat& grey, const Eigen::Vector2d& a,
                 const Eigen::Vector2d& along, const Eigen::Vector2d& across) {
  constexpr double kStep = 0.25;       // pixels along the profile
  constexpr double kReach = 0.3;       // of the step across, to each side
  constexpr double kMinContrast = 12;  // grey levels between the two tiles
  constexpr double kMinStepPx = 7;
  if (across.norm() < kMinStepPx || along.norm() < kMinStepPx) return -1;
  const double sine =
      std::abs(along.x() * across.y() - along.y() * across.x()) /
      (along.norm() * across.norm());
  if (!(sine > 0.3)) return -1;
  double one_side = 0, other_side = 0;
  const Eigen::Vector2d mid = a + 0.5 * along;
  const double centre_radius = 0.1 * std::min(along.norm(), across.norm());
  if (!MeanGrey(grey, mid + 0.5 * across, centre_radius, &one_side) ||
      !MeanGrey(grey, mid - 0.5 * across, centre_radius, &other_side)) {
    return -1;
  }
  const double contrast = std::abs(one_side - other_side);
  if (contrast < kMinContrast) return -1;
  const double half_length = kReach * across.norm();
  const Eigen::Vector2d direction = across.normalized();
  const int n = static_cast<int>(2 * half_length / kStep) + 1;
  std::vector<double> profile(n, 0.0);
  for (const double fraction : {0.22, 0.25, 0.28}) {
    const Eigen::Vector2d centre = a + fraction * along;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = centre + (-half_length + i * kStep) * direction;
      double value = 0;
      if (!SampleGrey(grey, p.x(), p.y(), &value)) return -1;
      profile[i] += value / 3;
    }
  }
  // The slope over one pixel (4 samples), the steepest along the profile.
  constexpr int kSpan = 4;
  double steepest = 0;
  for (int i = 0; i + kSpan < n; ++i) {
    steepest = std::max(steepest,
                        std::abs(profile[i + kSpan] - profile[i]) /
                            (kSpan * kStep));
  }
  if (!(steepest > 0)) return -1;
  return contrast / steepest * sine;
}

// The largest lattice component's corners with their relative labels, for
// the sharpness of a frame whose code was not read.
BoardObservation LatticeOf(const ImageResult& result) {
  BoardObservation lattice;
  const GridComponent& component = result.components.front();
  for (size_t k = 0; k < component.corner.size(); ++k) {
    lattice.id.push_back(component.ij[k]);
    lattice.xy.push_back(result.corners[component.corner[k]].xy);
  }
  return lattice;
}

double Median(std::vector<double> values) {
  if (values.empty()) return -1;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

// Where the candidate's outline is closest to one of `kept`: its index in
// `kept` and the distance (-1, infinity when `kept` is empty).
std::pair<int, double> ClosestOutline(
    const BoardOutline& outline,
    const std::vector<const VideoFrameCandidate*>& kept) {
  std::pair<int, double> closest{-1, std::numeric_limits<double>::infinity()};
  for (size_t k = 0; k < kept.size(); ++k) {
    const double distance = OutlineDistance(outline, kept[k]->outline);
    if (distance < closest.second) closest = {static_cast<int>(k), distance};
  }
  return closest;
}

// At most `max_frames` of `candidates`: the one with the most corners, then
// repeatedly the one farthest from all chosen (ties: the earlier frame).
// Returns the chosen positions, sorted.
std::vector<size_t> SpreadChoice(
    const std::vector<VideoFrameCandidate>& candidates, int max_frames) {
  std::vector<size_t> chosen;
  if (candidates.empty()) return chosen;
  if (static_cast<int>(candidates.size()) <= max_frames) {
    for (size_t i = 0; i < candidates.size(); ++i) chosen.push_back(i);
    return chosen;
  }
  size_t first = 0;
  for (size_t i = 1; i < candidates.size(); ++i) {
    if (candidates[i].result.decode.observation.id.size() >
        candidates[first].result.decode.observation.id.size()) {
      first = i;
    }
  }
  std::vector<double> distance(candidates.size(),
                               std::numeric_limits<double>::infinity());
  size_t next = first;
  while (static_cast<int>(chosen.size()) < max_frames) {
    chosen.push_back(next);
    distance[next] = -1;
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (distance[i] < 0) continue;
      distance[i] = std::min(distance[i], OutlineDistance(candidates[i].outline,
                                                          candidates[next].outline));
    }
    next = static_cast<size_t>(
        std::max_element(distance.begin(), distance.end()) - distance.begin());
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

}  // namespace

const char* VideoFrameOutcomeName(VideoFrameOutcome outcome) {
  return NameOf(kOutcomeNames, outcome, "unknown");
}

bool VideoFrameOptions::Check(std::string* why) const {
  if (frame_step < 1) return Fail("frame_step must be >= 1", why);
  if (min_corners < 6) return Fail("min_corners must be >= 6", why);
  if (!(max_edge_width_px > 0)) {
    return Fail("max_edge_width_px must be > 0", why);
  }
  if (max_edges < 4) return Fail("max_edges must be >= 4", why);
  if (!(min_pose_change >= 0)) return Fail("min_pose_change must be >= 0", why);
  if (max_frames < 1) return Fail("max_frames must be >= 1", why);
  return true;
}

std::string VideoFrameName(const std::string& video, int index) {
  return StringPrintf("%s#frame%04d", video.c_str(), index);
}

bool ParseVideoFrameName(const std::string& name, std::string* video,
                         int* index) {
  const size_t hash = name.rfind("#frame");
  if (hash == std::string::npos || hash == 0) return false;
  const std::string digits = name.substr(hash + 6);
  if (digits.empty() || digits.size() > 9 ||
      !std::all_of(digits.begin(), digits.end(),
                   [](char ch) { return ch >= '0' && ch <= '9'; })) {
    return false;
  }
  *video = name.substr(0, hash);
  *index = std::stoi(digits);
  return true;
}

bool LoadFrameImage(const std::string& file, cv::Mat* grey,
                    std::string* error) {
  std::string video;
  int index = 0;
  if (!ParseVideoFrameName(file, &video, &index) ||
      !HasVideoExtension(video)) {
    return LoadGreyImage(file, ImageLoadOptions(), grey, error);
  }
  VideoReader reader;
  if (!reader.Open(video, error)) return false;
  double time_ms = 0;
  for (int i = 0; i <= index; ++i) {
    if (!reader.Read(grey, &time_ms)) {
      return Fail(file + ": the video ends (or cannot be decoded) before "
                         "frame " + std::to_string(index),
                  error);
    }
  }
  return true;
}

int VideoFrames::Count(VideoFrameOutcome outcome) const {
  return static_cast<int>(
      std::count_if(frames.begin(), frames.end(),
                    [&](const VideoFrameRecord& r) { return r.outcome == outcome; }));
}

std::string VideoFrames::Summary() const {
  const int examined = static_cast<int>(frames.size());
  const int no_board = Count(VideoFrameOutcome::kNoBoard);
  std::ostringstream out;
  out << fs::path(file).filename().string() << ": " << frames_decoded
      << " frames";
  if (examined != frames_decoded) out << " (" << examined << " examined)";
  out << ", " << examined - no_board << " with the board, "
      << Count(VideoFrameOutcome::kFewCorners) << " with few corners, "
      << Count(VideoFrameOutcome::kBlurred) << " blurred, "
      << Count(VideoFrameOutcome::kNearDuplicate) << " near duplicates, "
      << Count(VideoFrameOutcome::kNotNeeded) << " not needed, "
      << Count(VideoFrameOutcome::kKept) << " kept";
  if (const int no_partner = Count(VideoFrameOutcome::kNoPartner);
      no_partner > 0) {
    out << ", " << no_partner << " without a partner in time";
  }
  if (!note.empty()) out << "; " << note;
  return out.str();
}

std::string VideoFrames::Csv(bool with_partners) const {
  std::ostringstream out;
  out << "frame,time_ms,outcome,corners,edge_width_px,pose_change_px,"
         "similar_frame,reason"
      << (with_partners ? ",reference_frame,time_difference_ms\n" : "\n");
  for (const VideoFrameRecord& r : frames) {
    std::string reason = r.reason;
    std::replace(reason.begin(), reason.end(), '"', '\'');
    out << r.index << "," << StringPrintf("%.3f", r.time_ms) << ","
        << VideoFrameOutcomeName(r.outcome) << "," << r.num_corners << ","
        << (r.edge_width_px < 0 ? "" : StringPrintf("%.2f", r.edge_width_px))
        << ","
        << (r.pose_change_px < 0 ? ""
                                 : StringPrintf("%.1f", r.pose_change_px))
        << "," << (r.similar_frame < 0 ? "" : std::to_string(r.similar_frame))
        << ",\"" << reason << "\"";
    if (with_partners) {
      out << ","
          << (r.reference_frame < 0 ? "" : std::to_string(r.reference_frame))
          << ","
          << (r.reference_frame < 0
                  ? ""
                  : StringPrintf("%.3f", r.time_difference_ms));
    }
    out << "\n";
  }
  return out.str();
}

double BoardEdgeWidth(const cv::Mat& grey, const BoardObservation& observation,
                      int max_edges) {
  std::map<std::pair<int, int>, Eigen::Vector2d> at;
  for (size_t k = 0; k < observation.id.size(); ++k) {
    at[{observation.id[k].x(), observation.id[k].y()}] = observation.xy[k];
  }
  const auto find = [&](int x, int y) -> const Eigen::Vector2d* {
    const auto it = at.find({x, y});
    return it == at.end() ? nullptr : &it->second;
  };
  // Edges along the board's x and along its y, each measured across.
  std::vector<double> widths[2];
  // Every stride-th corner (in id order), so the edges spread over the
  // board.
  const int stride = std::max<int>(
      1, static_cast<int>(2 * observation.id.size() / std::max(1, max_edges)));
  int counter = 0;
  for (const auto& [id, a] : at) {
    if (counter++ % stride != 0) continue;
    for (int direction = 0; direction < 2; ++direction) {
      const int dx = direction == 0 ? 1 : 0, dy = 1 - dx;
      const Eigen::Vector2d* b = find(id.first + dx, id.second + dy);
      if (b == nullptr) continue;
      // The step across: to the neighbour on the other axis, or from the
      // one on its other side.
      Eigen::Vector2d across;
      if (const Eigen::Vector2d* c = find(id.first + dy, id.second + dx)) {
        across = *c - a;
      } else if (const Eigen::Vector2d* c = find(id.first - dy, id.second - dx)) {
        across = a - *c;
      } else {
        continue;
      }
      const double rise = EdgeWidth(grey, a, *b - a, across);
      if (rise >= 0) widths[direction].push_back(rise);
    }
  }
  // A direction with a few measurable edges only (tiny or edge-on tiles)
  // does not tell; the frame's sharpness is then the other direction's.
  constexpr size_t kMinEdges = 5;
  double width = -1;
  for (const std::vector<double>& measured : widths) {
    if (measured.size() >= kMinEdges) width = std::max(width, Median(measured));
  }
  return width;
}

bool BoardOutlineOf(const Board& board, const BoardObservation& observation,
                    int width, int height, BoardOutline* outline) {
  // Pixels as rays of a pinhole of focal length `scale`: the homography
  // fit's angular outlier test then sees angles of a normal field of view.
  const double scale = std::max(width, height);
  const Eigen::Vector2d centre(width / 2.0, height / 2.0);
  std::vector<Eigen::Vector2d> board_xy;
  std::vector<Eigen::Vector3d> rays;
  for (size_t k = 0; k < observation.id.size(); ++k) {
    board_xy.push_back(board.Point(observation.id[k]).head<2>());
    const Eigen::Vector2d p = (observation.xy[k] - centre) / scale;
    rays.push_back(Eigen::Vector3d(p.x(), p.y(), 1.0).normalized());
  }
  Eigen::Matrix3d h;
  if (!EstimateBoardToRayHomography(board_xy, rays, InitializationOptions(),
                                    &h, nullptr)) {
    return false;
  }
  const Eigen::Vector2i first = board.origin;
  const Eigen::Vector2i last = board.origin + Eigen::Vector2i(board.cols - 1,
                                                              board.rows - 1);
  const Eigen::Vector2i corners[4] = {first,
                                      {last.x(), first.y()},
                                      last,
                                      {first.x(), last.y()}};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d ray =
        h * board.Point(corners[i]).head<2>().homogeneous();
    // A corner behind the camera or at the horizon: far from any pose.
    if (!(ray.z() > 1e-9)) return false;
    outline->col(i) = centre + scale * ray.hnormalized();
  }
  return true;
}

double OutlineDistance(const BoardOutline& a, const BoardOutline& b) {
  return (a - b).colwise().norm().mean();
}

bool ExamineVideo(
    const std::string& path, const Board& board,
    const PipelineOptions& pipeline, const VideoFrameOptions& options,
    const std::function<void(VideoFrameCandidate&&)>& on_candidate,
    VideoFrames* frames, std::string* error) {
  *frames = VideoFrames();
  frames->file = path;
  VideoReader reader;
  if (!reader.Open(path, error)) return false;
  frames->fps = reader.fps();
  frames->frames_stated = reader.frame_count();
  CornerDetector detector(pipeline.detector);
  cv::Mat grey;
  double time_ms = 0;
  for (int index = 0; reader.Read(&grey, &time_ms); ++index) {
    ++frames->frames_decoded;
    frames->width = grey.cols;
    frames->height = grey.rows;
    if (index % options.frame_step != 0) continue;
    VideoFrameRecord record;
    record.index = index;
    record.time_ms = time_ms;
    VideoFrameCandidate candidate;
    candidate.index = index;
    candidate.time_ms = time_ms;
    candidate.result.file = VideoFrameName(path, index);
    ImageResult& result = candidate.result;
    ProcessGreyImage(grey, board, pipeline, &result, &detector);
    const BoardObservation& seen = result.decode.observation;
    record.num_corners = static_cast<int>(seen.id.size());
    if (result.outcome != ImageOutcome::kUsable) {
      record.outcome = VideoFrameOutcome::kNoBoard;
      record.reason = std::string(ImageOutcomeName(result.outcome)) + ": " +
                      result.reason;
      // A lattice whose code could not be read: blur is the likely reason,
      // and when its edges say so the frame is counted as blurred.
      if (!result.components.empty()) {
        record.edge_width_px =
            BoardEdgeWidth(grey, LatticeOf(result), options.max_edges);
        if (record.edge_width_px > options.max_edge_width_px) {
          record.outcome = VideoFrameOutcome::kBlurred;
        }
      }
    } else if (record.num_corners < options.min_corners) {
      record.outcome = VideoFrameOutcome::kFewCorners;
    } else {
      record.edge_width_px = BoardEdgeWidth(grey, seen, options.max_edges);
      if (record.edge_width_px < 0 ||
          record.edge_width_px > options.max_edge_width_px) {
        record.outcome = VideoFrameOutcome::kBlurred;
      } else if (!BoardOutlineOf(board, seen, grey.cols, grey.rows,
                                 &candidate.outline)) {
        record.outcome = VideoFrameOutcome::kFewCorners;
        record.reason = "the corners give no board pose";
      } else {
        record.outcome = VideoFrameOutcome::kKept;
        // Only the corners with ids stay in memory.
        result.corners = {};
        result.components = {};
        on_candidate(std::move(candidate));
      }
    }
    frames->frames.push_back(std::move(record));
  }
  if (frames->frames_decoded == 0) {
    return Fail(path + ": not a readable video (no frame could be decoded)",
                error);
  }
  // Containers estimate their length; a shortfall of more than a second's
  // frames means decoding stopped early.
  const double slack = std::max(2.0, frames->fps);
  if (frames->frames_stated > frames->frames_decoded + slack) {
    frames->note = StringPrintf(
        "decoding stopped after %d of %lld frames (the rest of the file is "
        "damaged or cut)",
        frames->frames_decoded, frames->frames_stated);
  }
  return true;
}

bool ReadVideoFrames(const std::string& path, const Board& board,
                     const PipelineOptions& pipeline,
                     const VideoFrameOptions& options, VideoFrames* frames,
                     std::string* error) {
  // Near duplicates are dropped as the frames come, so only frames showing
  // a new pose are held.
  std::vector<VideoFrameCandidate> candidates;
  std::map<int, std::pair<int, double>> duplicate_of;  // frame -> (frame, px)
  const double diagonal_fraction = options.min_pose_change;
  double diagonal = 0;
  const auto on_candidate = [&](VideoFrameCandidate&& candidate) {
    diagonal = std::hypot(candidate.result.width, candidate.result.height);
    std::vector<const VideoFrameCandidate*> kept;
    for (const VideoFrameCandidate& c : candidates) kept.push_back(&c);
    const auto [closest, distance] = ClosestOutline(candidate.outline, kept);
    if (closest >= 0 && distance < diagonal_fraction * diagonal) {
      duplicate_of[candidate.index] = {candidates[closest].index, distance};
      return;
    }
    candidates.push_back(std::move(candidate));
  };
  if (!ExamineVideo(path, board, pipeline, options, on_candidate, frames,
                    error)) {
    return false;
  }
  const std::vector<size_t> chosen =
      SpreadChoice(candidates, options.max_frames);
  std::map<int, size_t> chosen_position;  // frame -> position in candidates
  for (size_t i : chosen) chosen_position[candidates[i].index] = i;
  std::vector<const VideoFrameCandidate*> chosen_candidates;
  for (size_t i : chosen) chosen_candidates.push_back(&candidates[i]);
  std::map<int, const VideoFrameCandidate*> by_index;
  for (const VideoFrameCandidate& c : candidates) by_index[c.index] = &c;
  for (VideoFrameRecord& record : frames->frames) {
    if (record.outcome != VideoFrameOutcome::kKept) continue;
    if (const auto dup = duplicate_of.find(record.index);
        dup != duplicate_of.end()) {
      record.outcome = VideoFrameOutcome::kNearDuplicate;
      record.similar_frame = dup->second.first;
      record.pose_change_px = dup->second.second;
      continue;
    }
    if (chosen_position.count(record.index) > 0) continue;
    // Beyond max_frames: say which chosen frame shows the closest pose.
    const auto [closest, distance] =
        ClosestOutline(by_index.at(record.index)->outline, chosen_candidates);
    record.outcome = VideoFrameOutcome::kNotNeeded;
    record.similar_frame = chosen_candidates[closest]->index;
    record.pose_change_px = distance;
  }
  for (size_t i : chosen) frames->kept.push_back(std::move(candidates[i].result));
  return true;
}

}  // namespace puzzlecal
