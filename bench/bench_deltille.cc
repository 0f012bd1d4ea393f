// Grid coverage on the deltille fisheye photos (an 11 x 8 inner-corner
// checkerboard, 20 mm tiles, strong fisheye) against pseudo-truth:
//  1. every photo runs through detection -> grid -> decode
//  (pipeline/pipeline.h);
//  2. the decoded checkerboard views calibrate a kannala-brandt-noncentral
//     camera (the central model is pixels off for the closest boards, which
//     shifted the pseudo-truth window of photo 0208 by a row);
//  3. per photo, the board frame of its view (the labels of its largest
//     component) is placed by the view's calibrated pose (PnP through the
//     camera for views the calibration did not use); the 11 x 8 window of
//     lattice points that looks most like the printed board (checkerboard
//     saddles at the projected tile centres) is the board; the pose
//     is refitted to every detection near a projected board corner and all
//     88 corners are projected again: the pseudo-truth;
//  4. detections within match_px of a projected corner carry its id, the
//     rest are off the board, and the grid's components are scored with the
//     wrong-label metric of tests/grid (fewest corners removed so that all
//     label differences match the id differences under the component's best
//     lattice transform).
// Prints JSON: per photo the board corners visible (projected inside the
// image), detected (a detection within match_px), labelled in the largest
// component, the largest component's size, the components holding board
// corners, wrong labels, off-board corners in those components
// (`off_board`, the grid's components whether decoded or not), off-board
// corners that hold a board id in the decoded output (`off_board_ids`), and
// the visible corners the detector missed; then a summary.
//
// With --models only the model comparison: kannala-brandt and
// kannala-brandt-noncentral on the decoded views, each with the default
// outlier rejection and with rejection off (RMS, rejected fraction, views
// used, parameters with standard deviations, and for the non-central model
// how far its far-field part is off at the closest board distance).
//
// Usage: bench_deltille [data_dir] [threads] [-v] [--draw DIR] [--models]
//                       [grid_option=value ...]
//   -v: per photo the grid's counters, unlabelled board corners and split
//   board edges on stderr; --draw: an overlay per photo into DIR.
//   data_dir: the folder holding deltille/fisheye (default $PUZZLECAL_DATA,
//   then ../shared).

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "calib/initialization.h"
#include "formats/camera_yaml.h"
#include "pipeline/pipeline.h"
#include "tests/grid/grid_test_util.h"
#include "tests/support/deltille_data.h"

