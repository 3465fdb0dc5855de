#include "sensors/protocol_fields.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

using Fields = std::vector<std::string>;

TEST(SplitCommasTest, KeepsEmptyFieldsSoPositionsMatchTheProtocol) {
  // A Gill WindSonic record with the direction missing in low wind: the empty field must stay.
  EXPECT_EQ(SplitCommas("Q,,000.08,M,00", true), (Fields{"Q", "", "000.08", "M", "00"}));
  EXPECT_EQ(SplitCommas("", false), (Fields{""}));
  EXPECT_EQ(SplitCommas(",", false), (Fields{"", ""}));
  EXPECT_EQ(SplitCommas("a,b,", false), (Fields{"a", "b", ""}));
}

TEST(SplitCommasTest, TrimsSpacesOnlyWhenAsked) {
  EXPECT_EQ(SplitCommas(" 3.2 ,\t270,  ", true), (Fields{"3.2", "270", ""}));
  EXPECT_EQ(SplitCommas(" 3.2 ,\t270", false), (Fields{" 3.2 ", "\t270"}));
}

TEST(ParseOptionalNumberTest, EmptyIsNaNGarbageIsAnErrorThatQuotesTheField) {
  double v = 0;
  std::string error;
  ASSERT_TRUE(ParseOptionalNumber("  ", &v, &error));
  EXPECT_TRUE(std::isnan(v));
  ASSERT_TRUE(ParseOptionalNumber(" 012.50 ", &v, &error));
  EXPECT_DOUBLE_EQ(v, 12.5);
  EXPECT_FALSE(ParseOptionalNumber("12.5x", &v, &error));
  EXPECT_NE(error.find("12.5x"), std::string::npos) << error;
  EXPECT_FALSE(ParseOptionalNumber("inf", &v, &error));
}

}  // namespace
}  // namespace clothwind::sensors
