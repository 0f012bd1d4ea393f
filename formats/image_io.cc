#include "formats/image_io.h"

#include <libdeflate.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>  // the IMREAD_ flags
#include <opencv2/imgproc.hpp>
#include <string>
#include <system_error>
#include <vector>

#include "formats/opencv_decoder.h"
#include "formats/png_filters.h"
#include "formats/video_io.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return s;
}

// What the file header tells before decoding: the image size (0 when the
// format is not parsed here) and, for PNG and JPEG, whether the file is
// complete. Decoders of truncated PNG/JPEG files often return a partly grey
// image with only a warning, so completeness is checked on the structure.
struct HeaderInfo {
  long long width = 0;
  long long height = 0;
  std::string truncation;  // empty when complete (or not checked)
  bool png = false;        // the PNG signature
  bool jpeg = false;       // the JPEG start-of-image marker
};

unsigned BigEndian(const std::vector<unsigned char>& b, size_t at, int n) {
  unsigned value = 0;
  for (int k = 0; k < n; ++k) value = (value << 8) | b[at + k];
  return value;
}

// PNG: walks the chunks (length, type, data, CRC) up to IEND; data after
// IEND is ignored. The size comes from IHDR.
void InspectPng(const std::vector<unsigned char>& b, HeaderInfo* info) {
  if (b.size() >= 24) {
    info->width = BigEndian(b, 16, 4);
    info->height = BigEndian(b, 20, 4);
  }
  size_t pos = 8;
  while (pos + 8 <= b.size()) {
    const size_t length = BigEndian(b, pos, 4);
    static const char kIend[] = "IEND";
    const bool iend =
        std::equal(b.begin() + pos + 4, b.begin() + pos + 8, kIend);
    if (iend) return;
    if (length > b.size()) break;  // also guards the sum below
    pos += 12 + length;
  }
  info->truncation = "truncated PNG (the chunks end before IEND)";
}

// JPEG: walks the marker segments up to the first start-of-scan (skipping
// APPn payloads, so an EXIF thumbnail's own markers do not count), reads the
// size from the start-of-frame segment, then needs an end-of-image marker
// somewhere after the scan starts (entropy-coded data never contains FF D9;
// data after it, as phones append, is ignored).
void InspectJpeg(const std::vector<unsigned char>& b, HeaderInfo* info) {
  size_t pos = 2;
  size_t scan = 0;
  while (pos + 4 <= b.size()) {
    if (b[pos] != 0xFF) break;  // not a marker: leave it to the decoder
    const unsigned char marker = b[pos + 1];
    if (marker == 0xFF) {  // fill byte
      ++pos;
      continue;
    }
    if (marker == 0xDA) {
      scan = pos;
      break;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD9)) {
      pos += 2;  // markers without a payload
      continue;
    }
    const size_t length = BigEndian(b, pos + 2, 2);
    const bool start_of_frame = marker >= 0xC0 && marker <= 0xCF &&
                                marker != 0xC4 && marker != 0xC8 &&
                                marker != 0xCC;
    if (start_of_frame && pos + 9 <= b.size()) {
      info->height = BigEndian(b, pos + 5, 2);
      info->width = BigEndian(b, pos + 7, 2);
    }
    pos += 2 + length;
  }
  if (scan == 0) {
    if (pos + 4 > b.size()) {
      info->truncation = "truncated JPEG (the file ends before the image data)";
    }
    return;
  }
  for (size_t k = scan + 2; k + 1 < b.size(); ++k) {
    if (b[k] == 0xFF && b[k + 1] == 0xD9) return;
  }
  info->truncation = "truncated JPEG (no end-of-image marker)";
}

// BMP: size from the DIB header (height may be negative: top-down rows).
void InspectBmp(const std::vector<unsigned char>& b, HeaderInfo* info) {
  if (b.size() < 26) return;
  auto little = [&](size_t at) {
    return static_cast<int32_t>(b[at] | (b[at + 1] << 8) | (b[at + 2] << 16) |
                                (static_cast<uint32_t>(b[at + 3]) << 24));
  };
  info->width = std::llabs(static_cast<long long>(little(18)));
  info->height = std::llabs(static_cast<long long>(little(22)));
}

