#include "formats/opencv_decoder.h"

#include <dlfcn.h>

namespace puzzlecal {

namespace {

// cv::Mat cv::imdecode(cv::InputArray, int), OpenCV 4.
using ImdecodeFunction = cv::Mat (*)(const cv::_InputArray&, int);
constexpr const char* kImdecodeSymbol = "_ZN2cv8imdecodeERKNS_11_InputArrayEi";

struct LoadedDecoder {
  ImdecodeFunction imdecode = nullptr;
  std::string error;  // why it is not there
};

LoadedDecoder Load() {
  LoadedDecoder loaded;
  // Never closed: OpenCV keeps process-wide state in it.
  void* library = dlopen(PUZZLECAL_IMGCODECS_SONAME, RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) {
    const char* why = dlerror();
    loaded.error = std::string("cannot load OpenCV's image decoders (") +
                   PUZZLECAL_IMGCODECS_SONAME +
                   "): " + (why != nullptr ? why : "unknown reason");
    return loaded;
  }
  loaded.imdecode =
      reinterpret_cast<ImdecodeFunction>(dlsym(library, kImdecodeSymbol));
  if (loaded.imdecode == nullptr) {
    loaded.error = std::string(PUZZLECAL_IMGCODECS_SONAME) +
                   " has no cv::imdecode (another OpenCV version?)";
  }
  return loaded;
}

}  // namespace

bool DecodeWithOpenCv(const std::vector<unsigned char>& bytes, int flags,
                      cv::Mat* image, std::string* error) {
  static const LoadedDecoder decoder = Load();
  if (decoder.imdecode == nullptr) {
    if (error != nullptr) *error = decoder.error;
    return false;
  }
  *image = decoder.imdecode(cv::_InputArray(bytes), flags);
  return true;
}

}  // namespace puzzlecal
