// libFuzzer target (c): the board and scene YAML readers.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz/config_yaml_case.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string broken = puzzlecal::fuzz::RunConfigYamlCase(data, size);
  if (!broken.empty()) {
    std::fprintf(stderr, "config_yaml_fuzzer: %s\n", broken.c_str());
    __builtin_trap();
  }
  return 0;
}
