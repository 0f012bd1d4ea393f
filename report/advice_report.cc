#include "report/advice_report.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "formats/png_writer.h"
#include "formats/yaml_emit.h"
#include "report/overlay.h"
#include "util/atomic_file.h"
#include "util/string_format.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

const cv::Scalar kSeenColour(150, 150, 150);   // BGR
const cv::Scalar kOutlineColour(40, 160, 40);  // green
const cv::Scalar kCentreColour(40, 40, 200);   // red
const cv::Scalar kFrameColour(60, 60, 60);
// Room around the image frame in the pictures, as a fraction of its size.
constexpr double kMarginFraction = 0.3;

void EmitUncertainty(YAML::Emitter& out, const std::string& key,
                     const FieldUncertainty& u) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "worst_px" << YAML::Value;
  EmitExact(out, u.worst_px);
  out << YAML::Key << "median_px" << YAML::Value;
  EmitExact(out, u.median_px);
  out << YAML::Key << "worst_band_median_px" << YAML::Value;
  EmitExact(out, u.worst_band_median_px);
  out << YAML::EndMap;
}

}  // namespace

std::vector<Eigen::Vector2d> SeenCorners(
    const std::vector<CalibrationView>& views,
    const CalibrationResult& result) {
  std::vector<Eigen::Vector2d> out;
  for (size_t v = 0; v < views.size() && v < result.view_used.size(); ++v) {
    if (!result.view_used[v]) continue;
    for (size_t i = 0; i < views[v].image_points.size(); ++i) {
      if (result.inlier[v][i]) out.push_back(views[v].image_points[i]);
    }
  }
  return out;
}

