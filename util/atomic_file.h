#ifndef PUZZLECAL_UTIL_ATOMIC_FILE_H_
#define PUZZLECAL_UTIL_ATOMIC_FILE_H_

#include <string>

namespace puzzlecal {

// Writes `contents` to `path` so that readers see either the old file or the
// complete new one: the bytes go to a temporary file in the same folder, are
// flushed to disk (fsync), and the temporary file is renamed over `path`.
// On failure returns false, leaves `path` untouched, removes the temporary
// file and sets *error (when not null) to a message naming the path and the
// reason.
bool WriteFileAtomically(const std::string& path, const std::string& contents,
                         std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_UTIL_ATOMIC_FILE_H_
