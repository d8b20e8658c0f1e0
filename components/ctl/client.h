#pragma once
// caliper-ctl's connection to a session and the pieces every verb shares: the verb table entry,
// the two kinds of errors (usage: exit 2, failure: exit 1) and option parsing.

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "arguments.h"
#include "caliper/rtc.hh"
#include "caliper/rtc/naming.h"

namespace caliper::ctl {

/// A failure the user should read: exit code 1.
struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Global options (before the verb).
struct Options {
  std::string nameservice;
  double timeout_s = 5.0;
};

/// The connection to a session: the ORB is started by the first verb that needs it, so that
/// verbs working on files alone (inspect) run without a naming service.
class Client {
 public:
  explicit Client(const Options& options) : options_(options) {}
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  /// The naming service's root context; Failure when it cannot be reached.
  CosNaming::NamingContext_ptr Root();
  /// A component by instance name or naming path; Failure when it is not bound.
  rtc::ComponentEntry Find(const std::string& name);
  /// A component's lifecycle object; `*path` receives its naming path.
  ::Caliper::RTC::LightweightRTObject_ptr Component(const std::string& name,
                                                    std::string* path = nullptr);
  /// "cannot reach PATH: ... (the process may have died; its name is stale)".
  static std::string Unreachable(const std::string& path, const CORBA::Exception& e);

  CORBA::ORB_ptr orb();
  /// The RootPOA, its manager activated: for servants in the client (listeners, consumers).
  PortableServer::POA_ptr RootPoa();
  const std::string& address();

 private:
  void Connect();

  Options options_;
  CORBA::ORB_var orb_;
  std::string address_;
};

/// One verb of the command line: `usage` (after `caliper-ctl `), a one-line summary for the
/// verb list, the group it is listed in, more lines for `VERB --help` (may be empty), and
/// whether it takes Ctrl-C itself (then SIGINT and SIGTERM are blocked in every thread and the
/// verb waits for them with sigwait).
struct Verb {
  std::string usage;
  std::string summary;
  std::function<int(Client&, std::vector<std::string>&)> run;
  std::string group = "components";
  std::string details;
  bool takes_interrupt = false;
};

}  // namespace caliper::ctl
