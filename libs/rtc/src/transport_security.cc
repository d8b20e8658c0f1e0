#include "caliper/rtc/transport_security.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <pwd.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <omniORB4/omniInterceptors.h>
#include <omniORB4/sslContext.h>  // also forces the link of libomnisslTP4 (OMNI_FORCE_LINK)
#include <openssl/err.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <vector>

#include "caliper/core/system.h"
#include "caliper/rtc/local_sockets.h"

namespace caliper::rtc {

namespace {

using Clock = std::chrono::steady_clock;

// this process's settings; strings that omniORB's SSL context points to live here
std::mutex g_mutex;
TransportSecurity g_security;

// the last TLS failure seen by this thread (a call's connection is made and read in the calling
// thread), kept for the message of the exception that follows it
struct HandshakeNote {
  std::string text;
  Clock::time_point when;
};
thread_local HandshakeNote t_note;
// our certificate chain was refused, the peer's failed verification, set by the callbacks
thread_local std::string t_verify_error;
// the peer of this thread's last handshake, and when it began
thread_local std::string t_peer;
thread_local Clock::time_point t_peer_when;
// a process without TLS: the hosts of the references this thread decoded lately that have only
// a TLS address (their plain IIOP port is 0), which that process's calls cannot reach; several
// when it decoded several (a listing), since a failed call does not say which object it was for
constexpr size_t kMaxTlsOnlyHosts = 8;
thread_local std::vector<HandshakeNote> t_tls_only;
// the unix sockets of the local references this thread decoded lately (another user's session
// refuses us at connect(), and the failed call does not say which socket it was)
constexpr size_t kMaxLocalSockets = 8;
thread_local std::vector<HandshakeNote> t_local_sockets;

std::string Trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

bool Readable(const std::string& path) { return access(path.c_str(), R_OK) == 0; }

std::string UserName() {
  const char* user = std::getenv("USER");
  if (user != nullptr && *user != '\0') return user;
  if (const passwd* pw = getpwuid(getuid()); pw != nullptr) return pw->pw_name;
  return "user";
}

std::string OpenSslErrors() {
  std::string text;
  char buf[256];
  while (const unsigned long code = ERR_get_error()) {
    ERR_error_string_n(code, buf, sizeof buf);
    text += (text.empty() ? "" : "; ") + std::string(ERR_reason_error_string(code) != nullptr
                                                         ? ERR_reason_error_string(code)
                                                         : buf);
  }
  return text.empty() ? "unknown OpenSSL error" : text;
}

// "giop:PROTO:HOST:PORT" -> PROTO and HOST (HOST without brackets; empty = every interface)
void SplitEndpoint(const std::string& endpoint, std::string* proto, std::string* host) {
  if (endpoint.rfind("giop:", 0) != 0)
    throw std::invalid_argument("endpoint '" + endpoint + "': expected giop:PROTOCOL:...");
  const size_t colon = endpoint.find(':', 5);
  if (colon == std::string::npos)
    throw std::invalid_argument("endpoint '" + endpoint + "': expected giop:PROTOCOL:...");
  *proto = endpoint.substr(5, colon - 5);
  std::string rest = endpoint.substr(colon + 1);
  if (*proto != "tcp" && *proto != "ssl") {
    host->clear();
    return;
  }
  if (!rest.empty() && rest.front() == '[') {
    const size_t close = rest.find(']');
    *host = rest.substr(1, close == std::string::npos ? std::string::npos : close - 1);
  } else {
    *host = rest.substr(0, rest.rfind(':'));
  }
}

// "corbaname:PROTO:ADDR..." -> the part after the scheme, or "" for another kind of address
std::string AfterScheme(const std::string& address) {
  for (const char* scheme : {"corbaname:", "corbaloc:"})
    if (address.rfind(scheme, 0) == 0) return address.substr(std::strlen(scheme));
  return "";
}

// the protocol of a corbaname:/corbaloc: address ("" for "::", iiop, ssliop, ...)
std::string AddressProtocol(const std::string& address) {
  const std::string rest = AfterScheme(address);
  const size_t colon = rest.find(':');
  return colon == std::string::npos ? "" : rest.substr(0, colon);
}

// HOST and PORT of the first address of a corbaname:/corbaloc: address
bool AddressHostPort(const std::string& address, std::string* host, std::string* port) {
  std::string rest = AfterScheme(address);
  const size_t colon = rest.find(':');
  if (colon == std::string::npos) return false;
  rest = rest.substr(colon + 1);
  rest = rest.substr(0, rest.find_first_of("/#,"));
  if (const size_t at = rest.find('@'); at != std::string::npos) rest = rest.substr(at + 1);
  *port = "2809";
  if (!rest.empty() && rest.front() == '[') {
    const size_t close = rest.find(']');
    if (close == std::string::npos) return false;
    *host = rest.substr(1, close - 1);
    if (close + 1 < rest.size() && rest[close + 1] == ':') *port = rest.substr(close + 2);
  } else {
    const size_t c = rest.find(':');
    *host = rest.substr(0, c);
    if (c != std::string::npos) *port = rest.substr(c + 1);
  }
  return !host->empty();
}

std::string ProtoName(int version) {
  return version == TLS1_3_VERSION ? "TLS 1.3" : version == TLS1_2_VERSION ? "TLS 1.2" : "TLS";
}

std::string PeerOf(const SSL* ssl) {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  const int fd = SSL_get_fd(ssl);
  if (fd < 0 || getpeername(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) return "the peer";
  char host[NI_MAXHOST], port[NI_MAXSERV];
  if (getnameinfo(reinterpret_cast<sockaddr*>(&addr), len, host, sizeof host, port, sizeof port,
                  NI_NUMERICHOST | NI_NUMERICSERV) != 0)
    return "the peer";
  return std::string(host) + ":" + port;
}

void Note(const std::string& text) {
  t_note.text = text;
  t_note.when = Clock::now();
}

// a peer's certificate that fails verification: remembered for the alert that follows
int VerifyCallback(int ok, X509_STORE_CTX* ctx) {
  if (!ok) {
    const int err = X509_STORE_CTX_get_error(ctx);
    std::string subject = "?";
    if (X509* cert = X509_STORE_CTX_get_current_cert(ctx); cert != nullptr) {
      char buf[256];
      X509_NAME_oneline(X509_get_subject_name(cert), buf, sizeof buf);
      subject = buf;
    }
    t_verify_error = std::string(X509_verify_cert_error_string(err)) + ", certificate " + subject;
  }
  return ok;
}

// fatal alerts in either direction: who refused whom, and why
void InfoCallback(const SSL* ssl, int where, int ret) {
  // the peer's address while the connection stands: after a refusal it may be reset
  if (where & SSL_CB_HANDSHAKE_START) {
    t_peer = PeerOf(ssl);
    t_peer_when = Clock::now();
  }
  if ((where & SSL_CB_ALERT) == 0 || (ret >> 8) != SSL3_AL_FATAL) return;
  const std::string alert = SSL_alert_desc_string_long(ret);
  std::string peer = PeerOf(ssl);
  if (peer == "the peer" && !t_peer.empty()) peer = t_peer;
  std::lock_guard<std::mutex> lock(g_mutex);
  const std::string ca = g_security.ca_file.empty() ? "our CA" : g_security.ca_file;
  if (where & SSL_CB_READ) {
    std::string why;
    const int code = ret & 0xff;
    if (code == SSL_AD_UNKNOWN_CA || code == SSL_AD_BAD_CERTIFICATE ||
        code == SSL_AD_CERTIFICATE_UNKNOWN || code == SSL_AD_DECRYPT_ERROR)
      why = ": it accepts only certificates of its own CA, and ours (" + g_security.key_file +
            ") is not one; use an identity made with the cluster's CA (launch/caliper certs)";
    else if (code == SSL_AD_CERTIFICATE_REQUIRED || code == SSL_AD_HANDSHAKE_FAILURE)
      why = ": it requires a certificate of the cluster's CA";
    Note(peer + " refused the TLS handshake (alert '" + alert + "')" + why);
  } else if (!t_verify_error.empty()) {
    Note("the certificate of " + peer + " is not signed by the cluster's CA (" + ca +
         "): " + t_verify_error + "; it belongs to another cluster, or its CA is not ours");
    t_verify_error.clear();
  } else if (SSL_in_init(ssl)) {
    // no refusal by the peer and no certificate of its we refused: what it sent broke off or made
    // no sense (a peer killed mid-handshake, or no TLS on that port), not a question of CAs
    Note("the connection to " + peer + " broke off during the TLS handshake (we sent alert '" +
         alert + "'): the peer closed it or died, or does not speak TLS there");
  }
  // an alert of ours on an established connection: the peer died or the connection broke
  // mid-message (a killed peer), which the exception itself says
}

void LogWithoutSslNotice(const char* message) {
  if (std::strstr(message, "SSL CA certificate location is not set") != nullptr) return;
  std::fputs(message, stderr);
}

// `text` as the newest of `notes`, at most `max` kept
void Remember(std::vector<HandshakeNote>* notes, const std::string& text, size_t max) {
  auto seen = std::find_if(notes->begin(), notes->end(),
                           [&](const HandshakeNote& n) { return n.text == text; });
  if (seen != notes->end()) notes->erase(seen);
  if (notes->size() == max) notes->erase(notes->begin());
  notes->push_back({text, Clock::now()});
}

// notes the references whose only address is a TLS one (without TLS), and those on a unix socket
CORBA::Boolean DecodeIor(omni::omniInterceptors::decodeIOR_T::info_T& info) {
  if (!info.has_iiop_body || info.iiop.address.port != 0) return true;
  for (CORBA::ULong i = 0; i < info.iiop.components.length(); ++i) {
    const IOP::TaggedComponent& component = info.iiop.components[i];
    if (component.tag == IOP::TAG_OMNIORB_UNIX_TRANS) {
      if (const std::string file = UnixSocketOfComponent(component); !file.empty())
        Remember(&t_local_sockets, file, kMaxLocalSockets);
    } else if (component.tag == IOP::TAG_SSL_SEC_TRANS) {
      Remember(&t_tls_only, info.iiop.address.host.in(), kMaxTlsOnlyHosts);
    }
  }
  return true;
}

int PasswordCallback(char* buf, int size, int, void* user) {
  const auto* password = static_cast<const std::string*>(user);
  const int n = static_cast<int>(std::min<size_t>(password->size(), static_cast<size_t>(size)));
  std::memcpy(buf, password->data(), static_cast<size_t>(n));
  return n;
}

struct SslCtxFree {
  void operator()(SSL_CTX* c) const { SSL_CTX_free(c); }
};
struct SslFree {
  void operator()(SSL* s) const { SSL_free(s); }
};
using SslCtxPtr = std::unique_ptr<SSL_CTX, SslCtxFree>;
using SslPtr = std::unique_ptr<SSL, SslFree>;

// loads the identity as omniORB will (chain and encrypted key from one PEM) and verifies it
// against the CA, so that a wrong password or a foreign certificate is an error now rather than
// handshakes that fail without a word
void CheckIdentity(const TransportSecurity& s) {
  ERR_clear_error();
  SslCtxPtr ctx(SSL_CTX_new(TLS_method()));
  if (!ctx) throw SecurityError("OpenSSL: " + OpenSslErrors());
  std::string password = s.key_password;
  SSL_CTX_set_default_passwd_cb(ctx.get(), PasswordCallback);
  SSL_CTX_set_default_passwd_cb_userdata(ctx.get(), &password);
  if (SSL_CTX_load_verify_locations(ctx.get(), s.ca_file.c_str(), nullptr) != 1)
    throw SecurityError("TLS: cannot read the CA certificate " + s.ca_file + ": " +
                        OpenSslErrors());
  if (SSL_CTX_use_certificate_chain_file(ctx.get(), s.key_file.c_str()) != 1)
    throw SecurityError("TLS: no certificate in " + s.key_file + ": " + OpenSslErrors() +
                        " (expected the key, the certificate and the CA's, as launch/caliper "
                        "certs writes them)");
  if (SSL_CTX_use_PrivateKey_file(ctx.get(), s.key_file.c_str(), SSL_FILETYPE_PEM) != 1)
    throw SecurityError("TLS: the private key in " + s.key_file +
                        " does not load with the password of its .pass file: " + OpenSslErrors());
  if (SSL_CTX_check_private_key(ctx.get()) != 1)
    throw SecurityError("TLS: the key in " + s.key_file + " does not match its certificate");
  // the certificate against the CA of ca.pem (not against the CA copy inside the .pem)
  X509* cert = SSL_CTX_get0_certificate(ctx.get());
  X509_STORE* store = SSL_CTX_get_cert_store(ctx.get());
  std::unique_ptr<X509_STORE_CTX, decltype(&X509_STORE_CTX_free)> verify(X509_STORE_CTX_new(),
                                                                         X509_STORE_CTX_free);
  if (!verify || X509_STORE_CTX_init(verify.get(), store, cert, nullptr) != 1)
    throw SecurityError("OpenSSL: " + OpenSslErrors());
  if (X509_verify_cert(verify.get()) != 1)
    throw SecurityError("TLS: the certificate in " + s.key_file + " does not verify against " +
                        s.ca_file + ": " +
                        X509_verify_cert_error_string(X509_STORE_CTX_get_error(verify.get())) +
                        " (it was made with another CA, or has expired)");
}

std::string CertsHint(const std::string& pki_dir_arg) {
  return "make the cluster's CA once with `launch/caliper certs ca" + pki_dir_arg +
         "`, an identity per host with `launch/caliper certs host NAME` and per user with "
         "`launch/caliper certs user NAME`, and copy ca.pem and the host's NAME.pem and "
         "NAME.pass to each host (or run with --insecure: plain GIOP that anyone who reaches "
         "the ports may use)";
}

// a TCP connection to HOST:PORT within timeout_ms; -1 when none
int Connect(const std::string& host, const std::string& port, int timeout_ms) {
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), port.c_str(), &hints, &found) != 0) return -1;
  int fd = -1;
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    if (connect(fd, a->ai_addr, a->ai_addrlen) == 0) break;
    if (errno == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      int err = 0;
      socklen_t len = sizeof err;
      if (poll(&p, 1, timeout_ms) == 1 && getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len) == 0 &&
          err == 0)
        break;
    }
    close(fd);
    fd = -1;
  }
  freeaddrinfo(found);
  if (fd < 0) return -1;
  // blocking again, with timeouts for the handshake
  timeval tv{timeout_ms / 1000, (timeout_ms % 1000) * 1000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
  const int fl = fcntl(fd, F_GETFL);
  fcntl(fd, F_SETFL, fl & ~O_NONBLOCK);
  return fd;
}

}  // namespace