HeaderInfo InspectHeader(const std::vector<unsigned char>& b) {
  HeaderInfo info;
  static const unsigned char kPngMagic[] = {0x89, 'P',  'N',  'G',
                                            0x0D, 0x0A, 0x1A, 0x0A};
  if (b.size() >= 8 && std::equal(kPngMagic, kPngMagic + 8, b.begin())) {
    info.png = true;
    InspectPng(b, &info);
  } else if (b.size() >= 2 && b[0] == 0xFF && b[1] == 0xD8) {
    info.jpeg = true;
    InspectJpeg(b, &info);
  } else if (b.size() >= 2 && b[0] == 'B' && b[1] == 'M') {
    InspectBmp(b, &info);
  }
  return info;
}

// Undoes, in place, the PNG filter of one row of `width` one-byte pixels
// (`row`: the filtered bytes after the filter-type byte), `prior` the row
// above (zeros for the first). False for an unknown filter type.
bool UnfilterRow(int filter, unsigned char* row, const unsigned char* prior,
                 int width) {
  switch (filter) {
    case 0:  // None
      return true;
    case 1:  // Sub
      for (int i = 1; i < width; ++i) row[i] += row[i - 1];
      return true;
    case 2:  // Up
      for (int i = 0; i < width; ++i) row[i] += prior[i];
      return true;
    case 3:  // Average
      row[0] += prior[0] >> 1;
      for (int i = 1; i < width; ++i) row[i] += (row[i - 1] + prior[i]) >> 1;
      return true;
    case 4:  // Paeth
      for (int i = 0; i < width; ++i) {
        row[i] += PaethPredictor(i > 0 ? row[i - 1] : 0, prior[i],
                                 i > 0 ? prior[i - 1] : 0);
      }
      return true;
    default:
      return false;
  }
}

// The IDAT data of an 8-bit grey, non-interlaced PNG without transparency
// (what calibration cameras write), CRCs checked; false for any other PNG
// or any irregularity.
bool GreyPngData(const std::vector<unsigned char>& b, int* width, int* height,
                 std::vector<unsigned char>* idat) {
  if (b.size() < 33 || BigEndian(b, 8, 4) != 13 ||
      !std::equal(b.begin() + 12, b.begin() + 16, "IHDR")) {
    return false;
  }
  const unsigned w = BigEndian(b, 16, 4), h = BigEndian(b, 20, 4);
  // Depth 8, colour type 0 (grey), compression, filter and interlace 0.
  if (w == 0 || h == 0 || w > (1u << 24) || h > (1u << 24) || b[24] != 8 ||
      b[25] != 0 || b[26] != 0 || b[27] != 0 || b[28] != 0) {
    return false;
  }
  idat->clear();
  idat->reserve(b.size());  // the IDAT chunks are part of the file
  for (size_t pos = 8; pos + 12 <= b.size();) {
    const size_t length = BigEndian(b, pos, 4);
    if (length > b.size() - pos - 12) return false;
    const unsigned char* type = b.data() + pos + 4;
    if (std::equal(type, type + 4, "IEND")) {
      *width = static_cast<int>(w);
      *height = static_cast<int>(h);
      return !idat->empty();
    }
    if (std::equal(type, type + 4, "tRNS")) return false;
    const bool is_idat = std::equal(type, type + 4, "IDAT");
    if (is_idat || std::equal(type, type + 4, "IHDR")) {
      if (libdeflate_crc32(0, type, length + 4) !=
          BigEndian(b, pos + 8 + length, 4)) {
        return false;
      }
    }
    if (is_idat) idat->insert(idat->end(), type + 4, type + 4 + length);
    pos += 12 + length;
  }
  return false;
}

}  // namespace

bool HasImageExtension(const std::filesystem::path& path) {
  const std::string ext = Lower(path.extension().string());
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" ||
         ext == ".tiff" || ext == ".bmp";
}

bool HasUnreadPhotoExtension(const std::filesystem::path& path) {
  static const char* const kExtensions[] = {
      // HEIC / HEIF (phones), and the newer compressed formats.
      ".heic", ".heif", ".hif", ".avif", ".webp", ".jxl",
      // Camera RAW.
      ".cr2", ".cr3", ".crw", ".nef", ".nrw", ".arw", ".srf", ".sr2", ".dng",
      ".raf", ".orf", ".rw2", ".rwl", ".pef", ".srw", ".x3f", ".3fr", ".iiq",
      ".erf", ".kdc", ".mrw", ".raw"};
  const std::string ext = Lower(path.extension().string());
  return std::any_of(std::begin(kExtensions), std::end(kExtensions),
                     [&](const char* known) { return ext == known; });
}

