// Capture advice on renders (issue figures): from 6 near-frontal centred
// views of the sample lens (pinhole-radtan) and of a 180-degree fisheye,
// rendered and detected, 4 advised views are rendered, added and the camera
// recalibrated after each; against 4 views drawn at random from the same
// candidates (10 draws). Then advised views are added one at a time (the
// advice recomputed each time) until the verdict is good, against the
// first advice's estimate. And the time of the advice on 30 views.
// "predicted": the same comparison as the advice's prediction scores it
// (PredictWithPoses, no render): the advised four against the 10 random
// draws, and the best and median of 500 more random draws, which says how
// much better than random any choice among the candidates could be.
// Prints JSON. `bench_advise splined` runs the splined lens alone.

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "advice/advice.h"
#include "calib/calibrate.h"
#include "evidence/judgement.h"
#include "pipeline/pipeline.h"
#include "sim/render.h"
#include "sim/scenes.h"
#include "sim/synthetic_views.h"
#include "util/statistics.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

// Random draws of 4 candidates whose uncertainty only the prediction
// scores (no render).
constexpr int kPredictedDraws = 500;

struct Lens {
  std::string name;
  Camera camera;
  Board board;
  RenderOptions render;
};

// Renders and detects one view per pose; the views of the poses whose
// photo gave one.
std::vector<CalibrationView> RenderedViews(
    const Lens& lens, const std::vector<Eigen::Isometry3d>& poses,
    int first_seed) {
  std::vector<ImageResult> images(poses.size());
  PipelineOptions pipeline;
  for (size_t k = 0; k < poses.size(); ++k) {
    RenderOptions render = lens.render;
    render.seed = first_seed + static_cast<int>(k);
    const cv::Mat image =
        RenderBoard(lens.board, lens.camera, poses[k], render);
    images[k].file = "view_" + std::to_string(k);
    if (image.empty()) continue;
    ProcessGreyImage(image, lens.board, pipeline, &images[k]);
  }
  int width = 0, height = 0;
  return MakeCalibrationViews(lens.board, &images, &width, &height);
}

bool Recalibrate(const Lens& lens, const std::vector<CalibrationView>& views,
                 CalibrationResult* result) {
  std::string error;
  if (!Calibrate(views, lens.camera.model, lens.camera.width,
                 lens.camera.height, CalibrationOptions(), result, &error)) {
    std::fprintf(stderr, "%s: %s\n", lens.name.c_str(), error.c_str());
    return false;
  }
  return result->covariance_ok;
}

FieldUncertainty UncertaintyOf(const CalibrationResult& result,
                               const AdviceOptions& options) {
  std::vector<bool> free;
  std::vector<int> index;
  for (size_t k = 0; k < result.param_fixed.size(); ++k) {
    free.push_back(!result.param_fixed[k]);
    if (free.back()) index.push_back(static_cast<int>(k));
  }
  Eigen::MatrixXd covariance(index.size(), index.size());
  for (size_t r = 0; r < index.size(); ++r) {
    for (size_t c = 0; c < index.size(); ++c) {
      covariance(r, c) = result.covariance(index[r], index[c]);
    }
  }
  return PredictFieldUncertainty(result.camera, free, covariance, options);
}

// Whether the verdict is good; `reason` gets its reason otherwise (quotes
// made single for the JSON).
bool VerdictGood(const std::vector<CalibrationView>& views,
                 const CalibrationResult& result, std::string* reason) {
  const Judgement judgement =
      JudgeCalibration(views, result, CalibrationOptions(), JudgementOptions());
  *reason = judgement.verdict.reason;
  std::replace(reason->begin(), reason->end(), '"', '\'');
  return judgement.verdict.kind == VerdictKind::kGood;
}

