#include "apps/options_io.h"

#include <yaml-cpp/yaml.h>

#include <climits>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "formats/yaml_emit.h"
#include "formats/yaml_fields.h"
#include "util/enum_names.h"

namespace puzzlecal {
namespace {

// ---- the fields, once per struct ----
//
// Fields<T>::Visit(v, o) calls v.Field("name", o.name) for every
// user-facing field of T and v.Group("name", o.name) for every nested
// group, in declaration order; O is T or const T. The reader, the writer
// and the list of allowed keys all walk these tables, so a field is named
// once. A field added to a struct and not here is simply not in the file
// (it keeps its default).

template <typename T>
struct Fields;

constexpr EnumName<SubpixelMethod> kSubpixelNames[] = {
    {SubpixelMethod::kNone, "none"},
    {SubpixelMethod::kCentroid, "centroid"},
    {SubpixelMethod::kGradientOrthogonality, "gradient-orthogonality"},
    {SubpixelMethod::kSaddleFit, "saddle-fit"},
};

// The loss names are calib's own (RobustLossName).
const EnumName<RobustLoss> kLossNames[] = {
    {RobustLoss::kNone, RobustLossName(RobustLoss::kNone)},
    {RobustLoss::kHuber, RobustLossName(RobustLoss::kHuber)},
    {RobustLoss::kCauchy, RobustLossName(RobustLoss::kCauchy)},
};

template <>
struct Fields<DetectorOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("normalize_by_max", o.normalize_by_max);
    v.Field("blur_sigma_px", o.blur_sigma_px);
    v.Field("num_levels", o.num_levels);
    v.Field("first_level", o.first_level);
    v.Field("trace_weight_k", o.trace_weight_k);
    v.Field("min_response", o.min_response);
    v.Field("noise_response_factor", o.noise_response_factor);
    v.Field("nms_radius_px", o.nms_radius_px);
    v.Field("nms_radius_coarse_px", o.nms_radius_coarse_px);
    v.Field("use_corner_mask", o.use_corner_mask);
    v.Field("use_ring_test", o.use_ring_test);
    v.Field("ring_radius_px", o.ring_radius_px);
    v.Field("ring_samples", o.ring_samples);
    v.Field("min_ring_contrast", o.min_ring_contrast);
    v.Field("max_ring_asymmetry", o.max_ring_asymmetry);
    v.Field("max_ring_asymmetry_clean", o.max_ring_asymmetry_clean);
    v.Field("min_ring_second_harmonic_clean", o.min_ring_second_harmonic_clean);
    v.Field("min_contrast_factor_clean", o.min_contrast_factor_clean);
    v.Field("min_ring_second_harmonic", o.min_ring_second_harmonic);
    v.Field("max_ring_centre_offset", o.max_ring_centre_offset);
    v.Field("ring_noise_factor", o.ring_noise_factor);
    v.Field("subpixel", o.subpixel);
    v.Field("window_fraction_of_neighbor", o.window_fraction_of_neighbor);
    v.Field("min_window_px", o.min_window_px);
    v.Field("max_window_px", o.max_window_px);
    v.Field("saddle_sigma_fraction", o.saddle_sigma_fraction);
    v.Field("min_saddle_sigma_px", o.min_saddle_sigma_px);
    v.Field("max_saddle_sigma_px", o.max_saddle_sigma_px);
    v.Field("saddle_max_iterations", o.saddle_max_iterations);
    v.Field("saddle_convergence_px", o.saddle_convergence_px);
    v.Field("max_iterations", o.max_iterations);
    v.Field("convergence_px", o.convergence_px);
    v.Field("max_shift_fraction", o.max_shift_fraction);
    v.Field("merge_distance_px", o.merge_distance_px);
    v.Field("orientation_spacing_fraction", o.orientation_spacing_fraction);
  }
};

template <>
struct Fields<GridCandidateOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("num_neighbors", o.num_neighbors);
    v.Field("min_orientation_difference_deg", o.min_orientation_difference_deg);
    v.Field("min_edge_length_px", o.min_edge_length_px);
    v.Field("max_abs_coordinate_px", o.max_abs_coordinate_px);
  }
};

