#include "caliper/client/session.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <sstream>

#include "caliper/core/system.h"
#include "caliper/rtc/client_orb.h"

namespace caliper::client {

std::string LatestSession() {
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  const std::string file = std::string(runtime != nullptr && *runtime != '\0' ? runtime : "/tmp") +
                           "/caliper-" + std::to_string(getuid()) + "/latest-session";
  // only a file of this user counts (another could leave one pointing at a session of theirs),
  // not a link, and what is read is the file checked
  const int fd = open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return "";
  struct stat st {};
  char text[4096];
  ssize_t n = -1;
  if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_uid == getuid())
    n = read(fd, text, sizeof text);
  close(fd);
  if (n <= 0) return "";
  std::istringstream in(std::string(text, static_cast<size_t>(n)));
  std::string address, pid;
  if (!std::getline(in, address) || !std::getline(in, pid) || address.empty()) return "";
  char* end = nullptr;
  const long id = std::strtol(pid.c_str(), &end, 10);
  if (end == pid.c_str() || *end != '\0' || id <= 0 || !core::ProcessAlive(id)) return "";
  return address;
}

std::string ResolveNamingAddress(const std::string& option) {
  if (!option.empty()) return option;
  const char* env = std::getenv("CALIPER_NAMESERVICE");
  if (env != nullptr && *env != '\0') return env;
  const std::string latest = LatestSession();
  return latest.empty() ? rtc::NamingAddress("") : latest;
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
    throw ConnectionError(std::string(e.what()) +
                              "\n  (is a session running? start one with `launch/caliper demo`, "
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
  address_ = ResolveNamingAddress(options_.nameservice);
  // TLS when on a network
  orb_ = rtc::ClientOrb(options_.program.c_str(), options_.timeout_s, address_);
}

}  // namespace caliper::client