namespace puzzlecal {
namespace {

// A detection within this distance of its projected corner counts as
// accurate.
constexpr double kMatchPx = 1.5;
// A detection is associated with the nearest projected board corner when it
// lies within this fraction of the local tile edge (in pixels) of it and that
// corner is also the nearest to it: the model and the detector disagree by
// up to several pixels at the fisheye rim, where tiles are still 15-30 px.
constexpr double kAssociateFraction = 0.3;
constexpr int kWindowMargin = 12;  // lattice points searched around a view

double Grey(const cv::Mat& image, const Eigen::Vector2d& p) {
  if (!(p.x() >= 0 && p.y() >= 0 && p.x() <= image.cols - 1 &&
        p.y() <= image.rows - 1))
    return -1;
  const int x0 = std::min(static_cast<int>(p.x()), image.cols - 2);
  const int y0 = std::min(static_cast<int>(p.y()), image.rows - 2);
  const double fx = p.x() - x0, fy = p.y() - y0;
  auto at = [&](int x, int y) { return double(image.at<uint8_t>(y, x)); };
  const double top = at(x0, y0) + fx * (at(x0 + 1, y0) - at(x0, y0));
  const double bottom =
      at(x0, y0 + 1) + fx * (at(x0 + 1, y0 + 1) - at(x0, y0 + 1));
  return top + fy * (bottom - top);
}

bool ProjectBoardPoint(const Camera& camera, const Eigen::Isometry3d& pose,
                       double tile, const Eigen::Vector2d& id,
                       Eigen::Vector2d* pixel) {
  const Eigen::Vector3d cam =
      pose * Eigen::Vector3d(id.x() * tile, id.y() * tile, 0);
  if (!camera.Project(cam, pixel)) return false;
  return std::isfinite(pixel->x()) && std::isfinite(pixel->y());
}

bool InImage(const Camera& camera, const Eigen::Vector2d& p) {
  return p.x() >= 0 && p.y() >= 0 && p.x() <= camera.width - 1 &&
         p.y() <= camera.height - 1;
}

// +1 or -1 (by the colouring) when lattice point `id` looks like a
// checkerboard saddle, else 0 (also when a tile centre is not in the image).
double SaddleScore(const cv::Mat& image, const Camera& camera,
                   const Eigen::Isometry3d& pose, double tile,
                   const Eigen::Vector2i& id) {
  double v[4];
  const double d[4][2] = {{0.5, 0.5}, {-0.5, -0.5}, {0.5, -0.5}, {-0.5, 0.5}};
  for (int k = 0; k < 4; ++k) {
    Eigen::Vector2d p;
    if (!ProjectBoardPoint(
            camera, pose, tile,
            id.cast<double>() + Eigen::Vector2d(d[k][0], d[k][1]), &p))
      return 0;
    v[k] = Grey(image, p);
    if (v[k] < 0) return 0;
  }
  // A saddle: each pair of opposite tiles alike, the pairs unlike (as
  // grid/'s saddle check). Points of the ring outside the inner corners,
  // where border tiles meet the paper, are not; counting them as 0 (not by
  // their contrast) keeps a bright ring from outweighing a dim rim column.
  const double raw = (v[0] + v[1] - v[2] - v[3]) / 2;
  const double spread = std::max(std::abs(v[0] - v[1]), std::abs(v[2] - v[3]));
  if (!(spread < std::abs(raw))) return 0;
  const double sign = raw > 0 ? 1 : -1;
  return ((id.x() + id.y()) % 2 == 0) ? sign : -sign;
}

struct PhotoTruth {
  bool ok = false;
  std::string why;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  // The board's 88 corners in the view's lattice frame and their pixels.
  std::vector<Eigen::Vector2i> id;
  std::vector<Eigen::Vector2d> xy;
  std::vector<char> visible;
};

// Board window (origin, cols, rows) in the lattice frame of `view`.
void FindBoardWindow(const cv::Mat& image, const Camera& camera,
                     const Eigen::Isometry3d& pose, const Board& board,
                     const CalibrationView& view, Eigen::Vector2i* origin,
                     Eigen::Vector2i* size) {
  Eigen::Vector2i low(1 << 20, 1 << 20), high(-(1 << 20), -(1 << 20));
  for (const Eigen::Vector3d& p : view.board_points) {
    const Eigen::Vector2i id(std::lround(p.x() / board.tile_size_m),
                             std::lround(p.y() / board.tile_size_m));
    low = low.cwiseMin(id);
    high = high.cwiseMax(id);
  }
  low -= Eigen::Vector2i::Constant(kWindowMargin);
  high += Eigen::Vector2i::Constant(kWindowMargin);
  const int w = high.x() - low.x() + 1, h = high.y() - low.y() + 1;
  // Summed-area table of the scores.
  std::vector<double> sat((w + 1) * (h + 1), 0.0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double s = SaddleScore(image, camera, pose, board.tile_size_m,
                                   low + Eigen::Vector2i(x, y));
      sat[(y + 1) * (w + 1) + x + 1] = s + sat[y * (w + 1) + x + 1] +
                                       sat[(y + 1) * (w + 1) + x] -
                                       sat[y * (w + 1) + x];
    }
  }
  double best = -1;
  for (const Eigen::Vector2i& dims :
       {Eigen::Vector2i(board.cols, board.rows),
        Eigen::Vector2i(board.rows, board.cols)}) {
    for (int y = 0; y + dims.y() <= h; ++y) {
      for (int x = 0; x + dims.x() <= w; ++x) {
        const int x1 = x + dims.x(), y1 = y + dims.y();
        const double s =
            std::abs(sat[y1 * (w + 1) + x1] - sat[y * (w + 1) + x1] -
                     sat[y1 * (w + 1) + x] + sat[y * (w + 1) + x]);
        if (s > best) {
          best = s;
          *origin = low + Eigen::Vector2i(x, y);
          *size = dims;
        }
      }
    }
  }
}

// Per truth corner: the associated detection (see kAssociateFraction) or -1.
std::vector<int> Associate(const std::vector<Eigen::Vector2i>& id,
                           const std::vector<Eigen::Vector2d>& xy,
                           const std::vector<char>& visible,
                           const std::vector<Corner>& corners) {
  std::map<std::pair<int, int>, int> index;
  for (size_t t = 0; t < id.size(); ++t) index[{id[t].x(), id[t].y()}] = t;
  std::vector<int> match(id.size(), -1);
  for (size_t t = 0; t < id.size(); ++t) {
    if (!visible[t]) continue;
    double spacing = 1e30;
    for (const auto& [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
      const auto n = index.find({id[t].x() + dx, id[t].y() + dy});
      if (n != index.end() && xy[n->second].x() > -1e8)
        spacing = std::min(spacing, (xy[n->second] - xy[t]).norm());
    }
    double best = kAssociateFraction * spacing;
    int best_k = -1;
    for (size_t k = 0; k < corners.size(); ++k) {
      const double d = (corners[k].xy - xy[t]).norm();
      if (d < best) best = d, best_k = static_cast<int>(k);
    }
    if (best_k < 0) continue;
    bool nearest = true;
    for (size_t u = 0; u < id.size() && nearest; ++u)
      if (u != t && (corners[best_k].xy - xy[u]).norm() < best) nearest = false;
    if (nearest) match[t] = best_k;
  }
  return match;
}

PhotoTruth MakeTruth(const cv::Mat& image, const Camera& camera,
                     const Board& board, const CalibrationView& view,
                     const Eigen::Isometry3d& start_pose,
                     const std::vector<Corner>& corners) {
  PhotoTruth truth;
  truth.pose = start_pose;
  Eigen::Vector2i origin(0, 0), size(board.cols, board.rows);
  FindBoardWindow(image, camera, truth.pose, board, view, &origin, &size);
  auto project_all = [&]() {
    truth.id.clear();
    truth.xy.clear();
    truth.visible.clear();
    for (int r = 0; r < size.y(); ++r) {
      for (int c = 0; c < size.x(); ++c) {
        const Eigen::Vector2i id = origin + Eigen::Vector2i(c, r);
        Eigen::Vector2d p(-1e9, -1e9);
        const bool ok = ProjectBoardPoint(camera, truth.pose, board.tile_size_m,
                                          id.cast<double>(), &p);
        truth.id.push_back(id);
        truth.xy.push_back(p);
        truth.visible.push_back(ok && InImage(camera, p));
      }
    }
  };
  project_all();
  // Refit the pose to every detection near a projected board corner.
  for (int round = 0; round < 2; ++round) {
    CalibrationView refit;
    const std::vector<int> match =
        Associate(truth.id, truth.xy, truth.visible, corners);
    for (size_t t = 0; t < truth.id.size(); ++t) {
      const int best_k = match[t];
      if (best_k < 0) continue;
      refit.board_points.push_back(
          board.tile_size_m *
          Eigen::Vector3d(truth.id[t].x(), truth.id[t].y(), 0));
      refit.image_points.push_back(corners[best_k].xy);
    }
    if (refit.board_points.size() < 6) break;
    InitializationOptions options;
    options.pose_refine_iterations = 30;
    Eigen::Isometry3d pose;
    std::string why;
    if (!EstimateViewPose(camera, refit, options, &pose, &why)) break;
    truth.pose = pose;
    project_all();
  }
  truth.ok = true;
  return truth;
}

struct PhotoFigures {
  std::string photo;
  int corners = 0;
  int visible = 0;
  int detected = 0;  // associated with a detection
  int accurate = 0;  // ... within kMatchPx
  // Detected board corners in the largest set joined by detected board
  // neighbours (one tile apart): the most one component can hold.
  int connected = 0;
  int labelled = 0;          // board corners in any component
  int labelled_largest = 0;  // board corners in the largest component
  int largest = 0;
  int board_components = 0;
  int wrong = 0;
  int off_board = 0;
  // Corners that hold a board id in the decoded output (what `detect`
  // writes and the calibration uses) but lie off the board.
  int off_board_ids = 0;
  std::vector<Eigen::Vector2d> missed;  // visible, not detected: pixels
  std::vector<Eigen::Vector2i> missed_id;
  // Detected board corners in no component, and board neighbours in two
  // different components (pixels).
  std::vector<int> unlabelled;                   // corner indices
  std::vector<std::pair<int, int>> split_edges;  // corner indices
  std::vector<std::pair<int, int>> board_edges;  // detected board neighbours
};

PhotoFigures Score(const std::vector<Corner>& corners,
                   const std::vector<GridComponent>& components,
                   const DecodeResult& decode, const PhotoTruth& truth) {
  PhotoFigures f;
  f.corners = static_cast<int>(corners.size());
  std::vector<grid_test::CornerTruth> corner_truth(corners.size());
  const std::vector<int> match =
      Associate(truth.id, truth.xy, truth.visible, corners);
  for (size_t t = 0; t < truth.id.size(); ++t) {
    if (!truth.visible[t]) continue;
    ++f.visible;
    const int best_k = match[t];
    if (best_k < 0) {
      f.missed.push_back(truth.xy[t]);
      f.missed_id.push_back(truth.id[t] - truth.id[0]);
      continue;
    }
    ++f.detected;
    if ((corners[best_k].xy - truth.xy[t]).norm() <= kMatchPx) ++f.accurate;
    corner_truth[best_k].board = 0;
    corner_truth[best_k].id = truth.id[t];
  }
  const grid_test::LabelCheck check =
      grid_test::CheckLabels(components, corner_truth);
  f.wrong = check.wrong;
  f.off_board = check.foreign;
  for (int k : decode.corner_index)
    if (corner_truth[k].board != 0) ++f.off_board_ids;
  f.labelled = check.labelled;
  std::vector<int> component_of(corners.size(), -1);
  for (size_t c = 0; c < components.size(); ++c) {
    int on = 0;
    for (int k : components[c].corner) {
      component_of[k] = static_cast<int>(c);
      if (corner_truth[k].board == 0) ++on;
    }
    if (on > 0) ++f.board_components;
    if (c == 0) {
      f.largest = static_cast<int>(components[c].corner.size());
      f.labelled_largest = on;
    }
  }
  // Board neighbours (one tile apart) that were both detected.
  std::map<std::pair<int, int>, int> detection_of;
  for (size_t t = 0; t < truth.id.size(); ++t)
    if (match[t] >= 0)
      detection_of[{truth.id[t].x(), truth.id[t].y()}] = match[t];
  {
    std::map<std::pair<int, int>, int> seen;
    for (const auto& [id, k] : detection_of) {
      if (seen.count(id)) continue;
      std::vector<std::pair<int, int>> queue = {id};
      seen[id] = 1;
      for (size_t q = 0; q < queue.size(); ++q) {
        for (const auto& [dx, dy] :
             {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
          const std::pair<int, int> n(queue[q].first + dx,
                                      queue[q].second + dy);
          if (detection_of.count(n) && !seen.count(n)) {
            seen[n] = 1;
            queue.push_back(n);
          }
        }
      }
      f.connected = std::max(f.connected, static_cast<int>(queue.size()));
    }
  }
  for (const auto& [id, k] : detection_of) {
    if (component_of[k] < 0) f.unlabelled.push_back(k);
    for (const auto& [dx, dy] : {std::pair{1, 0}, {0, 1}}) {
      const auto n = detection_of.find({id.first + dx, id.second + dy});
      if (n == detection_of.end()) continue;
      f.board_edges.push_back({k, n->second});
      const int ca = component_of[k], cb = component_of[n->second];
      if (ca >= 0 && cb >= 0 && ca != cb)
        f.split_edges.push_back({k, n->second});
    }
  }
  return f;
}

// Overlay: truth corners (blue crosses), detections (grey), components (one
// colour each, lattice edges drawn), split board edges (red).
void Draw(const std::string& file, const cv::Mat& grey,
          const std::vector<Corner>& corners,
          const std::vector<GridComponent>& components, const PhotoTruth& truth,
          const PhotoFigures& f) {
  cv::Mat out;
  cv::cvtColor(grey, out, cv::COLOR_GRAY2BGR);
  auto pt = [](const Eigen::Vector2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x())),
                     static_cast<int>(std::lround(p.y())));
  };
  for (size_t t = 0; t < truth.xy.size(); ++t)
    if (truth.visible[t])
      cv::drawMarker(out, pt(truth.xy[t]), cv::Scalar(255, 0, 0),
                     cv::MARKER_CROSS, 9, 1);
  for (const Corner& c : corners)
    cv::circle(out, pt(c.xy), 2, cv::Scalar(160, 160, 160), -1);
  const cv::Scalar colours[] = {{0, 220, 0},   {0, 220, 220}, {220, 0, 220},
                                {0, 128, 255}, {255, 255, 0}, {128, 0, 255}};
  for (size_t c = 0; c < components.size(); ++c) {
    const cv::Scalar colour = colours[c % 6];
    std::map<std::pair<int, int>, Eigen::Vector2d> at;
    for (size_t k = 0; k < components[c].corner.size(); ++k)
      at[{components[c].ij[k].x(), components[c].ij[k].y()}] =
          corners[components[c].corner[k]].xy;
    for (const auto& [l, p] : at) {
      cv::circle(out, pt(p), 3, colour, -1);
      for (const auto& [dx, dy] : {std::pair{1, 0}, {0, 1}}) {
        const auto q = at.find({l.first + dx, l.second + dy});
        if (q != at.end()) cv::line(out, pt(p), pt(q->second), colour, 1);
      }
    }
  }
  for (const auto& [p, q] : f.split_edges)
    cv::line(out, pt(corners[p].xy), pt(corners[q].xy), cv::Scalar(0, 0, 255),
             2);
  cv::imwrite(file, out);
}