void RunLens(const Lens& lens, bool last) {
  const std::vector<Eigen::Isometry3d> start_poses =
      sim::CentredFrontalPoses(lens.camera, lens.board, 6, 3);
  std::vector<CalibrationView> views = RenderedViews(lens, start_poses, 100);
  CalibrationResult result;
  if (!Recalibrate(lens, views, &result)) return;
  AdviceOptions options;
  const Timer advice_timer;
  const Advice advice = AdviseViews(views, result, lens.board, options);
  const double advice_seconds = advice_timer.Seconds();
  if (!advice.ok) {
    std::fprintf(stderr, "%s: %s\n", lens.name.c_str(), advice.error.c_str());
    return;
  }
  // One field for every comparison.
  options.field_radius_px = advice.field_radius_px;
  const FieldUncertainty start = UncertaintyOf(result, options);
  std::printf(
      "  {\"lens\": \"%s\", \"start_views\": %zu, \"field_deg\": %.1f, "
      "\"field_radius_px\": %.0f,\n",
      lens.name.c_str(), views.size(), advice.field_deg,
      advice.field_radius_px);
  std::printf(
      "   \"start_worst_px\": %.4f, \"advice_seconds\": %.3f, "
      "\"candidates\": %zu, \"photos_to_target_estimate\": %d, "
      "\"start_rms_px\": %.4f, \"noise_px\": %.4f,\n",
      start.worst_px, advice_seconds, advice.candidate_poses.size(),
      advice.photos_to_target, result.rms_px, advice.noise_sigma_px);
  std::printf("   \"advised\": [");
  std::vector<Eigen::Isometry3d> poses = start_poses;
  std::vector<CalibrationView> advised_views = views;
  double advised_worst = 0;
  for (size_t k = 0; k < advice.views.size(); ++k) {
    poses.push_back(advice.views[k].cam_from_board);
    const std::vector<CalibrationView> added =
        RenderedViews(lens, {advice.views[k].cam_from_board}, 200 + k);
    advised_views.insert(advised_views.end(), added.begin(), added.end());
    CalibrationResult again;
    if (!Recalibrate(lens, advised_views, &again)) return;
    const FieldUncertainty u = UncertaintyOf(again, options);
    advised_worst = u.worst_px;
    std::printf(
        "%s\n     {\"words\": \"%s\", \"detected\": %s, "
        "\"predicted_worst_px\": %.4f, \"recalibrated_worst_px\": %.4f, "
        "\"predicted_median_px\": %.4f, \"recalibrated_median_px\": %.4f, "
        "\"recalibrated_rms_px\": %.4f, \"recalibrated_noise_px\": %.4f}",
        k ? "," : "", advice.views[k].words.c_str(),
        added.empty() ? "false" : "true", advice.views[k].after.worst_px,
        u.worst_px, advice.views[k].after.median_px, u.median_px, again.rms_px,
        StatedNoiseSigma(again));
  }
  std::printf("],\n");
  std::vector<double> random_worst, random_predicted_worst;
  std::mt19937 rng(17);
  std::uniform_int_distribution<size_t> pick(0,
                                             advice.candidate_poses.size() - 1);
  auto draw_four = [&](std::mt19937* generator) {
    std::vector<Eigen::Isometry3d> random;
    for (int k = 0; k < 4; ++k)
      random.push_back(advice.candidate_poses[pick(*generator)]);
    return random;
  };
  // The prediction's own view of the choice: how low it puts the worst
  // uncertainty after 4 random candidates, over many draws.
  std::vector<double> many_predicted;
  std::mt19937 many_rng(29);
  for (int draw = 0; draw < kPredictedDraws; ++draw) {
    FieldUncertainty u;
    std::string error;
    if (PredictWithPoses(views, result, lens.board, draw_four(&many_rng),
                         options, &u, &error)) {
      many_predicted.push_back(u.worst_px);
    }
  }
  for (int draw = 0; draw < 10; ++draw) {
    const std::vector<Eigen::Isometry3d> random = draw_four(&rng);
    FieldUncertainty predicted;
    std::string error;
    if (PredictWithPoses(views, result, lens.board, random, options, &predicted,
                         &error)) {
      random_predicted_worst.push_back(predicted.worst_px);
    }
    std::vector<CalibrationView> random_views = views;
    const std::vector<CalibrationView> added =
        RenderedViews(lens, random, 300 + 10 * draw);
    random_views.insert(random_views.end(), added.begin(), added.end());
    CalibrationResult again;
    if (!Recalibrate(lens, random_views, &again)) continue;
    random_worst.push_back(UncertaintyOf(again, options).worst_px);
  }
  std::printf(
      "   \"advised_worst_px\": %.4f, \"random_median_worst_px\": %.4f, "
      "\"random_draws\": %zu, \"random_over_advised\": %.2f,\n",
      advised_worst, Median(random_worst), random_worst.size(),
      Median(random_worst) / advised_worst);
  const double advised_predicted = advice.views.back().after.worst_px;
  std::printf(
      "   \"predicted\": {\"advised_worst_px\": %.4f, "
      "\"random_median_worst_px\": %.4f, \"random_over_advised\": %.2f, "
      "\"draws\": %zu, \"best_draw_worst_px\": %.4f, "
      "\"median_draw_over_advised\": %.2f},\n",
      advised_predicted, Median(random_predicted_worst),
      Median(random_predicted_worst) / advised_predicted, many_predicted.size(),
      many_predicted.empty()
          ? -1.0
          : *std::min_element(many_predicted.begin(), many_predicted.end()),
      Median(many_predicted) / advised_predicted);
  // Advised views one at a time until the verdict is good.
  std::vector<CalibrationView> growing = views;
  CalibrationResult current = result;
  int photos = static_cast<int>(growing.size());
  // The verdict at the photo count the advice estimated: "good", its
  // reason, or why that count was not reached.
  std::string reason;
  bool good = VerdictGood(growing, current, &reason);
  std::string at_estimate =
      advice.photos_to_target < 0 ? "no estimate" : "not reached";
  if (photos >= advice.photos_to_target && advice.photos_to_target >= 0) {
    at_estimate = good ? "good" : reason;
  }
  AdviceOptions one = AdviceOptions();
  one.count = 1;
  while (!good && photos < 40) {
    const Advice next = AdviseViews(growing, current, lens.board, one);
    if (!next.ok) break;
    const std::vector<CalibrationView> added =
        RenderedViews(lens, {next.views[0].cam_from_board}, 500 + photos);
    growing.insert(growing.end(), added.begin(), added.end());
    ++photos;
    if (!Recalibrate(lens, growing, &current)) break;
    good = VerdictGood(growing, current, &reason);
    if (photos == advice.photos_to_target) at_estimate = good ? "good" : reason;
  }
  // Good before the estimate: good at it too.
  if (good && photos < advice.photos_to_target) at_estimate = "good";
  std::printf(
      "   \"photos_until_good\": %d, \"good\": %s, "
      "\"verdict_at_estimate\": \"%s\"}%s\n",
      photos, good ? "true" : "false", at_estimate.c_str(), last ? "" : ",");
}

