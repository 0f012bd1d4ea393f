// libFuzzer target (a): image bytes -> DetectCorners. See fuzz/detect_case.h.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz/detect_case.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string broken = puzzlecal::fuzz::RunDetectCase(data, size);
  if (!broken.empty()) {
    std::fprintf(stderr, "detect_fuzzer: %s\n", broken.c_str());
    __builtin_trap();
  }
  return 0;
}