std::string GridSummaryLine(const GridSummary& s) {
  char line[512];
  std::snprintf(
      line, sizeof line,
      "edges %d (orientation-filtered %d, penalised %d), merges %d, refused: "
      "neighbor_weight %d tree_mean %d ambiguous_axis %d collision %d "
      "contradiction %d collinearity %d sides_flip %d; removed: not_saddle %d "
      "prediction "
      "%d; attached %d, joined %d; components %d (dropped %d)",
      s.num_edges_considered, s.num_edges_orientation_filtered,
      s.num_edges_penalised, s.num_merges, s.num_rejected_neighbor_weight,
      s.num_rejected_tree_mean_weight, s.num_rejected_ambiguous_axis,
      s.num_rejected_label_collision, s.num_rejected_neighbor_contradiction,
      s.num_rejected_collinearity, s.num_rejected_sides_flip,
      s.num_removed_not_saddle, s.num_removed_by_prediction, s.num_attached,
      s.num_components_joined, s.num_components, s.num_components_dropped);
  return line;
}

// "name=value" for a numeric GridOptions field; false when unknown.
bool SetGridOption(const std::string& arg, GridOptions* o) {
  const size_t eq = arg.find('=');
  if (eq == std::string::npos) return false;
  const std::string name = arg.substr(0, eq);
  const double value = std::atof(arg.c_str() + eq + 1);
  const std::map<std::string, double*> doubles = {
      {"min_orientation_difference_deg",
       &o->candidates.min_orientation_difference_deg},
      {"intensity_difference_fraction",
       &o->image_tests.intensity_difference_fraction},
      {"penalty_factor", &o->image_tests.penalty_factor},
      {"neighbor_weight_ratio", &o->merge.neighbor_weight_ratio},
      {"tree_mean_weight_ratio_min", &o->merge.tree_mean_weight_ratio_min},
      {"tree_mean_weight_ratio_max", &o->merge.tree_mean_weight_ratio_max},
      {"max_collinearity_sin", &o->merge.max_collinearity_sin},
      {"max_line_spacing_ratio", &o->merge.max_line_spacing_ratio},
      {"max_axis_deviation_deg", &o->merge.max_axis_deviation_deg},
      {"max_axis_deviation_with_image_deg",
       &o->merge.max_axis_deviation_with_image_deg},
      {"max_adjacency_deviation_with_image_deg",
       &o->merge.max_adjacency_deviation_with_image_deg},
      {"max_adjacency_length_ratio", &o->merge.max_adjacency_length_ratio},
      {"max_axis_aspect_ratio", &o->merge.max_axis_aspect_ratio},
      {"saddle_sample_fraction", &o->cleanup.saddle_sample_fraction},
      {"side_offset_fraction", &o->image_tests.side_offset_fraction},
      {"side_min_contrast", &o->image_tests.side_min_contrast},
      {"line_prediction_tolerance", &o->cleanup.line_prediction_tolerance},
      {"attach_tolerance", &o->attach.tolerance},
      {"attach_contradiction_tolerance", &o->attach.contradiction_tolerance},
      {"attach_saddle_sample_fraction", &o->attach.saddle_sample_fraction},
      {"max_join_direction_deviation_deg",
       &o->attach.max_join_direction_deviation_deg}};
  const std::map<std::string, int*> ints = {
      {"num_neighbors", &o->candidates.num_neighbors},
      {"intensity_samples", &o->image_tests.intensity_samples},
      {"kruskal_passes", &o->merge.kruskal_passes},
      {"min_component_size", &o->cleanup.min_component_size},
      {"attach_rounds", &o->attach.rounds},
      {"attach_min_support", &o->attach.min_support},
      {"max_component_joins", &o->attach.max_component_joins}};
  if (doubles.count(name)) {
    *doubles.at(name) = value;
  } else if (ints.count(name)) {
    *ints.at(name) = static_cast<int>(value);
  } else if (name == "refuse_penalised_edges") {
    o->image_tests.refuse_penalised_edges = value != 0;
  } else if (name == "check_saddle_pattern") {
    o->cleanup.check_saddle_pattern = value != 0;
  } else {
    return false;
  }
  return true;
}

