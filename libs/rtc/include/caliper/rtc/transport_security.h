#pragma once
// How a process talks to the others: locally in plain GIOP over unix-domain sockets that only its
// user can reach (a session on one host, nothing to configure: local_sockets.h), or on a network
// over TLS with client certificates (omniORB's SSL transport,
// libomnisslTP4), or on a network in plain GIOP when asked explicitly (--insecure).
//
// Network mode: the process listens on an address other than loopback (--listen ADDR,
// $CALIPER_LISTEN, corba.endpoint, a -ORBendPoint option) or its naming service is not on
// loopback. Loopback means 127.0.0.0/8, ::1 or the name localhost: any other host name is a
// network address. TLS then:
//  - listens on giop:ssl:ADDR: and refuses plain TCP on every endpoint, also one passed as
//    -ORBendPoint (serverTransportRule "* ssl"), calls out over TLS only (clientTransportRule),
//    naming addresses corbaname::H:P mean corbaname:ssliop:H:P;
//  - proves itself with an identity made by `launch/caliper certs`: PKI/hosts/NAME.pem (a
//    component; NAME = the host it binds under) or PKI/users/NAME.pem (a client; NAME = $USER),
//    with the key's password in NAME.pass beside it; PKI is $CALIPER_PKI, else
//    ~/.config/caliper/pki; peers must show a certificate of the CA in PKI/ca.pem.
// Environment: CALIPER_PKI, CALIPER_TLS_IDENTITY (hosts/NAME, users/NAME or the path of a .pem),
// CALIPER_INSECURE=1 (plain network mode). A component exports what it resolved, so that the
// processes it starts (the manager's Models) use the same.

#include <omniORB4/CORBA.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace caliper::rtc {

/// Network mode without usable certificates, or contradictory settings; the message says what to
/// run (launch/caliper certs ...).
class SecurityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Transport {
  kLoopback,  ///< local: plain GIOP on unix sockets (or loopback TCP when asked): one host
  kTls,       ///< network mode over TLS with client certificates
  kInsecure,  ///< network mode in plain GIOP (--insecure): anyone who reaches a port is trusted
};

/// What a process was asked for (command line, configuration, environment).
struct SecurityRequest {
  std::string endpoint;        ///< the omniORB endpoint it listens on, e.g. giop:tcp:127.0.0.1:
  std::string naming_address;  ///< its naming service (corbaname::HOST:PORT)
  std::vector<std::string> extra_endpoints;  ///< -ORBendPoint options passed through to omniORB
  bool insecure = false;       ///< --insecure, corba.insecure, $CALIPER_INSECURE
  std::string pki_dir;         ///< '' = $CALIPER_PKI, else ~/.config/caliper/pki
  std::string identity;        ///< '' = $CALIPER_TLS_IDENTITY, else the default below
  bool component = false;      ///< default identity hosts/HOST (else users/$USER), other second
};

/// What a process does: its transport, its endpoint and, over TLS, its files.
struct TransportSecurity {
  Transport transport = Transport::kLoopback;
  std::string endpoint;   ///< giop:ssl:ADDR: over TLS on a network address, else as requested
  bool network_endpoint = false;  ///< listens on an address other hosts reach
  std::string pki_dir;
  std::string identity;   ///< hosts/NAME, users/NAME or a file path
  std::string ca_file;    ///< PKI/ca.pem
  std::string key_file;   ///< the identity's PEM: encrypted key, certificate, CA
  std::string key_password;
};

/// True for `$CALIPER_INSECURE` set to 1, true or yes.
bool InsecureFromEnvironment();

/// Decides the transport and finds the files; throws SecurityError (network mode without a CA
/// or an identity, with the `launch/caliper certs` commands that make them; an unreadable file;
/// an ssl endpoint with --insecure) and std::invalid_argument for a malformed endpoint.
TransportSecurity ResolveSecurity(const SecurityRequest& request);

/// The -ORB options (name, value pairs flattened) for `security` besides the endpoint: over TLS
/// the transport rules that refuse plain GIOP in and out, whatever the endpoints. Over TLS it
/// also configures omniORB's SSL context (CA, key, password, verification of the peer,
/// handshake diagnostics) for the ORB about to be initialised.
std::vector<std::string> SecurityOrbOptions(const TransportSecurity& security);

/// Records `security` as this process's (for SecureNamingAddress and the diagnostics) and
/// exports CALIPER_INSECURE / CALIPER_PKI / CALIPER_TLS_IDENTITY for the processes it starts.
void InstallProcessSecurity(const TransportSecurity& security);

/// After ORB_init: without TLS, watches the references the process decodes, so that a call to an
/// object with only a TLS address can be told apart from one to a dead peer.
void InstallTransportDiagnostics();

/// This process's transport security (loopback before InstallProcessSecurity).
const TransportSecurity& ProcessSecurity();

/// Over TLS, a corbaname:/corbaloc: address with the plain protocol ("::", ":iiop:") turned into
/// ":ssliop:"; otherwise the address unchanged.
std::string SecureNamingAddress(const std::string& address);

/// The HOST of corbaname:[PROTOCOL]:HOST:PORT[...] or corbaloc:..., '' when it has none.
std::string AddressHost(const std::string& address);

/// True for the addresses 127.0.0.0/8, ::1 (and ::ffff:127.x.y.z) and the name localhost;
/// false for any other name (127.example.com too) and for '' (every interface).
bool IsLoopbackHost(const std::string& host);

/// Why a call that failed with `e` may have failed at the transport, for the caller's message:
/// over TLS, the last handshake failure of this thread (the peer refused our certificate, or its
/// certificate is not of our CA, or it does not speak TLS); without TLS, a reference that only
/// TLS can reach. '' when there is nothing to add.
std::string TransportFailureNote(const CORBA::Exception& e);

/// For a naming service that could not be reached at `address`: asks it for a TLS handshake
/// with OpenSSL (2 s at most) and says whether it requires TLS when this process runs without,
/// or how the handshake fails. '' when the probe finds nothing to add.
std::string ProbeNamingService(const std::string& address);

/// The same for the process at HOST:PORT, named `where` in the message.
std::string ProbeTls(const std::string& host, const std::string& port, const std::string& where);

}  // namespace caliper::rtc
