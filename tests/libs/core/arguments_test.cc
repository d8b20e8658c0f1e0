#include "caliper/core/arguments.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace caliper::core {
namespace {

ArgumentSpec ToolSpec() {
  ArgumentSpec spec;
  spec.valued = {"--model", "--ids"};
  spec.flags = {"--live"};
  return spec;
}

TEST(ParseArgumentsTest, TakesValuedOptionsFlagsAndPositionalWordsInOrder) {
  const Arguments a = ParseArguments(
      {"--ids", "a,b", "file.log", "--live", "--ids", "c", "-1.5", "--model", "m1"}, ToolSpec());
  EXPECT_EQ(a.Error(), "");
  EXPECT_FALSE(a.help);
  EXPECT_EQ(a.Values("--ids"), (std::vector<std::string>{"a,b", "c"}));
  EXPECT_EQ(a.Value("--model"), "m1");
  EXPECT_EQ(a.Value("--absent", "fallback"), "fallback");
  EXPECT_TRUE(a.Has("--live"));
  EXPECT_FALSE(a.Has("--absent"));
  EXPECT_EQ(a.positional, (std::vector<std::string>{"file.log", "-1.5"}))
      << "a number is no option";
  ASSERT_EQ(a.options.size(), 4u);
  EXPECT_EQ(a.options[1].first, "--live");
}

TEST(ParseArgumentsTest, StopsAtTheFirstUnknownOptionOrMissingValue) {
  const Arguments unknown = ParseArguments({"x", "--bogus", "--model"}, ToolSpec());
  EXPECT_EQ(unknown.unknown, "--bogus");
  EXPECT_EQ(unknown.Error(), "unknown option '--bogus'");
  EXPECT_EQ(unknown.positional, std::vector<std::string>{"x"});
  const Arguments single_dash = ParseArguments({"-x"}, ToolSpec());
  EXPECT_EQ(single_dash.Error(), "unknown option '-x'");
  const Arguments missing = ParseArguments({"--live", "--model"}, ToolSpec());
  EXPECT_EQ(missing.missing_value, "--model");
  EXPECT_EQ(missing.Error(), "option --model needs a value");
  const Arguments help = ParseArguments({"--model", "m", "-h"}, ToolSpec());
  EXPECT_TRUE(help.help);
  EXPECT_EQ(help.Error(), "");
}

TEST(ParseArgumentsTest, PassesAnotherParsersOptionsWithTheirValues) {
  ArgumentSpec spec = ToolSpec();
  spec.pass = [](const std::string& w) {
    return w == "-platform" ? 2 : (w.rfind("-q", 0) == 0 ? 1 : 0);
  };
  const std::vector<std::string> words = {"-platform", "offscreen", "--live", "-qflag", "f"};
  const Arguments a = ParseArguments(words, spec);
  EXPECT_EQ(a.Error(), "");
  EXPECT_EQ(a.passed, (std::vector<size_t>{0, 1, 3}));
  EXPECT_EQ(a.positional, std::vector<std::string>{"f"});
  EXPECT_EQ(ParseArguments({"--live", "-platform"}, spec).Error(),
            "option -platform needs a value");
}

TEST(ParseArgumentsTest, CanStopAtTheFirstPositionalWord) {
  ArgumentSpec spec;
  spec.valued = {"--timeout"};
  spec.stop_at_positional = true;
  const Arguments a = ParseArguments({"--timeout", "3", "log", "--follow", "--timeout", "1"}, spec);
  EXPECT_EQ(a.Error(), "");
  EXPECT_EQ(a.Value("--timeout"), "3");
  EXPECT_EQ(a.positional, (std::vector<std::string>{"log", "--follow", "--timeout", "1"}));
}

}  // namespace
}  // namespace caliper::core
