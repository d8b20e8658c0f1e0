#pragma once
// A local session (no --listen) is reachable only by the user who started it: its processes
// listen on unix-domain sockets (omniORB's giop:unix: endpoints), not on TCP, in a directory that
// only that user can enter (mode 0700). Another user's connect() is refused by the kernel
// (EACCES), before omniORB reads a byte; root is not kept out (nothing on the machine keeps root
// out). The naming service of such a session listens on DIR/naming.sock and is addressed as
// corbaname:omniunix:DIR/naming.sock.
//
// The directory: $CALIPER_SOCKET_DIR (launch/caliper sets the session's DIR/sock), else the
// launcher's state directory, ${XDG_RUNTIME_DIR:-/tmp}/caliper-UID.

#include <omniORB4/CORBA.h>
#include <omniORB4/IIOP.h>

#include <functional>

#include <string>
#include <vector>

namespace caliper::rtc {

/// The endpoint a local process listens on.
inline constexpr const char* kLocalEndpoint = "giop:unix:";

/// Where this process's unix-domain sockets go: made (mode 0700) when missing, and checked: a
/// directory (not a link) of this user that no other user can enter, with room for a socket name
/// (at most 87 bytes: a socket path holds 107, and a name follows), an absolute path without %, :,
/// , or #. Throws SecurityError saying what is wrong and what
/// to do (CALIPER_SOCKET_DIR). The default directory is closed (0700) when it is ours; one of
/// another user (squatted) is not used: a private /tmp/caliper-UID-XXXXXX is made instead, and
/// said on stderr.
std::string LocalSocketDir();

/// The same, decided afresh from the environment (LocalSocketDir keeps the first answer).
std::string ResolveLocalSocketDir();

/// The omniORB options that put a giop:unix: endpoint's socket in LocalSocketDir(), readable
/// and writable by this user only.
std::vector<std::string> LocalSocketOrbOptions();

/// True for a corbaname:/corbaloc: address of a unix-domain socket (corbaname:omniunix:PATH).
bool IsLocalSocketAddress(const std::string& address);

/// The socket file of such an address ('' for another kind).
std::string LocalSocketPath(const std::string& address);

/// The address of the naming service listening on the unix socket PATH.
std::string LocalNamingAddress(const std::string& socket_path);

/// The socket file in omniORB's unix transport component of a reference ('' when it has none).
std::string UnixSocketOfComponent(const IOP::TaggedComponent& component);

/// Calls `visit` with each IIOP profile of `ref` that reads (a malformed one is passed over)
/// until it returns true; false when none did.
bool VisitIiopProfiles(CORBA::Object_ptr ref,
                       const std::function<bool(const IIOP::ProfileBody&)>& visit);

/// The unix socket of `ref` (its first IIOP profile's unix transport component), '' for a
/// reference without one (a network object).
std::string UnixSocketOf(CORBA::Object_ptr ref);

/// True when something listens on the unix socket `path`: a connect() there is not refused
/// (ECONNREFUSED: a file left by a process that is gone) and the file exists; true when it cannot
/// tell (a path too long to try, no socket to try with). omniORB tries a
/// local object's other addresses after a call timed out (its IIOP profile's placeholder, port
/// 0, which always fails to connect): a failed connect alone does not tell that it is gone.
bool LocalSocketListening(const std::string& path);

/// Why this process cannot connect to the unix socket `path`: a directory on the way that this
/// user cannot enter (its owner and mode: another user's session), a socket it may not write, no
/// socket at all (the session ended) or one nothing listens on (its process was killed). '' when
/// nothing stands in the way.
std::string LocalSocketNote(const std::string& path, const std::string& what);

}  // namespace caliper::rtc
