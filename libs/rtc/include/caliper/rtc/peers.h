#pragma once
// What a server can tell about the client behind an object reference it was given (an observer,
// a consumer, a listener): which process it is, and whether that process is gone.

#include <omniORB4/CORBA.h>

#include <chrono>
#include <string>

namespace caliper::rtc {

/// The client a reference belongs to: "unix:SOCKET" for a local one, else "host:port" of its
/// first IIOP profile, i.e. the endpoint of the ORB that serves it (one per client process). The calling connection's peer does not
/// serve: every local client is 127.0.0.1, and one client may call over several connections.
/// A client can name other endpoints in references it makes, so per-client caps need a total cap
/// beside them. "(no IIOP address)" when the reference has none.
std::string ClientOf(CORBA::Object_ptr ref);

/// The process behind a reference is gone: the object does not exist, or nothing listens at its
/// address. Anything else (a timeout, a broken connection, a refused call) may pass.
bool PeerGone(const CORBA::Exception& e);

/// The same, asked about `ref`: a local object (on a unix socket) is gone only when nothing
/// listens on its socket, since omniORB reports a failed connect to the placeholder address of
/// its IIOP profile (port 0) after a call to a slow peer timed out.
bool PeerGone(const CORBA::Exception& e, CORBA::Object_ptr ref);

/// Why `ref` cannot be taken as a `what` (e.g. "SceneObserver") of `repository_id`: it does not
/// exist, does not answer within `timeout`, or is another type (asked of the object itself:
/// omniORB answers _is_a locally from the reference's static type); "" when it can. Sets the
/// reference's call timeout to `timeout`.
std::string Unreachable(CORBA::Object_ptr ref, const char* what, const char* repository_id,
                        std::chrono::milliseconds timeout);

}  // namespace caliper::rtc