// What an ImageLoader keeps between files.
struct ImageLoader::Buffers {
  std::vector<unsigned char> bytes;  // the file
  std::vector<unsigned char> idat;   // a grey PNG's compressed pixels
  std::vector<unsigned char> zeros;  // the row above the first
  // The inflated rows, unfiltered in place into the grey image returned.
  cv::Mat pixels;
  std::unique_ptr<libdeflate_decompressor,
                  decltype(&libdeflate_free_decompressor)>
      inflater{nullptr, libdeflate_free_decompressor};
};

namespace {

// 8-bit grey PNGs inflated by libdeflate, the filters undone here:
// inflating is most of a PNG decoder's time, and libdeflate does it about
// 2.3 times faster than zlib (which libpng, behind cv::imdecode, uses) on
// 1600x1200 photos. The pixels are those of libpng. False for every other
// PNG and for any error, which go to OpenCV (same pixels, same messages).
// Decodes into `buffers->pixels`, or into a new buffer while an earlier
// image still holds that one.
bool DecodeGreyPng(const std::vector<unsigned char>& bytes,
                   ImageLoader::Buffers* buffers, cv::Mat* grey) {
  int width = 0, height = 0;
  std::vector<unsigned char>& idat = buffers->idat;
  if (!GreyPngData(bytes, &width, &height, &idat)) return false;
  const size_t row = static_cast<size_t>(width) + 1;
  const int size = static_cast<int>(row * height);
  cv::Mat& pixels = buffers->pixels;
  const bool shared = pixels.u != nullptr && pixels.u->refcount > 1;
  if (shared || pixels.cols != size) pixels = cv::Mat(1, size, CV_8UC1);
  if (buffers->inflater == nullptr) {
    buffers->inflater.reset(libdeflate_alloc_decompressor());
  }
  if (buffers->inflater == nullptr ||
      libdeflate_zlib_decompress(buffers->inflater.get(), idat.data(),
                                 idat.size(), pixels.data, pixels.total(),
                                 nullptr) != LIBDEFLATE_SUCCESS) {
    return false;
  }
  // In place: each row stays behind its filter-type byte (no 2 MB moved),
  // and the image is the view of the rows without those bytes (a row step
  // of width + 1).
  unsigned char* data = pixels.data;
  buffers->zeros.assign(width, 0);
  for (int y = 0; y < height; ++y) {
    unsigned char* pixel_row = data + y * row + 1;
    const unsigned char* prior =
        y > 0 ? pixel_row - row : buffers->zeros.data();
    if (!UnfilterRow(pixel_row[-1], pixel_row, prior, width)) {
      return false;
    }
  }
  *grey = pixels.reshape(1, height).colRange(1, width + 1);
  return true;
}

// The whole file, in one read.
bool ReadFile(const std::string& path, std::vector<unsigned char>* bytes) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) return false;
  const std::streamoff size = file.tellg();
  if (size < 0) return false;
  bytes->resize(static_cast<size_t>(size));
  file.seekg(0);
  return size == 0 ||
         static_cast<bool>(file.read(reinterpret_cast<char*>(bytes->data()),
                                     static_cast<std::streamsize>(size)));
}

}  // namespace

