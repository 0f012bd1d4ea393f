// `puzzlecal detect`: runs the corner detector on one image or a folder and
// writes detections.yaml (and overlays with --draw).

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "apps/common_flags.h"
#include "apps/image_io.h"
#include "apps/subcommand.h"
#include "detection/detector.h"

namespace puzzlecal {
namespace {

struct DetectedImage {
  std::string file;
  int width = 0;
  int height = 0;
  std::string reason;  // empty when the detector ran
  std::vector<Corner> corners;
};

// Corners as circles with a tick along the first Hessian eigenvector.
bool WriteOverlay(const cv::Mat& grey, const std::vector<Corner>& corners,
                  const std::string& path) {
  cv::Mat colour;
  cv::cvtColor(grey, colour, cv::COLOR_GRAY2BGR);
  const double radius = std::max(3.0, std::max(grey.cols, grey.rows) / 400.0);
  for (const Corner& c : corners) {
    const cv::Point2d p(c.xy.x(), c.xy.y());
    const cv::Point2d tick(std::cos(c.orientation), std::sin(c.orientation));
    cv::circle(colour, p, static_cast<int>(radius), cv::Scalar(0, 0, 255), 1,
               cv::LINE_AA);
    cv::line(colour, p - 2.0 * radius * tick, p + 2.0 * radius * tick,
             cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
  }
  try {
    return cv::imwrite(path, colour);
  } catch (const cv::Exception&) {
    return false;
  }
}

// Writes `text` to a temporary file beside `path` and renames it.
bool WriteAtomically(const std::string& path, const std::string& text,
                     std::string* error) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) {
      *error = "cannot write " + temporary;
      return false;
    }
    out << text;
    out.flush();
    if (!out) {
      *error = "failed writing " + temporary;
      return false;
    }
  }
  std::error_code code;
  std::filesystem::rename(temporary, path, code);
  if (code) {
    std::filesystem::remove(temporary, code);
    *error = "cannot rename " + temporary + " to " + path;
    return false;
  }
  return true;
}

std::string ToYaml(const std::vector<DetectedImage>& images) {
  YAML::Emitter out;
  out.SetDoublePrecision(9);
  out << YAML::BeginMap << YAML::Key << "images" << YAML::Value
      << YAML::BeginSeq;
  for (const DetectedImage& image : images) {
    out << YAML::BeginMap;
    out << YAML::Key << "file" << YAML::Value << image.file;
    out << YAML::Key << "width" << YAML::Value << image.width;
    out << YAML::Key << "height" << YAML::Value << image.height;
    out << YAML::Key << "decoded" << YAML::Value << false;
    out << YAML::Key << "reason" << YAML::Value
        << (image.reason.empty()
                ? std::string("corners only (no grid or decode in `detect`)")
                : image.reason);
    out << YAML::Key << "corners" << YAML::Value << YAML::BeginSeq;
    for (const Corner& c : image.corners) {
      // [x, y, col, row, component]; labels stay -1 without grid/decode.
      out << YAML::Flow << YAML::BeginSeq << c.xy.x() << c.xy.y() << -1 << -1
          << -1 << YAML::EndSeq;
    }
    out << YAML::EndSeq;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

int RunDetect() {
  if (FLAGS_images.empty() || FLAGS_out.empty()) {
    std::cerr << "puzzlecal detect: --images and --out are required\n";
    return kExitUsage;
  }
  ImageListing listing;
  std::string error;
  if (!ListImages(FLAGS_images, &listing, &error)) {
    std::cerr << "puzzlecal detect: " << error << "\n";
    return kExitBadInput;
  }
  if (!FLAGS_draw.empty()) {
    std::error_code code;
    std::filesystem::create_directories(FLAGS_draw, code);
    if (code) {
      std::cerr << "puzzlecal detect: cannot create --draw folder "
                << FLAGS_draw << "\n";
      return kExitOutputError;
    }
  }
  const DetectorOptions options;
  std::vector<DetectedImage> results;
  int readable = 0;
  for (const std::string& file : listing.images) {
    DetectedImage result;
    result.file = file;
    cv::Mat grey;
    if (!LoadGreyImage(file, ImageLoadOptions(), &grey, &error)) {
      std::cerr << "puzzlecal detect: " << error << "\n";
      result.reason = error;
      results.push_back(result);
      continue;
    }
    ++readable;
    result.width = grey.cols;
    result.height = grey.rows;
    DetectorSummary summary;
    result.corners = DetectCorners(grey, options, &summary);
    if (!summary.ok) {
      result.reason = "detector: " + summary.message;
    } else if (result.corners.empty()) {
      result.reason = "no corners found";
    }
    std::cout << file << ": " << result.corners.size() << " corners ("
              << summary.ms_total << " ms)\n";
    if (!FLAGS_draw.empty()) {
      const std::string stem = std::filesystem::path(file).stem().string();
      const std::string overlay =
          (std::filesystem::path(FLAGS_draw) / (stem + "_corners.png")).string();
      if (!WriteOverlay(grey, result.corners, overlay)) {
        std::cerr << "puzzlecal detect: cannot write overlay " << overlay
                  << "\n";
      }
    }
    results.push_back(std::move(result));
  }
  if (!WriteAtomically(FLAGS_out, ToYaml(results), &error)) {
    std::cerr << "puzzlecal detect: " << error << "\n";
    return kExitOutputError;
  }
  if (readable == 0) {
    std::cerr << "puzzlecal detect: no readable image in " << FLAGS_images
              << "\n";
    return kExitBadInput;
  }
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    detect, "detect", "detect checkerboard corners and write detections.yaml",
    "puzzlecal detect --images DIR_OR_FILE --out detections.yaml "
    "[--draw DIR]\n\nRuns the corner detector on every image and writes, per "
    "image, file, width,\nheight, decoded (false), reason and the corners as "
    "rows [x, y, col, row,\ncomponent] (labels -1: no grid or decode here). "
    "--draw writes overlays\n(circle per corner, tick along its first Hessian "
    "eigenvector).",
    {"images", "out", "draw"}, &RunDetect);

}  // namespace
}  // namespace puzzlecal
