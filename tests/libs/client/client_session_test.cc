// Where a client finds its session: an address given, $CALIPER_NAMESERVICE, the newest session
// the launcher started that still runs, the default; no naming service is needed.
#include "caliper/client/session.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace caliper::client {
namespace {

namespace fs = std::filesystem;

class SessionAddress : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("caliper-session-test-" + std::to_string(getpid()));
    fs::create_directories(dir_ / ("caliper-" + std::to_string(getuid())));
    setenv("XDG_RUNTIME_DIR", dir_.c_str(), 1);
    unsetenv("CALIPER_NAMESERVICE");
  }
  void TearDown() override { fs::remove_all(dir_); }
  void WriteLatest(const std::string& address, long pid) {
    std::ofstream(dir_ / ("caliper-" + std::to_string(getuid())) / "latest-session")
        << address << "\n" << pid << "\n/somewhere\n";
  }
  fs::path dir_;
};

TEST_F(SessionAddress, FindsTheLatestRunningSession) {
  WriteLatest("corbaname::127.0.0.1:40123", getpid());  // a process that runs: this one
  EXPECT_EQ(LatestSession(), "corbaname::127.0.0.1:40123");
  EXPECT_EQ(ResolveNamingAddress(""), "corbaname::127.0.0.1:40123");
}

TEST_F(SessionAddress, IgnoresASessionThatEnded) {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);  // reaped: its pid names no process now
  WriteLatest("corbaname::127.0.0.1:40123", child);
  EXPECT_EQ(LatestSession(), "");
  EXPECT_EQ(ResolveNamingAddress(""), "corbaname::127.0.0.1:2809");
}

TEST_F(SessionAddress, IgnoresAMissingOrMalformedFile) {
  EXPECT_EQ(LatestSession(), "");
  WriteLatest("corbaname::127.0.0.1:40123", 0);
  EXPECT_EQ(LatestSession(), "");
}

TEST_F(SessionAddress, TheVariableAndTheOptionComeFirst) {
  WriteLatest("corbaname::127.0.0.1:40123", getpid());
  setenv("CALIPER_NAMESERVICE", "corbaname::127.0.0.1:40999", 1);
  EXPECT_EQ(ResolveNamingAddress(""), "corbaname::127.0.0.1:40999");
  EXPECT_EQ(ResolveNamingAddress("corbaname::10.0.0.1:2809"), "corbaname::10.0.0.1:2809");
  unsetenv("CALIPER_NAMESERVICE");
}

}  // namespace
}  // namespace caliper::client
