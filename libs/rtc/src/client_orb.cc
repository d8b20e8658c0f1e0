#include "caliper/rtc/client_orb.h"

#include <algorithm>
#include <cstdlib>
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

CORBA::ORB_ptr ClientOrb(const char* program, double call_timeout_s) {
  // omniORB returns the existing ORB when there is one (its arguments are then ignored);
  // per-thread call timeouts (omniORB::setClientThreadCallTimeout) need supportPerThreadTimeOut
  std::string endpoint = "giop:tcp:127.0.0.1:";
  if (const char* listen = std::getenv("CALIPER_LISTEN"); listen != nullptr && *listen != '\0')
    endpoint = ListenEndpoint(listen);
  const std::string max_message = std::to_string(kMaxMessageBytes);
  std::vector<const char*> args = {program, "-ORBendPoint", endpoint.c_str(),
                                   "-ORBsupportPerThreadTimeOut", "1",
                                   "-ORBgiopMaxMsgSize", max_message.c_str()};
  const std::string timeout_ms = std::to_string(static_cast<long>(call_timeout_s * 1000));
  if (call_timeout_s > 0)
    for (const char* option : {"-ORBclientCallTimeOutPeriod", "-ORBclientConnectTimeOutPeriod"}) {
      args.push_back(option);
      args.push_back(timeout_ms.c_str());
    }
  args.push_back(nullptr);
  int argc = static_cast<int>(args.size()) - 1;
  return CORBA::ORB_init(argc, const_cast<char**>(args.data()));
}

}  // namespace caliper::rtc
