// A local process's unix sockets: the directory it puts them in (only its user may enter it; a
// directory open to others, of another user, a link or one too long for a socket path refused
// with the reason), the addresses of a naming service on a socket, whether something listens on a
// socket, and why another user cannot reach one.
#include "caliper/rtc/local_sockets.h"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>

#include "caliper/rtc/transport_security.h"

namespace caliper::rtc {
namespace {

class LocalSocketsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/caliper-ls-XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
    unsetenv("CALIPER_SOCKET_DIR");
  }
  void TearDown() override {
    unsetenv("CALIPER_SOCKET_DIR");
    ASSERT_EQ(std::system(("rm -rf " + dir_).c_str()), 0);
  }
  std::string Error() {
    try {
      ResolveLocalSocketDir();
    } catch (const SecurityError& e) {
      return e.what();
    }
    return "";
  }
  // a socket file at `path`; listening when `listen`, else left behind as a dead process does
  int Socket(const std::string& path, bool listen) {
    const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
    EXPECT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0) << std::strerror(errno);
    if (listen) EXPECT_EQ(::listen(fd, 4), 0);
    else close(fd);
    return listen ? fd : -1;
  }
  std::string dir_;
};

TEST_F(LocalSocketsTest, MakesTheChosenDirectoryPrivate) {
  const std::string dir = dir_ + "/sock";
  setenv("CALIPER_SOCKET_DIR", dir.c_str(), 1);
  EXPECT_EQ(ResolveLocalSocketDir(), dir);
  struct stat st {};
  ASSERT_EQ(stat(dir.c_str(), &st), 0);
  EXPECT_TRUE(S_ISDIR(st.st_mode));
  EXPECT_EQ(st.st_mode & 0777, 0700u);
  EXPECT_EQ(st.st_uid, geteuid());
}

TEST_F(LocalSocketsTest, RefusesADirectoryOthersMayEnterALinkAndATooLongPath) {
  const std::string open_dir = dir_ + "/open";
  ASSERT_EQ(mkdir(open_dir.c_str(), 0755), 0);
  ASSERT_EQ(chmod(open_dir.c_str(), 0755), 0);
  setenv("CALIPER_SOCKET_DIR", open_dir.c_str(), 1);
  EXPECT_NE(Error().find("other users may enter it (mode 0755)"), std::string::npos) << Error();
  EXPECT_NE(Error().find("CALIPER_SOCKET_DIR"), std::string::npos) << Error();

  const std::string link = dir_ + "/link";
  ASSERT_EQ(symlink(open_dir.c_str(), link.c_str()), 0);
  setenv("CALIPER_SOCKET_DIR", link.c_str(), 1);
  EXPECT_NE(Error().find("symbolic link"), std::string::npos) << Error();

  // 87 bytes fit (a 19-byte name, a slash and the NUL make 108), 88 do not
  const std::string base = dir_ + "/";
  const std::string fits = base + std::string(87 - base.size(), 'f');
  const std::string over = base + std::string(88 - base.size(), 'o');
  setenv("CALIPER_SOCKET_DIR", fits.c_str(), 1);
  EXPECT_EQ(Error(), "") << fits.size();
  setenv("CALIPER_SOCKET_DIR", over.c_str(), 1);
  EXPECT_NE(Error().find("88 bytes long: at most 87"), std::string::npos) << Error();

  for (const std::string& bad : {std::string("relative/sock"), dir_ + "/a%u", dir_ + "/a:b",
                                dir_ + "/a#b", dir_ + "/a,b"}) {
    setenv("CALIPER_SOCKET_DIR", bad.c_str(), 1);
    EXPECT_NE(Error().find("absolute path without"), std::string::npos) << bad << ": " << Error();
  }
}

