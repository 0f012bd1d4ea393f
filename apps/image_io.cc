#include "apps/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <system_error>

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool HasImageExtension(const fs::path& path) {
  const std::string ext = Lower(path.extension().string());
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" ||
         ext == ".tiff" || ext == ".bmp";
}

bool EndsWith(const std::vector<unsigned char>& bytes,
              const std::vector<unsigned char>& tail, size_t slack) {
  if (bytes.size() < tail.size()) return false;
  // Allow a few bytes of padding after the end marker.
  const size_t last_start = bytes.size() - tail.size();
  const size_t first_start = last_start > slack ? last_start - slack : 0;
  for (size_t start = last_start + 1; start-- > first_start;) {
    if (std::equal(tail.begin(), tail.end(), bytes.begin() + start)) {
      return true;
    }
  }
  return false;
}

// Decoders of truncated PNG/JPEG files often return a partly grey image with
// only a warning; the end markers tell a complete file.
std::string TruncationReason(const std::vector<unsigned char>& bytes) {
  static const std::vector<unsigned char> kPngMagic = {0x89, 'P', 'N', 'G'};
  static const std::vector<unsigned char> kPngEnd = {'I', 'E', 'N', 'D'};
  static const std::vector<unsigned char> kJpegMagic = {0xFF, 0xD8};
  static const std::vector<unsigned char> kJpegEnd = {0xFF, 0xD9};
  if (bytes.size() >= 4 &&
      std::equal(kPngMagic.begin(), kPngMagic.end(), bytes.begin())) {
    if (!EndsWith(bytes, kPngEnd, 64)) return "truncated PNG (no IEND chunk)";
  } else if (bytes.size() >= 2 &&
             std::equal(kJpegMagic.begin(), kJpegMagic.end(), bytes.begin())) {
    if (!EndsWith(bytes, kJpegEnd, 64)) {
      return "truncated JPEG (no end-of-image marker)";
    }
  }
  return "";
}

}  // namespace

bool ListImages(const std::string& path, ImageListing* listing,
                std::string* error) {
  *listing = ImageListing();
  std::error_code ec;
  const fs::path root(path);
  if (path.empty()) {
    *error = "no image folder given (--images)";
    return false;
  }
  const fs::file_status status = fs::status(root, ec);
  if (ec || !fs::exists(status)) {
    *error = path + ": no such file or folder";
    return false;
  }
  if (fs::is_regular_file(status)) {
    listing->images.push_back(path);
    return true;
  }
  if (!fs::is_directory(status)) {
    *error = path + ": neither a file nor a folder";
    return false;
  }
  fs::directory_iterator it(root, ec);
  if (ec) {
    *error = path + ": cannot read the folder (" + ec.message() + ")";
    return false;
  }
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    if (ec) {
      *error = path + ": cannot read the folder (" + ec.message() + ")";
      return false;
    }
    const fs::path entry = it->path();
    std::error_code entry_ec;
    if (!it->is_regular_file(entry_ec)) continue;
    if (HasImageExtension(entry)) {
      listing->images.push_back(entry.string());
    } else {
      listing->skipped.push_back(entry.string() +
                                 ": not an image file name (png, jpg, jpeg, "
                                 "tif, tiff, bmp)");
    }
  }
  std::sort(listing->images.begin(), listing->images.end());
  std::sort(listing->skipped.begin(), listing->skipped.end());
  if (listing->images.empty()) {
    *error = path +
             ": the folder holds no image files (png, jpg, jpeg, tif, "
             "tiff, bmp)";
    return false;
  }
  return true;
}

bool ImageLoadOptions::Check(std::string* why) const {
  if (max_pixels < 0) {
    if (why != nullptr) *why = "max_pixels must be >= 0";
    return false;
  }
  return true;
}

bool LoadGreyImage(const std::string& path, const ImageLoadOptions& options,
                   cv::Mat* grey, std::string* error) {
  *grey = cv::Mat();
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    *error = path + ": cannot open the file (missing or no read permission)";
    return false;
  }
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)),
                                   std::istreambuf_iterator<char>());
  if (bytes.empty()) {
    *error = path + ": empty file (0 bytes)";
    return false;
  }
  const std::string truncated = TruncationReason(bytes);
  if (!truncated.empty()) {
    *error = path + ": " + truncated;
    return false;
  }
  cv::Mat decoded;
  try {
    decoded = cv::imdecode(bytes, cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH);
  } catch (const cv::Exception& e) {
    *error = path + ": cannot decode the image (" + e.what() + ")";
    return false;
  }
  bytes.clear();
  bytes.shrink_to_fit();
  if (decoded.empty()) {
    *error = path + ": not a readable image (unknown format or corrupt data)";
    return false;
  }
  if (options.max_pixels > 0 &&
      static_cast<long long>(decoded.total()) > options.max_pixels) {
    *error = path + ": image of " + std::to_string(decoded.cols) + "x" +
             std::to_string(decoded.rows) + " pixels exceeds the limit of " +
             std::to_string(options.max_pixels) + " pixels";
    return false;
  }
  cv::Mat single;
  switch (decoded.channels()) {
    case 1:
      single = decoded;
      break;
    case 3:
      cv::cvtColor(decoded, single, cv::COLOR_BGR2GRAY);
      break;
    case 4:
      cv::cvtColor(decoded, single, cv::COLOR_BGRA2GRAY);
      break;
    default:
      *error = path + ": unsupported number of channels (" +
               std::to_string(decoded.channels()) + ")";
      return false;
  }
  if (single.depth() == CV_8U) {
    *grey = single;
    return true;
  }
  // 16-bit, float or other depths: scale by the image's own maximum.
  double min_value = 0, max_value = 0;
  cv::minMaxLoc(single, &min_value, &max_value);
  if (!(max_value > 0) || !std::isfinite(max_value)) {
    single.convertTo(*grey, CV_8U, 0.0);
    return true;
  }
  single.convertTo(*grey, CV_8U, 255.0 / max_value);
  return true;
}

bool CheckOutputPath(const std::string& path, std::string* error) {
  const fs::path out(path);
  fs::path folder = out.parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    *error =
        path + ": the output folder " + folder.string() + " does not exist";
    return false;
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    *error =
        path + ": the output folder " + folder.string() + " is not writable";
    return false;
  }
  if (fs::is_directory(out, ec)) {
    *error = path + ": is a folder, expected a file name";
    return false;
  }
  return true;
}

}  // namespace puzzlecal