template <>
struct Fields<GridEdgeImageOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("intensity_samples", o.intensity_samples);
    v.Field("intensity_difference_fraction", o.intensity_difference_fraction);
    v.Field("penalty_factor", o.penalty_factor);
    v.Field("refuse_penalised_edges", o.refuse_penalised_edges);
    v.Field("side_offset_fraction", o.side_offset_fraction);
    v.Field("side_min_contrast", o.side_min_contrast);
  }
};

template <>
struct Fields<GridMergeOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("neighbor_weight_ratio", o.neighbor_weight_ratio);
    v.Field("tree_mean_weight_ratio_min", o.tree_mean_weight_ratio_min);
    v.Field("tree_mean_weight_ratio_max", o.tree_mean_weight_ratio_max);
    v.Field("max_collinearity_sin", o.max_collinearity_sin);
    v.Field("max_line_spacing_ratio", o.max_line_spacing_ratio);
    v.Field("max_axis_deviation_deg", o.max_axis_deviation_deg);
    v.Field("max_axis_deviation_with_image_deg",
            o.max_axis_deviation_with_image_deg);
    v.Field("max_adjacency_deviation_with_image_deg",
            o.max_adjacency_deviation_with_image_deg);
    v.Field("max_adjacency_length_ratio", o.max_adjacency_length_ratio);
    v.Field("max_axis_aspect_ratio", o.max_axis_aspect_ratio);
    v.Field("kruskal_passes", o.kruskal_passes);
  }
};

template <>
struct Fields<GridCleanupOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("check_saddle_pattern", o.check_saddle_pattern);
    v.Field("saddle_sample_fraction", o.saddle_sample_fraction);
    v.Field("line_prediction_tolerance", o.line_prediction_tolerance);
    v.Field("min_component_size", o.min_component_size);
  }
};

template <>
struct Fields<GridAttachOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("rounds", o.rounds);
    v.Field("tolerance", o.tolerance);
    v.Field("contradiction_tolerance", o.contradiction_tolerance);
    v.Field("min_support", o.min_support);
    v.Field("saddle_sample_fraction", o.saddle_sample_fraction);
    v.Field("max_join_direction_deviation_deg",
            o.max_join_direction_deviation_deg);
    v.Field("max_component_joins", o.max_component_joins);
  }
};

template <>
struct Fields<GridOffLatticeOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("enabled", o.enabled);
    v.Field("tolerance", o.tolerance);
    v.Field("agreement", o.agreement);
    v.Field("min_agreeing", o.min_agreeing);
    v.Field("max_rounds", o.max_rounds);
  }
};

template <>
struct Fields<DecodeOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Group("bits", o.bits);
    v.Field("min_corners", o.min_corners);
    v.Field("max_label_extent", o.max_label_extent);
    v.Field("max_label_overhang", o.max_label_overhang);
    v.Field("max_lattice_deviation", o.max_lattice_deviation);
    v.Field("min_bits_read", o.min_bits_read);
    v.Field("min_agreement", o.min_agreement);
    v.Field("min_margin", o.min_margin);
    v.Field("min_log10_odds", o.min_log10_odds);
    v.Field("max_log10_nfa", o.max_log10_nfa);
    v.Field("refuse_better_off_board", o.refuse_better_off_board);
    v.Field("drop_corner_min_disagreeing_edges",
            o.drop_corner_min_disagreeing_edges);
  }
};

template <>
struct Fields<EdgeBitOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("min_confidence", o.min_confidence);
    v.Field("min_tile_contrast", o.min_tile_contrast);
    v.Field("disc_sample_offset", o.disc_sample_offset);
    v.Field("tile_sample_offset", o.tile_sample_offset);
  }
};

