#include "util/string_format.h"

#include <gtest/gtest.h>

namespace puzzlecal {
namespace {

TEST(StringFormatTest, FormatsShortAndLongResults) {
  EXPECT_EQ(StringPrintf("%.3f px, %d views", 0.12345, 12), "0.123 px, 12 views");
  const std::string long_text(1000, 'x');
  EXPECT_EQ(StringPrintf("<%s>", long_text.c_str()), "<" + long_text + ">");
  EXPECT_EQ(StringPrintf("%s", ""), "");
}

}  // namespace
}  // namespace puzzlecal