bool InsecureFromEnvironment() {
  const char* env = std::getenv("CALIPER_INSECURE");
  if (env == nullptr) return false;
  const std::string v = env;
  return v == "1" || v == "true" || v == "yes";
}

bool IsLoopbackHost(const std::string& host) {
  // addresses as numbers only: a host name such as 127.example.com may point anywhere
  if (strcasecmp(host.c_str(), "localhost") == 0) return true;
  in_addr v4{};
  if (inet_pton(AF_INET, host.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, host.c_str(), &v6) == 1)
    return IN6_IS_ADDR_LOOPBACK(&v6) || (IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127);
  return false;
}

std::string AddressHost(const std::string& address) {
  std::string host, port;
  return AddressHostPort(address, &host, &port) ? host : "";
}

TransportSecurity ResolveSecurity(const SecurityRequest& request) {
  TransportSecurity s;
  s.endpoint = request.endpoint;
  std::string proto, host;
  SplitEndpoint(request.endpoint, &proto, &host);
  s.network_endpoint = (proto == "tcp" || proto == "ssl") && !IsLoopbackHost(host);
  // endpoints passed to omniORB as they are (-ORBendPoint): one on a network address makes the
  // process a network one as much as its own endpoint does
  std::string extra_network, extra_ssl;
  for (const std::string& endpoint : request.extra_endpoints) {
    std::string extra_proto, extra_host;
    SplitEndpoint(endpoint, &extra_proto, &extra_host);
    if ((extra_proto == "tcp" || extra_proto == "ssl") && !IsLoopbackHost(extra_host) &&
        extra_network.empty())
      extra_network = endpoint;
    if (extra_proto == "ssl" && extra_ssl.empty()) extra_ssl = endpoint;
  }
  const std::string naming_host = AddressHost(request.naming_address);
  const bool naming_tls = AddressProtocol(request.naming_address) == "ssliop";
  const bool network = s.network_endpoint || proto == "ssl" || naming_tls ||
                       !extra_network.empty() || !extra_ssl.empty() ||
                       (!naming_host.empty() && !IsLoopbackHost(naming_host));
  if (!network) return s;
  if (request.insecure) {
    if (proto == "ssl" || !extra_ssl.empty())
      throw SecurityError("--insecure (plain network mode) with the TLS endpoint " +
                          (proto == "ssl" ? request.endpoint : extra_ssl) + ": drop one of them");
    if (naming_tls)
      throw SecurityError("--insecure (plain network mode) with the TLS naming service " +
                          request.naming_address + ": drop --insecure (CALIPER_INSECURE)");
    s.transport = Transport::kInsecure;
    return s;
  }
  s.transport = Transport::kTls;
  if (proto == "tcp" && s.network_endpoint) s.endpoint = "giop:ssl:" + request.endpoint.substr(9);

  s.pki_dir = request.pki_dir;
  if (s.pki_dir.empty())
    if (const char* env = std::getenv("CALIPER_PKI"); env != nullptr) s.pki_dir = env;
  if (s.pki_dir.empty()) s.pki_dir = "~/.config/caliper/pki";
  s.pki_dir = core::ExpandHome(s.pki_dir);
  const std::string dir_arg = request.pki_dir.empty() && std::getenv("CALIPER_PKI") == nullptr
                                  ? ""
                                  : " --dir " + s.pki_dir;
  const std::string why =
      "network mode uses TLS with certificates (" +
      (s.network_endpoint       ? "listening on " + request.endpoint
       : !extra_network.empty() ? "listening on " + extra_network + " (-ORBendPoint)"
                                : "naming service " + request.naming_address) +
      "): ";
  s.ca_file = s.pki_dir + "/ca.pem";
  if (!Readable(s.ca_file))
    throw SecurityError(why + "there is no CA certificate " + s.ca_file + "; " +
                        CertsHint(dir_arg));

  s.identity = request.identity;
  if (s.identity.empty())
    if (const char* env = std::getenv("CALIPER_TLS_IDENTITY"); env != nullptr) s.identity = env;
  auto pem_of = [&](const std::string& identity) {
    const bool path = identity.size() > 4 && identity.compare(identity.size() - 4, 4, ".pem") == 0;
    return path ? core::ExpandHome(identity) : s.pki_dir + "/" + identity + ".pem";
  };
  if (s.identity.empty()) {
    const std::string host_id = "hosts/" + core::HostName(), user_id = "users/" + UserName();
    const std::string first = request.component ? host_id : user_id;
    const std::string second = request.component ? user_id : host_id;
    s.identity = Readable(pem_of(first)) ? first : Readable(pem_of(second)) ? second : "";
    if (s.identity.empty())
      throw SecurityError(why + "no certificate for this " +
                          (request.component ? "host" : "user") + " in " + s.pki_dir +
                          " (looked for " + pem_of(first) + " and " + pem_of(second) + "); " +
                          CertsHint(dir_arg) +
                          ". CALIPER_TLS_IDENTITY (or corba.tls.identity) picks another one");
  }
  s.key_file = pem_of(s.identity);
  if (!Readable(s.key_file))
    throw SecurityError(why + "cannot read the identity " + s.key_file + " (" +
                        std::strerror(errno) + "); " + CertsHint(dir_arg));
  const std::string pass_file = s.key_file.substr(0, s.key_file.size() - 4) + ".pass";
  std::ifstream in(pass_file);
  if (!in)
    throw SecurityError("TLS: cannot read the key password " + pass_file +
                        " (launch/caliper certs writes it beside the .pem; copy both)");
  std::stringstream text;
  text << in.rdbuf();
  s.key_password = Trim(text.str());
  // omniORB loads no key at all without a password (an empty one counts as none)
  if (s.key_password.empty())
    throw SecurityError("TLS: the key password file " + pass_file + " is empty");
  CheckIdentity(s);
  return s;
}

