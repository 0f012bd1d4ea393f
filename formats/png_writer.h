#ifndef PUZZLECAL_FORMATS_PNG_WRITER_H_
#define PUZZLECAL_FORMATS_PNG_WRITER_H_

// PNG encoding without OpenCV's image codecs: Debian's libopencv_imgcodecs
// brings about 140 shared libraries (GDAL among them) whose loading and
// relocation took 90-100 ms of every start of the program, more than the
// calibration of the demo's 15 photos. Everything the program writes
// (reports, overlays, renders, undistorted photos) is PNG, so it is encoded
// here with libdeflate; the images read back through OpenCV or any PNG
// reader are the same pixels.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace puzzlecal {

// How EncodePng compresses.
struct PngWriteOptions {
  // libdeflate's compression level: 1 (fastest) .. 12 (smallest). Level 1
  // with per-row filters is smaller than OpenCV's default PNG and faster.
  int compression_level = 1;

  bool Check(std::string* why = nullptr) const;
};

// Encodes `image` as a PNG: CV_8U or CV_16U with 1 (grey), 2 (grey +
// alpha), 3 (BGR) or 4 (BGRA) channels, any stride; colour is stored as
// RGB(A), as OpenCV writes it. Each row gets the PNG filter whose output
// has the smallest sum of absolute values (the usual heuristic). False with
// the reason for an empty image or another type.
bool EncodePng(const cv::Mat& image, const PngWriteOptions& options,
               std::vector<unsigned char>* png, std::string* error);

// EncodePng with the default options, written atomically to `path` (a
// temporary file renamed over it). False with a message naming the path.
bool WritePngFile(const std::string& path, const cv::Mat& image,
                  std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_PNG_WRITER_H_