TEST_F(LocalSocketsTest, RefusesADirectoryOfAnotherUser) {
  if (geteuid() != 0) GTEST_SKIP() << "giving a directory to another user needs root";
  const std::string theirs = dir_ + "/theirs";
  ASSERT_EQ(mkdir(theirs.c_str(), 0700), 0);
  ASSERT_EQ(chown(theirs.c_str(), 65534, 65534), 0);  // nobody
  setenv("CALIPER_SOCKET_DIR", theirs.c_str(), 1);
  EXPECT_NE(Error().find("it belongs to"), std::string::npos) << Error();
}

TEST_F(LocalSocketsTest, ReadsTheSocketOfANamingAddress) {
  EXPECT_EQ(LocalNamingAddress("/run/x/naming.sock"), "corbaname:omniunix:/run/x/naming.sock");
  EXPECT_EQ(LocalSocketPath("corbaname:omniunix:/run/x/naming.sock"), "/run/x/naming.sock");
  EXPECT_EQ(LocalSocketPath("corbaname:omniunix:/run/x/naming.sock#host.host_cxt/m.rtc"),
            "/run/x/naming.sock");
  EXPECT_EQ(LocalSocketPath("corbaloc:omniunix:/run/x/naming.sock:/NameService"),
            "/run/x/naming.sock");
  EXPECT_TRUE(IsLocalSocketAddress("corbaname:omniunix:/a"));
  EXPECT_FALSE(IsLocalSocketAddress("corbaname::127.0.0.1:2809"));
  EXPECT_FALSE(IsLocalSocketAddress("corbaname:ssliop:10.0.0.1:2809"));
  // the transport's view: a local address is no network address
  SecurityRequest request;
  request.endpoint = kLocalEndpoint;
  request.naming_address = "corbaname:omniunix:/run/x/naming.sock";
  EXPECT_EQ(ResolveSecurity(request).transport, Transport::kLoopback);
}

TEST_F(LocalSocketsTest, TellsAListeningSocketFromOneLeftBehind) {
  const std::string live = dir_ + "/live.sock", dead = dir_ + "/dead.sock";
  const int fd = Socket(live, true);
  Socket(dead, false);
  EXPECT_TRUE(LocalSocketListening(live));
  EXPECT_FALSE(LocalSocketListening(dead)) << "a file nothing listens on: refused";
  EXPECT_FALSE(LocalSocketListening(dir_ + "/none.sock"));
  EXPECT_TRUE(LocalSocketListening("/" + std::string(120, 'x'))) << "cannot tell: not gone";
  EXPECT_EQ(LocalSocketNote(live, "the Model"), "") << "reachable: nothing to say";
  EXPECT_NE(LocalSocketNote(dead, "the Model").find("nothing listens on the Model's unix socket"),
            std::string::npos)
      << LocalSocketNote(dead, "the Model");
  EXPECT_NE(LocalSocketNote(dir_ + "/none.sock", "the Model").find("has ended"),
            std::string::npos);
  EXPECT_NE(LocalSocketNote("/nonexistent-dir/x.sock", "the Model").find("session has ended"),
            std::string::npos);
  close(fd);
}

TEST_F(LocalSocketsTest, SaysWhoseDirectoryKeepsAnotherUserOut) {
  if (geteuid() != 0) GTEST_SKIP() << "acting as another user needs root";
  const std::string sock_dir = dir_ + "/private";
  ASSERT_EQ(mkdir(sock_dir.c_str(), 0700), 0);
  const std::string path = sock_dir + "/naming.sock";
  const int fd = Socket(path, true);
  ASSERT_EQ(chmod(dir_.c_str(), 0755), 0);
  // as nobody (in a child: the ids of this process stay)
  const pid_t child = fork();
  if (child == 0) {
    if (setgid(65534) != 0 || setuid(65534) != 0) _exit(3);
    const std::string note = LocalSocketNote(path, "the naming service");
    _exit(note.find("the naming service's unix socket " + path + " is in " + sock_dir +
                    ", a directory of root (mode 0700)") != std::string::npos &&
                  note.find("reachable only by the user who started it") != std::string::npos
              ? 0
              : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
  close(fd);
}

}  // namespace
}  // namespace caliper::rtc
