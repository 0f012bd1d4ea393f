// `puzzlecal detect`: runs detection, grid and (with --board) decoding on one
// image or a folder and writes detections.yaml (and overlays with --draw).

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "apps/common_flags.h"
#include "apps/options_io.h"
#include "apps/subcommand.h"
#include "formats/board_file.h"
#include "formats/image_io.h"
#include "formats/png_writer.h"
#include "pipeline/pipeline.h"
#include "report/overlay.h"
#include "util/atomic_file.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// One output row: a corner and its label. col/row/component are -1 for a
// corner outside every lattice component (or, when the image was decoded,
// outside every decoded component).
struct LabelledCorner {
  Eigen::Vector2d xy;
  double orientation = 0.0;
  Eigen::Vector2i label{-1, -1};
  int component = -1;
};

// The rows of one image: absolute board ids when decoded, else the relative
// labels of decode/ (right-handed, per component) or, without a board, of
// grid/.
std::vector<LabelledCorner> LabelCorners(const ImageResult& image,
                                         bool have_board) {
  std::vector<LabelledCorner> rows(image.corners.size());
  for (size_t k = 0; k < image.corners.size(); ++k) {
    rows[k].xy = image.corners[k].xy;
    rows[k].orientation = image.corners[k].orientation;
  }
  if (have_board) {
    const DecodeResult& decode = image.decode;
    for (size_t k = 0; k < decode.corner_index.size(); ++k) {
      LabelledCorner& row = rows[decode.corner_index[k]];
      row.label = decode.observation.id[k];
      row.component = decode.component[k];
    }
  } else {
    for (size_t c = 0; c < image.components.size(); ++c) {
      const GridComponent& component = image.components[c];
      for (size_t k = 0; k < component.corner.size(); ++k) {
        LabelledCorner& row = rows[component.corner[k]];
        row.label = component.ij[k];
        row.component = static_cast<int>(c);
      }
    }
  }
  return rows;
}

// A distinct colour per component (golden-angle hues); red for unlabelled.
cv::Scalar ComponentColour(int component) {
  if (component < 0) return cv::Scalar(0, 0, 255);
  cv::Mat hsv(
      1, 1, CV_8UC3,
      cv::Scalar(static_cast<int>(30 + component * 137.508) % 180, 255, 230));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

// Corners as circles with a tick along the first Hessian eigenvector,
// lattice edges (label neighbours of one component) as lines in the
// component's colour, unlabelled corners in red, and the label of every
// corner whose col and row are multiples of 5.
bool WriteOverlay(const cv::Mat& grey, const std::vector<LabelledCorner>& rows,
                  const std::string& path, std::string* error) {
  const double radius = std::max(3.0, std::max(grey.cols, grey.rows) / 400.0);
  const int thickness = std::max(1, static_cast<int>(radius / 4));
  Overlay overlay;
  auto mark = [&](OverlayMark::Kind kind, const Eigen::Vector2d& at,
                  const Eigen::Vector2d& to, const cv::Scalar& colour) {
    OverlayMark m;
    m.kind = kind;
    m.at = at;
    m.to = to;
    m.size = radius;
    m.thickness = thickness;
    m.colour = colour;
    overlay.marks.push_back(m);
    return &overlay.marks.back();
  };
  // Lattice edges: sort labelled rows by (component, row, col) and look up
  // the right and lower neighbours by binary search.
  std::vector<int> order;
  for (size_t k = 0; k < rows.size(); ++k) {
    if (rows[k].component >= 0) order.push_back(static_cast<int>(k));
  }
  auto key = [&](int k) {
    return std::make_tuple(rows[k].component, rows[k].label.y(),
                           rows[k].label.x());
  };
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return key(a) < key(b); });
  for (int k : order) {
    const LabelledCorner& a = rows[k];
    for (int axis = 0; axis < 2; ++axis) {
      const Eigen::Vector2i step = Eigen::Vector2i::Unit(axis);
      const auto wanted = std::make_tuple(a.component, a.label.y() + step.y(),
                                          a.label.x() + step.x());
      auto it =
          std::lower_bound(order.begin(), order.end(), wanted,
                           [&](int m, const auto& w) { return key(m) < w; });
      if (it == order.end() || key(*it) != wanted) continue;
      mark(OverlayMark::Kind::kLine, a.xy, rows[*it].xy,
           ComponentColour(a.component));
    }
  }
  for (const LabelledCorner& c : rows) {
    const Eigen::Vector2d tick(std::cos(c.orientation),
                               std::sin(c.orientation));
    mark(OverlayMark::Kind::kCircle, c.xy, c.xy, ComponentColour(c.component));
    mark(OverlayMark::Kind::kLine, c.xy - 2.0 * radius * tick,
         c.xy + 2.0 * radius * tick, cv::Scalar(0, 255, 0));
    if (c.component >= 0 && c.label.x() % 5 == 0 && c.label.y() % 5 == 0) {
      OverlayMark* label = mark(OverlayMark::Kind::kText,
                                c.xy + Eigen::Vector2d(radius, -radius), c.xy,
                                cv::Scalar(255, 255, 0));
      label->size = 2.2 * radius;
      label->text =
          std::to_string(c.label.x()) + "," + std::to_string(c.label.y());
    }
  }
  return WritePngFile(path, DrawOverlay(grey, overlay, OverlayOptions()),
                      error);
}

