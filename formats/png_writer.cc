#include "formats/png_writer.h"

#include <libdeflate.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <memory>

#include "formats/png_filters.h"
#include "util/atomic_file.h"
#include "util/failure.h"

namespace puzzlecal {

namespace {

void AppendBigEndian32(uint32_t value, std::vector<unsigned char>* out) {
  for (int shift = 24; shift >= 0; shift -= 8) {
    out->push_back(static_cast<unsigned char>(value >> shift));
  }
}

// Length, type, data and the CRC of type and data.
void AppendChunk(const char* type, const unsigned char* data, size_t size,
                 std::vector<unsigned char>* png) {
  AppendBigEndian32(static_cast<uint32_t>(size), png);
  const size_t type_at = png->size();
  png->insert(png->end(), type, type + 4);
  png->insert(png->end(), data, data + size);
  AppendBigEndian32(libdeflate_crc32(0, png->data() + type_at, size + 4), png);
}

// Row y of `image` in PNG byte order: RGB(A) instead of BGR(A), 16-bit
// samples big-endian.
void PngRow(const cv::Mat& image, int y, unsigned char* out) {
  const int channels = image.channels();
  const bool colour = channels >= 3;
  if (image.depth() == CV_8U) {
    const unsigned char* in = image.ptr<unsigned char>(y);
    const size_t samples = static_cast<size_t>(image.cols) * channels;
    if (!colour) {
      std::copy(in, in + samples, out);
      return;
    }
    for (size_t i = 0; i < samples; i += channels) {
      out[i] = in[i + 2];
      out[i + 1] = in[i + 1];
      out[i + 2] = in[i];
      if (channels == 4) out[i + 3] = in[i + 3];
    }
    return;
  }
  const uint16_t* in = image.ptr<uint16_t>(y);
  for (int x = 0; x < image.cols; ++x) {
    for (int c = 0; c < channels; ++c) {
      const int from = colour && c < 3 ? 2 - c : c;
      const uint16_t v = in[x * channels + from];
      unsigned char* sample = out + 2 * (static_cast<size_t>(x) * channels + c);
      sample[0] = static_cast<unsigned char>(v >> 8);
      sample[1] = static_cast<unsigned char>(v & 0xff);
    }
  }
}

// Filters `row` (with `prior`, the row above in PNG order, zeros for the
// first) with each of the five PNG filters and appends the filter byte and
// the filtered bytes of the one whose bytes, read as signed, have the
// smallest sum of absolute values.
void AppendFilteredRow(const unsigned char* row, const unsigned char* prior,
                       size_t size, size_t bpp,
                       std::array<std::vector<unsigned char>, 5>* candidates,
                       std::vector<unsigned char>* out) {
  std::array<long long, 5> cost{};
  for (int f = 0; f < 5; ++f) {
    std::vector<unsigned char>& filtered = (*candidates)[f];
    filtered.resize(size);
    unsigned char* out_bytes = filtered.data();
    // Bytes left of the row (i < bpp) predict from a = c = 0.
    auto a = [&](size_t i) { return i >= bpp ? int{row[i - bpp]} : 0; };
    auto c = [&](size_t i) { return i >= bpp ? int{prior[i - bpp]} : 0; };
    for (size_t i = 0; i < size; ++i) {
      int predicted = 0;
      switch (f) {
        case 1:
          predicted = a(i);
          break;
        case 2:
          predicted = prior[i];
          break;
        case 3:
          predicted = (a(i) + prior[i]) >> 1;
          break;
        case 4:
          predicted = PaethPredictor(a(i), prior[i], c(i));
          break;
        default:
          break;
      }
      out_bytes[i] = static_cast<unsigned char>(row[i] - predicted);
    }
    long long sum = 0;
    for (size_t i = 0; i < size; ++i) {
      sum += std::abs(static_cast<signed char>(out_bytes[i]));
    }
    cost[f] = sum;
  }
  const int best = static_cast<int>(std::min_element(cost.begin(), cost.end()) -
                                    cost.begin());
  out->push_back(static_cast<unsigned char>(best));
  out->insert(out->end(), (*candidates)[best].begin(),
              (*candidates)[best].end());
}

}  // namespace

bool PngWriteOptions::Check(std::string* why) const {
  if (compression_level < 1 || compression_level > 12) {
    return Fail("compression_level must be in 1..12, got " +
                    std::to_string(compression_level),
                why);
  }
  return true;
}

bool EncodePng(const cv::Mat& image, const PngWriteOptions& options,
               std::vector<unsigned char>* png, std::string* error) {
  if (!options.Check(error)) return false;
  if (image.empty()) return Fail("the image is empty", error);
  const int depth = image.depth();
  const int channels = image.channels();
  if ((depth != CV_8U && depth != CV_16U) || channels < 1 || channels > 4 ||
      image.dims != 2) {
    return Fail("PNG holds 8- or 16-bit images of 1 to 4 channels, not " +
                    cv::typeToString(image.type()),
                error);
  }
  const size_t bpp = static_cast<size_t>(channels) * (depth == CV_16U ? 2 : 1);
  const size_t row_bytes = bpp * static_cast<size_t>(image.cols);
  std::vector<unsigned char> raw;
  raw.reserve((row_bytes + 1) * image.rows);
  std::vector<unsigned char> row(row_bytes), prior(row_bytes, 0);
  std::array<std::vector<unsigned char>, 5> candidates;
  for (int y = 0; y < image.rows; ++y) {
    PngRow(image, y, row.data());
    AppendFilteredRow(row.data(), prior.data(), row_bytes, bpp, &candidates,
                      &raw);
    std::swap(row, prior);
  }

  const std::unique_ptr<libdeflate_compressor,
                        decltype(&libdeflate_free_compressor)>
      compressor(libdeflate_alloc_compressor(options.compression_level),
                 libdeflate_free_compressor);
  if (compressor == nullptr) return Fail("out of memory compressing", error);
  std::vector<unsigned char> idat(
      libdeflate_zlib_compress_bound(compressor.get(), raw.size()));
  const size_t compressed = libdeflate_zlib_compress(
      compressor.get(), raw.data(), raw.size(), idat.data(), idat.size());
  if (compressed == 0) return Fail("the pixels did not compress", error);

  static const unsigned char kSignature[8] = {0x89, 'P',  'N',  'G',
                                              '\r', '\n', 0x1a, '\n'};
  png->assign(kSignature, kSignature + 8);
  std::vector<unsigned char> header;
  AppendBigEndian32(static_cast<uint32_t>(image.cols), &header);
  AppendBigEndian32(static_cast<uint32_t>(image.rows), &header);
  static const unsigned char kColourType[5] = {0, 0, 4, 2, 6};
  header.push_back(depth == CV_16U ? 16 : 8);
  header.push_back(kColourType[channels]);
  header.insert(header.end(), {0, 0, 0});  // deflate, adaptive, no interlace
  AppendChunk("IHDR", header.data(), header.size(), png);
  // Chunks hold at most 2^31 - 1 bytes; split long streams.
  constexpr size_t kMaxChunk = size_t{1} << 30;
  for (size_t at = 0; at < compressed; at += kMaxChunk) {
    AppendChunk("IDAT", idat.data() + at, std::min(kMaxChunk, compressed - at),
                png);
  }
  AppendChunk("IEND", nullptr, 0, png);
  return true;
}

bool WritePngFile(const std::string& path, const cv::Mat& image,
                  std::string* error) {
  std::vector<unsigned char> png;
  std::string why;
  if (!EncodePng(image, PngWriteOptions(), &png, &why)) {
    return Fail("cannot encode " + path + " as PNG: " + why, error);
  }
  return WriteFileAtomically(path, std::string(png.begin(), png.end()), error);
}

}  // namespace puzzlecal
