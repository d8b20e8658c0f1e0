// BoundThreadSpin: a process that may step on several threads starts again once with
// GOMP_SPINCOUNT = kThreadSpinCount, the same process and arguments, and libgomp reads it; a
// spin count or wait policy the environment sets is kept, and nothing starts again.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
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
  const std::string count = std::to_string(kThreadSpinCount);
  // first without the variable, then once more with it: the same process
  EXPECT_EQ(Count(out, "start pid="), 2) << out;
  std::smatch first;
  ASSERT_TRUE(std::regex_search(out, first, std::regex("start pid=(\\d+) GOMP_SPINCOUNT=-\n")))
      << out;
  const std::string pid = first[1];
  EXPECT_NE(out.find("start pid=" + pid + " GOMP_SPINCOUNT=" + count + "\n"), std::string::npos)
      << out;
  EXPECT_NE(out.find("after pid=" + pid + "\n"), std::string::npos) << out;
  // the name ps and pgrep match (its first 15 characters), not /proc/self/exe's "exe"
  EXPECT_NE(out.find("comm thread_spin_pro\n"), std::string::npos) << out;
  EXPECT_NE(out.find("arg 1 [one two]\narg 2 []\narg 3 [three]\n"), std::string::npos) << out;
  // libgomp read it as it loaded
  EXPECT_NE(out.find("GOMP_SPINCOUNT = '" + count + "'"), std::string::npos) << out;
}

TEST(ThreadSpin, KeepsTheEnvironmentsSpinCount) {
  const std::string out = RunProbe("GOMP_SPINCOUNT=1234");
  EXPECT_EQ(Count(out, "start pid="), 1) << out;
  EXPECT_NE(out.find("GOMP_SPINCOUNT = '1234'"), std::string::npos) << out;
  EXPECT_NE(out.find("arg 1 [one two]\narg 2 []\narg 3 [three]\n"), std::string::npos) << out;
}

TEST(ThreadSpin, KeepsTheEnvironmentsWaitPolicy) {
  // a policy alone sets the spin (ACTIVE: spin long), so no count is added
  const std::string out = RunProbe("OMP_WAIT_POLICY=active");
  EXPECT_EQ(Count(out, "start pid="), 1) << out;
  EXPECT_NE(out.find("OMP_WAIT_POLICY = 'ACTIVE'"), std::string::npos) << out;
  EXPECT_EQ(out.find("GOMP_SPINCOUNT = '" + std::to_string(kThreadSpinCount) + "'"),
            std::string::npos)
      << out;
}

}  // namespace
}  // namespace caliper::physics_bullet