void EmitImage(const ImageResult& image, bool have_board, YAML::Emitter* out) {
  const bool decoded = have_board && image.decode.absolute_ids;
  std::string reason;
  if (image.outcome == ImageOutcome::kUnreadable ||
      image.outcome == ImageOutcome::kNoCorners ||
      image.outcome == ImageOutcome::kNoGrid ||
      image.outcome == ImageOutcome::kNotDecoded) {
    reason = image.reason;
  } else if (!have_board) {
    reason = "no board given: labels are relative to their component";
  } else if (!decoded) {
    reason = image.decode.reason.empty()
                 ? "labels are relative to their component"
                 : image.decode.reason;
  }
  *out << YAML::BeginMap;
  *out << YAML::Key << "file" << YAML::Value << image.file;
  *out << YAML::Key << "width" << YAML::Value << image.width;
  *out << YAML::Key << "height" << YAML::Value << image.height;
  *out << YAML::Key << "decoded" << YAML::Value << decoded;
  *out << YAML::Key << "reason" << YAML::Value << reason;
  *out << YAML::Key << "corners" << YAML::Value << YAML::BeginSeq;
  for (const LabelledCorner& c : LabelCorners(image, have_board)) {
    *out << YAML::Flow << YAML::BeginSeq << c.xy.x() << c.xy.y() << c.label.x()
         << c.label.y() << c.component << YAML::EndSeq;
  }
  *out << YAML::EndSeq;
  if (have_board && !image.decode.components.empty()) {
    // The decision per lattice component, so a refusal can be understood.
    *out << YAML::Key << "components" << YAML::Value << YAML::BeginSeq;
    for (const ComponentDecoding& c : image.decode.components) {
      *out << YAML::Flow << YAML::BeginMap;
      *out << YAML::Key << "component" << YAML::Value << c.component;
      *out << YAML::Key << "corners" << YAML::Value << c.num_corners;
      *out << YAML::Key << "decoded" << YAML::Value << c.decoded;
      if (!c.reason.empty()) {
        *out << YAML::Key << "reason" << YAML::Value << c.reason;
      }
      if (c.bits_read > 0) {
        *out << YAML::Key << "bits_read" << YAML::Value << c.bits_read;
        *out << YAML::Key << "agreement" << YAML::Value << c.agreement;
        *out << YAML::Key << "margin" << YAML::Value << c.margin;
      }
      *out << YAML::EndMap;
    }
    *out << YAML::EndSeq;
  }
  *out << YAML::EndMap;
}

