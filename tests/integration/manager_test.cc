// caliper-manager with real processes: a private omniNames, a manager capped at two Models,
// driven by caliper-ctl's cluster verbs; Models killed, destroyed, and taken down with it.
#include "caliper/cluster.hh"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "caliper/core/system.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

namespace C = ::Caliper::Cluster;

using std::chrono::milliseconds;
using std::chrono::seconds;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// What `caliper-ctl create` printed: instance -> pid.
std::map<std::string, pid_t> Created(const std::string& out) {
  std::map<std::string, pid_t> created;
  const std::regex line("created (\\S+) \\(pid (\\d+)\\)");
  for (std::sregex_iterator it(out.begin(), out.end(), line), end; it != end; ++it)
    created[(*it)[1]] = static_cast<pid_t>(std::stol((*it)[2]));
  return created;
}

/// True once `pid` is gone: reaped by its parent, or reaped here as an orphan (we subreap).
bool Gone(pid_t pid) { return waitpid(pid, nullptr, WNOHANG) == pid || !core::ProcessAlive(pid); }

class ManagerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // Models orphaned by a killed manager come to this process: reaped, not left as zombies
    prctl(PR_SET_CHILD_SUBREAPER, 1);
    naming_ = std::make_unique<NamingService>(dir_.path());
    const std::string dir = dir_.path();
    manager_ = std::make_unique<Process>(
        std::vector<std::string>{Bin("caliper-manager"), "--nameservice", naming_->address(),
                                 "-o", "manager.max_models=2", "-o",
                                 "manager.output_dir=" + dir + "/children", "-o",
                                 "log.service=none", "-o", "log.spool_dir=" + dir + "/spool"},
        dir + "/manager.out");
    ASSERT_TRUE(
        WaitFor([&] { return Contains(Ctl({"managers"}).out, "0/2 running"); }, seconds(10)))
        << manager_->Output();
  }

  CommandResult Ctl(const std::vector<std::string>& args) {
    return caliper::testing::Ctl(naming_->address(), args);
  }

  /// Creates `count` Models through ctl; instance -> pid.
  std::map<std::string, pid_t> Create(int count) {
    const auto r = Ctl({"create", "--count", std::to_string(count)});
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err << manager_->Output();
    return Created(r.out);
  }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> manager_;
};

TEST_F(ManagerTest, RunsModelsUpToItsCapReportsDeathsAndStopsTheRest) {
  const auto models = Create(2);
  ASSERT_EQ(models.size(), 2u);
  for (const auto& [name, pid] : models) {
    const auto status = Ctl({"status", "--model", name});
    EXPECT_EQ(status.exit_code, 0) << name << ": " << status.err;
  }
  const auto full = Ctl({"create"});
  EXPECT_EQ(full.exit_code, 1);
  EXPECT_TRUE(Contains(full.err, "manager0: 2 of 2 children run (manager.max_models allows more)"))
      << full.err;

  // one Model dies: the manager says how, and logs it
  const auto& [killed, killed_pid] = *models.begin();
  const auto& [other, other_pid] = *models.rbegin();
  ASSERT_EQ(kill(killed_pid, SIGKILL), 0);
  const std::regex dead(killed + " +pid " + std::to_string(killed_pid) + " +killed by signal 9 ");
  std::string listing;
  EXPECT_TRUE(WaitFor(
      [&] {
        listing = Ctl({"managers"}).out;
        return std::regex_search(listing, dead);
      },
      seconds(2)))
      << listing;
  EXPECT_TRUE(Contains(listing, "1/2 running")) << listing;
  EXPECT_TRUE(Contains(manager_->Output(), killed + " (pid " + std::to_string(killed_pid) +
                                               ") killed by signal 9 after"))
      << manager_->Output();

  // the other is destroyed: ended, unbound, forgotten
  const auto destroyed = Ctl({"destroy", other});
  EXPECT_EQ(destroyed.exit_code, 0) << destroyed.err;
  EXPECT_TRUE(Contains(destroyed.out, "destroyed " + other)) << destroyed.out;
  EXPECT_TRUE(Gone(other_pid));
  EXPECT_FALSE(Contains(Ctl({"ls"}).out, other + " ")) << Ctl({"ls"}).out;
  EXPECT_FALSE(Contains(Ctl({"managers"}).out, other + " "));
  const auto again = Ctl({"destroy", other});
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_TRUE(Contains(again.err, "no manager runs '" + other + "' (manager0 runs " + killed + ")"))
      << again.err;

  // stopping the manager stops what it runs
  const auto last = Create(1);
  ASSERT_EQ(last.size(), 1u);
  manager_->Signal(SIGTERM);
  EXPECT_EQ(manager_->Wait(seconds(10)), 0) << manager_->Output();
  EXPECT_TRUE(Gone(last.begin()->second));
}