// One calibration of the comparison: model, outlier policy, figures.
void PrintModelCalibration(const std::vector<CalibrationView>& views,
                           CameraModelId model, bool rejection, int width,
                           int height, bool last) {
  CalibrationOptions options;
  if (!rejection) options.outlier_k = 0;
  CalibrationResult result;
  std::string error;
  const bool ok =
      Calibrate(views, model, width, height, options, &result, &error);
  int corners = 0;
  for (const CalibrationView& view : views) {
    corners += static_cast<int>(view.board_points.size());
  }
  std::printf("    {\"model\": \"%s\", \"outlier_rejection\": %s, \"ok\": %s",
              CameraModelName(model), rejection ? "true" : "false",
              ok ? "true" : "false");
  if (!ok) {
    std::printf(", \"error\": \"%s\"}%s\n", error.c_str(), last ? "" : ",");
    return;
  }
  const std::vector<std::string> names = CameraModelParamNames(model);
  const CalibrationRange range = MeasureCalibrationRange(views, result);
  std::printf(
      ", \"rms_px\": %.4f, \"rms_point_px\": %.4f, \"views_used\": %d, "
      "\"views\": %zu, \"corners\": %d, \"rejected\": %d, "
      "\"rejected_fraction\": %.4f, \"closest_board_m\": %.4f, "
      "\"max_field_angle_deg\": %.1f",
      result.rms_px, result.rms_point_px, result.num_views_used, views.size(),
      corners, result.num_outliers,
      corners > 0 ? static_cast<double>(result.num_outliers) / corners : 0.0,
      range.closest_board_distance_m, range.max_field_angle_deg);
  for (size_t k = 0; k < names.size(); ++k) {
    std::printf(", \"%s\": %.6g, \"%s_stddev\": %.3g", names[k].c_str(),
                result.camera.params[k], names[k].c_str(),
                result.param_stddev[k]);
  }
  if (!CameraModelIsCentral(model)) {
    std::printf(", \"far_field_error_px_at_closest\": %.3f",
                FarFieldErrorPx(result.camera, range.closest_board_distance_m,
                                range.max_field_angle_deg));
  }
  std::printf("}%s\n", last ? "" : ",");
}