namespace {

// "12 HEIC files and 1 CR2 file": `files` counted by extension (as
// spelled, in capitals), the extensions in alphabetical order.
std::string CountByExtension(const std::vector<std::string>& files) {
  std::map<std::string, int> count;
  for (const std::string& file : files) {
    std::string ext = fs::path(file).extension().string();
    if (!ext.empty()) ext.erase(0, 1);
    for (char& c : ext) c = static_cast<char>(std::toupper(c));
    ++count[ext];
  }
  std::string text;
  size_t k = 0;
  for (const auto& [ext, n] : count) {
    if (k > 0) text += k + 1 == count.size() ? " and " : ", ";
    text += std::to_string(n) + " " + ext + (n == 1 ? " file" : " files");
    ++k;
  }
  return text;
}

// What `files` (photos in formats not read) are and what to do with them.
std::string UnreadPhotosAdvice(const std::vector<std::string>& files) {
  return CountByExtension(files) +
         " (HEIC/HEIF, RAW and the like are not read): convert them to JPEG "
         "or PNG";
}

// The sub-folders of `root` that hold image files (or videos when
// `with_videos`) themselves, by name, and how many of each they hold.
void SubfoldersWithImages(const fs::path& root, bool with_videos,
                          std::vector<std::string>* names, int* images,
                          int* videos) {
  names->clear();
  *images = 0;
  *videos = 0;
  std::error_code ec;
  for (fs::directory_iterator it(root, ec), end; !ec && it != end;
       it.increment(ec)) {
    std::error_code entry_ec;
    if (!it->is_directory(entry_ec)) continue;
    int found = 0;
    std::error_code sub_ec;
    for (fs::directory_iterator sub(it->path(), sub_ec); !sub_ec && sub != end;
         sub.increment(sub_ec)) {
      std::error_code file_ec;
      if (!sub->is_regular_file(file_ec)) continue;
      if (HasImageExtension(sub->path())) {
        ++*images;
        ++found;
      } else if (with_videos && HasVideoExtension(sub->path().string())) {
        ++*videos;
        ++found;
      }
    }
    if (found > 0) names->push_back(it->path().filename().string());
  }
  std::sort(names->begin(), names->end());
}

// "1 image file", "3 videos".
std::string CountOf(int n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// Why the folder `path` gave nothing to read, beyond "no image files": its
// sub-folders that hold images, the photos in formats it does not read.
std::string NothingToReadDetails(const std::string& path, bool with_videos,
                                 const std::vector<std::string>& unread) {
  std::string details;
  std::vector<std::string> folders;
  int images = 0, videos = 0;
  SubfoldersWithImages(fs::path(path), with_videos, &folders, &images, &videos);
  if (!folders.empty()) {
    std::string list;
    const size_t shown = folders.size() > 4 ? 3 : folders.size();
    for (size_t k = 0; k < shown; ++k) {
      if (k > 0) list += k + 1 == folders.size() ? " and " : ", ";
      list += folders[k];
    }
    if (shown < folders.size()) {
      list += " and " + std::to_string(folders.size() - shown) + " more";
    }
    std::string held;
    if (images > 0) held = CountOf(images, "image file", "image files");
    if (videos > 0) {
      held +=
          (held.empty() ? "" : " and ") + CountOf(videos, "video", "videos");
    }
    details += std::string("; its sub-folder") +
               (folders.size() == 1 ? " " : "s ") + list +
               (folders.size() == 1 ? " holds " : " hold ") + held +
               " (sub-folders are not searched): for a folder with one "
               "sub-folder per camera use calibrate-rig, otherwise point "
               "--images at one of them";
  }
  if (!unread.empty()) {
    details += "; it holds " + UnreadPhotosAdvice(unread);
  }
  return details;
}

// ListImages, with videos listed apart when `with_videos`.
bool ListMedia(const std::string& path, bool with_videos, ImageListing* listing,
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
    const bool video = with_videos && HasVideoExtension(path);
    (video ? listing->videos : listing->images).push_back(path);
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
    } else if (with_videos && HasVideoExtension(entry.string())) {
      listing->videos.push_back(entry.string());
    } else if (HasVideoExtension(entry.string())) {
      listing->skipped.push_back(entry.string() +
                                 ": a video (calibrate and calibrate-rig read "
                                 "videos)");
    } else if (HasUnreadPhotoExtension(entry)) {
      listing->unread_photos.push_back(entry.string());
      listing->skipped.push_back(entry.string() +
                                 ": a photo format not read (png, jpg, jpeg, "
                                 "tif, tiff, bmp are)");
    } else {
      listing->skipped.push_back(entry.string() +
                                 ": not an image file name (png, jpg, jpeg, "
                                 "tif, tiff, bmp)");
    }
  }
  std::sort(listing->images.begin(), listing->images.end());
  std::sort(listing->videos.begin(), listing->videos.end());
  std::sort(listing->skipped.begin(), listing->skipped.end());
  std::sort(listing->unread_photos.begin(), listing->unread_photos.end());
  if (listing->images.empty() && listing->videos.empty()) {
    *error = path +
             (with_videos ? ": the folder holds no image files (png, jpg, "
                            "jpeg, tif, tiff, bmp) and no videos (mp4, avi, "
                            "mkv, mov, ...)"
                          : ": the folder holds no image files (png, jpg, "
                            "jpeg, tif, tiff, bmp)") +
             NothingToReadDetails(path, with_videos, listing->unread_photos);
    return false;
  }
  if (!listing->unread_photos.empty()) {
    listing->note = path + ": skipped " +
                    UnreadPhotosAdvice(listing->unread_photos) + " to use them";
  }
  return true;
}

}  // namespace

