// `puzzlecal diff`: the far-field projection difference between two camera
// files, per field-angle band and as a map.

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "apps/common_flags.h"
#include "apps/subcommand.h"
#include "camera/camera_models.h"
#include "evidence/evidence.h"
#include "formats/camera_yaml.h"
#include "report/image_chart.h"
#include "util/string_format.h"

DEFINE_double(max_angle, 0,
              "Compare only rays at most this many degrees off camera A's "
              "axis (0: the field both calibrations observed when both files "
              "say, else every pixel both cameras see).");

namespace puzzlecal {
namespace {

constexpr char kChartFile[] = "projection_difference.png";

// What a camera file says of its uncertainty, for the output.
std::string UncertaintyOf(const CameraFileStats& stats) {
  if (stats.covariance.size() > 0) return "covariance of its parameters";
  if (!stats.param_stddev.empty()) {
    return "parameter sigmas without their covariance (not enough for the "
           "uncertainty of the projection)";
  }
  return "no uncertainty";
}

int RunDiff() {
  const std::vector<std::string>& files = SubcommandArguments();
  if (files.size() != 2) {
    std::cerr << "puzzlecal diff: two camera files are needed (got "
              << files.size() << "). Run `puzzlecal diff --help`.\n";
    return kExitUsage;
  }
  if (!(FLAGS_max_angle >= 0 && FLAGS_max_angle < 180)) {
    std::cerr << "puzzlecal diff: --max-angle must lie in [0, 180).\n";
    return kExitUsage;
  }
  Camera cameras[2];
  CameraFileStats stats[2];
  for (int k = 0; k < 2; ++k) {
    std::string error;
    if (!ReadCameraFile(files[k], &cameras[k], &error, &stats[k])) {
      std::cerr << "puzzlecal diff: " << error << "\n";
      return kExitBadInput;
    }
  }
  if (cameras[0].width != cameras[1].width ||
      cameras[0].height != cameras[1].height) {
    std::cerr << "puzzlecal diff: " << files[0] << " is for images of "
              << cameras[0].width << " x " << cameras[0].height << ", "
              << files[1] << " for " << cameras[1].width << " x "
              << cameras[1].height << " pixels; the two cannot be compared.\n";
    return kExitBadInput;
  }
  std::error_code ec;
  if (!FLAGS_out.empty() && (std::filesystem::create_directories(FLAGS_out, ec),
                             !std::filesystem::is_directory(FLAGS_out))) {
    std::cerr << "puzzlecal diff: cannot create the folder " << FLAGS_out
              << (ec ? ": " + ec.message() : "") << "\n";
    return kExitOutputError;
  }
  const Eigen::MatrixXd* covariance[2] = {nullptr, nullptr};
  for (int k = 0; k < 2; ++k) {
    if (stats[k].covariance.size() > 0) covariance[k] = &stats[k].covariance;
  }
  // The field both calibrations observed, when the files say.
  double max_angle = FLAGS_max_angle;
  if (max_angle == 0 && stats[0].max_field_angle_deg > 0 &&
      stats[1].max_field_angle_deg > 0) {
    max_angle =
        std::min(stats[0].max_field_angle_deg, stats[1].max_field_angle_deg);
  }
  const ProjectionDiff diff =
      ProjectionDifference(cameras[0], cameras[1], max_angle, EvidenceOptions(),
                           covariance[0], covariance[1]);
  if (!diff.ok) {
    std::cerr << "puzzlecal diff: " << files[0] << " and " << files[1] << ": "
              << diff.error << "\n";
    return kExitNoResult;
  }
  if (ConsoleVerbosity() != Verbosity::kQuiet) {
    for (int k = 0; k < 2; ++k) {
      std::cout << (k == 0 ? "A: " : "B: ") << files[k] << " ("
                << CameraModelName(cameras[k].model) << ", " << cameras[k].width
                << " x " << cameras[k].height << "), "
                << UncertaintyOf(stats[k]) << "\n";
    }
    std::cout << "projection difference of B against A"
              << (FLAGS_max_angle > 0 ? " (up to --max-angle)"
                  : max_angle > 0
                      ? " (within the field both calibrations observed)"
                      : " (the files do not say where their calibrations "
                        "observed: every pixel both cameras see)")
              << ":\n"
              << ProjectionDifferenceText(diff, "  ");
    if (!diff.expected_ok) {
      std::cout << "  expected difference: unknown (neither file carries the "
                   "covariance of its parameters)\n";
    } else if (covariance[0] == nullptr || covariance[1] == nullptr) {
      std::cout << "  expected difference: from "
                << (covariance[0] != nullptr ? "A" : "B")
                << "'s covariance alone (the other file has none)\n";
    }
  }
  if (!FLAGS_out.empty()) {
    const std::string path =
        (std::filesystem::path(FLAGS_out) / kChartFile).string();
    std::string error;
    if (!WriteProjectionDifferenceChart(
            path, diff, cameras[0].width, cameras[0].height,
            "Projection difference: " +
                std::filesystem::path(files[1]).filename().string() +
                " against " +
                std::filesystem::path(files[0]).filename().string(),
            &error)) {
      std::cerr << "puzzlecal diff: " << error << "\n";
      return kExitOutputError;
    }
    std::cout << "wrote " << path << "\n";
  }
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    diff, "diff", "compare the projection of two camera files",
    "puzzlecal diff A.yaml B.yaml [--out DIR] [--max-angle DEG]\n\n"
    "Compares two camera files (any format puzzlecal reads, any two models, "
    "one image size)\nas mrcal-show-projection-diff does: each pixel of a "
    "grid is unprojected with A,\nturned by the rotation that best aligns "
    "the two cameras, projected with B and compared\nwith A's projection. "
    "Prints the rotation and, per field-angle band, the median,\n95th "
    "percentile and largest difference in pixels, with the difference the "
    "files'\nuncertainties give when they carry a covariance (puzzlecal "
    "camera files do). --out\nwrites the map as DIR/projection_difference.png."
    "\n\nExit codes: 0 done, 2 bad command line, 3 unreadable file or "
    "different image sizes,\n4 nothing to compare, 5 the map cannot be "
    "written.",
    {"out", "max_angle"}, &RunDiff, /*max_arguments=*/2);

}  // namespace
}  // namespace puzzlecal
