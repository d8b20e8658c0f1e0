#include "caliper/core/numbers.h"

#include <gtest/gtest.h>

#include <clocale>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "comma_locale.h"

namespace caliper::core {
namespace {

TEST(ParseDoubleTest, ReadsTheWholeTextAsADecimalNumber) {
  double v = 0;
  ASSERT_TRUE(ParseDouble("1.5", &v));
  EXPECT_EQ(v, 1.5);
  ASSERT_TRUE(ParseDouble("-2e-3", &v));
  EXPECT_EQ(v, -2e-3);
  ASSERT_TRUE(ParseDouble("+4", &v));
  EXPECT_EQ(v, 4.0);
  ASSERT_TRUE(ParseDouble("-INF", &v));
  EXPECT_TRUE(std::isinf(v) && v < 0);
  ASSERT_TRUE(ParseDouble("NaN", &v));
  EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(ToDouble("0.1"), 0.1);
}

TEST(ParseDoubleTest, RejectsAnythingElseSayingWhy) {
  for (const char* bad : {"", "1,5", " 1", "1 ", "1.5x", "+-1", "++1", "+", "0x10", "ten"}) {
    double v = 7;
    std::string why;
    EXPECT_FALSE(ParseDouble(bad, &v, &why)) << bad;
    EXPECT_EQ(why, std::string("'") + bad + "' is not a number");
    EXPECT_EQ(v, 7) << "a rejected text leaves the value";
  }
  std::string why;
  double v = 0;
  EXPECT_FALSE(ParseDouble("1e400", &v, &why));
  EXPECT_EQ(why, "'1e400' is out of range");
  try {
    ToDouble("1,5");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "'1,5' is not a number");
  }
}

TEST(ParseIntTest, ReadsWholeDecimalIntegersOnly) {
  long long v = 0;
  ASSERT_TRUE(ParseInt("-12", &v));
  EXPECT_EQ(v, -12);
  ASSERT_TRUE(ParseInt("+7", &v));
  EXPECT_EQ(v, 7);
  std::string why;
  EXPECT_FALSE(ParseInt("1.5", &v, &why));
  EXPECT_EQ(why, "'1.5' is not an integer");
  EXPECT_FALSE(ParseInt("99999999999999999999", &v, &why));
  EXPECT_EQ(why, "'99999999999999999999' is out of range");
}

TEST(ParseDoubleTest, IgnoresACommaDecimalLocale) {
  CALIPER_COMMA_DECIMAL_LOCALE(locale);
  double v = 0;
  ASSERT_TRUE(ParseDouble("1.5", &v));
  EXPECT_EQ(v, 1.5);
  EXPECT_FALSE(ParseDouble("1,5", &v));
}

TEST(FormatDoubleTest, WritesTheShortestTextThatReadsBackBitForBit) {
  CALIPER_COMMA_DECIMAL_LOCALE(locale);  // and never a comma
  EXPECT_EQ(FormatDouble(0.1), "0.1");
  EXPECT_EQ(FormatDouble(1.5), "1.5");
  EXPECT_EQ(FormatDouble(-2e-5), "-2e-05");
  EXPECT_EQ(FormatDouble(0.0039), "0.0039");
  EXPECT_EQ(FormatDouble(HUGE_VAL), "inf");
  for (const double v : {0.1, 1.0 / 3, -0.0, 5e-324, 1.7976931348623157e308, 123456789.125,
                         -HUGE_VAL}) {
    double back = 0;
    ASSERT_TRUE(ParseDouble(FormatDouble(v), &back)) << FormatDouble(v);
    EXPECT_EQ(std::memcmp(&back, &v, sizeof v), 0) << FormatDouble(v);
  }
  double back = 0;
  ASSERT_TRUE(ParseDouble(FormatDouble(NAN), &back));
  EXPECT_TRUE(std::isnan(back));
}

TEST(ClassicLocaleScopeTest, GivesTheThreadTheCLocaleAndRestoresBoth) {
  CALIPER_COMMA_DECIMAL_LOCALE(locale);
  const std::string before = std::setlocale(LC_ALL, nullptr);
  {
    const ClassicLocaleScope classic;
    EXPECT_EQ(std::strtod("1.5", nullptr), 1.5);
    std::ostringstream out;
    out << 1.5;
    EXPECT_EQ(out.str(), "1.5");
    EXPECT_EQ(std::setlocale(LC_ALL, nullptr), before) << "the process's C locale is kept";
  }
  EXPECT_EQ(std::strtod("1,5", nullptr), 1.5);
  std::ostringstream out;
  out << 1.5;
  EXPECT_EQ(out.str(), "1,5");
}

}  // namespace
}  // namespace caliper::core
