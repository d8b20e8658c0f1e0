// Unit expressions of the Caliper extension.
#include "units.h"

#include <gtest/gtest.h>

#include <cmath>

namespace caliper::collada::internal {
namespace {

Unit Parse(const std::string& text) {
  Unit u;
  std::string bad;
  EXPECT_TRUE(ParseUnit(text, &u, &bad)) << text << ": " << bad;
  return u;
}

TEST(UnitsTest, ScalesPrefixedLengths) {
  EXPECT_DOUBLE_EQ(Parse("mm").scale, 1e-3);
  EXPECT_DOUBLE_EQ(Parse("cm").scale, 1e-2);
  EXPECT_DOUBLE_EQ(Parse("km").scale, 1e3);
  EXPECT_TRUE(Parse("mm").SameDimension(Parse("m")));
}

TEST(UnitsTest, CombinesProductsQuotientsAndPowers) {
  const Unit torque_per_angle = Parse("N m/rad");
  EXPECT_TRUE(torque_per_angle.SameDimension(Parse("kg m^2/s^2/rad")));
  EXPECT_DOUBLE_EQ(Parse("N mm/deg").scale, 1e-3 * 180 / M_PI);
  EXPECT_DOUBLE_EQ(Parse("g cm^2").scale, 1e-3 * 1e-4);
  EXPECT_TRUE(Parse("V s/rad").SameDimension(Parse("N m/A/rad")));
  EXPECT_TRUE(Parse("(rad/s^2)/N").SameDimension(Parse("rad/(kg m)")));
}

TEST(UnitsTest, KnowsElectricalUnits) {
  EXPECT_TRUE(Parse("ohm").SameDimension(Parse("V/A")));
  EXPECT_TRUE(Parse("\xce\xa9").SameDimension(Parse("ohm")));
  EXPECT_DOUBLE_EQ(Parse("mohm").scale, 1e-3);
  EXPECT_DOUBLE_EQ(Parse("mH").scale, 1e-3);
  EXPECT_TRUE(Parse("H").SameDimension(Parse("V s/A")));
  EXPECT_DOUBLE_EQ(Parse("mA").scale, 1e-3);
  EXPECT_DOUBLE_EQ(Parse("kV").scale, 1e3);
}

TEST(UnitsTest, TreatsEmptyOneAndDashAsDimensionless) {
  for (const char* text : {"", "1", "-"}) {
    const Unit u = Parse(text);
    EXPECT_EQ(u.scale, 1) << text;
    EXPECT_EQ(u.dimension, (std::array<int, 5>{}));
  }
  EXPECT_DOUBLE_EQ(Parse("%").scale, 0.01);
}

TEST(UnitsTest, RejectsUnknownSymbols) {
  Unit u;
  std::string bad;
  EXPECT_FALSE(ParseUnit("furlong", &u, &bad));
  EXPECT_EQ(bad, "furlong");
  EXPECT_FALSE(ParseUnit("N m/parsec", &u, &bad));
  EXPECT_EQ(bad, "parsec");
  EXPECT_FALSE(ParseUnit("m^", &u, &bad));
}

TEST(UnitsTest, RejectsUnitsBeyondItsBoundsSayingWhy) {
  // found by fuzzing: 1e-6^9999 underflowed to a scale of 0, large powers overflowed the
  // exponents (int), and every parenthesis recursed once
  Unit u;
  std::string bad, why;
  EXPECT_FALSE(ParseUnit("kg m^3 um^9999", &u, &bad, &why));
  EXPECT_EQ(bad, "^9999");
  EXPECT_EQ(why, "a power beyond 12 in magnitude");
  EXPECT_FALSE(ParseUnit("((m^12)^12)", &u, &bad, &why));
  EXPECT_EQ(why, "an exponent beyond 24 in magnitude");
  EXPECT_FALSE(ParseUnit("pm^12 pg^12", &u, &bad, &why));
  EXPECT_EQ(bad, "pg^12");
  EXPECT_EQ(why, "a scale to SI that a double cannot hold");
  EXPECT_FALSE(ParseUnit(std::string(100000, '(') + "m", &u, &bad, &why));
  EXPECT_EQ(why, "more than 16 nested parentheses");
  EXPECT_TRUE(ParseUnit("kg m^2/(s^2 rad)", &u, &bad, &why));
  EXPECT_EQ(why, "");
  EXPECT_FALSE(ParseUnit("furlong", &u, &bad, &why));
  EXPECT_EQ(why, "") << "an unknown symbol has no bound to name";
}

}  // namespace
}  // namespace caliper::collada::internal
