#include "util/enum_names.h"

#include <gtest/gtest.h>

namespace puzzlecal {
namespace {

enum class Colour { kRed, kGreen, kBlue };
constexpr EnumName<Colour> kColourNames[] = {
    {Colour::kRed, "red"}, {Colour::kGreen, "green"}};

TEST(EnumNamesTest, NamesBothWaysAndListsTheChoices) {
  EXPECT_STREQ(NameOf(kColourNames, Colour::kGreen), "green");
  EXPECT_STREQ(NameOf(kColourNames, Colour::kBlue), "unknown");
  Colour colour = Colour::kBlue;
  EXPECT_TRUE(ValueOf(kColourNames, "red", &colour));
  EXPECT_EQ(colour, Colour::kRed);
  EXPECT_FALSE(ValueOf(kColourNames, "purple", &colour));
  EXPECT_EQ(colour, Colour::kRed);
  EXPECT_EQ(JoinedNames(kColourNames), "red, green");
}

}  // namespace
}  // namespace puzzlecal
