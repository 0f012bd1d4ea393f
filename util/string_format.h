#ifndef PUZZLECAL_UTIL_STRING_FORMAT_H_
#define PUZZLECAL_UTIL_STRING_FORMAT_H_

// printf-style formatting into a std::string, for messages and reports.

#include <string>

namespace puzzlecal {

// StringPrintf("%.3f px", rms): the whole result, however long.
std::string StringPrintf(const char* format, ...)
    __attribute__((format(printf, 1, 2)));

}  // namespace puzzlecal

#endif  // PUZZLECAL_UTIL_STRING_FORMAT_H_