template <>
struct Fields<CalibrationOptions> {
  // Not here: num_threads (--threads). fixed_params are held on top of the
  // ones --format needs (Kalibr's radtan: k3) and --fix names.
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("fixed_params", o.fixed_params);
    v.Field("fix_focal_length", o.fix_focal_length);
    v.Field("fix_principal_point", o.fix_principal_point);
    v.Field("fix_distortion", o.fix_distortion);
    v.Field("same_focal_length", o.same_focal_length);
    v.Field("initial_params", o.initial_params);
    v.Field("loss", o.loss);
    v.Field("loss_scale_px", o.loss_scale_px);
    v.Field("outlier_k", o.outlier_k);
    v.Field("outlier_iterations", o.outlier_iterations);
    v.Field("min_outlier_threshold_px", o.min_outlier_threshold_px);
    v.Field("coarse_stride", o.coarse_stride);
    v.Field("initial_trust_region_radius", o.initial_trust_region_radius);
    v.Field("max_iterations", o.max_iterations);
    v.Field("function_tolerance", o.function_tolerance);
    v.Field("gradient_tolerance", o.gradient_tolerance);
    v.Field("parameter_tolerance", o.parameter_tolerance);
    v.Field("covariance_min_eigenvalue_ratio",
            o.covariance_min_eigenvalue_ratio);
    v.Field("deterministic", o.deterministic);
    v.Field("min_corners_per_view", o.min_corners_per_view);
    v.Field("min_views", o.min_views);
    v.Field("min_orientation_spread_deg", o.min_orientation_spread_deg);
    v.Field("min_coverage", o.min_coverage);
    v.Field("max_focal_relative_stddev", o.max_focal_relative_stddev);
    v.Field("coverage_grid", o.coverage_grid);
    v.Field("max_rms_px", o.max_rms_px);
    v.Field("staged_distortion", o.staged_distortion);
    v.Field("compute_covariance", o.compute_covariance);
    v.Field("far_field_start_function_tolerance",
            o.far_field_start_function_tolerance);
    v.Field("far_field_start_outlier_iterations",
            o.far_field_start_outlier_iterations);
    v.Field("far_field_start_max_views", o.far_field_start_max_views);
    v.Group("spline_prior", o.spline_prior);
    v.Field("spline_grid_margin", o.spline_grid_margin);
    v.Field("spline_knot_spacing_deg", o.spline_knot_spacing_deg);
    v.Group("initialization", o.initialization);
  }
};

template <>
struct Fields<SplinePriorOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("smoothness_weight", o.smoothness_weight);
    v.Field("zero_weight", o.zero_weight);
  }
};

template <>
struct Fields<InitializationOptions> {
  // Not here: num_threads (Calibrate sets it from --threads).
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("reweight_iterations", o.reweight_iterations);
    v.Field("reweight_k", o.reweight_k);
    v.Field("focal_search_min_ratio", o.focal_search_min_ratio);
    v.Field("focal_search_max_ratio", o.focal_search_max_ratio);
    v.Field("focal_search_steps", o.focal_search_steps);
    v.Field("focal_search_refine_iterations", o.focal_search_refine_iterations);
    v.Field("focal_search_reweight_iterations",
            o.focal_search_reweight_iterations);
    v.Field("focal_search_truncation_px", o.focal_search_truncation_px);
    v.Field("focal_search_max_views", o.focal_search_max_views);
    v.Field("focal_search_max_corners_per_view",
            o.focal_search_max_corners_per_view);
    v.Field("focal_search_scan_max_views", o.focal_search_scan_max_views);
    v.Field("focal_search_scan_candidates", o.focal_search_scan_candidates);
    v.Field("max_focal_aspect", o.max_focal_aspect);
    v.Field("pose_refine_iterations", o.pose_refine_iterations);
    v.Field("pose_refine_loss_px", o.pose_refine_loss_px);
    v.Field("start_refine_iterations", o.start_refine_iterations);
    v.Field("start_refine_max_views", o.start_refine_max_views);
    v.Field("start_refine_max_corners_per_view",
            o.start_refine_max_corners_per_view);
    v.Field("start_refine_loss_px", o.start_refine_loss_px);
    v.Field("start_refine_pose_iterations", o.start_refine_pose_iterations);
  }
};