// Central and non-central fisheye, with the current outlier policy and
// with rejection off.
void PrintModelComparison(const std::vector<CalibrationView>& views, int width,
                          int height) {
  std::printf("  \"models\": [\n");
  const CameraModelId models[] = {CameraModelId::kKannalaBrandt,
                                  CameraModelId::kKannalaBrandtNoncentral};
  for (int m = 0; m < 2; ++m) {
    for (int r = 0; r < 2; ++r) {
      PrintModelCalibration(views, models[m], r == 0, width, height,
                            m == 1 && r == 1);
    }
  }
  std::printf("  ],\n");
}

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) {
  using namespace puzzlecal;
  cv::setNumThreads(1);
  std::string data_dir;
  int threads = 1;
  bool verbose = false;
  GridOptions grid_options;
  int positional = 0;
  std::string draw_dir;
  bool models_only = false;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--draw" && a + 1 < argc) {
      draw_dir = argv[++a];
    } else if (arg == "--models") {
      models_only = true;
    } else if (arg == "-v") {
      verbose = true;
    } else if (arg.find('=') != std::string::npos) {
      if (!SetGridOption(arg, &grid_options)) {
        std::fprintf(stderr, "unknown grid option %s\n", arg.c_str());
        return 2;
      }
    } else if (positional++ == 0) {
      data_dir = arg;
    } else {
      threads = std::max(1, std::atoi(arg.c_str()));
    }
  }
  std::string why;
  if (!grid_options.Check(&why)) {
    std::fprintf(stderr, "grid options: %s\n", why.c_str());
    return 2;
  }
  const std::string dir = data_dir.empty() ? testing_data::DeltilleFolder()
                                           : data_dir + "/deltille/fisheye";
  const std::vector<std::string> files = testing_data::DeltillePhotoFiles(dir);
  if (files.empty()) {
    std::printf("{\"error\": \"no photos in %s\"}\n", dir.c_str());
    return 1;
  }
  Board board;
  board.type = BoardType::kCheckerboard;
  board.cols = 11;
  board.rows = 8;
  board.tile_size_m = 0.020;
  PipelineOptions options;
  std::vector<ImageResult> results =
      ProcessImageFiles(files, board, options, threads);
  int width = 0, height = 0;
  const std::vector<CalibrationView> views =
      MakeCalibrationViews(board, &results, &width, &height);
  if (models_only) {
    std::printf("{\n  \"benchmark\": \"deltille_fisheye_models\",\n");
    PrintModelComparison(views, width, height);
    std::printf("  \"photos\": %zu, \"views\": %zu\n}\n", files.size(),
                views.size());
    return 0;
  }
  CalibrationOptions calib_options;
  CalibrationResult calibration;
  std::string error;
  if (!Calibrate(views, CameraModelId::kKannalaBrandtNoncentral, width, height,
                 calib_options, &calibration, &error)) {
    std::printf("{\"error\": \"calibration failed: %s\"}\n", error.c_str());
    return 1;
  }
  const Camera& camera = calibration.camera;
  std::printf("{\n  \"benchmark\": \"deltille_fisheye_grid\",\n");
  std::printf(
      "  \"calibration\": {\"views_used\": %d, \"fx\": %.2f, \"cx\": %.2f, "
      "\"cy\": %.2f, \"rms_px\": %.3f, \"expected\": {\"fx\": 296.43, \"cx\": "
      "794.98, \"cy\": 609.23, \"rms_px\": 0.153}},\n",
      calibration.num_views_used, camera.params[0], camera.params[2],
      camera.params[3], calibration.rms_px);
  std::printf("  \"photos\": [\n");
  int photos = 0, all_visible_detected = 0, all_in_one = 0,
      all_in_one_of_detected = 0, all_connected_in_one = 0, grid_lost = 0,
      total_labelled_largest = 0, total_connected = 0, total_wrong = 0,
      total_off = 0, total_off_ids = 0, total_missed = 0, no_truth = 0;
  std::vector<std::string> split_photos;
  for (size_t i = 0; i < results.size(); ++i) {
    const ImageResult& result = results[i];
    const std::string photo = files[i].substr(files[i].size() - 8, 4);
    ++photos;
    const int v = result.view_index;
    Eigen::Isometry3d pose;
    bool have_pose = false;
    if (v >= 0 && calibration.view_used[v]) {
      pose = calibration.cam_from_board[v];
      have_pose = true;
    } else if (v >= 0) {
      InitializationOptions init;
      init.pose_refine_iterations = 30;
      std::string why;
      have_pose = EstimateViewPose(camera, views[v], init, &pose, &why);
    }
    std::printf("%s", i ? ",\n" : "");
    if (!have_pose) {
      ++no_truth;
      std::printf(
          "    {\"photo\": \"%s\", \"corners\": %zu, \"truth\": false, "
          "\"reason\": \"%s\"}",
          photo.c_str(), result.corners.size(), result.reason.c_str());
      continue;
    }
    const cv::Mat image = cv::imread(files[i], cv::IMREAD_GRAYSCALE);
    const PhotoTruth truth =
        MakeTruth(image, camera, board, views[v], pose, result.corners);
    // The truth comes from the default pipeline; the grid under test may
    // use other options.
    GridSummary grid_summary;
    std::vector<GridEdgeTrace> trace;
    const std::vector<GridComponent> components =
        BuildGrid(result.corners, image, grid_options, &grid_summary, &trace);
    PhotoFigures f = Score(result.corners, components, result.decode, truth);
    if (!draw_dir.empty())
      Draw(draw_dir + "/" + photo + ".png", image, result.corners, components,
           truth, f);
    if (verbose) {
      std::fprintf(stderr, "%s: %s\n", photo.c_str(),
                   GridSummaryLine(grid_summary).c_str());
      std::map<std::pair<int, int>, const GridEdgeTrace*> edge_of;
      for (const GridEdgeTrace& t : trace)
        edge_of[{std::min(t.a, t.b), std::max(t.a, t.b)}] = &t;
      const std::vector<Corner>& c = result.corners;
      auto describe = [&](int p, int q) {
        const auto e = edge_of.find({std::min(p, q), std::max(p, q)});
        std::string what = "not a candidate edge";
        if (e != edge_of.end()) {
          char text[128];
          std::snprintf(text, sizeof text, "%s (length %.1f%s)",
                        GridEdgeDecisionName(e->second->decision),
                        e->second->length,
                        e->second->penalised ? ", penalised" : "");
          what = text;
        }
        std::fprintf(stderr, "    %.0f %.0f - %.0f %.0f: %s\n", c[p].xy.x(),
                     c[p].xy.y(), c[q].xy.x(), c[q].xy.y(), what.c_str());
      };
      for (int k : f.unlabelled) {
        std::fprintf(stderr, "  unlabelled %.0f %.0f\n", c[k].xy.x(),
                     c[k].xy.y());
        for (const auto& [p, q] : f.board_edges)
          if (p == k || q == k) describe(p, q);
      }
      // Lattice neighbours in a component that are no board neighbours.
      std::map<int, Eigen::Vector2i> id_of;
      for (size_t t = 0; t < truth.id.size(); ++t) {
        for (size_t k = 0; k < c.size(); ++k) {
          if (truth.visible[t] && (c[k].xy - truth.xy[t]).norm() < 0.3 * 20)
            id_of[static_cast<int>(k)] = truth.id[t];
        }
      }
      for (const GridComponent& component : components) {
        std::map<std::pair<int, int>, int> at;
        for (size_t k = 0; k < component.corner.size(); ++k)
          at[{component.ij[k].x(), component.ij[k].y()}] = component.corner[k];
        for (const auto& [l, p] : at) {
          for (const auto& [dx, dy] : {std::pair{1, 0}, {0, 1}}) {
            const auto q = at.find({l.first + dx, l.second + dy});
            if (q == at.end()) continue;
            const auto ip = id_of.find(p), iq = id_of.find(q->second);
            const bool ok = ip != id_of.end() && iq != id_of.end() &&
                            (ip->second - iq->second).cwiseAbs().sum() == 1;
            if (!ok && ip != id_of.end() && iq != id_of.end()) {
              std::fprintf(stderr, "  bad adjacency:\n");
              describe(p, q->second);
            }
          }
        }
      }
      int sampled = 0, penalised = 0;
      for (const auto& [p, q] : f.board_edges) {
        const auto e = edge_of.find({std::min(p, q), std::max(p, q)});
        if (e == edge_of.end() ||
            e->second->decision == GridEdgeDecision::kSameTree)
          continue;
        ++sampled;
        if (e->second->penalised) {
          ++penalised;
          std::fprintf(stderr, "  penalised board edge:\n");
          describe(p, q);
        }
      }
      std::fprintf(stderr, "  board edges sampled %d, penalised %d\n", sampled,
                   penalised);
      std::fprintf(stderr, "  split:\n");
      for (const auto& [p, q] : f.split_edges) describe(p, q);
    }
    const bool all_detected = f.visible == 88 && f.detected == 88;
    if (all_detected) ++all_visible_detected;
    if (f.labelled_largest == 88) {
      ++all_in_one;
      if (all_detected) ++all_in_one_of_detected;
    }
    if (f.labelled_largest >= f.connected) {
      ++all_connected_in_one;
    } else {
      split_photos.push_back(photo);
      grid_lost += f.connected - f.labelled_largest;
    }
    total_labelled_largest += f.labelled_largest;
    total_connected += f.connected;
    total_wrong += f.wrong;
    total_off += f.off_board;
    total_off_ids += f.off_board_ids;
    total_missed += f.visible - f.detected;
    std::printf(
        "    {\"photo\": \"%s\", \"corners\": %d, \"visible\": %d, "
        "\"detected\": %d, \"within_1_5px\": %d, \"connected\": %d, "
        "\"labelled\": %d, \"labelled_largest\": %d, "
        "\"largest\": %d, \"board_components\": %d, \"wrong\": %d, "
        "\"off_board\": %d, \"off_board_ids\": %d, \"missed\": [",
        photo.c_str(), f.corners, f.visible, f.detected, f.accurate,
        f.connected, f.labelled, f.labelled_largest, f.largest,
        f.board_components, f.wrong, f.off_board, f.off_board_ids);
    for (size_t m = 0; m < f.missed.size(); ++m) {
      std::printf("%s[%d, %d, %.0f, %.0f]", m ? ", " : "", f.missed_id[m].x(),
                  f.missed_id[m].y(), f.missed[m].x(), f.missed[m].y());
    }
    std::printf("]}");
  }
  std::printf("\n  ],\n");
  std::printf(
      "  \"summary\": {\"photos\": %d, \"no_truth\": %d, "
      "\"all_88_in_largest\": %d, \"all_88_detected\": %d, "
      "\"all_88_in_largest_of_those\": %d, \"all_connected_in_largest\": "
      "%d, \"labelled_largest\": %d, \"connected\": %d, \"grid_lost\": %d, "
      "\"wrong\": %d, \"off_board\": %d, \"off_board_ids\": %d, "
      "\"missed_by_detector\": %d, \"split\": [",
      photos, no_truth, all_in_one, all_visible_detected,
      all_in_one_of_detected, all_connected_in_one, total_labelled_largest,
      total_connected, grid_lost, total_wrong, total_off, total_off_ids,
      total_missed);
  for (size_t s = 0; s < split_photos.size(); ++s)
    std::printf("%s\"%s\"", s ? ", " : "", split_photos[s].c_str());
  std::printf("]}\n}\n");
  return 0;
}
