#include "formats/video_io.h"

#include <dlfcn.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <new>
#include <opencv2/videoio.hpp>  // the class layouts and CAP_ constants only

#include "formats/image_io.h"
#include "util/failure.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// The library is loaded, never linked: only its two default constructors
// are looked up. Every other member used here is virtual, so it is called
// through the object's vtable, which the constructor set, and the program
// holds no reference to the library's symbols.
using Constructor = void (*)(void*);
constexpr const char* kCaptureConstructor = "_ZN2cv12VideoCaptureC1Ev";
constexpr const char* kWriterConstructor = "_ZN2cv11VideoWriterC1Ev";

struct LoadedVideoio {
  Constructor capture = nullptr;
  Constructor writer = nullptr;
  std::string error;  // why it is not there
};

LoadedVideoio Load() {
  LoadedVideoio loaded;
  // Never closed: OpenCV keeps process-wide state in it.
  void* library = dlopen(PUZZLECAL_VIDEOIO_SONAME, RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) {
    const char* why = dlerror();
    loaded.error = std::string("cannot load OpenCV's video library (") +
                   PUZZLECAL_VIDEOIO_SONAME +
                   "): " + (why != nullptr ? why : "unknown reason");
    return loaded;
  }
  loaded.capture =
      reinterpret_cast<Constructor>(dlsym(library, kCaptureConstructor));
  loaded.writer =
      reinterpret_cast<Constructor>(dlsym(library, kWriterConstructor));
  if (loaded.capture == nullptr || loaded.writer == nullptr) {
    loaded.error = std::string(PUZZLECAL_VIDEOIO_SONAME) +
                   " has no cv::VideoCapture / cv::VideoWriter (another "
                   "OpenCV version?)";
  }
  return loaded;
}

const LoadedVideoio& Videoio() {
  static const LoadedVideoio loaded = Load();
  return loaded;
}

// An object of class T constructed by the library's constructor in storage
// of T's size, destroyed through its virtual destructor.
template <typename T>
class LibraryObject {
 public:
  explicit LibraryObject(Constructor construct) {
    construct(storage_);
    object_ = std::launder(reinterpret_cast<T*>(storage_));
  }
  ~LibraryObject() { object_->~T(); }
  LibraryObject(const LibraryObject&) = delete;
  LibraryObject& operator=(const LibraryObject&) = delete;
  T* operator->() { return object_; }

 private:
  alignas(T) unsigned char storage_[sizeof(T)];
  T* object_ = nullptr;
};

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return text;
}

int FourCc(const char code[4]) {
  return code[0] | (code[1] << 8) | (code[2] << 16) | (code[3] << 24);
}

}  // namespace

bool HasVideoExtension(const std::string& path) {
  static const char* const kExtensions[] = {
      ".mp4", ".m4v", ".mov", ".avi", ".mkv", ".webm", ".mpg", ".mpeg", ".wmv"};
  const std::string ext = Lower(fs::path(path).extension().string());
  return std::any_of(std::begin(kExtensions), std::end(kExtensions),
                     [&](const char* known) { return ext == known; });
}

// ---- reading ----

struct VideoReader::Capture : LibraryObject<cv::VideoCapture> {
  using LibraryObject::LibraryObject;
};

VideoReader::VideoReader() = default;
VideoReader::~VideoReader() = default;

bool VideoReader::Open(const std::string& path, std::string* error) {
  capture_.reset();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    return Fail(path + ": no such file", error);
  }
  const LoadedVideoio& videoio = Videoio();
  if (videoio.capture == nullptr) return Fail(path + ": " + videoio.error, error);
  auto capture = std::make_unique<Capture>(videoio.capture);
  bool opened = false;
  try {
    opened = (*capture)->open(path, cv::CAP_FFMPEG) && (*capture)->isOpened();
  } catch (const cv::Exception& e) {
    return Fail(path + ": not a readable video (" + e.what() + ")", error);
  }
  if (!opened) {
    return Fail(path +
                    ": not a readable video (no stream FFmpeg can decode: "
                    "damaged, empty or not a video)",
                error);
  }
  fps_ = (*capture)->get(cv::CAP_PROP_FPS);
  frame_count_ =
      std::max(0LL, static_cast<long long>((*capture)->get(
                        cv::CAP_PROP_FRAME_COUNT)));
  width_ = static_cast<int>((*capture)->get(cv::CAP_PROP_FRAME_WIDTH));
  height_ = static_cast<int>((*capture)->get(cv::CAP_PROP_FRAME_HEIGHT));
  capture_ = std::move(capture);
  return true;
}

bool VideoReader::Read(cv::Mat* grey, double* time_ms) {
  if (capture_ == nullptr) return false;
  try {
    if (!(*capture_)->read(decoded_) || decoded_.empty()) return false;
    *time_ms = (*capture_)->get(cv::CAP_PROP_POS_MSEC);
  } catch (const cv::Exception&) {
    return false;  // a damaged stream ends here
  }
  std::string why;
  return GreyFromImage(decoded_, grey, &why);
}

// ---- writing ----

bool VideoWriteOptions::Check(std::string* why) const {
  if (!(fps > 0)) return Fail("fps must be > 0", why);
  if (!(quality >= 1 && quality <= 100)) {
    return Fail("quality must be in [1, 100]", why);
  }
  return true;
}

struct VideoWriter::Writer : LibraryObject<cv::VideoWriter> {
  using LibraryObject::LibraryObject;
};

VideoWriter::VideoWriter() = default;
VideoWriter::~VideoWriter() { Close(); }

bool VideoWriter::Open(const std::string& path, const cv::Size& size,
                       const VideoWriteOptions& options, std::string* error) {
  Close();
  std::string why;
  if (!options.Check(&why)) return Fail(path + ": " + why, error);
  const std::string ext = Lower(fs::path(path).extension().string());
  const char* codec = nullptr;
  if (ext == ".avi" || ext == ".mkv") codec = "MJPG";
  if (ext == ".mp4" || ext == ".mov") codec = "mp4v";
  if (codec == nullptr) {
    return Fail(path + ": write videos as .avi, .mkv, .mp4 or .mov", error);
  }
  const LoadedVideoio& videoio = Videoio();
  if (videoio.writer == nullptr) return Fail(path + ": " + videoio.error, error);
  auto writer = std::make_unique<Writer>(videoio.writer);
  bool opened = false;
  try {
    opened = (*writer)->open(path, FourCc(codec), options.fps, size,
                             /*isColor=*/false) &&
             (*writer)->isOpened();
    if (opened) (*writer)->set(cv::VIDEOWRITER_PROP_QUALITY, options.quality);
  } catch (const cv::Exception& e) {
    return Fail(path + ": cannot write the video (" + e.what() + ")", error);
  }
  if (!opened) {
    return Fail(path + ": cannot write the video (folder missing or "
                       "read-only, or no " +
                    std::string(codec) + " encoder)",
                error);
  }
  writer_ = std::move(writer);
  size_ = size;
  path_ = path;
  return true;
}

bool VideoWriter::Write(const cv::Mat& grey, std::string* error) {
  if (writer_ == nullptr) return Fail("no video open for writing", error);
  if (grey.type() != CV_8UC1 || grey.size() != size_) {
    return Fail(path_ + ": a frame must be 8-bit grey of the video's size",
                error);
  }
  try {
    (*writer_)->write(grey);
  } catch (const cv::Exception& e) {
    return Fail(path_ + ": writing a frame failed (" + e.what() + ")", error);
  }
  return true;
}

void VideoWriter::Close() {
  if (writer_ != nullptr) (*writer_)->release();
  writer_.reset();
}

}  // namespace puzzlecal