template <>
struct Fields<EvidenceOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("grid_step_px", o.grid_step_px);
    v.Field("band_width_deg", o.band_width_deg);
    v.Field("distance_bins", o.distance_bins);
    v.Field("min_bin_count", o.min_bin_count);
    v.Field("cross_validation", o.cross_validation);
    v.Field("cross_validation_splits", o.cross_validation_splits);
    v.Field("report_angles_deg", o.report_angles_deg);
    v.Field("report_azimuths", o.report_azimuths);
    v.Field("view_focal_min_corners", o.view_consistency.min_corners);
    v.Field("view_focal_max_iterations", o.view_consistency.max_iterations);
    v.Field("grid_min_samples", o.grid_min_samples);
  }
};

template <>
struct Fields<VerdictOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("halves_factor", o.halves_factor);
    v.Field("halves_floor_px", o.halves_floor_px);
    v.Field("halves_min_bands", o.halves_min_bands);
    v.Field("halves_max_scale", o.halves_max_scale);
    v.Field("halves_uniform_floor_px", o.halves_uniform_floor_px);
    v.Field("halves_min_z", o.halves_min_z);
    v.Field("residual_se_factor", o.residual_se_factor);
    v.Field("residual_floor_px", o.residual_floor_px);
    v.Field("closeness_rms_ratio", o.closeness_rms_ratio);
    v.Field("closeness_floor_px", o.closeness_floor_px);
    v.Field("pinhole_max_field_deg", o.pinhole_max_field_deg);
    v.Field("max_outlier_fraction", o.max_outlier_fraction);
    v.Field("view_rms_factor", o.view_rms_factor);
    v.Field("view_rms_floor_px", o.view_rms_floor_px);
    v.Field("max_view_outlier_fraction", o.max_view_outlier_fraction);
    v.Field("max_bad_view_fraction", o.max_bad_view_fraction);
    v.Field("min_views", o.min_views);
    v.Field("min_coverage", o.min_coverage);
    v.Field("max_uncertainty_px", o.max_uncertainty_px);
    v.Field("check_distortion_determined", o.check_distortion_determined);
    v.Field("min_undetermined_distortion_stddev",
            o.min_undetermined_distortion_stddev);
    v.Field("view_focal_spread_factor", o.view_focal_spread_factor);
    v.Field("view_focal_floor_px", o.view_focal_floor_px);
    v.Field("max_named_views", o.max_named_views);
    v.Field("view_field_factor", o.view_field_factor);
    v.Field("view_field_floor_px", o.view_field_floor_px);
  }
};

template <>
struct Fields<ModelSelectionOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("holdout_every", o.holdout_every);
    v.Field("holdout_offset", o.holdout_offset);
    v.Field("candidates", o.candidates);
    v.Field("pinhole_max_field_deg", o.pinhole_max_field_deg);
    v.Field("min_relative_gain", o.min_relative_gain);
    v.Field("gross_error_k", o.gross_error_k);
    v.Field("gross_error_floor_px", o.gross_error_floor_px);
    v.Field("all_folds", o.all_folds);
    v.Field("min_gain_z", o.min_gain_z);
    v.Field("conventional_max_field_deg", o.conventional_max_field_deg);
  }
};

template <>
struct Fields<RigCalibrationOptions> {
  // Not here: camera (the calibration section).
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("min_shared_frames", o.min_shared_frames);
    v.Field("max_start_rotation_deviation_deg",
            o.max_start_rotation_deviation_deg);
  }
};

template <>
struct Fields<RigEvidenceOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("moved_factor", o.moved_factor);
    v.Field("min_moved_px", o.min_moved_px);
    v.Field("max_joint_over_alone", o.max_joint_over_alone);
  }
};

template <>
struct Fields<RecheckOptions> {
  // Not here: evidence (the evidence section).
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("worse_view_factor", o.worse_view_factor);
    v.Field("drift_sigmas", o.drift_sigmas);
    v.Field("min_drift_px", o.min_drift_px);
    v.Field("max_detectable_px", o.max_detectable_px);
  }
};

template <>
struct Fields<VideoFrameOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("frame_step", o.frame_step);
    v.Field("min_corners", o.min_corners);
    v.Field("max_edge_width_px", o.max_edge_width_px);
    v.Field("max_edges", o.max_edges);
    v.Field("min_pose_change", o.min_pose_change);
    v.Field("max_frames", o.max_frames);
  }
};

template <>
struct Fields<RigVideoOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("max_time_difference_ms", o.max_time_difference_ms);
  }
};

