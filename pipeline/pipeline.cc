#include "pipeline/pipeline.h"

#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>
#include <utility>

#include "util/enum_names.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

// Relative labels of different components are not comparable: a view built
// from them keeps the component with the most points (a checkerboard view;
// any consistent labelling is a rigid motion of the board plane).
void KeepLargestComponent(DecodeResult* decode) {
  std::map<int, int> points_per_component;
  for (int component : decode->component) ++points_per_component[component];
  int best = -1, best_count = 0;
  for (const auto& [component, count] : points_per_component) {
    if (count > best_count) {  // ties: the lower index, i.e. the larger grid
      best = component;
      best_count = count;
    }
  }
  DecodeResult kept = *decode;
  kept.observation = BoardObservation();
  kept.corner_index.clear();
  kept.component.clear();
  for (size_t k = 0; k < decode->component.size(); ++k) {
    if (decode->component[k] != best) continue;
    kept.observation.id.push_back(decode->observation.id[k]);
    kept.observation.xy.push_back(decode->observation.xy[k]);
    kept.corner_index.push_back(decode->corner_index[k]);
    kept.component.push_back(best);
  }
  *decode = std::move(kept);
}

// The bytes of `file`; false when it cannot be read.
bool ReadFileBytes(const std::string& file, std::string* bytes) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  bytes->assign(std::istreambuf_iterator<char>(in),
                std::istreambuf_iterator<char>());
  return !in.bad();
}

}  // namespace

constexpr EnumName<ImageOutcome> kImageOutcomeNames[] = {
    {ImageOutcome::kUsable, "usable"},
    {ImageOutcome::kUnreadable, "unreadable"},
    {ImageOutcome::kNoCorners, "no corners"},
    {ImageOutcome::kNoGrid, "no consistent grid"},
    {ImageOutcome::kNotDecoded, "code not recognised"},
    {ImageOutcome::kTooFewCorners, "too few corners"},
    {ImageOutcome::kSizeMismatch, "image size differs"},
    {ImageOutcome::kPartialBoard, "part of the board only"},
    {ImageOutcome::kRepeatedPhoto, "repeated photo"},
};

const char* ImageOutcomeName(ImageOutcome outcome) {
  return NameOf(kImageOutcomeNames, outcome, "unknown");
}

bool PipelineOptions::Check(std::string* why) const {
  std::string inner;
  if (!detector.Check(&inner)) {
    if (why != nullptr) *why = "detector: " + inner;
    return false;
  }
  if (!grid.Check(&inner)) {
    if (why != nullptr) *why = "grid: " + inner;
    return false;
  }
  if (!decode.Check(&inner)) {
    if (why != nullptr) *why = "decode: " + inner;
    return false;
  }
  if (!load.Check(&inner)) {
    if (why != nullptr) *why = "load: " + inner;
    return false;
  }
  if (min_corners < 4) {
    if (why != nullptr) *why = "min_corners must be >= 4";
    return false;
  }
  return true;
}

