#include "caliper/rtc/local_sockets.h"

#include <fcntl.h>
#include <pwd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <omniORB4/IIOP.h>
#include <omniORB4/cdrStream.h>
#include <omniORB4/omniIOR.h>
#include <omniORB4/omniObjRef.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>

#include "caliper/rtc/transport_security.h"

namespace caliper::rtc {

namespace {

// sun_path holds 107 bytes and a NUL; a slash and omniORB's name (%09u-%09u, 19 bytes) or ours
// (naming.sock) follow the directory
constexpr size_t kMaxDirBytes = 107 - 1 - 19;

// the name of a user (getpwuid_r: notes are made on any thread)
std::string UserOf(uid_t uid) {
  passwd pw{};
  passwd* found = nullptr;
  char buffer[4096];
  if (getpwuid_r(uid, &pw, buffer, sizeof buffer, &found) == 0 && found != nullptr)
    return found->pw_name;
  return "uid " + std::to_string(uid);
}

std::string Octal(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

// '' when `dir` is a directory of this user that nobody else can enter, else what is wrong
std::string Unsafe(const std::string& dir) {
  struct stat st {};
  if (lstat(dir.c_str(), &st) != 0) {
    const int error = errno;
    return std::string("cannot read it (") + std::strerror(error) + ")";
  }
  if (S_ISLNK(st.st_mode)) return "it is a symbolic link";
  if (!S_ISDIR(st.st_mode)) return "it is not a directory";
  if (st.st_uid != geteuid()) return "it belongs to " + UserOf(st.st_uid);
  if ((st.st_mode & 077) != 0) return "other users may enter it (mode " + Octal(st.st_mode) + ")";
  return "";
}

std::string Checked(const std::string& dir, const std::string& source) {
  if (dir.size() > kMaxDirBytes)
    throw SecurityError("the directory for this session's unix sockets, " + dir + " (" + source +
                        "), is " + std::to_string(dir.size()) + " bytes long: at most " +
                        std::to_string(kMaxDirBytes) + " leave room for a socket's name (a " +
                        "socket path holds 107); set CALIPER_SOCKET_DIR to a shorter directory");
  // the paths go into references that other processes read (absolute), and omniORB expands %u
  // in it; ':', ',' and '#' would end the path in a corbaname:omniunix: address
  if (dir.front() != '/' || dir.find_first_of("%:,#") != std::string::npos)
    throw SecurityError("the directory for unix sockets " + dir + " (" + source + ") is refused: " +
                        "give an absolute path without %, :, , or #");
  if (mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    const int error = errno;
    throw SecurityError("cannot make the directory for unix sockets " + dir + " (" + source +
                        "): " + std::strerror(error) + "; set CALIPER_SOCKET_DIR to another");
  }
  if (const std::string why = Unsafe(dir); !why.empty())
    throw SecurityError("the directory for unix sockets " + dir + " (" + source + ") is refused: " +
                        why + "; a local session needs a directory only its user can enter " +
                        "(chmod 700, or set CALIPER_SOCKET_DIR to another)");
  return dir;
}

std::string ResolveDir() {
  if (const char* env = std::getenv("CALIPER_SOCKET_DIR"); env != nullptr && *env != '\0')
    return Checked(env, "$CALIPER_SOCKET_DIR");
  // the launcher's state directory (latest-session lives there too): in systemd's per-user
  // runtime directory when there is one of ours, else in /tmp
  std::string base = "/tmp";
  if (const char* run = std::getenv("XDG_RUNTIME_DIR"); run != nullptr && *run != '\0') {
    struct stat st {};
    if (stat(run, &st) == 0 && st.st_uid == geteuid()) base = run;
  }
  const std::string dir = base + "/caliper-" + std::to_string(geteuid());
  if (mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    const int error = errno;
    throw SecurityError("cannot make the directory for unix sockets " + dir + ": " +
                        std::strerror(error) + "; set CALIPER_SOCKET_DIR to another");
  }
  struct stat st {};
  // ours but opened up (an older launcher made it 0755): closed again
  if (lstat(dir.c_str(), &st) == 0 && S_ISDIR(st.st_mode) && st.st_uid == geteuid() &&
      (st.st_mode & 077) != 0)
    chmod(dir.c_str(), 0700);
  const std::string why = Unsafe(dir);
  if (why.empty()) return Checked(dir, "the default");
  // someone else made it first: never use it, make a private one
  std::string pattern = dir + "-XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) {
    const int error = errno;
    throw SecurityError("cannot make a private directory for unix sockets " + pattern + ": " +
                        std::strerror(error));
  }
  std::cerr << "caliper: " << dir << " is not used for unix sockets (" << why << "); using "
            << pattern << " instead\n";
  return Checked(pattern, "made because " + dir + " is refused");
}

}  // namespace

std::string LocalSocketDir() {
  static std::mutex mutex;
  static std::string dir;
  std::lock_guard<std::mutex> lock(mutex);
  if (dir.empty()) dir = ResolveDir();
  return dir;
}

std::string ResolveLocalSocketDir() { return ResolveDir(); }

std::vector<std::string> LocalSocketOrbOptions() {
  return {"-ORBunixTransportDirectory", LocalSocketDir(), "-ORBunixTransportPermission", "0600"};
}

std::string LocalSocketPath(const std::string& address) {
  for (const char* prefix : {"corbaname:omniunix:", "corbaloc:omniunix:"}) {
    const size_t n = std::strlen(prefix);
    if (address.compare(0, n, prefix) != 0) continue;
    std::string path = address.substr(n);
    // corbaloc:omniunix:PATH:/KEY and corbaname:omniunix:PATH#NAME
    if (const size_t key = path.find(":/"); key != std::string::npos) path.resize(key);
    if (const size_t name = path.find('#'); name != std::string::npos) path.resize(name);
    return path;
  }
  return "";
}

bool IsLocalSocketAddress(const std::string& address) { return !LocalSocketPath(address).empty(); }

std::string LocalNamingAddress(const std::string& socket_path) {
  return "corbaname:omniunix:" + socket_path;
}

std::string UnixSocketOfComponent(const IOP::TaggedComponent& component) {
  if (component.tag != IOP::TAG_OMNIORB_UNIX_TRANS) return "";
  // an encapsulation of the host name and the file name, read with omniORB's own stream
  try {
    cdrEncapsulationStream stream(component.component_data.get_buffer(),
                                  component.component_data.length(), 1);
    CORBA::String_var host = stream.unmarshalRawString();
    CORBA::String_var file = stream.unmarshalRawString();
    return file.in();
  } catch (...) {
    return "";
  }
}

bool VisitIiopProfiles(CORBA::Object_ptr ref,
                       const std::function<bool(const IIOP::ProfileBody&)>& visit) {
  if (CORBA::is_nil(ref)) return false;
  bool done = false;
  omniIOR* ior = ref->_PR_getobj()->_getIOR();
  const IOP::TaggedProfileList& profiles = ior->iopProfiles();
  for (CORBA::ULong i = 0; i < profiles.length() && !done; ++i) {
    if (profiles[i].tag != IOP::TAG_INTERNET_IOP) continue;
    try {
      IIOP::ProfileBody body;
      IIOP::unmarshalProfile(profiles[i], body);
      done = visit(body);
    } catch (const CORBA::SystemException&) {
      // a malformed profile: try the next one
    }
  }
  ior->release();
  return done;
}

std::string UnixSocketOf(CORBA::Object_ptr ref) {
  std::string socket;
  VisitIiopProfiles(ref, [&](const IIOP::ProfileBody& body) {
    for (CORBA::ULong c = 0; c < body.components.length() && socket.empty(); ++c)
      socket = UnixSocketOfComponent(body.components[c]);
    return !socket.empty();
  });
  return socket;
}

bool LocalSocketListening(const std::string& path) {
  sockaddr_un address{};
  if (path.empty() || path.size() >= sizeof address.sun_path) return true;  // cannot tell
  address.sun_family = AF_UNIX;
  std::memcpy(address.sun_path, path.c_str(), path.size());
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return true;  // cannot tell: not gone
  const int rc = connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  const int error = errno;
  close(fd);
  // EAGAIN: its backlog is full (a stopped process): there, but busy
  return rc == 0 || (error != ECONNREFUSED && error != ENOENT);
}

std::string LocalSocketNote(const std::string& path, const std::string& what) {
  if (path.empty() || path.front() != '/') return "";
  // every directory on the way must let us search it
  for (size_t slash = path.find('/', 1); slash != std::string::npos;
       slash = path.find('/', slash + 1)) {
    const std::string dir = path.substr(0, slash);
    if (faccessat(AT_FDCWD, dir.c_str(), X_OK, AT_EACCESS) == 0) continue;
    const int error = errno;
    struct stat st {};
    if (error == EACCES && stat(dir.c_str(), &st) == 0)
      return what + "'s unix socket " + path + " is in " + dir + ", a directory of " +
             UserOf(st.st_uid) + " (mode " + Octal(st.st_mode) + ") that " + UserOf(geteuid()) +
             " cannot enter: a local Caliper session is reachable only by the user who started "
             "it; run your own (launch/caliper session), or ask for a network session with "
             "certificates (docs/cluster.md)";
    if (error == ENOENT)
      return "there is no " + dir + " for " + what + "'s socket " + path +
             ": the session has ended, or the address is from another machine";
    return "cannot enter " + dir + " on the way to " + what + "'s socket " + path + " (" +
           std::strerror(error) + ")";
  }
  struct stat st {};
  if (stat(path.c_str(), &st) != 0)
    return "there is no socket " + path + " for " + what + ": the process has ended";
  if (!S_ISSOCK(st.st_mode)) return path + " is not a socket";
  if (faccessat(AT_FDCWD, path.c_str(), W_OK, AT_EACCESS) != 0)
    return what + "'s unix socket " + path + " belongs to " + UserOf(st.st_uid) + " (mode " +
           Octal(st.st_mode) + "), which " + UserOf(geteuid()) + " may not use: a local Caliper " +
           "session is reachable only by the user who started it";
  // a file left by a process that was killed
  if (!LocalSocketListening(path))
    return "nothing listens on " + what + "'s unix socket " + path + ": the process has ended";
  return "";
}

}  // namespace caliper::rtc