std::vector<std::string> SecurityOrbOptions(const TransportSecurity& security) {
  if (security.transport != Transport::kTls) {
    // the SSL transport is linked into every program: without TLS it says at each start that it
    // is disabled, which is as meant
    omniORB::setLogFunction(LogWithoutSslNotice);
    // a local process: its sockets in a directory only its user can enter
    if (security.endpoint.rfind("giop:unix:", 0) == 0) return LocalSocketOrbOptions();
    return {};
  }
  std::vector<std::string> options = {"-ORBclientTransportRule", "* ssl",
                                      "-ORBserverTransportRule", "* ssl"};
  if (security.endpoint.rfind("giop:unix:", 0) == 0)
    for (auto& o : LocalSocketOrbOptions()) options.push_back(o);
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    g_security = security;
    // omniORB keeps these pointers: they point into g_security, which lives as long as the process
    sslContext::certificate_authority_file = g_security.ca_file.c_str();
    sslContext::key_file = g_security.key_file.c_str();
    sslContext::key_file_password = g_security.key_password.c_str();
  }
  sslContext::verify_mode = SSL_VERIFY_PEER | SSL_VERIFY_FAIL_IF_NO_PEER_CERT;
  sslContext::verify_callback = VerifyCallback;
  sslContext::info_callback = InfoCallback;
  // TLS only, in and out, whatever the endpoints: a plain one passed as -ORBendPoint, set in
  // $ORBendPoint or in omniORB's configuration file listens, but refuses every connection
  return options;
}