void ProcessGreyImage(const cv::Mat& grey, const Board& board,
                      const PipelineOptions& options, ImageResult* result,
                      CornerDetector* detector) {
  // The options come from the program, not from the user: a bad value is a
  // programming error.
  std::string why;
  CHECK(options.Check(&why)) << "pipeline options: " << why;
  result->width = grey.cols;
  result->height = grey.rows;
  Timer timer;
  DetectorSummary detector_summary;
  result->corners =
      detector != nullptr
          ? detector->Detect(grey, &detector_summary)
          : DetectCorners(grey, options.detector, &detector_summary);
  result->seconds_detect = timer.Seconds();
  if (!detector_summary.ok) {
    result->outcome = ImageOutcome::kNoCorners;
    result->reason = detector_summary.message;
    return;
  }
  if (static_cast<int>(result->corners.size()) < options.min_corners) {
    result->outcome = ImageOutcome::kNoCorners;
    result->reason = "found " + std::to_string(result->corners.size()) +
                     " corners, a view needs " +
                     std::to_string(options.min_corners);
    return;
  }
  timer.Restart();
  result->components = BuildGrid(result->corners, grey, options.grid);
  if (result->components.empty() ||
      static_cast<int>(result->components.front().corner.size()) <
          options.min_corners) {
    result->seconds_grid_decode = timer.Seconds();
    result->outcome = ImageOutcome::kNoGrid;
    result->reason = "no lattice of " + std::to_string(options.min_corners) +
                     " or more consistent corners among " +
                     std::to_string(result->corners.size()) + " detections";
    return;
  }
  if (!options.run_decode) {
    result->seconds_grid_decode = timer.Seconds();
    result->outcome = ImageOutcome::kUsable;
    result->reason = std::to_string(result->components.size()) +
                     " lattice components, largest " +
                     std::to_string(result->components.front().corner.size()) +
                     " corners (not decoded: no board given)";
    return;
  }
  result->decode = DecodeBoard(board, result->corners, result->components, grey,
                               options.decode);
  result->seconds_grid_decode = timer.Seconds();
  if (board.Traits().absolute_ids && !result->decode.decoded) {
    result->outcome = ImageOutcome::kNotDecoded;
    result->reason = result->decode.reason;
    return;
  }
  if (!result->decode.absolute_ids) KeepLargestComponent(&result->decode);
  const int num_ids = static_cast<int>(result->decode.observation.id.size());
  if (num_ids < options.min_corners) {
    result->outcome = ImageOutcome::kTooFewCorners;
    result->reason = std::to_string(num_ids) +
                     " corners with board ids, a view needs " +
                     std::to_string(options.min_corners);
    return;
  }
  result->outcome = ImageOutcome::kUsable;
  result->reason = std::to_string(num_ids) + " corners";
}

ImageResult ProcessImageFile(const std::string& file, const Board& board,
                             const PipelineOptions& options,
                             CornerDetector* detector, ImageLoader* loader) {
  ImageResult result;
  result.file = file;
  const Timer timer;
  cv::Mat grey;
  std::string error;
  const bool loaded = loader != nullptr
                          ? loader->Load(file, &grey, &error)
                          : LoadGreyImage(file, options.load, &grey, &error);
  result.seconds_load = timer.Seconds();
  if (!loaded) {
    result.outcome = ImageOutcome::kUnreadable;
    result.reason = error;
    return result;
  }
  ProcessGreyImage(grey, board, options, &result, detector);
  return result;
}

std::vector<ImageResult> ProcessImageFiles(
    const std::vector<std::string>& files, const Board& board,
    const PipelineOptions& options, int num_threads,
    const std::function<void(size_t, const ImageResult&)>& on_done) {
  std::vector<ImageResult> results(files.size());
  if (num_threads <= 0) {
    num_threads = std::max(1u, std::thread::hardware_concurrency());
  }
  num_threads = std::min<int>(num_threads, std::max<size_t>(1, files.size()));
  std::atomic<size_t> next{0};
  std::mutex done_mutex;
  auto worker = [&]() {
    CornerDetector detector(options.detector);
    ImageLoader loader(options.load);
    for (size_t i = next++; i < files.size(); i = next++) {
      results[i] =
          ProcessImageFile(files[i], board, options, &detector, &loader);
      if (on_done) {
        std::lock_guard<std::mutex> lock(done_mutex);
        on_done(i, results[i]);
      }
    }
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < num_threads; ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& thread : threads) thread.join();
  return results;
}

bool FilesHoldSameBytes(const std::string& a, const std::string& b) {
  std::error_code ec_a, ec_b;
  const std::uintmax_t size_a = std::filesystem::file_size(a, ec_a);
  const std::uintmax_t size_b = std::filesystem::file_size(b, ec_b);
  if (ec_a || ec_b || size_a != size_b) return false;
  std::string bytes_a, bytes_b;
  return ReadFileBytes(a, &bytes_a) && ReadFileBytes(b, &bytes_b) &&
         bytes_a == bytes_b;
}