bool ListImages(const std::string& path, ImageListing* listing,
                std::string* error) {
  return ListMedia(path, /*with_videos=*/false, listing, error);
}

bool ListImagesAndVideos(const std::string& path, ImageListing* listing,
                         std::string* error) {
  return ListMedia(path, /*with_videos=*/true, listing, error);
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
  return ImageLoader(options).Load(path, grey, error);
}

ImageLoader::ImageLoader(const ImageLoadOptions& options)
    : options_(options), buffers_(std::make_unique<Buffers>()) {}
ImageLoader::~ImageLoader() = default;
ImageLoader::ImageLoader(ImageLoader&&) noexcept = default;
ImageLoader& ImageLoader::operator=(ImageLoader&&) noexcept = default;

bool ImageLoader::Decode(const std::string& path, bool grey_jpeg,
                         cv::Mat* decoded, std::string* error) {
  *decoded = cv::Mat();
  const ImageLoadOptions& options = options_;
  std::vector<unsigned char>& bytes = buffers_->bytes;
  if (!ReadFile(path, &bytes)) {
    *error = path + ": cannot open the file (missing or no read permission)";
    return false;
  }
  if (bytes.empty()) {
    *error = path + ": empty file (0 bytes)";
    return false;
  }
  const HeaderInfo header = InspectHeader(bytes);
  if (!header.truncation.empty()) {
    *error = path + ": " + header.truncation;
    return false;
  }
  // Refused before decoding where the header gives the size: decoding alone
  // would claim the memory the limit is there to protect.
  if (options.max_pixels > 0 && header.width > 0 && header.height > 0 &&
      header.width * header.height > options.max_pixels) {
    *error = path + ": image of " + std::to_string(header.width) + "x" +
             std::to_string(header.height) + " pixels exceeds the limit of " +
             std::to_string(options.max_pixels) + " pixels";
    return false;
  }
  if (header.png && DecodeGreyPng(bytes, buffers_.get(), decoded)) return true;
  try {
    // JPEGs straight to grey: libjpeg-turbo then skips the chroma
    // (upsampling and colour conversion), 2.7 times faster on a 1600x1200
    // colour photo. EXIF orientation is not applied to any format: the
    // calibration needs the sensor's own pixel frame.
    std::string why;
    if (!DecodeWithOpenCv(
            bytes,
            header.jpeg && grey_jpeg
                ? cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION
                : cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH,
            decoded, &why)) {
      *error = path + ": " + why;
      return false;
    }
  } catch (const cv::Exception& e) {
    *error = path + ": cannot decode the image (" + e.what() + ")";
    return false;
  }
  if (decoded->empty()) {
    *error = path + ": not a readable image (unknown format or corrupt data)";
    return false;
  }
  if (options.max_pixels > 0 &&
      static_cast<long long>(decoded->total()) > options.max_pixels) {
    *error = path + ": image of " + std::to_string(decoded->cols) + "x" +
             std::to_string(decoded->rows) + " pixels exceeds the limit of " +
             std::to_string(options.max_pixels) + " pixels";
    *decoded = cv::Mat();
    return false;
  }
  return true;
}

bool ImageLoader::LoadUnchanged(const std::string& path, cv::Mat* image,
                                std::string* error) {
  return Decode(path, /*grey_jpeg=*/false, image, error);
}

bool GreyFromImage(const cv::Mat& image, cv::Mat* grey, std::string* why) {
  cv::Mat single;
  switch (image.channels()) {
    case 1:
      single = image;
      break;
    case 3:
      cv::cvtColor(image, single, cv::COLOR_BGR2GRAY);
      break;
    case 4:
      cv::cvtColor(image, single, cv::COLOR_BGRA2GRAY);
      break;
    default:
      return Fail("unsupported number of channels (" +
                      std::to_string(image.channels()) + ")",
                  why);
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

bool ImageLoader::Load(const std::string& path, cv::Mat* grey,
                       std::string* error) {
  *grey = cv::Mat();
  cv::Mat decoded;
  if (!Decode(path, /*grey_jpeg=*/true, &decoded, error)) return false;
  std::string why;
  if (!GreyFromImage(decoded, grey, &why)) {
    *error = path + ": " + why;
    return false;
  }
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
