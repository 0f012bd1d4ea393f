#include "util/string_format.h"

#include <cstdarg>
#include <cstdio>
#include <vector>

namespace puzzlecal {

std::string StringPrintf(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  char small[128];
  const int needed = std::vsnprintf(small, sizeof(small), format, args);
  va_end(args);
  std::string result;
  if (needed < 0) {
    result = "";
  } else if (static_cast<size_t>(needed) < sizeof(small)) {
    result.assign(small, static_cast<size_t>(needed));
  } else {
    std::vector<char> large(static_cast<size_t>(needed) + 1);
    std::vsnprintf(large.data(), large.size(), format, copy);
    result.assign(large.data(), static_cast<size_t>(needed));
  }
  va_end(copy);
  return result;
}

}  // namespace puzzlecal
