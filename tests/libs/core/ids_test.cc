#include "caliper/core/ids.h"

#include <gtest/gtest.h>

namespace caliper::core {
namespace {

TEST(IdSafeTest, LowerCasesAndJoinsEverythingElseWithOneUnderscore) {
  EXPECT_EQ(IdSafe("ecce_arm"), "ecce_arm");
  EXPECT_EQ(IdSafe("ECCE Arm"), "ecce_arm");
  EXPECT_EQ(IdSafe("Arm V2!"), "arm_v2");
  EXPECT_EQ(IdSafe("  Two -- spaces  "), "two_spaces");
  EXPECT_EQ(IdSafe("UR5e (robotiq 2F-85)"), "ur5e_robotiq_2f_85");
  EXPECT_EQ(IdSafe("a.b"), "a_b") << "a dot would split the id";
}

TEST(IdSafeTest, BytesBeyondAsciiAreNotLettersAndNothingLeftIsModel) {
  EXPECT_EQ(IdSafe("Br\xc3\xa4uer Arm"), "br_uer_arm");  // UTF-8 a-umlaut
  EXPECT_EQ(IdSafe("Br\xe4uer"), "br_uer");              // Latin-1 a-umlaut
  EXPECT_EQ(IdSafe(""), "model");
  EXPECT_EQ(IdSafe("!?"), "model");
  EXPECT_EQ(IdSafe("\xc3\xa4"), "model");
}

}  // namespace
}  // namespace caliper::core
