// caliper-ctl inspect: reports what a COLLADA file holds without a session (the naming service
// given is unreachable), exits 1 naming the file and the problem when it does not import, 2 on
// bad usage, and --export writes a file that inspects the same.
#include <gtest/gtest.h>

#include <cstdlib>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "support/process.h"

namespace caliper::testing {
namespace {

// nothing listens there: a verb that tried the naming service would fail
const char* const kNoSession = "corbaname::127.0.0.1:1";

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string Source(const std::string& relative) {
  const char* dir = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(dir != nullptr ? dir : ".") + "/" + relative;
}

// the report's count lines: "bodies (6: 5 dynamic, 1 static)", "tendons (14; ...)", ...
std::vector<std::string> Counts(const std::string& report) {
  static const std::regex kCount(
      "^(materials|bodies|constraints|couplings|obstacles|tendons|actuators|warnings) \\(.*$");
  std::vector<std::string> lines;
  std::istringstream in(report);
  for (std::string line; std::getline(in, line);)
    if (std::regex_match(line, kCount)) lines.push_back(line);
  return lines;
}

TEST(Inspect, ListsWhatAShippedModelHoldsWithoutASession) {
  const auto r = Ctl(kNoSession, {"inspect", Source("models/ecce_arm.dae")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Contains(r.out, "COLLADA 1.5.0")) << r.out;
  EXPECT_TRUE(Contains(r.out, "bodies (6: 5 dynamic, 1 static)")) << r.out;
  EXPECT_TRUE(Contains(r.out, "constraints (5)")) << r.out;
  EXPECT_TRUE(Contains(r.out, "actuators (14: 10 dc_motor_tendon, 1 hill_muscle, 3 ligament)"))
      << r.out;
  for (const std::string actuator : {"girdle_elevator", "shoulder_flexor", "elbow_extensor",
                                     "wrist_flexor", "biceps", "costoclavicular"})
    EXPECT_TRUE(std::regex_search(r.out, std::regex("\n  " + actuator + " +[a-z_]+ on ")))
        << actuator << " not listed:\n"
        << r.out;
  // parameters with their units, limits in degrees, paths with their wraps
  EXPECT_TRUE(Contains(r.out, "stiffness 3000 N/m")) << r.out;
  EXPECT_TRUE(Contains(r.out, "max_isometric_force 150 N")) << r.out;
  EXPECT_TRUE(Contains(r.out, "limits 0 .. 145 deg")) << r.out;
  // hinge axes: frame_b's z in body_b's frame and in world at the description pose
  EXPECT_TRUE(Contains(r.out, "axis (0, -1, 0) in upper_arm, (0, -1, 0) in world")) << r.out;
  EXPECT_TRUE(Contains(r.out, "wrap elbow_pulley")) << r.out;
  EXPECT_TRUE(Contains(r.out, "warnings (0)")) << r.out;
  EXPECT_EQ(r.err, "");
}

TEST(Inspect, NamesTheFileAndTheProblemOfAFileThatDoesNotImport) {
  struct Case {
    std::string file;
    std::string problem;
  };
  const std::vector<Case> cases = {
      {"tests/data/collada/malformed_negative_mass.dae", "a dynamic body needs a positive mass"},
      {"tests/data/collada/malformed_unknown_kind.dae", "unknown actuator kind"},
      {"tests/data/collada/malformed_xml.dae", ":40: malformed XML"},
      {"tests/data/collada/no_such_file.dae", "cannot open"},
  };
  for (const Case& c : cases) {
    const auto r = Ctl(kNoSession, {"inspect", Source(c.file)});
    EXPECT_EQ(r.exit_code, 1) << c.file;
    EXPECT_TRUE(Contains(r.err, Source(c.file))) << r.err;
    EXPECT_TRUE(Contains(r.err, c.problem)) << r.err;
    EXPECT_EQ(r.out, "") << "a file that does not import is not reported as a scene";
    EXPECT_FALSE(Contains(r.err, "terminate")) << r.err;
  }
}

TEST(Inspect, ExportedFileInspectsTheSame) {
  TempDir dir;
  const std::string out = dir.path() + "/exported.dae";
  const auto original =
      Ctl(kNoSession, {"inspect", Source("models/ecce_arm.dae"), "--export", out});
  ASSERT_EQ(original.exit_code, 0) << original.err;
  EXPECT_TRUE(Contains(original.out, "exported to " + out)) << original.out;
  const auto again = Ctl(kNoSession, {"inspect", out});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(Counts(again.out), Counts(original.out));
  EXPECT_EQ(Counts(again.out).size(), 8u) << again.out;
}

TEST(Inspect, BadUsageExitsWith2AndHelpWith0) {
  const auto none = Ctl(kNoSession, {"inspect"});
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_TRUE(Contains(none.err, "expected a file")) << none.err;
  const auto two = Ctl(kNoSession, {"inspect", "a.dae", "b.dae"});
  EXPECT_EQ(two.exit_code, 2);
  const auto no_value = Ctl(kNoSession, {"inspect", Source("models/ecce_arm.dae"), "--export"});
  EXPECT_EQ(no_value.exit_code, 2);
  EXPECT_TRUE(Contains(no_value.err, "--export needs a value")) << no_value.err;
  const auto unknown = Ctl(kNoSession, {"inspect", "--frobnicate", "a.dae"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_TRUE(Contains(unknown.err, "unknown option '--frobnicate'")) << unknown.err;
  const auto help = Ctl(kNoSession, {"inspect", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_TRUE(Contains(help.out, "Usage: caliper-ctl inspect FILE [--export OUT.dae]")) << help.out;
}

TEST(Inspect, AFailedExportExits1) {
  const auto r = Ctl(kNoSession, {"inspect", Source("models/pendulum_tendon.dae"), "--export",
                                  "/nonexistent-dir/out.dae"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(Contains(r.err, "/nonexistent-dir/out.dae")) << r.err;
}

}  // namespace
}  // namespace caliper::testing
