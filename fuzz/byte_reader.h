#ifndef PUZZLECAL_FUZZ_BYTE_READER_H_
#define PUZZLECAL_FUZZ_BYTE_READER_H_

// Turns fuzz input bytes into values. Header-only and compiler-neutral so the
// regression tests (built with the normal compiler) replay exactly the code
// path the fuzz targets ran.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace puzzlecal {
namespace fuzz {

// Reads values front to back; past the end every read returns zeros, so any
// input decodes to some case.
class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  size_t remaining() const { return size_ - position_; }
  const uint8_t* current() const { return data_ + position_; }

  uint8_t Byte() { return position_ < size_ ? data_[position_++] : 0; }

  uint16_t U16() {
    const uint16_t low = Byte();
    return static_cast<uint16_t>(low | (Byte() << 8));
  }

  uint32_t U32() {
    const uint32_t low = U16();
    return low | (static_cast<uint32_t>(U16()) << 16);
  }

  // Integer in [low, high] (inclusive).
  int IntInRange(int low, int high) {
    const uint32_t span = static_cast<uint32_t>(high - low) + 1;
    return low + static_cast<int>(U16() % span);
  }

  // Fraction in [0, 1] with 16-bit resolution.
  double Unit() { return U16() / 65535.0; }

  // Double in [low, high].
  double DoubleInRange(double low, double high) {
    return low + (high - low) * Unit();
  }

  // Any bit pattern: NaN, inf, denormals, huge values included.
  double RawDouble() {
    uint8_t bytes[sizeof(double)];
    for (uint8_t& b : bytes) b = Byte();
    double value;
    std::memcpy(&value, bytes, sizeof(value));
    return value;
  }

  // Consumes up to `count` bytes into `out` (zero-filled past the end).
  void Bytes(uint8_t* out, size_t count) {
    const size_t available = std::min(count, remaining());
    if (available > 0) std::memcpy(out, current(), available);
    std::memset(out + available, 0, count - available);
    position_ += available;
  }

  void SkipToEnd() { position_ = size_; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t position_ = 0;
};

}  // namespace fuzz
}  // namespace puzzlecal

#endif  // PUZZLECAL_FUZZ_BYTE_READER_H_
