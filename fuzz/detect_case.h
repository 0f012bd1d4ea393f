#ifndef PUZZLECAL_FUZZ_DETECT_CASE_H_
#define PUZZLECAL_FUZZ_DETECT_CASE_H_

// Fuzz case (a): arbitrary bytes -> a small image -> DetectCorners.
//
// Byte 0 selects how the image is made:
//  - even: the remaining bytes are an encoded file for cv::imdecode (PNG,
//    JPEG, BMP, TIFF, ... whatever OpenCV reads), decoded unchanged (8/16-bit,
//    1/3/4 channels, float);
//  - odd: a raw buffer: width and height (1..kMaxSide), pixel type (8-bit,
//    16-bit, float with any bit pattern incl. NaN/inf, 8-bit 3- or
//    4-channel), then the pixels (zeros when the input runs out).
// Byte 1 varies the detector options (levels, sub-pixel method, filters).
// Images above kMaxPixels are skipped: the target is the detector on small
// images, and huge headers would only measure the decoder's allocation.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "detection/corner.h"
#include "detection/detector.h"
#include "fuzz/byte_reader.h"

namespace puzzlecal {
namespace fuzz {

constexpr int kDetectMaxSide = 256;
constexpr long long kDetectMaxPixels = 1 << 20;

inline DetectorOptions DetectOptionsFromByte(uint8_t selector) {
  DetectorOptions options;
  options.num_levels = 1 + (selector & 3);               // 1..4
  options.first_level = (selector >> 2) & 1;             // 0 or 1
  switch ((selector >> 3) & 3) {
    case 0: options.subpixel = SubpixelMethod::kGradientOrthogonality; break;
    case 1: options.subpixel = SubpixelMethod::kCentroid; break;
    default: options.subpixel = SubpixelMethod::kNone; break;
  }
  options.use_corner_mask = ((selector >> 5) & 1) == 0;
  options.use_ring_test = ((selector >> 6) & 1) == 0;
  options.normalize_by_max = ((selector >> 7) & 1) == 0;
  if (options.first_level >= options.num_levels) options.first_level = 0;
  return options;
}

// Builds the image the bytes describe; empty when the bytes decode to none.
inline cv::Mat DetectImageFromBytes(ByteReader* reader, uint8_t mode) {
  if ((mode & 1) == 0) {
    std::vector<uint8_t> encoded(reader->current(),
                                 reader->current() + reader->remaining());
    reader->SkipToEnd();
    if (encoded.empty()) return cv::Mat();
    try {
      return cv::imdecode(encoded, cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH);
    } catch (const cv::Exception&) {
      return cv::Mat();  // the decoder refused the bytes: not our code
    }
  }
  const int width = reader->IntInRange(1, kDetectMaxSide);
  const int height = reader->IntInRange(1, kDetectMaxSide);
  static const int kTypes[] = {CV_8UC1, CV_16UC1, CV_32FC1, CV_8UC3, CV_8UC4};
  const int type = kTypes[reader->Byte() % 5];
  cv::Mat image(height, width, type);
  const size_t row_bytes = static_cast<size_t>(width) * image.elemSize();
  for (int y = 0; y < height; ++y) reader->Bytes(image.ptr<uint8_t>(y), row_bytes);
  return image;
}

// Runs one fuzz case. Returns "" or the broken promise of DetectCorners
// (the fuzz target traps on it; the regression tests expect "").
inline std::string RunDetectCase(const uint8_t* data, size_t size) {
  ByteReader reader(data, size);
  const uint8_t mode = reader.Byte();
  const DetectorOptions options = DetectOptionsFromByte(reader.Byte());
  const cv::Mat image = DetectImageFromBytes(&reader, mode);
  if (static_cast<long long>(image.total()) > kDetectMaxPixels) return "";
  DetectorSummary summary;
  const std::vector<Corner> corners = DetectCorners(image, options, &summary);
  // Contract checks: the summary counts what is returned, and corners lie in
  // the image with finite values.
  if (static_cast<size_t>(summary.corners) != corners.size()) {
    return "summary.corners differs from the number of corners returned";
  }
  for (const Corner& c : corners) {
    if (!(c.xy.x() >= -0.5 && c.xy.x() <= image.cols - 0.5 &&
          c.xy.y() >= -0.5 && c.xy.y() <= image.rows - 0.5)) {
      return "a corner lies outside the image";
    }
    if (!std::isfinite(c.response) || !std::isfinite(c.orientation)) {
      return "a corner has a non-finite response or orientation";
    }
  }
  return "";
}

}  // namespace fuzz
}  // namespace puzzlecal

#endif  // PUZZLECAL_FUZZ_DETECT_CASE_H_
