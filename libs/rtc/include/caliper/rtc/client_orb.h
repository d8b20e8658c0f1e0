#pragma once
// The ORB of a client program (the Main Window, the plotter, the log viewer, caliper-ctl): one per
// process, listening for the callbacks it serves (data consumers, listeners) on the loopback
// interface, or in network mode on the address in $CALIPER_LISTEN (over TLS unless
// CALIPER_INSECURE=1; see transport_security.h).

#include <omniORB4/CORBA.h>

#include <string>

namespace caliper::rtc {

/// The largest GIOP message a Caliper ORB sends or accepts by default [bytes]: scenes and
/// recordings travel by content (omniORB's own default, 2 MiB, is too small for meshes).
constexpr long kMaxMessageBytes = 256L * 1024 * 1024;

/// `giop:tcp:ADDR:` for a listening address (an IPv6 one in brackets; ResolveSecurity makes it
/// giop:ssl:ADDR: over TLS); throws std::invalid_argument for an empty or malformed one.
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

/// The process's ORB: initialised on the first call (endpoint giop:unix: in a directory only this
/// user can enter, local_sockets.h; or in network
/// mode giop:ssl:$CALIPER_LISTEN: over TLS, giop:tcp:$CALIPER_LISTEN: with CALIPER_INSECURE=1;
/// network mode also when the naming service, `naming_address` or else $CALIPER_NAMESERVICE, is
/// not on loopback: see transport_security.h; per-thread call timeouts enabled; messages up to
/// kMaxMessageBytes; `program` names it; outgoing calls and connections time out after
/// `call_timeout_s` when it is > 0), the same ORB afterwards (also when the process initialised
/// one itself before: then its options stand). Throws SecurityError in network mode without
/// usable certificates (the message says which `launch/caliper certs` commands make them).
CORBA::ORB_ptr ClientOrb(const char* program = "caliper", double call_timeout_s = 0,
                         const std::string& naming_address = "");

/// Prints the loud warning of plain network mode (--insecure) on stderr.
void WarnInsecure(const std::string& program, const std::string& endpoint);

}  // namespace caliper::rtc
