// The manager's Supervisor with /bin/sh children: the cap, how children ended, TERM -> KILL,
// output files, and that no child outlives the supervisor or its process.
#include "children.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <memory>
#include <string>
#include <vector>

#include "caliper/core/system.h"
#include "support/process.h"

namespace caliper::manager {
namespace {

using std::chrono::milliseconds;
using testing::ReadFile;
using testing::TempDir;
using testing::WaitFor;

const std::vector<std::string> kSleep = {"/bin/sleep", "30"};

std::vector<std::string> Shell(const std::string& script) { return {"/bin/sh", "-c", script}; }

/// True once `pid` is gone: reaped by its parent, or reaped here when it was handed to this
/// process (a subreaper) as an orphan.
bool Gone(pid_t pid) { return waitpid(pid, nullptr, WNOHANG) == pid || !core::ProcessAlive(pid); }

class SupervisorTest : public ::testing::Test {
 protected:
  std::unique_ptr<Supervisor> Make(size_t max_running, milliseconds grace = milliseconds(5000),
                                   size_t keep_ended = 50) {
    SupervisorOptions options;
    options.max_running = max_running;
    options.capacity_key = "test.max_children";
    options.output_dir = dir_.path();
    options.grace = grace;
    options.keep_ended = keep_ended;
    return std::make_unique<Supervisor>(options);
  }

  /// The state of `pid` once it ended (waits up to a second).
  std::string EndedState(const Supervisor& s, pid_t pid) {
    WaitFor([&] { return !s.Status(pid)->running; }, milliseconds(1000));
    return s.Status(pid)->state;
  }

  TempDir dir_;
};

TEST_F(SupervisorTest, StartsUpToTheCapAndNamesTheKeyThatRaisesIt) {
  auto s = Make(2);
  s->Start("shell", kSleep);
  s->Start("shell", kSleep);
  EXPECT_EQ(s->running(), 2u);
  EXPECT_EQ(s->capacity(), 2u);
  try {
    s->Start("shell", kSleep);
    FAIL() << "a third child started";
  } catch (const CapacityReached& e) {
    EXPECT_EQ(std::string(e.what()), "2 of 2 children run (test.max_children allows more)");
  }
  EXPECT_EQ(s->List().size(), 2u);
}

TEST_F(SupervisorTest, RecordsHowChildrenEndedAndFreesTheirSlots) {
  auto s = Make(2);
  const pid_t killed = s->Start("shell", kSleep);
  const pid_t exited = s->Start("shell", Shell("exit 3"));
  s->SetRegistered(killed, "sleeper0", "host.host_cxt/sleeper0.rtc");
  EXPECT_EQ(s->Status(killed)->state, "running");
  ASSERT_EQ(kill(killed, SIGKILL), 0);
  EXPECT_EQ(EndedState(*s, killed), "killed by signal 9");
  EXPECT_EQ(EndedState(*s, exited), "exited with code 3");
  EXPECT_EQ(s->running(), 0u);
  // ended children stay listed, after the running ones, with the time they ran
  const pid_t next = s->Start("shell", kSleep);
  const auto list = s->List();
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[0].pid, next);
  EXPECT_EQ(list[0].state, "starting");
  EXPECT_EQ(list[1].instance, "sleeper0");
  EXPECT_FALSE(list[1].running);
  EXPECT_LT(list[1].uptime, 2.0);
  EXPECT_EQ(s->PidOf("sleeper0"), killed);
}

TEST_F(SupervisorTest, StopEscalatesToKillWhenTermIsIgnored) {
  auto s = Make(2, milliseconds(300));
  const pid_t stubborn =
      s->Start("shell", Shell("trap '' TERM; echo ready; while :; do sleep 0.05; done"));
  const std::string output = dir_.path() + "/shell-" + std::to_string(stubborn) + ".out";
  ASSERT_TRUE(WaitFor([&] { return ReadFile(output) == "ready\n"; }, milliseconds(2000)));
  auto t0 = std::chrono::steady_clock::now();
  s->Stop(stubborn);
  const auto took = std::chrono::steady_clock::now() - t0;
  EXPECT_GE(took, milliseconds(300));
  EXPECT_LT(took, milliseconds(1500));
  EXPECT_FALSE(s->Status(stubborn).has_value()) << "a stopped child is forgotten";
  EXPECT_TRUE(Gone(stubborn));

  // one that obeys TERM ends at once
  const pid_t obedient = s->Start("shell", kSleep);
  t0 = std::chrono::steady_clock::now();
  s->Stop(obedient);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, milliseconds(300));
  EXPECT_EQ(s->running(), 0u);
}

