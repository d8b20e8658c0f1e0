// Where a client finds its session: an address given, $CALIPER_NAMESERVICE (unless it names a local
// session nobody listens on and a session runs), the newest session the launcher started that
// still runs, the default; no naming service is needed (a unix socket of this process stands in).
#include "caliper/client/session.h"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
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

// A unix socket of this process that accepts connections, as a local session's naming service
// (the choice asks only whether something listens there).
class Listener {
 public:
  explicit Listener(const fs::path& path) : path_(path) {
    fd_ = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
    if (fd_ < 0 || bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        listen(fd_, 4) != 0)
      ADD_FAILURE() << "cannot listen on " << path;
  }
  ~Listener() {
    close(fd_);
    fs::remove(path_);
  }
  std::string address() const { return "corbaname:omniunix:" + path_.string(); }

 private:
  fs::path path_;
  int fd_ = -1;
};

TEST_F(SessionAddress, TheVariableAndTheOptionComeFirst) {
  const Listener live(dir_ / "live.sock");
  WriteLatest("corbaname::127.0.0.1:40123", getpid());
  setenv("CALIPER_NAMESERVICE", live.address().c_str(), 1);
  EXPECT_EQ(ResolveNamingAddress(""), live.address());
  const NamingChoice choice = ChooseNamingAddress("");
  EXPECT_EQ(choice.source, "$CALIPER_NAMESERVICE");
  EXPECT_EQ(choice.note, "");
  // a network address is kept as exported, answering or not (nothing is probed)
  setenv("CALIPER_NAMESERVICE", "corbaname::192.0.2.1:2809", 1);
  EXPECT_EQ(ResolveNamingAddress(""), "corbaname::192.0.2.1:2809");
  EXPECT_EQ(ResolveNamingAddress("corbaname::10.0.0.1:2809"), "corbaname::10.0.0.1:2809");
  unsetenv("CALIPER_NAMESERVICE");
}

TEST_F(SessionAddress, AnEndedLocalSessionInTheVariableGivesWayToTheRunningSession) {
  std::string gone;
  {
    const Listener ended(dir_ / "ended.sock");  // a session that has ended: nobody listens
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
