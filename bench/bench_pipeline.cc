// Photo -> lattice ids, stage by stage, on a folder of checkerboard photos
// (default: the deltille fisheye photos, an 11 x 8 inner-corner board),
// against OpenCV's cv::findChessboardCornersSB on some of the same photos in
// the same run. Per photo, one thread, CPU time of the thread (medians over
// the photos):
//   read_file   the file into memory;
//   zlib_inflate  the PNG's IDAT stream inflated by zlib alone (the floor
//               of any PNG decoder that uses zlib: the unfiltering and the
//               checks come on top);
//   decode_opencv  cv::imdecode to grey (libpng, or libjpeg-turbo);
//   load        ImageLoader::Load, as the pipeline reads a photo (file, checks,
//               decoding);
//   detect      CornerDetector::Detect (one detector kept across photos);
//   grid_decode BuildGrid + DecodeBoard;
//   image_to_ids  detect + grid_decode: the image already in memory, on
//               the same footing as SB's figure below (reading excluded);
//   photo_to_ids  load + detect + grid_decode.
// findChessboardCornersSB runs with flags 0 on one thread
// (cv::setNumThreads(1)) on the grey image already in memory, so its time
// excludes reading. Then the folder through ProcessImageFiles (the
// calibrate/detect pipeline, reading overlapped with detection) on 1 and 2
// threads: wall time per photo, and CPU time of all threads per photo (on
// a shared machine the wall time measures the neighbours too; on two free
// cores two threads take at least half their CPU time). Prints JSON.
//
// Then the calibration of the folder's views (from the 2-thread run) on 2
// threads with kannala-brandt and kannala-brandt-noncentral (the models of
// a fisheye folder), as `calibrate` runs it: the solve and the evidence
// (cross-validation halves), their seconds and iterations, and the whole
// `calibrate` per photo (the 2-thread folder run plus both) against SB.
// Last, the program itself (the `puzzlecal` built beside this bench, when
// found): `puzzlecal version` (the program's start alone, best of 5) and
// `puzzlecal calibrate --threads 2 --model kannala-brandt-noncentral` of
// the folder, wall time from the shell (start, images, calibration,
// evidence, camera file; no report), per photo and against SB.
//
// Usage: bench_pipeline [folder] [sb_photos] [cols rows]
//   folder: default the deltille photos (skipped with a message when
//   absent); sb_photos: photos given to findChessboardCornersSB (default
//   4); cols rows: inner corners of the board (default 11 8).

#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "decode/decoder.h"
#include "detection/detector.h"
#include "evidence/evidence.h"
#include "formats/image_io.h"
#include "grid/grid.h"
#include "pipeline/pipeline.h"
#include "target/board.h"
#include "tests/support/deltille_data.h"
#include "util/statistics.h"