template <>
struct Fields<AdviceOptions> {
  // Not here: count (--count), field_deg (--field-deg), num_threads
  // (--threads), target_uncertainty_px and target_min_views (the verdict
  // section's max_uncertainty_px and min_views), spline_prior (the
  // calibration section's: the prior the calibration used).
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("field_radius_px", o.field_radius_px);
    v.Field("max_fold_fraction", o.max_fold_fraction);
    v.Field("field_samples", o.field_samples);
    v.Field("position_cols", o.position_cols);
    v.Field("position_rows", o.position_rows);
    v.Field("distance_factors", o.distance_factors);
    v.Field("tilts_deg", o.tilts_deg);
    v.Field("tilt_directions", o.tilt_directions);
    v.Field("min_view_angle_deg", o.min_view_angle_deg);
    v.Field("min_visible_fraction", o.min_visible_fraction);
    v.Field("image_margin_px", o.image_margin_px);
    v.Field("min_tile_px", o.min_tile_px);
    v.Field("max_corners_per_view", o.max_corners_per_view);
    v.Field("min_separation_fraction", o.min_separation_fraction);
    v.Field("min_separation_deg", o.min_separation_deg);
    v.Field("min_distance_ratio", o.min_distance_ratio);
    v.Field("max_estimate_views", o.max_estimate_views);
    v.Field("noise_sigma_px", o.noise_sigma_px);
    v.Field("prior_focal_fraction", o.prior_focal_fraction);
    v.Field("prior_centre_fraction", o.prior_centre_fraction);
    v.Field("prior_distortion", o.prior_distortion);
  }
};

template <>
struct Fields<PipelineOptions> {
  // Section pipeline: what is left of PipelineOptions besides its groups
  // (those are sections of their own, see Fields<RunOptions>). Not here:
  // run_decode (`detect` sets it from --board).
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("min_corners", o.min_corners);
  }
};

template <>
struct Fields<ImageLoadOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Field("max_pixels", o.max_pixels);
  }
};

template <>
struct Fields<GridOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Group("candidates", o.candidates);
    v.Group("image_tests", o.image_tests);
    v.Group("merge", o.merge);
    v.Group("cleanup", o.cleanup);
    v.Group("attach", o.attach);
    v.Group("off_lattice", o.off_lattice);
  }
};

// The file's top-level sections.
template <>
struct Fields<RunOptions> {
  template <typename V, typename O>
  static void Visit(V& v, O& o) {
    v.Group("detector", o.pipeline.detector);
    v.Group("grid", o.pipeline.grid);
    v.Group("decode", o.pipeline.decode);
    v.Group("load", o.pipeline.load);
    v.Group("pipeline", o.pipeline);
    v.Group("calibration", o.calibration);
    v.Group("evidence", o.evidence);
    v.Group("verdict", o.verdict);
    v.Group("model_selection", o.model_selection);
    v.Group("rig", o.rig);
    v.Group("rig_evidence", o.rig_evidence);
    v.Group("check", o.check);
    v.Group("video", o.video);
    v.Group("rig_video", o.rig_video);
    v.Group("advice", o.advice);
  }
};

// ---- allowed keys ----

class KeyVisitor {
 public:
  template <typename X>
  void Field(const char* key, const X&) {
    keys.insert(key);
  }
  template <typename X>
  void Group(const char* key, const X&) {
    keys.insert(key);
  }
  std::set<std::string> keys;
};

template <typename T>
std::set<std::string> KeysOf() {
  static const T defaults{};
  KeyVisitor visitor;
  Fields<T>::Visit(visitor, defaults);
  return visitor.keys;
}

// ---- reading ----

// Reads the fields of one map (at `path`) into a struct; the first failure
// is kept by the FieldReader and ends the reading.
class ReadVisitor {
 public:
  ReadVisitor(FieldReader* reader, const YAML::Node& map, std::string path)
      : reader_(reader), map_(map), path_(std::move(path)) {}