void InstallProcessSecurity(const TransportSecurity& security) {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    if (security.transport != Transport::kTls || g_security.transport != Transport::kTls)
      g_security = security;
  }
  if (security.transport == Transport::kInsecure) setenv("CALIPER_INSECURE", "1", 1);
  if (security.transport == Transport::kTls) {
    unsetenv("CALIPER_INSECURE");
    setenv("CALIPER_PKI", security.pki_dir.c_str(), 1);
    setenv("CALIPER_TLS_IDENTITY", security.identity.c_str(), 1);
  }
}

void InstallTransportDiagnostics() {
  // without TLS only: a TLS process reaches no unix socket and no TLS-only reference is news to
  // it, and it would look at paths in references that remote clients give it
  static std::once_flag once;
  if (ProcessSecurity().transport != Transport::kTls)
    std::call_once(once, [] { omniORB::getInterceptors()->decodeIOR.add(DecodeIor); });
}

const TransportSecurity& ProcessSecurity() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_security;
}

std::string SecureNamingAddress(const std::string& address) {
  if (ProcessSecurity().transport != Transport::kTls) return address;
  for (const char* scheme : {"corbaname:", "corbaloc:"}) {
    const std::string s = scheme;
    if (address.rfind(s + ":", 0) == 0) return s + "ssliop:" + address.substr(s.size() + 1);
    if (address.rfind(s + "iiop:", 0) == 0) return s + "ssliop:" + address.substr(s.size() + 5);
  }
  return address;
}


