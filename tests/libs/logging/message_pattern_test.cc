// Regular expressions from outside: RE2 syntax, the hostile patterns of issue 19 answered at once,
// the length bound, RE2's reasons for bad patterns.
#include "caliper/logging/message_pattern.h"

#include <gtest/gtest.h>

#include <string>

namespace caliper::logging {
namespace {

/// The message of the PatternError that compiling `pattern` throws, or "" when it compiles.
std::string ErrorOf(const std::string& pattern) {
  try {
    MessagePattern p(pattern);
  } catch (const PatternError& e) {
    return e.what();
  }
  return "";
}

TEST(MessagePatternTest, SearchesAnywhereInTheText) {
  const MessagePattern p("joint [0-9]+ above");
  EXPECT_TRUE(p.Search("warning: joint 12 above limit"));
  EXPECT_FALSE(p.Search("joint x above"));
  EXPECT_TRUE(MessagePattern("").Search("anything"));
  EXPECT_TRUE(MessagePattern("^step \\d+$").Search("step 42"));
  EXPECT_FALSE(MessagePattern("^step \\d+$").Search("step 42 done"));
  EXPECT_TRUE(MessagePattern("\\bfor\\b").Search("slack for 20 steps"));
  EXPECT_FALSE(MessagePattern("\\bfor\\b").Search("formal"));
}

TEST(MessagePatternTest, AnchorsAndDotKeepToOneTextNotOneLine) {
  EXPECT_FALSE(MessagePattern("first.second").Search("first\nsecond")) << ". is not a newline";
  EXPECT_FALSE(MessagePattern("^second").Search("first\nsecond")) << "^ is the text's start";
  EXPECT_TRUE(MessagePattern("(?m)^second").Search("first\nsecond"));
}

TEST(MessagePatternTest, CaseInsensitiveOnRequest) {
  EXPECT_FALSE(MessagePattern("tendon").Search("Tendon triceps"));
  EXPECT_TRUE(MessagePattern("tendon", false).Search("Tendon triceps"));
  EXPECT_TRUE(MessagePattern("(?i)tendon").Search("TENDON"));
}

TEST(MessagePatternTest, AlternationOverTwentyKilobytesNeitherRecursesNorFails) {
  // std::regex overflowed the stack here
  std::string message;
  for (int i = 0; i < 10 * 1024; ++i) message += "ab";
  EXPECT_FALSE(MessagePattern("(a|b)*c").Search(message));
  EXPECT_TRUE(MessagePattern("^(a|b)*$").Search(message));
}

TEST(MessagePatternTest, NestedQuantifiersDoNotBacktrack) {
  // exponential for a backtracking matcher (more than 30 s with std::regex)
  const MessagePattern p("(a*)*b");
  EXPECT_FALSE(p.Search(std::string(20, 'a')));
  EXPECT_FALSE(p.Search(std::string(16 * 1024, 'a')));
  EXPECT_TRUE(p.Search(std::string(20, 'a') + "b"));
}

TEST(MessagePatternTest, RefusesPatternsLongerThanTheBound) {
  const std::string longest(kMaxPatternBytes, 'a');
  EXPECT_EQ(ErrorOf(longest), "");
  EXPECT_TRUE(MessagePattern(longest).Search(longest));
  EXPECT_EQ(ErrorOf(longest + "a"),
            "regular expression too long: " + std::to_string(kMaxPatternBytes + 1) +
                " bytes, at most " + std::to_string(kMaxPatternBytes));
}

TEST(MessagePatternTest, BadPatternsCarryRe2sReasonAndThePattern) {
  EXPECT_EQ(ErrorOf("joint ("), "bad regular expression 'joint (': missing ): joint (");
  EXPECT_EQ(ErrorOf("[a"), "bad regular expression '[a': missing ]: [a");
  // what RE2 does not have at all
  EXPECT_EQ(ErrorOf("(a)\\1"), "bad regular expression '(a)\\1': invalid escape sequence: \\1");
  EXPECT_EQ(ErrorOf("a(?=b)"), "bad regular expression 'a(?=b)': invalid perl operator: (?=");
}

TEST(MessagePatternTest, RefusesPatternsThatNeedTooMuchMemory) {
  // within RE2's repetition limit, but a thousand copies of every letter's program
  EXPECT_EQ(ErrorOf("\\pL{1000}"),
            "bad regular expression '\\pL{1000}': pattern too large - compile failed");
  // nested repetitions are refused before they are compiled
  EXPECT_EQ(ErrorOf("(\\pL{100}){100}"),
            "bad regular expression '(\\pL{100}){100}': invalid repetition size: {100}");
}

TEST(MessagePatternTest, MovesKeepTheExpression) {
  MessagePattern a("tendon");
  MessagePattern b(std::move(a));
  EXPECT_TRUE(b.Search("a tendon"));
  MessagePattern c("other");
  c = std::move(b);
  EXPECT_TRUE(c.Search("a tendon"));
  EXPECT_FALSE(c.Search("other"));
}

}  // namespace
}  // namespace caliper::logging
