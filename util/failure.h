#ifndef PUZZLECAL_UTIL_FAILURE_H_
#define PUZZLECAL_UTIL_FAILURE_H_

// The one shape of a failure in puzzlecal's libraries: a function that can
// fail on its input returns bool and, on failure, fills `std::string* error`
// (may be null) with a message that names the input and says what to change.
// Fail() is the one helper for that: `return Fail("...", error);`.

#include <string>

namespace puzzlecal {

// Sets *error (when not null) to `message` and returns false.
inline bool Fail(const std::string& message, std::string* error) {
  if (error != nullptr) *error = message;
  return false;
}

}  // namespace puzzlecal

#endif  // PUZZLECAL_UTIL_FAILURE_H_
