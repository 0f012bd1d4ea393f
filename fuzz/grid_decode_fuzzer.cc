// libFuzzer target (b): corner sets -> BuildGrid -> DecodeBoard. See
// fuzz/grid_decode_case.h.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz/grid_decode_case.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string broken = puzzlecal::fuzz::RunGridDecodeCase(data, size);
  if (!broken.empty()) {
    std::fprintf(stderr, "grid_decode_fuzzer: %s\n", broken.c_str());
    __builtin_trap();
  }
  return 0;
}
