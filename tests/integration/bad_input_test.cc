// Bad input: clear messages and non-zero exit codes, never a crash.
#include <gtest/gtest.h>

#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(BadInput, CtlNamesTheUnreachableNamingService) {
  const std::string address = "corbaname::127.0.0.1:" + std::to_string(FreePort());
  const auto r = Ctl(address, {"ls"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(Contains(r.err, "cannot reach the naming service at " + address)) << r.err;
  EXPECT_FALSE(Contains(r.err, "terminate")) << r.err;
}

TEST(BadInput, CtlRejectsUnknownVerbsAndMissingArguments) {
  const auto verb = Ctl("corbaname::127.0.0.1:1", {"frobnicate"});
  EXPECT_EQ(verb.exit_code, 2);
  EXPECT_TRUE(Contains(verb.err, "unknown verb 'frobnicate'")) << verb.err;
  const auto args = Ctl("corbaname::127.0.0.1:1", {"state"});
  EXPECT_EQ(args.exit_code, 2);
  EXPECT_TRUE(Contains(args.err, "expected exactly one component name")) << args.err;
  const auto regex = Ctl("corbaname::127.0.0.1:1", {"log", "--grep", "("});
  EXPECT_EQ(regex.exit_code, 2);
  EXPECT_TRUE(Contains(regex.err, "bad regular expression")) << regex.err;
}

TEST(BadInput, EveryVerbHasHelp) {
  for (const std::string verb : {"ls", "state", "activate", "deactivate", "reset", "exit", "log"}) {
    const auto r = Ctl("corbaname::127.0.0.1:1", {verb, "--help"});
    EXPECT_EQ(r.exit_code, 0) << verb;
    EXPECT_TRUE(Contains(r.out, "Usage: caliper-ctl " + verb)) << r.out;
  }
}

TEST(BadInput, CtlNamesAnUnknownComponent) {
  TempDir dir;
  NamingService naming(dir.path());
  const auto r = Ctl(naming.address(), {"activate", "nosuch0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(Contains(r.err, "no component named 'nosuch0'")) << r.err;
}

TEST(BadInput, MalformedConfigurationStopsWithExitCode2) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"-o", "exec.rate=fast"}, "exec.rate = 'fast': expected a finite number"},
      {{"-o", "exec.rate=-5"}, "exec.rate = '-5': out of range"},
      {{"-o", "exec.kind=sometimes"}, "expected one of periodic external"},
      {{"-o", "exec.auto_activate=maybe"}, "expected true or false"},
      {{"-o", "sample.records_per_tick=1.5"}, "expected an integer"},
      {{"-o", "novalue"}, "'novalue' is not of the form key=value"},
      {{"-f", "/nonexistent/caliper.conf"}, "/nonexistent/caliper.conf: cannot open"},
      {{"--frobnicate"}, "unknown argument '--frobnicate'"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> argv = {Bin("caliper-sample")};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    const auto r = RunCommand(argv);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << " " << c.args.back();
    EXPECT_TRUE(Contains(r.err, c.message)) << r.err;
  }
}

TEST(BadInput, ConfigFileErrorsNameTheLine) {
  TempDir dir;
  const std::string file = dir.path() + "/bad.conf";
  FILE* f = fopen(file.c_str(), "w");
  fputs("# a comment\nexec.rate = 10\nexec.rate = ten\n", f);
  fclose(f);
  const auto r = RunCommand({Bin("caliper-sample"), "-f", file});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(Contains(r.err, file + ":3: exec.rate = 'ten'")) << r.err;
}

TEST(BadInput, UnknownKeysWarnButStart) {
  TempDir dir;
  NamingService naming(dir.path());
  Process sample({Bin("caliper-sample"), "--nameservice", naming.address(), "-o", "bogus.key=1",
                  "-o", "log.service=none"},
                 dir.path() + "/sample.out");
  ASSERT_TRUE(WaitFor([&] { return Ctl(naming.address(), {"state", "sample0"}).exit_code == 0; },
                      seconds(10)));
  EXPECT_TRUE(Contains(sample.Output(), "unknown key 'bogus.key' (ignored)")) << sample.Output();
}

TEST(BadInput, ComponentWithoutNamingServiceSaysWhereItLooked) {
  const std::string address = "corbaname::127.0.0.1:" + std::to_string(FreePort());
  const auto r = RunCommand({Bin("caliper-sample"), "--nameservice", address});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(Contains(r.err, "cannot reach the naming service at " + address)) << r.err;
}

TEST(BadInput, HelpListsEveryConfigurationKey) {
  const auto r = RunCommand({Bin("caliper-sample"), "--help"});
  EXPECT_EQ(r.exit_code, 0);
  for (const std::string key : {"exec.rate", "naming.update.interval", "sample.record_limit"})
    EXPECT_TRUE(Contains(r.out, key)) << key;
}

}  // namespace
}  // namespace caliper::testing
