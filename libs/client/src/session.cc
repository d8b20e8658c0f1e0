#include "caliper/client/session.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <iostream>
#include <mutex>
#include <sstream>
#include <vector>

#include "caliper/core/system.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/local_sockets.h"

namespace caliper::client {

namespace {

// ${XDG_RUNTIME_DIR:-/tmp}/caliper-UID/NAME: where the launcher says what runs
std::string StateFile(const std::string& name) {
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  return std::string(runtime != nullptr && *runtime != '\0' ? runtime : "/tmp") + "/caliper-" +
         std::to_string(getuid()) + "/" + name;
}

// The lines of a launcher's state file (ADDRESS, PID[, DIRECTORY]) when the file is this user's
// (another could leave one pointing at a session of theirs), not a link, and PID still runs;
// what is read is the file checked. Empty when not.
std::vector<std::string> LiveStateFile(const std::string& file) {
  const int fd = open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return {};
  struct stat st {};
  char text[4096];
  ssize_t n = -1;
  if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_uid == getuid())
    n = read(fd, text, sizeof text);
  close(fd);
  if (n <= 0) return {};
  std::istringstream in(std::string(text, static_cast<size_t>(n)));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  if (lines.size() < 2 || lines[0].empty()) return {};
  char* end = nullptr;
  const long id = std::strtol(lines[1].c_str(), &end, 10);
  if (end == lines[1].c_str() || *end != '\0' || id <= 0 || !core::ProcessAlive(id)) return {};
  return lines;
}

// A local session's address (corbaname:omniunix:PATH) whose socket nobody listens on any more:
// what a $CALIPER_NAMESERVICE exported from a session that has ended looks like. A network
// address someone exported on purpose is kept as it is (its errors name it).
bool EndedLocalSession(const std::string& address) {
  return rtc::IsLocalSocketAddress(address) &&
         !rtc::LocalSocketListening(rtc::LocalSocketPath(address));
}

}  // namespace

std::string LatestSession() {
  const std::vector<std::string> lines = LiveStateFile(StateFile("latest-session"));
  return lines.empty() ? "" : lines[0];
}

NamingChoice ChooseNamingAddress(const std::string& option) {
  if (!option.empty()) return {option, "--nameservice"};
  const std::vector<std::string> latest = LiveStateFile(StateFile("latest-session"));
  const std::vector<std::string> own = LiveStateFile(StateFile("nameserver"));
  NamingChoice found;
  if (!latest.empty())
    found = {latest[0], "the newest running session" +
                            (latest.size() > 2 ? " (" + latest[2] + ")" : std::string())};
  else if (!own.empty())
    found = {own[0], "the naming service of `launch/caliper nameserver start`"};
  const char* env = std::getenv("CALIPER_NAMESERVICE");
  if (env != nullptr && *env != '\0') {
    // a variable left from a session that has ended gives way to one that runs
    if (found.address.empty() || found.address == env || !EndedLocalSession(env))
      return {env, "$CALIPER_NAMESERVICE"};
    found.note = std::string("$CALIPER_NAMESERVICE (") + env + ") does not answer; using " +
                 found.source + ", " + found.address;
    return found;
  }
  if (!found.address.empty()) return found;
  return {rtc::NamingAddress(""), "the default (no running session of yours was found)"};
}

namespace {

// the note of a passed-over $CALIPER_NAMESERVICE, once a process
void SayNote(const NamingChoice& choice) {
  static std::once_flag said;
  if (!choice.note.empty())
    std::call_once(said, [&] { std::cerr << "caliper: " << choice.note << "\n"; });
}

}  // namespace

std::string ResolveNamingAddress(const std::string& option) {
  const NamingChoice choice = ChooseNamingAddress(option);
  SayNote(choice);
  return choice.address;
}

Session::~Session() {
  if (CORBA::is_nil(orb_)) return;
  try {
    orb_->destroy();
  } catch (...) {
  }
}

CosNaming::NamingContext_ptr Session::Root() {
  Connect();
  try {
    return rtc::ResolveRoot(orb_, address_);
  } catch (const rtc::Unreachable& e) {
    throw ConnectionError(std::string(e.what()) + "\n  (the address is " + source_ +
                              "; is a session running? start one with `launch/caliper session`, "
                              "or pass --nameservice corbaname::HOST:PORT)",
                          address_);
  }
}

rtc::ComponentEntry Session::Find(const std::string& name) {
  CosNaming::NamingContext_var root = Root();
  try {
    return rtc::FindComponent(root, name);
  } catch (const rtc::NotFound& e) {
    throw Failure(e.what());
  }
}

std::vector<rtc::ComponentEntry> Session::List() {
  CosNaming::NamingContext_var root = Root();
  try {
    return rtc::ListComponents(root);
  } catch (const CORBA::SystemException& e) {
    throw ConnectionError(Unreachable(address_, e), address_);
  }
}

::Caliper::RTC::LightweightRTObject_ptr Session::Component(const std::string& name,
                                                           std::string* path) {
  rtc::ComponentEntry e = Find(name);
  if (path) *path = e.path;
  try {
    ::Caliper::RTC::LightweightRTObject_var obj =
        ::Caliper::RTC::LightweightRTObject::_narrow(e.object);
    if (CORBA::is_nil(obj)) throw Failure(e.path + " is not a Caliper component");
    return obj._retn();
  } catch (const CORBA::Exception& ex) {
    throw ConnectionError(Unreachable(e.path, ex), e.path);
  }
}

std::string Session::Unreachable(const std::string& path, const CORBA::Exception& e) {
  return "cannot reach " + path + ": " + rtc::Describe(e) +
         " (the process may have died; its name is stale)";
}

CORBA::ORB_ptr Session::orb() {
  Connect();
  return orb_.in();
}

PortableServer::POA_ptr Session::RootPoa() {
  CORBA::Object_var obj = orb()->resolve_initial_references("RootPOA");
  PortableServer::POA_var poa = PortableServer::POA::_narrow(obj);
  poa->the_POAManager()->activate();
  return poa._retn();
}

const std::string& Session::address() {
  Connect();
  return address_;
}

void Session::Connect() {
  if (!CORBA::is_nil(orb_)) return;
  const NamingChoice choice = ChooseNamingAddress(options_.nameservice);
  SayNote(choice);
  address_ = choice.address;
  source_ = choice.source;
  // TLS when on a network
  orb_ = rtc::ClientOrb(options_.program.c_str(), options_.timeout_s, address_);
}

}  // namespace caliper::client
