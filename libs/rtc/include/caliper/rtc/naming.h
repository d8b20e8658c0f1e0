#pragma once
// The CORBA naming service as Caliper uses it: components bound as `<host>.host_cxt/<instance>.rtc`.

#include <omniORB4/CORBA.h>
#include <omniORB4/Naming.hh>

#include <stdexcept>
#include <string>
#include <vector>

namespace caliper::rtc {

/// The naming service (or a component) could not be reached; the message says which address.
class Unreachable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A name that is not bound.
class NotFound : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The address clients use: `--nameservice` if given, else $CALIPER_NAMESERVICE, else
/// corbaname::127.0.0.1:2809.
std::string NamingAddress(const std::string& from_option);

/// Resolves and checks the root context at `address` (corbaname::HOST:PORT); throws Unreachable.
CosNaming::NamingContext_ptr ResolveRoot(CORBA::ORB_ptr orb, const std::string& address);

struct ComponentEntry {
  std::string host;      ///< the host context, without `.host_cxt`
  std::string instance;  ///< e.g. model0
  std::string path;      ///< host.host_cxt/model0.rtc
  CORBA::Object_var object;
};

/// Every `<host>.host_cxt/<instance>.rtc` binding, sorted by host and instance.
std::vector<ComponentEntry> ListComponents(CosNaming::NamingContext_ptr root);

/// Finds `model0`, `model0@host`, `host/model0` or `host.host_cxt/model0.rtc`; prefers this host when several
/// hosts have the instance. Throws NotFound listing what is bound.
ComponentEntry FindComponent(CosNaming::NamingContext_ptr root, const std::string& name);

/// `host.host_cxt/instance.rtc` as a CosNaming name.
CosNaming::Name ComponentName(const std::string& host, const std::string& instance);

/// True when the object answers (a dead or unreachable object is false, never an exception).
bool ObjectAlive(CORBA::Object_ptr object);

/// A short description of a CORBA system exception, e.g. `TRANSIENT (connect failed)`.
std::string Describe(const CORBA::Exception& e);

}  // namespace caliper::rtc
