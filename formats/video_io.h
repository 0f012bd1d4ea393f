#ifndef PUZZLECAL_FORMATS_VIDEO_IO_H_
#define PUZZLECAL_FORMATS_VIDEO_IO_H_

// Reading and writing video files one frame at a time, through OpenCV's
// videoio (Debian's build decodes with FFmpeg: mp4, avi, mkv, mov, ...).
// libopencv_videoio is loaded on first use, as the image decoders are
// (formats/opencv_decoder.h): linked, it and FFmpeg's libraries would be
// loaded at every start of the program, also by runs that read no video.

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace puzzlecal {

// True for the file names of videos: mp4, m4v, mov, avi, mkv, webm, mpg,
// mpeg, wmv (any case).
bool HasVideoExtension(const std::string& path);

// One video file, decoded frame by frame: only the last frame read is held.
// One reader serves one thread at a time.
class VideoReader {
 public:
  VideoReader();
  ~VideoReader();
  VideoReader(const VideoReader&) = delete;
  VideoReader& operator=(const VideoReader&) = delete;

  // Opens `path`. False with a message naming the file and the reason
  // (missing, not a video, no decodable stream, videoio not loadable).
  bool Open(const std::string& path, std::string* error);

  // The next frame as 8-bit grey (GreyFromImage's conversion) and its time
  // stamp in milliseconds from the stream's start (the container's
  // presentation time). False at the end of the stream or when the next
  // frame cannot be decoded (a damaged file ends there).
  bool Read(cv::Mat* grey, double* time_ms);

  // What the container says (0 when it does not say): frames per second
  // and the number of frames (an estimate for some containers).
  double fps() const { return fps_; }
  long long frame_count() const { return frame_count_; }
  int width() const { return width_; }
  int height() const { return height_; }

  struct Capture;  // defined in video_io.cc

 private:
  std::unique_ptr<Capture> capture_;
  cv::Mat decoded_;  // the last frame as decoded (BGR), reused
  double fps_ = 0;
  long long frame_count_ = 0;
  int width_ = 0;
  int height_ = 0;
};

// What VideoWriter writes.
struct VideoWriteOptions {
  // Frames per second stored in the file; > 0.
  double fps = 30.0;
  // The codec's quality in percent where the codec has one (motion JPEG:
  // 100 keeps corners as accurate as the frames were; the compression then
  // still halves the size of raw frames). In [1, 100].
  double quality = 100.0;

  bool Check(std::string* why = nullptr) const;
};

// Writes a video frame by frame: motion JPEG for .avi and .mkv, MPEG-4 part
// 2 for .mp4 and .mov (FFmpeg's encoders in Debian's OpenCV).
class VideoWriter {
 public:
  VideoWriter();
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // Opens `path` for frames of `size` (8-bit grey). False with a message
  // naming the file and the reason.
  bool Open(const std::string& path, const cv::Size& size,
            const VideoWriteOptions& options, std::string* error);
  // Appends one 8-bit grey frame of the opened size.
  bool Write(const cv::Mat& grey, std::string* error);
  // Finishes the file (also done by the destructor).
  void Close();

  struct Writer;  // defined in video_io.cc

 private:
  std::unique_ptr<Writer> writer_;
  cv::Size size_;
  std::string path_;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_VIDEO_IO_H_
