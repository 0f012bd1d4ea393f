// `puzzlecal undistort`: photos through a calibrated camera in, the same
// photos through a pinhole camera without distortion out, with that camera.

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "apps/common_flags.h"
#include "apps/subcommand.h"
#include "formats/camera_yaml.h"
#include "formats/image_io.h"
#include "formats/png_writer.h"
#include "pipeline/undistort.h"

DEFINE_double(alpha, 0.0,
              "Field of the undistorted images, as in "
              "cv::getOptimalNewCameraMatrix: 0 = no black border, 1 = every "
              "source pixel the model can invert.");

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

constexpr char kUsage[] =
    "puzzlecal undistort --camera camera.yaml --images DIR_OR_FILE --out DIR "
    "[--alpha A]\n\n"
    "Writes each image as seen by a pinhole camera without distortion "
    "(DIR/NAME.png) and that\ncamera (DIR/undistorted_camera.yaml, puzzlecal "
    "format). The target keeps the image size;\n--alpha chooses its field "
    "(0: only pixels with image content, 1: all of the image the\nmodel can "
    "invert). Fisheye lenses are cut at 60 degrees from the axis (a 120-degree "
    "field).\nWhere the model has no inverse (a distortion that folds over "
    "near the image corners)\nthe target covers the invertible region only, "
    "and the summary says so.";

constexpr char kTargetFile[] = "undistorted_camera.yaml";

int RunUndistort() {
  if (FLAGS_camera.empty() || FLAGS_images.empty() || FLAGS_out.empty()) {
    std::cerr << "puzzlecal undistort: --camera, --images and --out are "
                 "required. Run `puzzlecal undistort --help`.\n";
    return kExitUsage;
  }
  UndistortOptions options;
  options.alpha = FLAGS_alpha;
  std::string error;
  if (!options.Check(&error)) {
    std::cerr << "puzzlecal undistort: --alpha " << FLAGS_alpha << ": " << error
              << ".\n";
    return kExitUsage;
  }
  Camera source;
  if (!ReadCameraFile(FLAGS_camera, &source, &error)) {
    std::cerr << "puzzlecal undistort: " << error << "\n";
    return kExitBadInput;
  }
  ImageListing listing;
  if (!ListImages(FLAGS_images, &listing, &error)) {
    std::cerr << "puzzlecal undistort: " << error << "\n";
    return kExitBadInput;
  }
  if (!listing.note.empty() && ConsoleVerbosity() != Verbosity::kQuiet) {
    std::cerr << "note: " << listing.note << "\n";
  }
  std::error_code ec;
  fs::create_directories(FLAGS_out, ec);
  const std::string target_path = (fs::path(FLAGS_out) / kTargetFile).string();
  if (!fs::is_directory(FLAGS_out) || !CheckOutputPath(target_path, &error)) {
    std::cerr << "puzzlecal undistort: cannot write into '" << FLAGS_out << "'"
              << (error.empty() ? "" : ": " + error) << "\n";
    return kExitOutputError;
  }

  const UndistortResult chosen = ChooseUndistortTarget(source, options);
  std::cout << chosen.Summary(options);
  cv::Mat map_x, map_y;
  MakeUndistortMaps(source, chosen.target, options, &map_x, &map_y);

  int written = 0, failed = 0;
  ImageLoader loader;
  for (const std::string& file : listing.images) {
    cv::Mat image;
    if (!loader.LoadUnchanged(file, &image, &error)) {
      std::cerr << error << "; skipped\n";
      ++failed;
      continue;
    }
    if (image.cols != source.width || image.rows != source.height) {
      std::cerr << file << ": " << image.cols << "x" << image.rows
                << " differs from the camera's " << source.width << "x"
                << source.height << "; skipped\n";
      ++failed;
      continue;
    }
    cv::Mat undistorted;
    cv::remap(image, undistorted, map_x, map_y, cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, cv::Scalar::all(0));
    const std::string out =
        (fs::path(FLAGS_out) / fs::path(file).stem()).string() + ".png";
    if (!WritePngFile(out, undistorted, &error)) {
      std::cerr << "puzzlecal undistort: " << error << "\n";
      return kExitOutputError;
    }
    ++written;
  }
  if (!WriteCameraFile(target_path, CameraFileFormat::kPuzzlecal, chosen.target,
                       CameraFileStats(), &error)) {
    std::cerr << "puzzlecal undistort: " << error << "\n";
    return kExitOutputError;
  }
  std::cout << "wrote " << written << " image" << (written == 1 ? "" : "s")
            << " and " << target_path << " into " << FLAGS_out << "\n";
  if (written == 0) {
    std::cerr << "puzzlecal undistort: none of the " << failed
              << " images could be undistorted.\n";
    return kExitBadInput;
  }
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    undistort, "undistort",
    "undistort photos with a calibrated camera (to check a calibration)",
    kUsage, {"camera", "images", "out", "alpha"}, &RunUndistort);

}  // namespace
}  // namespace puzzlecal
