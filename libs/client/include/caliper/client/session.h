#pragma once
// The connection to a Caliper session: the process's ORB and the session's naming service, and
// the components bound in it. Every client (caliper-ctl, caliper-calibrate, the GUI tools, the
// Python package) starts here.
//
//   client::Session session({"", 5.0, "my-tool"});      // the latest session, 5 s per call
//   client::ModelRef m = client::ConnectModel(session, "model0");
//
// The ORB is made on the first call that needs it (rtc::ClientOrb: loopback, or TLS when the
// naming service is on a network), so that a program working on files alone needs no session.
// Threads that call into the ORB must be known to omniORB (rtc::OmniThread); the library's own
// threads are.

#include <string>

#include "caliper/client/errors.h"
#include "caliper/rtc.hh"
#include "caliper/rtc/naming.h"

namespace caliper::client {

/// The naming service of the newest session the launcher started on this host for this user and
/// that still runs (`launch/caliper session` or `demo` writes it to
/// ${XDG_RUNTIME_DIR:-/tmp}/caliper-UID/latest-session: the address, the naming service's pid,
/// the session's directory); "" when there is none or its naming service has ended.
std::string LatestSession();

/// Which naming service a client uses and why.
struct NamingChoice {
  std::string address;
  std::string source;  ///< "--nameservice", "$CALIPER_NAMESERVICE", "the newest running session (DIR)", ...
  std::string note;    ///< why $CALIPER_NAMESERVICE was passed over ("" when it was not)
};

/// Where a session's naming service is: `option` when given, else $CALIPER_NAMESERVICE, else
/// the latest session (LatestSession), else the one of `launch/caliper nameserver start`, else
/// corbaname::127.0.0.1:2809. A $CALIPER_NAMESERVICE naming a local session whose socket nobody
/// listens on any more (exported from a session that has ended) gives way to the latest session
/// or that naming service, with a note saying so; a network address is always kept.
NamingChoice ChooseNamingAddress(const std::string& option);

/// ChooseNamingAddress's address; its note, when there is one, goes to stderr (once a process).
std::string ResolveNamingAddress(const std::string& option);

struct SessionOptions {
  /// corbaname::HOST:PORT; "" for ResolveNamingAddress's choice.
  std::string nameservice;
  /// Every call's deadline [s]; 0 for none.
  double timeout_s = 5.0;
  /// The program's name in the ORB's messages.
  std::string program = "caliper-client";
};

class Session {
 public:
  explicit Session(SessionOptions options) : options_(std::move(options)) {}
  /// Destroys the process's ORB once it was started.
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// The naming service's root context; ConnectionError when it cannot be reached (the message
  /// says how to start a session or pass its address).
  CosNaming::NamingContext_ptr Root();
  /// A component by instance name (model0), host/instance or naming path; Failure when it is
  /// not bound (the message lists what is).
  rtc::ComponentEntry Find(const std::string& name);
  /// Every component bound, sorted by host and instance.
  std::vector<rtc::ComponentEntry> List();
  /// A component's lifecycle object; `*path` receives its naming path.
  ::Caliper::RTC::LightweightRTObject_ptr Component(const std::string& name,
                                                    std::string* path = nullptr);
  /// "cannot reach PATH: ... (the process may have died; its name is stale)".
  static std::string Unreachable(const std::string& path, const CORBA::Exception& e);

  CORBA::ORB_ptr orb();
  /// The RootPOA, its manager activated: for servants in the client (listeners, consumers).
  PortableServer::POA_ptr RootPoa();
  /// The naming service's address this session uses.
  const std::string& address();
  /// Where that address came from (NamingChoice::source).
  const std::string& address_source() {
    address();
    return source_;
  }
  const SessionOptions& options() const { return options_; }

 private:
  void Connect();

  SessionOptions options_;
  CORBA::ORB_var orb_;
  std::string address_;
  std::string source_;
};

}  // namespace caliper::client
