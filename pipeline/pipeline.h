#ifndef PUZZLECAL_PIPELINE_PIPELINE_H_
#define PUZZLECAL_PIPELINE_PIPELINE_H_

// One image through detection -> grid -> decode, and a folder of images in
// parallel with a bounded number of images in memory.

#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "camera/calibration_view.h"
#include "decode/decoder.h"
#include "detection/corner.h"
#include "detection/detector.h"
#include "formats/image_io.h"
#include "grid/grid.h"
#include "grid/grid_component.h"
#include "target/board.h"

namespace puzzlecal {

// What an image yielded.
enum class ImageOutcome {
  kUsable,         // enough corners with board ids
  kUnreadable,     // the file could not be loaded
  kNoCorners,      // the detector found too few corners
  kNoGrid,         // no consistent lattice among the corners
  kNotDecoded,     // PuzzleBoard: no component decoded
  kTooFewCorners,  // decoded, but fewer corners than a view needs
  kSizeMismatch,   // image size differs from the one most images have
  kPartialBoard,   // a rig: part of a plain checkerboard (relative labels)
  kRepeatedPhoto,  // the file's bytes are an earlier image's (a copy)
};

// "usable", "unreadable", "no corners", ...
const char* ImageOutcomeName(ImageOutcome outcome);

struct PipelineOptions {
  DetectorOptions detector;  // corner detection
  GridOptions grid;          // lattice reconstruction
  DecodeOptions decode;      // board ids
  ImageLoadOptions load;     // image loading limits
  // An image needs at least this many corners with board ids to be a view.
  // Default 6 (a pose has 6 degrees of freedom; fewer cannot constrain it).
  int min_corners = 6;
  // False: stop after the grid (relative labels in `components`, no board
  // ids), for `puzzlecal detect` without a board file. Default true.
  bool run_decode = true;

  bool Check(std::string* why = nullptr) const;
};

struct ImageResult {
  std::string file;
  int width = 0;
  int height = 0;
  ImageOutcome outcome = ImageOutcome::kUnreadable;
  std::string reason;                     // why not usable, or details
  std::vector<Corner> corners;            // all detections
  std::vector<GridComponent> components;  // lattice components
  DecodeResult decode;                    // ids and per-component decisions
  double seconds_load = 0;                // reading and decoding the file
  double seconds_detect = 0;              // corner detection
  double seconds_grid_decode = 0;         // grid + decode
  // The index of the calibration view this image became
  // (MakeCalibrationViews), -1 when it gave none.
  int view_index = -1;
};

// Runs detection, grid and decode on a grey image (`board` is not read when
// options.run_decode is false). `detector`, when given, was made with
// options.detector and is reused (its buffers kept across images); else one
// is made for this image.
void ProcessGreyImage(const cv::Mat& grey, const Board& board,
                      const PipelineOptions& options, ImageResult* result,
                      CornerDetector* detector = nullptr);

// Loads `file` and processes it; the image is released on return.
// `loader` and `detector`, when given, are reused (made with options.load
// and options.detector); else they are made for this file.
ImageResult ProcessImageFile(const std::string& file, const Board& board,
                             const PipelineOptions& options,
                             CornerDetector* detector = nullptr,
                             ImageLoader* loader = nullptr);

// Processes `files` on `num_threads` workers (0 = all cores), each holding
// one image, one ImageLoader and one CornerDetector at a time: while one worker
// reads and decodes a file, the others detect in theirs, so reading overlaps
// detection. Results come in the order of `files` and do not depend on the
// thread count (each image's result depends on that image alone).
// `on_done(index, result)` is called (serialised) as each image finishes,
// for progress output.
std::vector<ImageResult> ProcessImageFiles(
    const std::vector<std::string>& files, const Board& board,
    const PipelineOptions& options, int num_threads,
    const std::function<void(size_t, const ImageResult&)>& on_done = {});

// Whether files `a` and `b` hold the same bytes (their sizes compared
// first, so files of different sizes are not read); false when either
// cannot be read.
bool FilesHoldSameBytes(const std::string& a, const std::string& b);

// Marks each usable image whose file holds the same bytes as an earlier
// usable image's (a copy under another name: it adds no view, only weight)
// as kRepeatedPhoto, reason "not used: the same photo as <earlier file
// name>"; the earlier one in `images` order is kept. Files are compared by
// size first, so only files of a shared size are read. Records that name
// no file (a video's frames) are left alone. Returns how many were marked.
int MarkRepeatedPhotos(std::vector<ImageResult>* images);

// The calibration views of a run: one per usable image of the size most
// usable images have (images of another size are marked kSizeMismatch),
// copies of an earlier image left out (MarkRepeatedPhotos). Sets each
// image's view_index; `width`/`height` return the image size (0 when no
// image is usable).
std::vector<CalibrationView> MakeCalibrationViews(
    const Board& board, std::vector<ImageResult>* images, int* width,
    int* height);

// The image file of each of `num_views` views (by ImageResult::view_index).
std::vector<std::string> ViewFiles(const std::vector<ImageResult>& images,
                                   size_t num_views);

}  // namespace puzzlecal

#endif  // PUZZLECAL_PIPELINE_PIPELINE_H_
