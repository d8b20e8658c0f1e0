// Where a client finds its session: an address given, $CALIPER_NAMESERVICE (unless nothing listens
// there and a session runs), the newest session the launcher started that still runs, the
// default; no naming service is needed (a loopback port of this process stands in for one).
#include "caliper/client/session.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
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

// A TCP port of this process that accepts connections (a naming service stand-in: the choice
// asks only whether something listens).
class Listener {
 public:
  Listener() {
    fd_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t n = sizeof a;
    if (fd_ < 0 || bind(fd_, reinterpret_cast<sockaddr*>(&a), n) != 0 || listen(fd_, 4) != 0 ||
        getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n) != 0)
      ADD_FAILURE() << "cannot listen on loopback";
    port_ = ntohs(a.sin_port);
  }
  ~Listener() { close(fd_); }
  std::string address() const { return "corbaname::127.0.0.1:" + std::to_string(port_); }

 private:
  int fd_ = -1;
  int port_ = 0;
};

TEST_F(SessionAddress, TheVariableAndTheOptionComeFirst) {
  const Listener live;
  WriteLatest("corbaname::127.0.0.1:40123", getpid());
  setenv("CALIPER_NAMESERVICE", live.address().c_str(), 1);
  EXPECT_EQ(ResolveNamingAddress(""), live.address());
  const NamingChoice choice = ChooseNamingAddress("");
  EXPECT_EQ(choice.source, "$CALIPER_NAMESERVICE");
  EXPECT_EQ(choice.note, "");
  EXPECT_EQ(ResolveNamingAddress("corbaname::10.0.0.1:2809"), "corbaname::10.0.0.1:2809");
  unsetenv("CALIPER_NAMESERVICE");
}

TEST_F(SessionAddress, AVariableWhereNothingListensGivesWayToTheRunningSession) {
  std::string gone;
  {
    const Listener ended;  // a naming service that has ended: its port is closed again
    gone = ended.address();
  }
  WriteLatest("corbaname::127.0.0.1:40123", getpid());
  setenv("CALIPER_NAMESERVICE", gone.c_str(), 1);
  const NamingChoice choice = ChooseNamingAddress("");
  EXPECT_EQ(choice.address, "corbaname::127.0.0.1:40123");
  EXPECT_NE(choice.note.find("$CALIPER_NAMESERVICE (" + gone + ") does not answer"),
            std::string::npos)
      << choice.note;
  EXPECT_NE(choice.source.find("the newest running session"), std::string::npos) << choice.source;
  // without a running session the variable stays: there is nothing better to give way to
  fs::remove(dir_ / ("caliper-" + std::to_string(getuid())) / "latest-session");
  EXPECT_EQ(ChooseNamingAddress("").address, gone);
  unsetenv("CALIPER_NAMESERVICE");
}

}  // namespace
}  // namespace caliper::client
