#include "formats/png_writer.h"

#include <gtest/gtest.h>
#include <libdeflate.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "formats/image_io.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// Smooth gradients (which the predicting filters shrink) with a noisy band
// (which they do not), `channels` of `depth`.
cv::Mat TestImage(int depth, int channels, int seed) {
  cv::Mat image(37, 53, CV_MAKETYPE(depth, channels));
  std::mt19937 random(seed);
  const double scale = depth == CV_16U ? 257.0 : 1.0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      for (int c = 0; c < channels; ++c) {
        const double smooth = 2 * x + 3 * y + 40 * c;
        const double value =
            y > 20 && y < 26 ? std::uniform_int_distribution<>(0, 255)(random)
                             : static_cast<int>(smooth) % 256;
        const int index = x * channels + c;
        if (depth == CV_8U) {
          image.ptr<uint8_t>(y)[index] = static_cast<uint8_t>(value);
        } else {
          // Clamped: 255 * 257 + 6 does not fit 16 bits.
          image.ptr<uint16_t>(y)[index] =
              static_cast<uint16_t>(std::min(65535.0, value * scale + (x % 7)));
        }
      }
    }
  }
  return image;
}

bool SamePixels(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         cv::countNonZero(a.reshape(1) != b.reshape(1)) == 0;
}

TEST(PngWriterTest, OpenCvReadsBackEveryTypeExactly) {
  for (int depth : {CV_8U, CV_16U}) {
    for (int channels = 1; channels <= 4; ++channels) {
      SCOPED_TRACE(cv::typeToString(CV_MAKETYPE(depth, channels)));
      const cv::Mat image = TestImage(depth, channels, 7 * channels + depth);
      std::vector<unsigned char> png;
      std::string error;
      ASSERT_TRUE(EncodePng(image, PngWriteOptions(), &png, &error)) << error;
      const cv::Mat decoded = cv::imdecode(png, cv::IMREAD_UNCHANGED);
      // OpenCV reads grey + alpha PNGs as BGRA; every other type comes back
      // as written (BGR order included).
      if (channels == 2) {
        ASSERT_EQ(decoded.channels(), 4);
        std::vector<cv::Mat> planes, back;
        cv::split(image, planes);
        cv::split(decoded, back);
        EXPECT_TRUE(SamePixels(back[0], planes[0]));
        EXPECT_TRUE(SamePixels(back[2], planes[0]));
        EXPECT_TRUE(SamePixels(back[3], planes[1]));
      } else {
        EXPECT_TRUE(SamePixels(decoded, image));
      }
    }
  }
}

TEST(PngWriterTest, RowsPickDifferentFiltersAndCompress) {
  const cv::Mat image = TestImage(CV_8U, 1, 3);
  std::vector<unsigned char> png;
  ASSERT_TRUE(EncodePng(image, PngWriteOptions(), &png, nullptr));
  // One IDAT chunk after the signature and the IHDR chunk.
  const size_t idat_at = 8 + 25;
  ASSERT_GT(png.size(), idat_at + 12);
  ASSERT_EQ(std::string(png.begin() + idat_at + 4, png.begin() + idat_at + 8),
            "IDAT");
  const size_t length = (size_t{png[idat_at]} << 24) |
                        (size_t{png[idat_at + 1]} << 16) |
                        (size_t{png[idat_at + 2]} << 8) | png[idat_at + 3];
  ASSERT_LE(idat_at + 8 + length, png.size());
  const size_t raw_size = image.total() + image.rows;  // + a filter byte/row
  std::vector<unsigned char> raw(raw_size);
  libdeflate_decompressor* inflater = libdeflate_alloc_decompressor();
  const libdeflate_result result =
      libdeflate_zlib_decompress(inflater, png.data() + idat_at + 8, length,
                                 raw.data(), raw.size(), nullptr);
  libdeflate_free_decompressor(inflater);
  ASSERT_EQ(result, LIBDEFLATE_SUCCESS);
  std::set<int> filters;
  for (int y = 0; y < image.rows; ++y) {
    filters.insert(raw[y * (image.cols + 1)]);
  }
  // The gradient rows predict well from their neighbours (Sub, Up, Paeth);
  // the noisy band does not. Each row's choice is its own.
  EXPECT_GE(filters.size(), 2u);
  for (int f : filters) EXPECT_LE(f, 4);
  // The smooth rows shrink to little; the noisy band's 6 rows do not.
  EXPECT_LT(length, raw_size / 2);
  EXPECT_TRUE(SamePixels(cv::imdecode(png, cv::IMREAD_UNCHANGED), image));
}

TEST(PngWriterTest, GreyPngsLoadThroughThePipelinesOwnDecoder) {
  const fs::path dir = fs::temp_directory_path() /
                       ("puzzlecal_png_writer_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const cv::Mat image = TestImage(CV_8U, 1, 11);
  const std::string path = (dir / "grey.png").string();
  std::string error;
  ASSERT_TRUE(WritePngFile(path, image, &error)) << error;
  cv::Mat grey;
  ASSERT_TRUE(LoadGreyImage(path, ImageLoadOptions(), &grey, &error)) << error;
  EXPECT_TRUE(SamePixels(grey, image));
  // Colour keeps its channels through LoadUnchanged (OpenCV's decoder).
  const cv::Mat colour = TestImage(CV_16U, 3, 12);
  const std::string colour_path = (dir / "colour.png").string();
  ASSERT_TRUE(WritePngFile(colour_path, colour, &error)) << error;
  cv::Mat unchanged;
  ImageLoader loader;
  ASSERT_TRUE(loader.LoadUnchanged(colour_path, &unchanged, &error)) << error;
  EXPECT_TRUE(SamePixels(unchanged, colour));
  fs::remove_all(dir);
}

TEST(PngWriterTest, RefusesWhatPngCannotHoldWithTheReason) {
  std::vector<unsigned char> png;
  std::string error;
  EXPECT_FALSE(EncodePng(cv::Mat(), PngWriteOptions(), &png, &error));
  EXPECT_NE(error.find("empty"), std::string::npos) << error;
  EXPECT_FALSE(EncodePng(cv::Mat(4, 4, CV_32FC1, cv::Scalar(0.5)),
                         PngWriteOptions(), &png, &error));
  EXPECT_NE(error.find("CV_32F"), std::string::npos) << error;
  PngWriteOptions options;
  options.compression_level = 0;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("compression_level"), std::string::npos) << error;
  EXPECT_FALSE(WritePngFile("/nonexistent-folder/x.png",
                            cv::Mat(2, 2, CV_8UC1, cv::Scalar(1)), &error));
  EXPECT_NE(error.find("/nonexistent-folder/x.png"), std::string::npos)
      << error;
}

}  // namespace
}  // namespace puzzlecal