int RunDetect() {
  if (FLAGS_images.empty() || FLAGS_out.empty()) {
    std::cerr << "puzzlecal detect: --images and --out are required. Run "
                 "`puzzlecal detect --help`.\n";
    return kExitUsage;
  }
  if (FLAGS_threads < 0) {
    std::cerr << "puzzlecal detect: --threads must be >= 0.\n";
    return kExitUsage;
  }
  std::string error;
  RunOptions run_options;  // --options FILE, or the defaults
  if (!FLAGS_options.empty() &&
      !LoadOptionsFile(FLAGS_options, &run_options, &error)) {
    std::cerr << "puzzlecal detect: " << error << "\n";
    return kExitBadInput;
  }
  const bool have_board = !FLAGS_board.empty();
  Board board;
  if (have_board && !LoadBoardFile(FLAGS_board, &board, &error)) {
    std::cerr << "puzzlecal detect: " << error << "\n";
    return kExitBadInput;
  }
  if (!CheckOutputPath(FLAGS_out, &error)) {
    std::cerr << "puzzlecal detect: " << error << "\n";
    return kExitOutputError;
  }
  ImageListing listing;
  if (!ListImages(FLAGS_images, &listing, &error)) {
    std::cerr << "puzzlecal detect: " << error << "\n";
    return kExitBadInput;
  }
  if (!listing.note.empty() && ConsoleVerbosity() != Verbosity::kQuiet) {
    std::cerr << "note: " << listing.note << "\n";
  }
  for (const std::string& skipped : listing.skipped) {
    if (ConsoleVerbosity() == Verbosity::kVerbose) {
      std::cerr << "skipped " << skipped << "\n";
    }
  }
  if (!FLAGS_draw.empty()) {
    std::error_code code;
    fs::create_directories(FLAGS_draw, code);
    if (code) {
      std::cerr << "puzzlecal detect: cannot create --draw folder "
                << FLAGS_draw << ": " << code.message() << "\n";
      return kExitOutputError;
    }
  }

  PipelineOptions options = run_options.pipeline;
  options.run_decode = have_board;
  const int threads =
      FLAGS_threads > 0
          ? FLAGS_threads
          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  cv::setNumThreads(1);
  const std::vector<ImageResult> images = ProcessImageFiles(
      listing.images, board, options, threads,
      [](size_t, const ImageResult& image) {
        if (image.outcome == ImageOutcome::kUnreadable) {
          std::cerr << "puzzlecal detect: " << image.reason << "\n";
          return;
        }
        if (ConsoleVerbosity() == Verbosity::kQuiet) return;
        std::cout << image.file << ": " << image.corners.size() << " corners, "
                  << image.components.size() << " lattice components; "
                  << ImageOutcomeName(image.outcome) << " (" << image.reason
                  << ")\n";
      });
  const int readable = static_cast<int>(
      std::count_if(images.begin(), images.end(), [](const ImageResult& r) {
        return r.outcome != ImageOutcome::kUnreadable;
      }));
  if (readable == 0) {
    std::cerr << "puzzlecal detect: no readable image in " << FLAGS_images
              << "; nothing written\n";
    return kExitBadInput;
  }

  YAML::Emitter out;
  out.SetDoublePrecision(9);
  out << YAML::BeginMap << YAML::Key << "images" << YAML::Value
      << YAML::BeginSeq;
  for (const ImageResult& image : images) EmitImage(image, have_board, &out);
  out << YAML::EndSeq << YAML::EndMap;
  if (!WriteFileAtomically(FLAGS_out, std::string(out.c_str()) + "\n",
                           &error)) {
    std::cerr << "puzzlecal detect: " << error << "\n";
    return kExitOutputError;
  }

  if (!FLAGS_draw.empty()) {
    // Overlays are drawn after the run, one image in memory at a time, named
    // after the image (a.png -> a_corners.png; a second a.jpg gets
    // a_2_corners.png).
    std::set<std::string> stems;
    for (const ImageResult& image : images) {
      if (image.outcome == ImageOutcome::kUnreadable) continue;
      cv::Mat grey;
      if (!LoadGreyImage(image.file, options.load, &grey, &error)) continue;
      const std::string base = fs::path(image.file).stem().string();
      std::string stem = base;
      for (int k = 2; !stems.insert(stem).second; ++k) {
        stem = base + "_" + std::to_string(k);
      }
      const std::string overlay =
          (fs::path(FLAGS_draw) / (stem + "_corners.png")).string();
      std::string overlay_error;
      if (!WriteOverlay(grey, LabelCorners(image, have_board), overlay,
                        &overlay_error)) {
        std::cerr << "puzzlecal detect: cannot write overlay: " << overlay_error
                  << "\n";
      }
    }
  }
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(
    detect, "detect", "detect, label and decode corners; write detections.yaml",
    "puzzlecal detect --images DIR_OR_FILE [--board BOARD.yaml] --out "
    "detections.yaml\n                 [--draw DIR] [--threads N] [--options "
    "FILE]\n\n"
    "Runs corner detection, grid reconstruction and, with --board, decoding "
    "on\nevery image. Writes per image: file, width, height, decoded (true "
    "when the\nids are absolute board ids), reason (why it yielded nothing "
    "or was not\ndecoded), corners as rows [x, y, col, row, component] "
    "(absolute ids when\ndecoded, else labels relative to their component; "
    "-1 for a corner outside\nevery component) and, with --board, the "
    "decision per component. Exits 3\nwithout writing when no image is "
    "readable. --draw writes overlays: a\ncircle per corner in its "
    "component's colour (red: unlabelled), a tick\nalong its first Hessian "
    "eigenvector, lattice edges, and every fifth label.",
    {"images", "board", "out", "draw", "threads", "options"}, &RunDetect);

}  // namespace
}  // namespace puzzlecal
