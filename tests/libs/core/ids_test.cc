#include "caliper/core/ids.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace caliper::core {
namespace {

TEST(IdSafeTest, LowerCasesAsciiAndJoinsEverythingElseWithOneUnderscore) {
  // {name, id}: the Model's channels start with the id, and clients build ids with it
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"ecce_arm", "ecce_arm"},
      {"ECCE Arm", "ecce_arm"},
      {"Arm V2!", "arm_v2"},
      {"  Two -- spaces  ", "two_spaces"},
      {"UR5e (robotiq 2F-85)", "ur5e_robotiq_2f_85"},
      {"a.b", "a_b"},                       // a dot would split the id
      {"Br\xc3\xa4uer Arm", "br_uer_arm"},  // UTF-8 a-umlaut: not a letter here
      {"Br\xe4uer", "br_uer"},              // Latin-1 a-umlaut, under any locale
      {"", "model"},                        // nothing left: the Model's name for it
      {"!?", "model"},
      {"\xc3\xa4", "model"},
  };
  for (const auto& [name, id] : cases) EXPECT_EQ(IdSafe(name), id) << "'" << name << "'";
}

}  // namespace
}  // namespace caliper::core
