#ifndef PUZZLECAL_FORMATS_PNG_FILTERS_H_
#define PUZZLECAL_FORMATS_PNG_FILTERS_H_

// Arithmetic of the PNG row filters shared by the grey-PNG decoder
// (image_io.cc) and the PNG writer (png_writer.cc).

#include <cstdlib>

namespace puzzlecal {

// The Paeth predictor of the PNG specification: of the byte to the left
// (a), above (b) and above-left (c), the one closest to a + b - c (ties in
// the order a, b, c).
inline int PaethPredictor(int a, int b, int c) {
  const int pa = std::abs(b - c), pb = std::abs(a - c);
  const int pc = std::abs(a + b - 2 * c);
  return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

}  // namespace puzzlecal

#endif  // PUZZLECAL_FORMATS_PNG_FILTERS_H_
