// libFuzzer target (d): the camera file reader (four formats).

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz/camera_yaml_case.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string broken = puzzlecal::fuzz::RunCameraYamlCase(data, size);
  if (!broken.empty()) {
    std::fprintf(stderr, "camera_yaml_fuzzer: %s\n", broken.c_str());
    __builtin_trap();
  }
  return 0;
}