std::string TransportFailureNote(const CORBA::Exception& e) {
  const auto* sys = CORBA::SystemException::_downcast(&e);
  if (sys == nullptr) return "";
  const std::string name = e._name();
  if (name != "TRANSIENT" && name != "COMM_FAILURE") return "";
  if (!t_note.text.empty() && Clock::now() - t_note.when < std::chrono::seconds(30)) {
    std::string note = t_note.text;
    t_note.text.clear();
    return note;
  }
  // over TLS 1.3 a peer refuses our certificate after our side of the handshake: the call may
  // fail sending before the alert is read. A TLS 1.2 handshake with that peer tells.
  if (ProcessSecurity().transport == Transport::kTls && !t_peer.empty() &&
      Clock::now() - t_peer_when < std::chrono::seconds(30)) {
    const std::string peer = t_peer;
    t_peer.clear();
    const size_t colon = peer.rfind(':');
    if (colon != std::string::npos) {
      const std::string note = ProbeTls(peer.substr(0, colon), peer.substr(colon + 1), peer);
      if (!note.empty()) return note;
    }
  }
  const std::string minor = sys->NP_minorString() != nullptr ? sys->NP_minorString() : "";
  if (minor == "TRANSIENT_ConnectFailed") {
    // a local object: another user's session, or one that has ended. The failed call does not
    // say which of the references read lately it was for: the newest unreachable one is named,
    // and how many others are unreachable too
    std::string note;
    size_t others = 0;
    for (auto n = t_local_sockets.rbegin(); n != t_local_sockets.rend(); ++n) {
      if (Clock::now() - n->when >= std::chrono::seconds(60)) break;  // older ones follow
      std::string why = LocalSocketNote(n->text, "the object");
      // the newest reference is most likely the one called: reachable, there is nothing to say
      // (older ones may be of processes long gone)
      if (n == t_local_sockets.rbegin() && why.empty()) break;
      if (why.empty()) continue;
      note.empty() ? note = why : (++others, note);
    }
    if (!note.empty()) {
      t_local_sockets.clear();
      if (others > 0)
        note = std::to_string(others + 1) + " local references read lately are unreachable; " +
               "the newest: " + note;
      return note;
    }
  }
  const std::string mode = ProcessSecurity().transport == Transport::kInsecure
                               ? "--insecure / CALIPER_INSECURE"
                               : "local mode";
  std::string hosts;  // of the TLS-only references decoded in the last minute, oldest first
  size_t count = 0;
  for (const HandshakeNote& n : t_tls_only)
    if (Clock::now() - n.when < std::chrono::seconds(60)) {
      hosts += (hosts.empty() ? "" : ", ") + n.text;
      ++count;
    }
  if (ProcessSecurity().transport != Transport::kTls && count > 0 &&
      (minor == "TRANSIENT_ConnectFailed" || minor == "TRANSIENT_NoUsableProfile")) {
    t_tls_only.clear();
    return "the object (on " + std::string(count > 1 ? "one of " : "") + hosts +
           ") is reachable only over TLS with a certificate of its cluster's CA; this process "
           "runs without TLS (" + mode + ")";
  }
  if (minor == "TRANSIENT_NoUsableProfile") {
    if (ProcessSecurity().transport == Transport::kTls)
      return "the object has no TLS address (its process runs without TLS, --insecure?), and "
             "this one talks only TLS on the network";
    return "the object is reachable only over TLS with a certificate of its cluster's CA; this "
           "process runs without TLS (" + mode + ")";
  }
  return "";
}

