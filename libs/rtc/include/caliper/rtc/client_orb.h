#pragma once
// The ORB of a client program (the Main Window, the plotter, the log viewer, caliper-ctl): one per
// process, listening for the callbacks it serves (data consumers, listeners) on the loopback
// interface, or in network mode on the address in $CALIPER_LISTEN.

#include <omniORB4/CORBA.h>

#include <string>

namespace caliper::rtc {

/// The largest GIOP message a Caliper ORB sends or accepts by default [bytes]: scenes and
/// recordings travel by content (omniORB's own default, 2 MiB, is too small for meshes).
constexpr long kMaxMessageBytes = 256L * 1024 * 1024;

/// `giop:tcp:ADDR:` for a listening address (an IPv6 one in brackets); throws
/// std::invalid_argument for an empty or malformed one.
std::string ListenEndpoint(const std::string& address);

/// Makes the calling thread known to omniORB for its lifetime, which per-thread call timeouts
/// need (a std::thread is not an omni_thread); does nothing in a thread omniORB already knows.
class OmniThread {
 public:
  OmniThread();
  ~OmniThread();
  OmniThread(const OmniThread&) = delete;
  OmniThread& operator=(const OmniThread&) = delete;

 private:
  bool dummy_;
};

/// The process's ORB: initialised on the first call (endpoint giop:tcp:127.0.0.1, or
/// giop:tcp:$CALIPER_LISTEN: in network mode; per-thread call timeouts enabled; messages up to
/// kMaxMessageBytes; `program` names it; outgoing calls and connections time out after
/// `call_timeout_s` when it is > 0), the same ORB afterwards (also when the process initialised
/// one itself before: then its options stand).
CORBA::ORB_ptr ClientOrb(const char* program = "caliper", double call_timeout_s = 0);

}  // namespace caliper::rtc