double AdviceSecondsOn30Views() {
  const SceneSpec scene = SampleScene();
  sim::SyntheticScene synthetic;
  synthetic.camera = scene.camera;
  synthetic.board_cols = scene.board.cols;
  synthetic.board_rows = scene.board.rows;
  synthetic.tile = scene.board.tile_size_m;
  synthetic.num_views = 30;
  synthetic.noise_px = 0.05;
  synthetic.min_visible_fraction = 0.5;
  const sim::SyntheticData data = sim::MakeSyntheticData(synthetic);
  CalibrationResult result;
  std::string error;
  Board board = scene.board;
  board.origin = Eigen::Vector2i::Zero();
  if (!Calibrate(data.views, scene.camera.model, scene.camera.width,
                 scene.camera.height, CalibrationOptions(), &result, &error)) {
    std::fprintf(stderr, "30 views: %s\n", error.c_str());
    return -1;
  }
  double best = 1e9;
  for (int run = 0; run < 3; ++run) {
    const Timer timer;
    const Advice advice =
        AdviseViews(data.views, result, board, AdviceOptions());
    best = std::min(best, timer.Seconds());
    if (!advice.ok) return -1;
  }
  return best;
}

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) {
  using namespace puzzlecal;
  const SceneSpec sample = SampleScene();
  // A lens kannala-brandt cannot follow (sim::TruthBumpyFisheye), calibrated
  // with the splined model: the advice over its 209 parameters.
  Lens splined{"bumpy 190-degree fisheye (kannala-brandt-splined)",
               sim::TruthBumpyFisheye(), sample.board, sample.render};
  splined.render.occluders.clear();
  if (argc > 1 && std::string(argv[1]) == "splined") {
    std::printf("{\n \"lenses\": [\n");
    RunLens(splined, true);
    std::printf(" ]\n}\n");
    return 0;
  }
  Lens pinhole{"sample lens (pinhole-radtan 800x600)", sample.camera,
               sample.board, sample.render};
  pinhole.render.occluders.clear();
  Lens fisheye{"180-degree fisheye (kannala-brandt 640x480)",
               FisheyeLensCamera(640, 480, 180.0), sample.board, sample.render};
  std::printf("{\n \"lenses\": [\n");
  RunLens(pinhole, false);
  RunLens(fisheye, false);
  // The A4 board (13 x 8 corners, 20 mm tiles) the README recommends
  // printing: it covers less of the field from any one pose.
  const Board a4 = MakeBoard(BoardType::kPuzzleBoard, 13, 8,
                             Eigen::Vector2i(100, 200), 0.020);
  Lens pinhole_a4{"sample lens, A4 board", sample.camera, a4, pinhole.render};
  Lens fisheye_a4{"180-degree fisheye, A4 board", fisheye.camera, a4,
                  sample.render};
  RunLens(pinhole_a4, false);
  RunLens(fisheye_a4, false);
  RunLens(splined, true);
  std::printf(" ],\n \"advise_seconds_30_views_1_thread\": %.3f\n}\n",
              AdviceSecondsOn30Views());
  return 0;
}