cv::Mat DrawAdvicePicture(const Advice& advice, int index,
                          const std::vector<Eigen::Vector2d>& seen, int width) {
  const AdvisedView& view = advice.views[index];
  const Camera& camera = advice.camera;
  // The image frame with room around it, so that a board larger than the
  // view shows whole: white around, light grey inside the frame.
  const Eigen::Vector2d offset(kMarginFraction * camera.width,
                               kMarginFraction * camera.height);
  const cv::Size size(static_cast<int>(camera.width + 2 * offset.x()),
                      static_cast<int>(camera.height + 2 * offset.y()));
  cv::Mat canvas(size, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Rect frame(static_cast<int>(offset.x()),
                       static_cast<int>(offset.y()), camera.width,
                       camera.height);
  canvas(frame).setTo(cv::Scalar(232, 232, 232));
  std::vector<cv::Point> polygon;
  for (const Eigen::Vector2d& p : view.outline_px) {
    polygon.emplace_back(cvRound(p.x() + offset.x()),
                         cvRound(p.y() + offset.y()));
  }
  if (polygon.size() >= 3) {
    cv::Mat filled = canvas.clone();
    cv::fillPoly(filled, std::vector<std::vector<cv::Point>>{polygon},
                 kOutlineColour);
    cv::addWeighted(filled, 0.25, canvas, 0.75, 0.0, canvas);
  }
  cv::rectangle(canvas, frame, kFrameColour, 2);

  Overlay overlay;
  const std::string& words = view.words;
  const size_t comma = words.find(", ");
  overlay.title =
      StringPrintf("Next photo %d of %zu: %s", index + 1, advice.views.size(),
                   words.substr(0, comma).c_str());
  if (comma != std::string::npos) overlay.subtitle = words.substr(comma + 2);
  for (const Eigen::Vector2d& p : seen) {
    OverlayMark dot;
    dot.kind = OverlayMark::Kind::kCircle;
    dot.at = p + offset;
    dot.size = 1.5;
    dot.colour = kSeenColour;
    overlay.marks.push_back(dot);
  }
  const std::vector<Eigen::Vector2d>& outline = view.outline_px;
  for (size_t k = 0; k < outline.size(); ++k) {
    OverlayMark line;
    line.kind = OverlayMark::Kind::kLine;
    line.at = outline[k] + offset;
    line.to = outline[(k + 1) % outline.size()] + offset;
    line.thickness = 3;
    line.colour = kOutlineColour;
    // A jump across the picture (the outline leaving a fisheye's field) is
    // not an edge of the board.
    if ((line.to - line.at).norm() > 0.25 * camera.width) continue;
    overlay.marks.push_back(line);
  }
  OverlayMark centre;
  centre.kind = OverlayMark::Kind::kCross;
  centre.at = view.centre_px + offset;
  centre.size = 8;
  centre.thickness = 2;
  centre.colour = kCentreColour;
  overlay.marks.push_back(centre);
  overlay.legend = {
      {OverlayMark::Kind::kLine, kOutlineColour,
       "the board where it should appear"},
      {OverlayMark::Kind::kCross, kCentreColour, "its centre"},
      {OverlayMark::Kind::kCircle, kSeenColour, "corners seen so far"}};
  OverlayOptions options;
  options.width = std::max(0, width);
  return DrawOverlay(canvas, overlay, options);
}

std::string AdvicePictureName(int index) {
  return StringPrintf("next_%d.png", index + 1);
}

std::string AdviceYaml(const Advice& advice) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "camera_model" << YAML::Value
      << CameraModelName(advice.camera.model);
  out << YAML::Key << "image_width" << YAML::Value << advice.camera.width;
  out << YAML::Key << "image_height" << YAML::Value << advice.camera.height;
  out << YAML::Key << "field_deg" << YAML::Value;
  EmitExact(out, advice.field_deg);
  out << YAML::Key << "noise_sigma_px" << YAML::Value;
  EmitExact(out, advice.noise_sigma_px);
  out << YAML::Key << "views_taken" << YAML::Value << advice.views_taken;
  EmitUncertainty(out, "uncertainty_now", advice.now);
  out << YAML::Key << "target_uncertainty_px" << YAML::Value;
  EmitExact(out, advice.target_uncertainty_px);
  out << YAML::Key << "photos_to_target" << YAML::Value;
  if (advice.photos_to_target >= 0) {
    out << advice.photos_to_target;
  } else {
    out << YAML::Null;
  }
  out << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
  for (size_t k = 0; k < advice.views.size(); ++k) {
    const AdvisedView& v = advice.views[k];
    out << YAML::BeginMap;
    out << YAML::Key << "picture" << YAML::Value
        << AdvicePictureName(static_cast<int>(k));
    out << YAML::Key << "words" << YAML::Value << v.words;
    out << YAML::Key << "cam_from_board" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "R" << YAML::Value;
    EmitRows(out, v.cam_from_board.linear());
    out << YAML::Key << "t" << YAML::Value;
    EmitFlow(out, {v.cam_from_board.translation().x(),
                   v.cam_from_board.translation().y(),
                   v.cam_from_board.translation().z()});
    out << YAML::EndMap;
    out << YAML::Key << "centre_px" << YAML::Value;
    EmitFlow(out, {v.centre_px.x(), v.centre_px.y()});
    out << YAML::Key << "distance_m" << YAML::Value;
    EmitExact(out, v.distance_m);
    out << YAML::Key << "tilt_deg" << YAML::Value;
    EmitExact(out, v.tilt_deg);
    out << YAML::Key << "tilt_direction_deg" << YAML::Value;
    EmitExact(out, v.tilt_direction_deg);
    out << YAML::Key << "visible_corners" << YAML::Value << v.visible_corners;
    EmitUncertainty(out, "expected_after", v.after);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(
             "# puzzlecal capture advice: the next board poses, "
             "best first\n") +
         out.c_str() + "\n";
}

bool WriteAdviceFiles(const std::string& dir, const Advice& advice,
                      const std::vector<Eigen::Vector2d>& seen, int width,
                      std::vector<std::string>* files, std::string* error) {
  for (size_t k = 0; k < advice.views.size(); ++k) {
    const std::string name = AdvicePictureName(static_cast<int>(k));
    const cv::Mat picture =
        DrawAdvicePicture(advice, static_cast<int>(k), seen, width);
    if (!WritePngFile((fs::path(dir) / name).string(), picture, error)) {
      return false;
    }
    if (files != nullptr) files->push_back(name);
  }
  if (!WriteFileAtomically((fs::path(dir) / "advice.yaml").string(),
                           AdviceYaml(advice), error)) {
    return false;
  }
  if (files != nullptr) files->push_back("advice.yaml");
  return true;
}

std::string AdviceMarkdown(const Advice& advice, int heading_level) {
  const std::string hashes(heading_level, '#');
  std::string out = hashes + " Next photos\n\n";
  if (!advice.ok) return out + "No advice: " + advice.error + ".\n\n";
  out += StringPrintf(
      "The projection uncertainty with the %d views taken, over the field up "
      "to %.0f degrees: worst %.3f px, median %.3f px (the verdict asks for "
      "every 10-degree band's median at or below %.2f px; the worst band's "
      "is %.3f px). The photos below lower it the most, in this order "
      "(advice.yaml holds their poses):\n\n",
      advice.views_taken, advice.field_deg, advice.now.worst_px,
      advice.now.median_px, advice.target_uncertainty_px,
      advice.now.worst_band_median_px);
  out += "| photo | how to hold the board | worst after | median after |\n";
  out += "|---|---|---:|---:|\n";
  for (size_t k = 0; k < advice.views.size(); ++k) {
    const AdvisedView& v = advice.views[k];
    out += StringPrintf("| %zu | %s | %.3f px | %.3f px |\n", k + 1,
                        v.words.c_str(), v.after.worst_px, v.after.median_px);
  }
  out += "\n";
  if (advice.photos_to_target >= 0) {
    out += StringPrintf(
        "About %d photos in all (%d more, the advised ones and others like "
        "them) should reach the verdict's limit.\n\n",
        advice.photos_to_target,
        std::max(0, advice.photos_to_target - advice.views_taken));
  } else {
    out +=
        "Photos like these alone do not reach the verdict's limit within "
        "the estimate's reach: the lens or the board may need other "
        "poses (closer, more tilted).\n\n";
  }
  for (size_t k = 0; k < advice.views.size(); ++k) {
    out += StringPrintf("![next photo %zu](%s)\n\n", k + 1,
                        AdvicePictureName(static_cast<int>(k)).c_str());
  }
  return out;
}

}  // namespace puzzlecal
