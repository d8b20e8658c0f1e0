#include "caliper/rtc/client_orb.h"

#include "caliper/rtc/local_sockets.h"
#include "caliper/rtc/naming.h"
#include "caliper/rtc/transport_security.h"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace caliper::rtc {

std::string ListenEndpoint(const std::string& address) {
  if (address.empty()) throw std::invalid_argument("empty listening address");
  for (char c : address)
    if (c == '/' || c == ' ' || c == ',')
      throw std::invalid_argument("listening address '" + address +
                                  "': expected a host name or an IP address");
  // one colon: a host with a port, which the ORB chooses itself
  if (std::count(address.begin(), address.end(), ':') == 1)
    throw std::invalid_argument("listening address '" + address +
                                "': give the address alone, without a port");
  const bool ipv6 = address.find(':') != std::string::npos && address.front() != '[';
  return "giop:tcp:" + (ipv6 ? "[" + address + "]" : address) + ":";
}

OmniThread::OmniThread() : dummy_(omni_thread::self() == nullptr) {
  if (dummy_) omni_thread::create_dummy();
}

OmniThread::~OmniThread() {
  if (dummy_) omni_thread::release_dummy();
}

CORBA::ORB_ptr ClientOrb(const char* program, double call_timeout_s,
                         const std::string& naming_address) {
  // omniORB returns the existing ORB when there is one (its arguments are then ignored);
  // per-thread call timeouts (omniORB::setClientThreadCallTimeout) need supportPerThreadTimeOut
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  static bool secured = false;  // the transport is chosen once: omniORB keeps the SSL settings
  std::vector<std::string> options;
  if (!secured) {
    SecurityRequest request;
    request.endpoint = kLocalEndpoint;  // callbacks (feeds, observers) reach only this user
    if (const char* listen = std::getenv("CALIPER_LISTEN"); listen != nullptr && *listen != '\0')
      request.endpoint = ListenEndpoint(listen);
    request.naming_address = NamingAddress(naming_address);
    request.insecure = InsecureFromEnvironment();
    const TransportSecurity security = ResolveSecurity(request);
    if (security.transport == Transport::kInsecure) WarnInsecure(program, security.endpoint);
    options = {"-ORBendPoint", security.endpoint};
    for (auto& o : SecurityOrbOptions(security)) options.push_back(o);
    InstallProcessSecurity(security);
    secured = true;
  }
  const std::string max_message = std::to_string(kMaxMessageBytes);
  std::vector<const char*> args = {program, "-ORBsupportPerThreadTimeOut", "1",
                                   "-ORBgiopMaxMsgSize", max_message.c_str()};
  for (const auto& o : options) args.push_back(o.c_str());
  const std::string timeout_ms = std::to_string(static_cast<long>(call_timeout_s * 1000));
  if (call_timeout_s > 0)
    for (const char* option : {"-ORBclientCallTimeOutPeriod", "-ORBclientConnectTimeOutPeriod"}) {
      args.push_back(option);
      args.push_back(timeout_ms.c_str());
    }
  args.push_back(nullptr);
  int argc = static_cast<int>(args.size()) - 1;
  CORBA::ORB_ptr orb = CORBA::ORB_init(argc, const_cast<char**>(args.data()));
  InstallTransportDiagnostics();
  return orb;
}

void WarnInsecure(const std::string& program, const std::string& endpoint) {
  std::cerr << "\n"
            << program << ": WARNING: INSECURE network mode (--insecure / CALIPER_INSECURE): plain\n"
            << "  GIOP without TLS on " << endpoint << ": no encryption and no authentication;\n"
            << "  anyone who reaches this host's ports can load and write files and drive the\n"
            << "  Models. Use it only on a network you trust entirely (see launch/caliper certs).\n\n";
}

}  // namespace caliper::rtc