std::string ProbeNamingService(const std::string& address) {
  if (IsLocalSocketAddress(address))
    return LocalSocketNote(LocalSocketPath(address), "the naming service");
  std::string host, port;
  if (!AddressHostPort(address, &host, &port)) return "";
  return ProbeTls(host, port, "the naming service at " + host + ":" + port);
}

std::string ProbeTls(const std::string& host, const std::string& port, const std::string& where) {
  const TransportSecurity security = ProcessSecurity();
  const bool tls = security.transport == Transport::kTls;
  const int fd = Connect(host, port, 2000);
  if (fd < 0) return "nothing accepts connections at " + host + ":" + port;
  ERR_clear_error();
  SslCtxPtr ctx(SSL_CTX_new(TLS_client_method()));
  if (!ctx) {
    close(fd);
    return "";
  }
  // TLS 1.2: the server's verdict on our certificate comes within the handshake
  SSL_CTX_set_max_proto_version(ctx.get(), TLS1_2_VERSION);
  std::string password = security.key_password;
  if (tls) {
    SSL_CTX_set_default_passwd_cb(ctx.get(), PasswordCallback);
    SSL_CTX_set_default_passwd_cb_userdata(ctx.get(), &password);
    SSL_CTX_load_verify_locations(ctx.get(), security.ca_file.c_str(), nullptr);
    SSL_CTX_use_certificate_chain_file(ctx.get(), security.key_file.c_str());
    SSL_CTX_use_PrivateKey_file(ctx.get(), security.key_file.c_str(), SSL_FILETYPE_PEM);
    SSL_CTX_set_verify(ctx.get(), SSL_VERIFY_PEER, VerifyCallback);
    SSL_CTX_set_info_callback(ctx.get(), InfoCallback);
  } else {
    SSL_CTX_set_verify(ctx.get(), SSL_VERIFY_NONE, nullptr);
  }
  SslPtr ssl(SSL_new(ctx.get()));
  SSL_set_fd(ssl.get(), fd);
  t_note.text.clear();
  t_verify_error.clear();
  const bool ok = SSL_connect(ssl.get()) == 1;
  const bool spoke_tls = SSL_get0_peer_certificate(ssl.get()) != nullptr || ok;
  const std::string version = ProtoName(SSL_version(ssl.get()));
  std::string note = t_note.text;
  t_note.text.clear();
  ERR_clear_error();
  ssl.reset();
  close(fd);
  if (!tls) {
    if (!spoke_tls) return "";
    return where + " speaks TLS and requires a certificate of its cluster's CA; this process "
           "runs without TLS (" +
           std::string(security.transport == Transport::kInsecure
                           ? "--insecure / CALIPER_INSECURE): drop --insecure"
                           : "a plain loopback address): give its TLS address "
                             "corbaname:ssliop:HOST:PORT") +
           " and use an identity made by launch/caliper certs";
  }
  if (ok) return "";  // the handshake works: the failure is elsewhere
  if (!note.empty()) return note;
  if (!spoke_tls)
    return where + " does not complete a TLS handshake: it may run without TLS (--insecure), "
           "and this process talks only TLS on the network";
  return "the TLS handshake with " + where + " failed (" + version + ")";
}

}  // namespace caliper::rtc
