#ifndef PUZZLECAL_FORMATS_IMAGE_IO_H_
#define PUZZLECAL_FORMATS_IMAGE_IO_H_

// Finding and loading the photos of a calibration run.

#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace puzzlecal {

// True for the file names ListImages lists as images (png, jpg/jpeg,
// tif/tiff, bmp; any case).
bool HasImageExtension(const std::filesystem::path& path);

// True for the file names of photo formats ListImages does not read:
// HEIC/HEIF (and AVIF, WebP, JPEG XL) and camera RAW (cr2, cr3, nef, arw,
// dng, raf, orf, rw2, ...; any case).
bool HasUnreadPhotoExtension(const std::filesystem::path& path);

// What ListImages found.
struct ImageListing {
  std::vector<std::string> images;   // image files, sorted by name
  std::vector<std::string> videos;   // ListImagesAndVideos: video files
  std::vector<std::string> skipped;  // other entries, with the reason
  // The skipped files in photo formats that are not read
  // (HasUnreadPhotoExtension), sorted by name.
  std::vector<std::string> unread_photos;
  // One line for the user when photos in such formats were skipped beside
  // images that are read: how many of which format, and to convert them
  // ("DIR: skipped 3 HEIC files (...): convert them to JPEG or PNG to use
  // them"); "" when none.
  std::string note;
};

// Lists the image files (png, jpg/jpeg, tif/tiff, bmp; any case) of a folder,
// sorted by file name, or the one file `path` names; sub-folders are not
// searched. False with a message naming `path` when it does not exist, is
// not readable, or holds no image; for a folder without images the message
// also names its sub-folders that hold images (a folder of camera folders
// is calibrate-rig's) and counts the photos in formats that are not read,
// by format, with the advice to convert them.
bool ListImages(const std::string& path, ImageListing* listing,
                std::string* error);

// ListImages for the commands that read videos too: video files (by name:
// formats/video_io.h HasVideoExtension) go to `listing->videos`, sorted by
// name; `path` may name one video. False when the folder holds neither.
bool ListImagesAndVideos(const std::string& path, ImageListing* listing,
                         std::string* error);

// Limits applied while loading.
struct ImageLoadOptions {
  // Images with more pixels than this are refused: PNG, JPEG and BMP before
  // decoding (their headers give the size; decoding alone would need too
  // much memory), other formats after. 0 disables the check.
  long long max_pixels = 120'000'000;

  bool Check(std::string* why = nullptr) const;
};

// Loads one image as 8-bit grey (colour and alpha are converted, 16-bit is
// scaled to 8 bits by its own maximum so dark 16-bit photos keep their
// contrast; colour JPEGs give their luma channel). Pixels stay in the
// sensor's frame: an EXIF orientation tag is not applied. False with a message
// naming the file and the reason (missing, unreadable, not an image, truncated,
// too large, empty).
bool LoadGreyImage(const std::string& path, const ImageLoadOptions& options,
                   cv::Mat* grey, std::string* error);

// The one conversion of an image to the 8-bit grey the detector reads:
// BGR / BGRA (OpenCV's channel order) to luma, 16-bit, float or other
// depths scaled by the image's own maximum. False (with a reason) for other
// channel counts.
bool GreyFromImage(const cv::Mat& image, cv::Mat* grey, std::string* why);

// LoadGreyImage for many files: keeps its buffers (the file's bytes, the
// compressed and the inflated data of 8-bit grey PNGs, the inflater) from
// one file to the next, so a folder of same-size photos costs no allocation
// and no page fault after the first (fresh buffers were 3 ms of a 1600x1200
// PNG's 8 ms). A grey image it returned is never overwritten: while the
// caller still holds it, the next Load decodes into a new buffer. One
// loader serves one thread at a time.
class ImageLoader {
 public:
  explicit ImageLoader(const ImageLoadOptions& options = {});
  ~ImageLoader();
  ImageLoader(ImageLoader&&) noexcept;
  ImageLoader& operator=(ImageLoader&&) noexcept;
  ImageLoader(const ImageLoader&) = delete;
  ImageLoader& operator=(const ImageLoader&) = delete;

  // As LoadGreyImage with this loader's options.
  bool Load(const std::string& path, cv::Mat* grey, std::string* error);
  // The image as stored: its channels (BGR order) and depth kept, no EXIF
  // orientation applied; the same checks and messages as Load.
  bool LoadUnchanged(const std::string& path, cv::Mat* image,
                     std::string* error);

  struct Buffers;  // defined in image_io.cc

 private:
  // The file's pixels: 8-bit grey PNGs decoded here, every other image by
  // OpenCV (JPEGs straight to grey when `grey_jpeg`); sizes checked.
  bool Decode(const std::string& path, bool grey_jpeg, cv::Mat* decoded,
              std::string* error);

  ImageLoadOptions options_;
  std::unique_ptr<Buffers> buffers_;
};

// Fails early when an output file cannot be written, before any work is
// done: false with a message naming `path` when its folder does not exist or
// is not writable, or when `path` is a folder.
bool CheckOutputPath(const std::string& path, std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_IMAGE_IO_H_