  void Field(const char* key, int& x) {
    if (reader_->ok()) reader_->Int(map_, path_, key, kOptional, &x);
  }
  void Field(const char* key, double& x) {
    if (reader_->ok()) reader_->Double(map_, path_, key, kOptional, &x);
  }
  void Field(const char* key, bool& x) {
    if (reader_->ok()) reader_->Bool(map_, path_, key, kOptional, &x);
  }
  void Field(const char* key, long long& x) {
    uint64_t value = 0;
    if (!reader_->ok() || !map_[key] ||
        !reader_->Uint64(map_, path_, key, kOptional, &value)) {
      return;
    }
    if (value > static_cast<uint64_t>(LLONG_MAX)) {
      reader_->Fail(FieldReader::Join(path_, key), "is too large");
      return;
    }
    x = static_cast<long long>(value);
  }
  void Field(const char* key, std::vector<double>& x) {
    if (reader_->ok()) reader_->Doubles(map_, path_, key, kOptional, -1, &x);
  }
  void Field(const char* key, std::vector<std::string>& x);
  void Field(const char* key, SubpixelMethod& x) {
    Enum(key, kSubpixelNames, &x);
  }
  void Field(const char* key, RobustLoss& x) { Enum(key, kLossNames, &x); }

  template <typename T>
  void Group(const char* key, T& group);

 private:
  static constexpr Presence kOptional = Presence::kOptional;

  template <typename E, size_t N>
  void Enum(const char* key, const EnumName<E> (&names)[N], E* x) {
    std::string name;
    if (!reader_->ok() || !map_[key] ||
        !reader_->String(map_, path_, key, kOptional, &name)) {
      return;
    }
    if (!ValueOf(names, name, x)) {
      reader_->Fail(
          FieldReader::Join(path_, key),
          "must be one of " + JoinedNames(names) + ", got '" + name + "'");
    }
  }

  FieldReader* reader_;
  const YAML::Node map_;
  const std::string path_;
};

// A list of names (model names).
void ReadVisitor::Field(const char* key, std::vector<std::string>& x) {
  YAML::Node list;
  if (!reader_->ok() || !reader_->List(map_, path_, key, kOptional, &list) ||
      !list) {
    return;
  }
  const std::string field = FieldReader::Join(path_, key);
  std::vector<std::string> names;
  for (size_t i = 0; i < list.size(); ++i) {
    if (!list[i].IsScalar()) {
      reader_->Fail(FieldReader::Index(field, i), "must be a name");
      return;
    }
    names.push_back(list[i].Scalar());
  }
  x = names;
}

// The map `node` at `path` into `group`: only T's keys; a missing or empty
// (null) map leaves the group as it was.
template <typename T>
bool ReadGroup(FieldReader* reader, const YAML::Node& node,
               const std::string& path, T* group) {
  if (!node || node.IsNull()) return true;
  if (!reader->OnlyKeys(node, path, KeysOf<T>())) return false;
  ReadVisitor visitor(reader, node, path);
  Fields<T>::Visit(visitor, *group);
  return reader->ok();
}

template <typename T>
void ReadVisitor::Group(const char* key, T& group) {
  YAML::Node child;
  if (!reader_->ok() || !reader_->Child(map_, path_, key, kOptional, &child)) {
    return;
  }
  ReadGroup(reader_, child, FieldReader::Join(path_, key), &group);
}

// ---- checking ----

// Every group's Check(), in the file's order; false with "section 'NAME':
// WHY".
bool CheckSections(const RunOptions& o, std::string* why) {
  std::string inner;
  const auto failed = [&](const char* section) {
    *why = std::string("section '") + section + "': " + inner;
    return false;
  };
  if (!o.pipeline.detector.Check(&inner)) return failed("detector");
  if (!o.pipeline.grid.Check(&inner)) return failed("grid");
  if (!o.pipeline.decode.Check(&inner)) return failed("decode");
  if (!o.pipeline.load.Check(&inner)) return failed("load");
  if (!o.pipeline.Check(&inner)) return failed("pipeline");
  if (!o.calibration.Check(&inner)) return failed("calibration");
  if (!o.evidence.Check(&inner)) return failed("evidence");
  if (!o.verdict.Check(&inner)) return failed("verdict");
  if (!o.model_selection.Check(&inner)) return failed("model_selection");
  if (!o.rig.Check(&inner)) return failed("rig");
  if (!o.rig_evidence.Check(&inner)) return failed("rig_evidence");
  if (!o.check.Check(&inner)) return failed("check");
  if (!o.video.Check(&inner)) return failed("video");
  if (!o.rig_video.Check(&inner)) return failed("rig_video");
  if (!o.advice.Check(&inner)) return failed("advice");
  return true;
}