TEST_F(SupervisorTest, WritesTheChildsOutputToTypePidFile) {
  auto s = Make(1);
  const pid_t pid = s->Start("shell", Shell("echo to-stdout; echo to-stderr >&2; exit 0"));
  EXPECT_EQ(EndedState(*s, pid), "exited with code 0");
  const std::string file = dir_.path() + "/shell-" + std::to_string(pid) + ".out";
  EXPECT_EQ(s->Status(pid)->output_file, file);
  EXPECT_EQ(ReadFile(file), "to-stdout\nto-stderr\n");
  EXPECT_EQ(TailOfFile(file, 1), "to-stderr");
  EXPECT_EQ(TailOfFile(file, 10), "to-stdout\nto-stderr");
  EXPECT_EQ(TailOfFile(dir_.path() + "/missing.out", 10), "");
}

TEST_F(SupervisorTest, RefusesWhatCannotRunAndNamesWhatItRuns) {
  auto s = Make(1);
  try {
    s->Start("x", {"/nonexistent/caliper-x"});
    FAIL() << "started a missing program";
  } catch (const StartFailed& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot run /nonexistent/caliper-x: No such file or directory");
  }
  EXPECT_EQ(s->running(), 0u);
  EXPECT_TRUE(s->List().empty());
  const pid_t pid = s->Start("shell", kSleep);
  s->SetRegistered(pid, "sleeper0", "host.host_cxt/sleeper0.rtc");
  try {
    s->PidOf("sleeper7");
    FAIL();
  } catch (const UnknownComponent& e) {
    EXPECT_EQ(std::string(e.what()), "no child named 'sleeper7' (running: sleeper0)");
  }
  EXPECT_THROW(s->Stop(pid + 100000), UnknownComponent);
}

TEST_F(SupervisorTest, KeepsOnlyTheLastEndedChildren) {
  auto s = Make(3, milliseconds(5000), 2);
  std::vector<pid_t> pids;
  for (int i = 0; i < 3; ++i) {
    pids.push_back(s->Start("shell", Shell("exit " + std::to_string(i))));
    EndedState(*s, pids.back());
  }
  const auto list = s->List();
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].pid, pids[1]);
  EXPECT_EQ(list[1].pid, pids[2]);
}

TEST_F(SupervisorTest, NoChildOutlivesTheSupervisor) {
  pid_t pid;
  {
    auto s = Make(1);
    pid = s->Start("shell", kSleep);
    ASSERT_FALSE(Gone(pid));
  }
  EXPECT_TRUE(Gone(pid));
}

TEST_F(SupervisorTest, AKilledParentTakesItsChildrenDown) {
  // orphans come to this process, which can then tell how they ended
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  int report[2];
  ASSERT_EQ(pipe(report), 0);
  const pid_t manager = fork();
  if (manager == 0) {
    close(report[0]);
    auto s = Make(1);
    const pid_t child = s->Start("shell", kSleep);
    if (write(report[1], &child, sizeof child) != sizeof child) _exit(2);
    pause();  // until killed
    _exit(0);
  }
  close(report[1]);
  pid_t orphan = 0;
  const ssize_t n = read(report[0], &orphan, sizeof orphan);
  close(report[0]);
  const bool started = n == static_cast<ssize_t>(sizeof orphan) && !Gone(orphan);
  kill(manager, SIGKILL);
  waitpid(manager, nullptr, 0);
  ASSERT_TRUE(started);
  int status = 0;
  EXPECT_TRUE(WaitFor([&] { return waitpid(orphan, &status, WNOHANG) == orphan; },
                      milliseconds(2000)));
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
}

}  // namespace
}  // namespace caliper::manager
