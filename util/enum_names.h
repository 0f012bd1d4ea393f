#ifndef PUZZLECAL_UTIL_ENUM_NAMES_H_
#define PUZZLECAL_UTIL_ENUM_NAMES_H_

// One table per enum maps its values to the names users see (flags, files,
// reports), in both directions:
//
//   inline constexpr EnumName<RobustLoss> kRobustLossNames[] = {
//       {RobustLoss::kNone, "none"}, {RobustLoss::kHuber, "huber"}};
//   NameOf(kRobustLossNames, RobustLoss::kHuber)  -> "huber"
//   ValueOf(kRobustLossNames, "huber", &loss)     -> true

#include <cstddef>
#include <string>

namespace puzzlecal {

template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

// The name of `value`; `fallback` when the table lacks it.
template <typename Enum, size_t N>
const char* NameOf(const EnumName<Enum> (&table)[N], Enum value,
                   const char* fallback = "unknown") {
  for (const EnumName<Enum>& entry : table) {
    if (entry.value == value) return entry.name;
  }
  return fallback;
}

// Sets *value to the entry named `name`; false (and *value untouched) for a
// name the table lacks.
template <typename Enum, size_t N>
bool ValueOf(const EnumName<Enum> (&table)[N], const std::string& name,
             Enum* value) {
  for (const EnumName<Enum>& entry : table) {
    if (name == entry.name) {
      *value = entry.value;
      return true;
    }
  }
  return false;
}

// The names, joined by ", " (for messages that list the choices).
template <typename Enum, size_t N>
std::string JoinedNames(const EnumName<Enum> (&table)[N]) {
  std::string joined;
  for (const EnumName<Enum>& entry : table) {
    if (!joined.empty()) joined += ", ";
    joined += entry.name;
  }
  return joined;
}

}  // namespace puzzlecal

#endif  // PUZZLECAL_UTIL_ENUM_NAMES_H_