// ---- writing ----

// Writes every field as `key: value` into the open map of `out`; numbers
// with the fewest digits that read back exactly.
class WriteVisitor {
 public:
  explicit WriteVisitor(YAML::Emitter* out) : out_(*out) {}

  void Field(const char* key, const int& x) { Key(key) << x; }
  void Field(const char* key, const long long& x) { Key(key) << x; }
  void Field(const char* key, const bool& x) { Key(key) << x; }
  void Field(const char* key, const double& x) { EmitExact(Key(key), x); }
  void Field(const char* key, const std::vector<double>& x) {
    EmitExactFlow(Key(key), x);
  }
  void Field(const char* key, const std::vector<std::string>& x) {
    Key(key) << YAML::Flow << YAML::BeginSeq;
    for (const std::string& name : x) out_ << name;
    out_ << YAML::EndSeq;
  }
  void Field(const char* key, const SubpixelMethod& x) {
    Key(key) << NameOf(kSubpixelNames, x);
  }
  void Field(const char* key, const RobustLoss& x) {
    Key(key) << NameOf(kLossNames, x);
  }

  template <typename T>
  void Group(const char* key, const T& group) {
    Key(key) << YAML::BeginMap;
    Fields<T>::Visit(*this, group);
    out_ << YAML::EndMap;
  }

 private:
  YAML::Emitter& Key(const char* key) {
    return out_ << YAML::Key << key << YAML::Value;
  }

  YAML::Emitter& out_;
};

constexpr char kHeader[] =
    "# puzzlecal options (read with --options FILE by calibrate, detect,\n"
    "# calibrate-rig, check and advise). Every field with its value; delete\n"
    "# the ones you keep at their defaults. Meaning and range of each field:\n"
    "# detector detection/detector.h (DetectorOptions), grid grid/grid.h\n"
    "# (GridOptions),\n"
    "# decode decode/decoder.h and decode/edge_bits.h (DecodeOptions,\n"
    "# EdgeBitOptions), load formats/image_io.h (ImageLoadOptions),\n"
    "# pipeline pipeline/pipeline.h (PipelineOptions), calibration\n"
    "# calib/calibrate.h and\n"
    "# calib/initialization.h, evidence evidence/evidence.h, verdict\n"
    "# evidence/verdict.h, model_selection evidence/model_selection.h, rig\n"
    "# calib/rig_calibration.h (its camera options are the calibration\n"
    "# section), rig_evidence evidence/rig_evidence.h, check\n"
    "# evidence/recheck.h, video pipeline/video_frames.h, rig_video\n"
    "# pipeline/rig_video.h, advice\n"
    "# advice/advice.h. --threads and --format's fixed parameters are flags\n"
    "# only.\n";

}  // namespace

bool LoadOptionsFile(const std::string& path, RunOptions* options,
                     std::string* error) {
  std::string text;
  return ReadTextFile(path, &text, error) &&
         ParseOptionsText(text, path, options, error);
}

bool ParseOptionsText(const std::string& text, const std::string& source,
                      RunOptions* options, std::string* error) {
  YAML::Node root;
  if (!ParseYaml(text, source, &root, error)) return false;
  RunOptions read = *options;
  FieldReader reader(source, error);
  if (!ReadGroup(&reader, root, "", &read)) return false;
  read.rig.camera = read.calibration;
  std::string why;
  if (!CheckSections(read, &why)) {
    *error = source + ": " + why;
    return false;
  }
  *options = read;
  return true;
}

std::string OptionsYaml(const RunOptions& options) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  WriteVisitor visitor(&out);
  Fields<RunOptions>::Visit(visitor, options);
  out << YAML::EndMap;
  return kHeader + std::string(out.c_str()) + "\n";
}

}  // namespace puzzlecal