TEST_F(ManagerTest, AKilledManagerTakesItsModelsDown) {
  const auto models = Create(1);
  ASSERT_EQ(models.size(), 1u);
  const pid_t pid = models.begin()->second;
  manager_->Signal(SIGKILL);
  manager_->Wait(seconds(5));
  int status = 0;
  EXPECT_TRUE(WaitFor([&] { return waitpid(pid, &status, WNOHANG) == pid; }, seconds(5)));
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
      << "a Model shuts down cleanly on the parent-death signal (TERM): " << status;
}

TEST_F(ManagerTest, AFailedStartShowsTheEndOfTheModelsOutput) {
  const auto r = Ctl({"create", "-o", "model.scene=/nonexistent/scene.dae"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(std::regex_search(
      r.err, std::regex("caliper-model \\(pid \\d+\\) exited with code 1 before it registered; "
                        "the end of .*/children/model-\\d+\\.out:\n")))
      << r.err;
  EXPECT_TRUE(Contains(r.err, "/nonexistent/scene.dae")) << r.err;
  EXPECT_TRUE(Contains(Ctl({"managers"}).out, "0/2 running"));
  // where a child listens is the manager's choice: a client cannot open it to every interface
  const auto open = Ctl({"create", "-o", "corba.endpoint=giop:tcp::"});
  EXPECT_EQ(open.exit_code, 1);
  EXPECT_TRUE(Contains(open.err, "'corba.endpoint' is set by the manager")) << open.err;
  // nor anything not on the allow-list: timeouts, message sizes, the fail point of tests
  for (const char* key : {"corba.call_timeout=0.01", "model.inject_fault=bad_alloc@1"}) {
    const auto refused = Ctl({"create", "-o", key});
    EXPECT_EQ(refused.exit_code, 1) << key;
    EXPECT_TRUE(Contains(refused.err, "is not one a client may set")) << refused.err;
  }
  EXPECT_TRUE(Contains(Ctl({"managers"}).out, "0/2 running"));
}

TEST_F(ManagerTest, AChildThatNeverRegistersIsStoppedAfterTheStartTimeout) {
  // a second manager whose "caliper-model" never binds
  const std::string bin = dir_.path() + "/fake-bin";
  ASSERT_EQ(mkdir(bin.c_str(), 0755), 0);
  std::ofstream(bin + "/caliper-model") << "#!/bin/sh\necho pretending to start\nexec sleep 30\n";
  ASSERT_EQ(chmod((bin + "/caliper-model").c_str(), 0755), 0);
  Process slow({Bin("caliper-manager"), "--nameservice", naming_->address(), "-o",
                "manager.bin_dir=" + bin, "-o", "manager.start_timeout=0.5", "-o",
                "manager.output_dir=" + dir_.path() + "/children", "-o", "log.service=none"},
               dir_.path() + "/slow.out");
  ASSERT_TRUE(WaitFor([&] { return Contains(Ctl({"managers"}).out, "/manager1.rtc"); },
                      seconds(10)))
      << slow.Output();

  const auto r = Ctl({"create", "--manager", "manager1"});
  EXPECT_EQ(r.exit_code, 1);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      r.err, m,
      std::regex("manager1: caliper-model \\(pid (\\d+)\\) did not register in the naming "
                 "service within 0.5 s \\(stopped it\\); the end of .*:\npretending to start")))
      << r.err;
  EXPECT_TRUE(Gone(static_cast<pid_t>(std::stol(m[1]))));
  EXPECT_TRUE(Contains(Ctl({"managers"}).out, "/manager1.rtc  0/"));
}

TEST_F(ManagerTest, ServantAnswersWithTheIdlExceptionsAndTheirReasons) {
  CORBA::ORB_ptr orb = rtc::ClientOrb("manager_test", 30);
  {
    CosNaming::NamingContext_var root = rtc::ResolveRoot(orb, naming_->address());
    C::Manager_var manager = C::Manager::_narrow(rtc::FindComponent(root, "manager0").object);
    ASSERT_FALSE(CORBA::is_nil(manager));
    Caliper::RTC::NameValueList config;
    try {
      C::Child_var child = manager->create("renderer", config);
      ADD_FAILURE() << "started a renderer";
    } catch (const C::UnknownComponent& e) {
      EXPECT_STREQ(e.reason.in(),
                   "'renderer' is not a type this manager starts (it starts: model)");
    }
    try {
      manager->destroy("model9");
      ADD_FAILURE() << "destroyed what it does not run";
    } catch (const C::UnknownComponent& e) {
      EXPECT_STREQ(e.reason.in(), "no child named 'model9' (it runs none)");
    }
    EXPECT_EQ(manager->capacity(), 2u);
    EXPECT_EQ(manager->running(), 0u);
    C::ChildSeq_var none = manager->list();
    EXPECT_EQ(none->length(), 0u);
  }
  orb->destroy();
}

}  // namespace
}  // namespace caliper::testing
