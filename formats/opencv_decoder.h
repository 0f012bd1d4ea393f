#ifndef PUZZLECAL_FORMATS_OPENCV_DECODER_H_
#define PUZZLECAL_FORMATS_OPENCV_DECODER_H_

// cv::imdecode, loaded on first use. Debian's libopencv_imgcodecs brings
// about 140 shared libraries whose loading took 90-100 ms of every start of
// the program; the photos of a calibration are usually 8-bit grey PNGs,
// which image_io decodes itself, so OpenCV's decoders are loaded only when
// an image needs them (JPEG, TIFF, BMP, colour or 16-bit PNG).

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace puzzlecal {

// cv::imdecode(bytes, flags) from the libopencv_imgcodecs this program was
// built against. False with the reason when that library cannot be loaded;
// otherwise true with what cv::imdecode returned (empty for data it cannot
// decode). cv::Exception from the decoder propagates, as from cv::imdecode.
// Thread-safe.
bool DecodeWithOpenCv(const std::vector<unsigned char>& bytes, int flags,
                      cv::Mat* image, std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_OPENCV_DECODER_H_