namespace puzzlecal {
namespace {

double ThreadMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double WallMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::vector<unsigned char> ReadBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  std::vector<unsigned char> bytes(static_cast<size_t>(file.tellg()));
  file.seekg(0);
  file.read(reinterpret_cast<char*>(bytes.data()), bytes.size());
  return bytes;
}

unsigned BigEndian32(const std::vector<unsigned char>& b, size_t at) {
  return (unsigned{b[at]} << 24) | (unsigned{b[at + 1]} << 16) |
         (unsigned{b[at + 2]} << 8) | b[at + 3];
}

// Milliseconds zlib needs to inflate the IDAT stream of a PNG into the
// filtered scanlines (-1 when the file is no PNG or inflation fails). The
// IDAT chunks are gathered beforehand (not timed).
double ZlibInflateMs(const std::vector<unsigned char>& png) {
  if (png.size() < 33 || png[1] != 'P' || png[2] != 'N' || png[3] != 'G') {
    return -1.0;
  }
  const unsigned width = BigEndian32(png, 16), height = BigEndian32(png, 20);
  const int depth = png[24], colour = png[25];
  const int channels = colour == 0   ? 1
                       : colour == 2 ? 3
                       : colour == 4 ? 2
                       : colour == 6 ? 4
                                     : 1;
  const size_t row = (static_cast<size_t>(width) * channels * depth + 7) / 8;
  std::vector<unsigned char> idat;
  for (size_t pos = 8; pos + 12 <= png.size();) {
    const size_t length = BigEndian32(png, pos);
    if (pos + 12 + length > png.size()) break;
    if (std::equal(png.begin() + pos + 4, png.begin() + pos + 8, "IDAT")) {
      idat.insert(idat.end(), png.begin() + pos + 8,
                  png.begin() + pos + 8 + length);
    }
    pos += 12 + length;
  }
  std::vector<unsigned char> out((row + 1) * height);
  uLongf out_size = out.size();
  const double t = ThreadMs();
  const int status =
      uncompress(out.data(), &out_size, idat.data(), idat.size());
  const double ms = ThreadMs() - t;
  return status == Z_OK ? ms : -1.0;
}

struct PhotoTimes {
  double read_file = 0, zlib_inflate = -1, decode_opencv = 0, load = 0;
  double detect = 0, grid_decode = 0;
  int corners = 0, ids = 0;
};

PhotoTimes MeasurePhoto(const std::string& file, const Board& board,
                        const PipelineOptions& options,
                        CornerDetector* detector, ImageLoader* loader,
                        cv::Mat* grey) {
  PhotoTimes p;
  double t = ThreadMs();
  const std::vector<unsigned char> bytes = ReadBytes(file);
  p.read_file = ThreadMs() - t;
  p.zlib_inflate = ZlibInflateMs(bytes);
  t = ThreadMs();
  const cv::Mat by_opencv = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  p.decode_opencv = ThreadMs() - t;
  std::string error;
  t = ThreadMs();
  if (!loader->Load(file, grey, &error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return p;
  }
  p.load = ThreadMs() - t;
  if (cv::norm(by_opencv, *grey, cv::NORM_INF) != 0.0) {
    std::fprintf(stderr, "%s: LoadGreyImage differs from cv::imdecode\n",
                 file.c_str());
  }
  t = ThreadMs();
  const std::vector<Corner> corners = detector->Detect(*grey);
  p.detect = ThreadMs() - t;
  p.corners = static_cast<int>(corners.size());
  t = ThreadMs();
  const std::vector<GridComponent> components =
      BuildGrid(corners, *grey, options.grid);
  const DecodeResult decode =
      DecodeBoard(board, corners, components, *grey, options.decode);
  p.grid_decode = ThreadMs() - t;
  p.ids = static_cast<int>(decode.observation.id.size());
  return p;
}

double ProcessMs() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

// ProcessImageFiles on `threads` threads: wall and CPU (all threads)
// milliseconds per photo, and the usable photos.
struct FolderRun {
  double wall_ms = 0;
  double cpu_ms = 0;
  int usable = 0;
};

FolderRun RunFolder(const std::vector<std::string>& files, const Board& board,
                    const PipelineOptions& options, int threads,
                    std::vector<ImageResult>* results_out = nullptr) {
  FolderRun run;
  const double wall = WallMs(), cpu = ProcessMs();
  std::vector<ImageResult> results =
      ProcessImageFiles(files, board, options, threads);
  run.wall_ms = (WallMs() - wall) / files.size();
  run.cpu_ms = (ProcessMs() - cpu) / files.size();
  for (const ImageResult& r : results) {
    run.usable += r.outcome == ImageOutcome::kUsable ? 1 : 0;
  }
  if (results_out != nullptr) *results_out = std::move(results);
  return run;
}

// One model's calibration of the views on `threads` threads, then its
// evidence, as `calibrate` runs them (wall seconds).
struct CalibrationRun {
  bool ok = false;
  double calibrate_s = 0, evidence_s = 0;
  double initialization_s = 0, covariance_s = 0;  // parts of calibrate_s
  int iterations = 0;
  double rms_px = 0;
};

CalibrationRun RunCalibration(const std::vector<CalibrationView>& views,
                              CameraModelId model, int width, int height,
                              int threads) {
  CalibrationRun run;
  CalibrationOptions options;
  options.num_threads = threads;
  CalibrationResult result;
  std::string error;
  double t = WallMs();
  run.ok = Calibrate(views, model, width, height, options, &result, &error);
  run.calibrate_s = (WallMs() - t) * 1e-3;
  if (!run.ok) {
    std::fprintf(stderr, "%s: %s\n", CameraModelName(model), error.c_str());
    return run;
  }
  run.iterations = result.iterations;
  run.rms_px = result.rms_px;
  run.initialization_s = result.initialization_seconds;
  run.covariance_s = result.covariance_seconds;
  t = WallMs();
  const Evidence evidence =
      ComputeEvidence(views, result, options, EvidenceOptions());
  run.evidence_s = (WallMs() - t) * 1e-3;
  return run;
}

// The `puzzlecal` program built beside this bench (<build>/apps/), or empty.
std::string ProgramBesideThisBench() {
  std::error_code ec;
  const std::filesystem::path self =
      std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const std::filesystem::path program =
      self.parent_path().parent_path() / "apps" / "puzzlecal";
  return std::filesystem::exists(program, ec) ? program.string() : "";
}

// Wall milliseconds of a shell command (-1 when it fails).
double CommandMs(const std::string& command) {
  const double t = WallMs();
  const int status = std::system(command.c_str());
  const double ms = WallMs() - t;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? ms : -1.0;
}

// The program's start and its whole `calibrate` of the folder.
struct ProgramRun {
  double start_ms = -1;      // `puzzlecal version`, best of 5
  double calibrate_ms = -1;  // the whole calibrate command
};

ProgramRun RunProgram(const std::string& folder, const Board& board) {
  ProgramRun run;
  const std::string program = ProgramBesideThisBench();
  if (program.empty()) return run;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("puzzlecal_bench_pipeline_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string board_file = (dir / "board.yaml").string();
  std::ofstream(board_file) << "type: checkerboard\ncols: " << board.cols
                            << "\nrows: " << board.rows
                            << "\ntile_size_m: " << board.tile_size_m << "\n";
  for (int k = 0; k < 5; ++k) {
    const double ms = CommandMs("'" + program + "' version >/dev/null");
    if (ms >= 0 && (run.start_ms < 0 || ms < run.start_ms)) run.start_ms = ms;
  }
  run.calibrate_ms = CommandMs(
      "'" + program + "' calibrate --images '" + folder + "' --board '" +
      board_file + "' --model kannala-brandt-noncentral --threads 2 --out '" +
      (dir / "camera.yaml").string() + "' --quiet >/dev/null 2>&1");
  std::filesystem::remove_all(dir);
  return run;
}

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) {
  using namespace puzzlecal;
  const std::string folder =
      argc > 1 ? argv[1] : testing_data::DeltilleFolder();
  const int sb_photos = argc > 2 ? std::max(1, std::atoi(argv[2])) : 4;
  Board board;
  board.type = BoardType::kCheckerboard;
  board.cols = argc > 4 ? std::atoi(argv[3]) : 11;
  board.rows = argc > 4 ? std::atoi(argv[4]) : 8;
  board.tile_size_m = 0.02;
  ImageListing listing;
  std::string error;
  if (folder.empty() || !ListImages(folder, &listing, &error)) {
    std::printf("{\"skipped\": \"no photo folder (%s)\"}\n",
                folder.empty() ? "deltille photos not found" : error.c_str());
    return 0;
  }
  cv::setNumThreads(1);
  PipelineOptions options;
  CornerDetector detector(options.detector);
  ImageLoader loader(options.load);
  std::vector<PhotoTimes> photos;
  std::vector<double> sb_ms;
  int sb_found = 0;
  for (size_t i = 0; i < listing.images.size(); ++i) {
    cv::Mat grey;
    photos.push_back(MeasurePhoto(listing.images[i], board, options, &detector,
                                  &loader, &grey));
    const size_t step = std::max<size_t>(1, listing.images.size() / sb_photos);
    if (!grey.empty() && i % step == 0 &&
        static_cast<int>(sb_ms.size()) < sb_photos) {
      std::vector<cv::Point2f> sb_corners;
      const double t = ThreadMs();
      sb_found += cv::findChessboardCornersSB(
          grey, cv::Size(board.cols, board.rows), sb_corners, 0);
      sb_ms.push_back(ThreadMs() - t);
    }
  }
  auto median_of = [&](double PhotoTimes::*field) {
    std::vector<double> v;
    for (const PhotoTimes& p : photos) {
      if (p.*field >= 0) v.push_back(p.*field);
    }
    return Median(v);
  };
  std::vector<double> to_ids, image_to_ids, ids, corners;
  for (const PhotoTimes& p : photos) {
    to_ids.push_back(p.load + p.detect + p.grid_decode);
    image_to_ids.push_back(p.detect + p.grid_decode);
    ids.push_back(p.ids);
    corners.push_back(p.corners);
  }
  const double sb = Median(sb_ms);
  const double photo_to_ids = Median(to_ids);
  const FolderRun one = RunFolder(listing.images, board, options, 1);
  std::vector<ImageResult> results;
  const FolderRun two = RunFolder(listing.images, board, options, 2, &results);
  int width = 0, height = 0;
  const std::vector<CalibrationView> views =
      MakeCalibrationViews(board, &results, &width, &height);
  const CameraModelId models[] = {CameraModelId::kKannalaBrandt,
                                  CameraModelId::kKannalaBrandtNoncentral};
  CalibrationRun calibration[2];
  for (int m = 0; m < 2; ++m) {
    calibration[m] = RunCalibration(views, models[m], width, height, 2);
  }
  std::printf("{\n  \"folder_photos\": %zu,\n", listing.images.size());
  std::printf("  \"median_corners\": %.0f, \"median_ids\": %.0f,\n",
              Median(corners), Median(ids));
  std::printf(
      "  \"one_thread_cpu_ms_median\": {\"read_file\": %.2f, "
      "\"zlib_inflate\": %.2f, \"decode_opencv\": %.2f, \"load\": %.2f, "
      "\"detect\": %.2f, \"grid_decode\": %.2f, \"image_to_ids\": %.2f, "
      "\"photo_to_ids\": %.2f},\n",
      median_of(&PhotoTimes::read_file), median_of(&PhotoTimes::zlib_inflate),
      median_of(&PhotoTimes::decode_opencv), median_of(&PhotoTimes::load),
      median_of(&PhotoTimes::detect), median_of(&PhotoTimes::grid_decode),
      Median(image_to_ids), photo_to_ids);
  std::printf(
      "  \"find_chessboard_corners_sb\": {\"photos\": %zu, \"found\": %d, "
      "\"cpu_ms_median\": %.1f},\n",
      sb_ms.size(), sb_found, sb);
  // On two free cores, two threads take at least half their CPU time.
  std::printf(
      "  \"folder_ms_per_photo\": {\"threads_1_wall\": %.2f, "
      "\"threads_1_cpu\": %.2f, \"threads_2_wall\": %.2f, "
      "\"threads_2_cpu\": %.2f, \"threads_2_cpu_over_2\": %.2f, "
      "\"usable\": [%d, %d]},\n",
      one.wall_ms, one.cpu_ms, two.wall_ms, two.cpu_ms, two.cpu_ms / 2,
      one.usable, two.usable);
  std::printf("  \"calibration_threads_2\": [\n");
  std::vector<double> whole_ms(2);
  for (int m = 0; m < 2; ++m) {
    const CalibrationRun& c = calibration[m];
    whole_ms[m] = two.wall_ms +
                  1e3 * (c.calibrate_s + c.evidence_s) / listing.images.size();
    std::printf(
        "    {\"model\": \"%s\", \"ok\": %s, \"views\": %zu, "
        "\"calibrate_s\": %.3f, \"initialization_s\": %.3f, "
        "\"covariance_s\": %.3f, \"iterations\": %d, \"rms_px\": %.4f, "
        "\"evidence_s\": %.3f, \"whole_calibrate_ms_per_photo\": %.2f, "
        "\"whole_calibrate_speedup_over_sb\": %.1f}%s\n",
        CameraModelName(models[m]), c.ok ? "true" : "false", views.size(),
        c.calibrate_s, c.initialization_s, c.covariance_s, c.iterations,
        c.rms_px, c.evidence_s, whole_ms[m],
        sb / whole_ms[m], m == 0 ? "," : "");
  }
  std::printf("  ],\n");
  const ProgramRun program = RunProgram(folder, board);
  const double program_ms_per_photo =
      program.calibrate_ms / listing.images.size();
  std::printf(
      "  \"program\": {\"found\": %s, \"start_ms\": %.1f, "
      "\"calibrate_noncentral_threads_2_ms\": %.0f, "
      "\"calibrate_ms_per_photo\": %.2f, \"calibrate_speedup_over_sb\": "
      "%.1f},\n",
      program.calibrate_ms >= 0 ? "true" : "false", program.start_ms,
      program.calibrate_ms, program_ms_per_photo,
      program.calibrate_ms > 0 ? sb / program_ms_per_photo : 0.0);
  std::printf(
      "  \"speedup_over_sb\": {\"photo_to_ids_one_thread\": %.1f, "
      "\"image_to_ids_one_thread\": %.1f, "
      "\"detect_only\": %.1f, \"folder_threads_1_wall\": %.1f, "
      "\"folder_threads_2_wall\": %.1f, \"folder_threads_2_cpu_over_2\": "
      "%.1f}\n}\n",
      sb / photo_to_ids, sb / Median(image_to_ids),
      sb / median_of(&PhotoTimes::detect), sb / one.wall_ms,
      sb / two.wall_ms, sb / (two.cpu_ms / 2));
  return 0;
}
