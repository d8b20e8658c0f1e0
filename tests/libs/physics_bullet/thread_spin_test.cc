// BoundThreadSpin: a process that may step on several threads starts again once with
// GOMP_SPINCOUNT set to the turns of kThreadSpinTime on this processor, the same process and
// arguments, and libgomp reads it; a spin count or wait policy the environment sets is kept, and
// nothing starts again. SpinTurns and MeasureSpinTurn, which size the count.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>
#include <regex>
#include <string>

#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::physics_bullet {
namespace {

// the probe's output (stdout and stderr) run under `env` (env(1)'s arguments)
std::string RunProbe(const std::string& env) {
  // the probe's path quoted: a clone's path may hold spaces (not single quotes)
  const std::string command = "env -u GOMP_SPINCOUNT -u OMP_WAIT_POLICY " + env + " '" +
                              THREAD_SPIN_PROBE + "' 'one two' '' three 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  EXPECT_NE(pipe, nullptr) << command;
  if (pipe == nullptr) return "";
  std::string out;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command << "\n" << out;
  return out;
}

int Count(const std::string& text, const std::string& pattern) {
  const std::regex re(pattern);
  return static_cast<int>(
      std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
}

TEST(ThreadSpin, StartsAgainOnceWithTheBoundedSpinAndTheSameArguments) {
  const std::string out = RunProbe("");
  // first without the variable, then once more with it: the same process
  EXPECT_EQ(Count(out, "start pid="), 2) << out;
  std::smatch first;
  ASSERT_TRUE(std::regex_search(out, first, std::regex("start pid=(\\d+) GOMP_SPINCOUNT=-\n")))
      << out;
  const std::string pid = first[1];
  std::smatch second;
  ASSERT_TRUE(
      std::regex_search(out, second, std::regex("start pid=" + pid + " GOMP_SPINCOUNT=(\\d+)\n")))
      << out;
  const std::string count = second[1];
  EXPECT_NE(out.find("after pid=" + pid + " GOMP_SPINCOUNT=" + count + "\n"), std::string::npos)
      << out;
  // the name ps and pgrep match (its first 15 characters), not /proc/self/exe's "exe"
  EXPECT_NE(out.find("comm thread_spin_pro\n"), std::string::npos) << out;
  EXPECT_NE(out.find("arg 1 [one two]\narg 2 []\narg 3 [three]\n"), std::string::npos) << out;
  // libgomp read it as it loaded
  EXPECT_NE(out.find("GOMP_SPINCOUNT = '" + count + "'"), std::string::npos) << out;
  // the turns of kThreadSpinTime on this processor, as this process measures them (within a
  // factor of 3: either measurement may run on a busy machine)
  const double turns = std::stod(count);
  const double here = static_cast<double>(SpinTurns(kThreadSpinTime, MeasureSpinTurn()));
  EXPECT_GE(turns, kMinSpinTurns);
  EXPECT_LE(turns, kMaxSpinTurns);
  EXPECT_GT(turns, here / 3) << "measured here: " << here;
  EXPECT_LT(turns, here * 3) << "measured here: " << here;
}

TEST(ThreadSpin, TurnsForATimeAtATurnsTime) {
  EXPECT_EQ(SpinTurns(250e-6, 25e-9), 10000);
  EXPECT_EQ(SpinTurns(250e-6, 47e-9), 5319);              // rounded: 5319.1
  EXPECT_EQ(SpinTurns(250e-6, 1e-6), kMinSpinTurns);      // 250: too short to cover a gap
  EXPECT_EQ(SpinTurns(250e-6, 1e-10), kMaxSpinTurns);     // 2.5 million: libgomp's default
  EXPECT_EQ(SpinTurns(250e-6, 0.0), kFallbackSpinTurns);  // a clock that saw no time
  EXPECT_EQ(SpinTurns(250e-6, -1e-9), kFallbackSpinTurns);
  EXPECT_EQ(SpinTurns(250e-6, std::numeric_limits<double>::quiet_NaN()), kFallbackSpinTurns);
  EXPECT_EQ(SpinTurns(250e-6, std::numeric_limits<double>::infinity()), kFallbackSpinTurns);
}

TEST(ThreadSpin, ATurnTakesAPauseHintsTime) {
  // a load and a pause hint: more than nothing, far less than a microsecond on any processor
  const double turn = MeasureSpinTurn();
  EXPECT_GT(turn, 0.0);
  EXPECT_LT(turn, 1e-6);
  // the fastest of its runs: measured again, within a factor of 3
  const double again = MeasureSpinTurn();
  EXPECT_LT(std::max(turn, again) / std::min(turn, again), 3.0) << turn << " " << again;
}

TEST(ThreadSpin, KeepsTheEnvironmentsSpinCount) {
  const std::string out = RunProbe("GOMP_SPINCOUNT=1234");
  EXPECT_EQ(Count(out, "start pid="), 1) << out;
  EXPECT_NE(out.find("GOMP_SPINCOUNT = '1234'"), std::string::npos) << out;
  EXPECT_NE(out.find(" GOMP_SPINCOUNT=1234\n"), std::string::npos) << out;  // after the call
  EXPECT_NE(out.find("arg 1 [one two]\narg 2 []\narg 3 [three]\n"), std::string::npos) << out;
}

TEST(ThreadSpin, KeepsTheEnvironmentsWaitPolicy) {
  // a policy alone sets the spin (ACTIVE: spin long), so no count is added
  const std::string out = RunProbe("OMP_WAIT_POLICY=active");
  EXPECT_EQ(Count(out, "start pid="), 1) << out;
  EXPECT_NE(out.find("OMP_WAIT_POLICY = 'ACTIVE'"), std::string::npos) << out;
  EXPECT_NE(out.find(" GOMP_SPINCOUNT=-\n"), std::string::npos) << out;
  EXPECT_EQ(Count(out, "GOMP_SPINCOUNT=\\d"), 0) << out;
  EXPECT_NE(out.find("after pid="), std::string::npos) << out;
  EXPECT_EQ(Count(out, "GOMP_SPINCOUNT=-\n"), 2) << out;  // at the start and after the call
}

}  // namespace
}  // namespace caliper::physics_bullet