int MarkRepeatedPhotos(std::vector<ImageResult>* images) {
  // The usable images by file size, in input order.
  std::map<std::uintmax_t, std::vector<size_t>> by_size;
  for (size_t i = 0; i < images->size(); ++i) {
    const ImageResult& image = (*images)[i];
    if (image.outcome != ImageOutcome::kUsable) continue;
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(image.file, ec);
    if (ec) continue;  // no such file: a video's frame ("clip.mp4#frame12")
    by_size[size].push_back(i);
  }
  int marked = 0;
  for (const auto& [size, same_size] : by_size) {
    if (same_size.size() < 2) continue;
    // The first image of each content so far, with the hash of its bytes; a
    // hash match is confirmed byte for byte.
    std::vector<std::pair<size_t, size_t>> originals;  // (hash, image)
    for (const size_t i : same_size) {
      ImageResult& image = (*images)[i];
      std::string bytes;
      if (!ReadFileBytes(image.file, &bytes)) continue;
      const size_t hash = std::hash<std::string>()(bytes);
      const ImageResult* original = nullptr;
      for (const auto& [original_hash, k] : originals) {
        std::string original_bytes;
        if (original_hash == hash &&
            ReadFileBytes((*images)[k].file, &original_bytes) &&
            original_bytes == bytes) {
          original = &(*images)[k];
          break;
        }
      }
      if (original == nullptr) {
        originals.emplace_back(hash, i);
        continue;
      }
      image.outcome = ImageOutcome::kRepeatedPhoto;
      image.reason = "not used: the same photo as " +
                     std::filesystem::path(original->file).filename().string();
      ++marked;
    }
  }
  return marked;
}

std::vector<CalibrationView> MakeCalibrationViews(
    const Board& board, std::vector<ImageResult>* images, int* width,
    int* height) {
  *width = 0;
  *height = 0;
  std::vector<CalibrationView> views;
  for (ImageResult& image : *images) image.view_index = -1;
  MarkRepeatedPhotos(images);
  // The size most usable images have (the first of them on a tie).
  std::map<std::pair<int, int>, int> count;
  int best = 0;
  for (const ImageResult& image : *images) {
    if (image.outcome != ImageOutcome::kUsable) continue;
    const int n = ++count[{image.width, image.height}];
    if (n > best) {
      best = n;
      *width = image.width;
      *height = image.height;
    }
  }
  for (size_t i = 0; i < images->size(); ++i) {
    ImageResult& image = (*images)[i];
    if (image.outcome != ImageOutcome::kUsable) continue;
    if (image.width != *width || image.height != *height) {
      image.outcome = ImageOutcome::kSizeMismatch;
      std::ostringstream reason;
      reason << image.width << "x" << image.height << " differs from the "
             << *width << "x" << *height << " most images have";
      image.reason = reason.str();
      continue;
    }
    CalibrationView view;
    view.name = std::filesystem::path(image.file).filename().string();
    const BoardObservation& observation = image.decode.observation;
    for (size_t k = 0; k < observation.id.size(); ++k) {
      view.board_points.push_back(board.Point(observation.id[k]));
      view.image_points.push_back(observation.xy[k]);
    }
    image.view_index = static_cast<int>(views.size());
    views.push_back(std::move(view));
  }
  return views;
}

std::vector<std::string> ViewFiles(const std::vector<ImageResult>& images,
                                   size_t num_views) {
  std::vector<std::string> files(num_views);
  for (const ImageResult& image : images) {
    if (image.view_index >= 0 &&
        static_cast<size_t>(image.view_index) < num_views) {
      files[image.view_index] = image.file;
    }
  }
  return files;
}

}  // namespace puzzlecal
