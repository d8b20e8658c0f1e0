#include "client.h"

#include "caliper/rtc/client_orb.h"

#include <cctype>

namespace caliper::ctl {

Client::~Client() {
  if (CORBA::is_nil(orb_)) return;
  try {
    orb_->destroy();
  } catch (...) {
  }
}

CosNaming::NamingContext_ptr Client::Root() {
  Connect();
  try {
    return rtc::ResolveRoot(orb_, address_);
  } catch (const rtc::Unreachable& e) {
    throw Failure(std::string(e.what()) +
                  "\n  (is a session running? start one with `launch/caliper demo`, or pass "
                  "--nameservice corbaname::HOST:PORT)");
  }
}

rtc::ComponentEntry Client::Find(const std::string& name) {
  CosNaming::NamingContext_var root = Root();
  try {
    return rtc::FindComponent(root, name);
  } catch (const rtc::NotFound& e) {
    throw Failure(e.what());
  }
}

::Caliper::RTC::LightweightRTObject_ptr Client::Component(const std::string& name,
                                                          std::string* path) {
  rtc::ComponentEntry e = Find(name);
  if (path) *path = e.path;
  try {
    ::Caliper::RTC::LightweightRTObject_var obj =
        ::Caliper::RTC::LightweightRTObject::_narrow(e.object);
    if (CORBA::is_nil(obj)) throw Failure(e.path + " is not a Caliper component");
    return obj._retn();
  } catch (const CORBA::Exception& ex) {
    throw Failure(Unreachable(e.path, ex));
  }
}

std::string Client::Unreachable(const std::string& path, const CORBA::Exception& e) {
  return "cannot reach " + path + ": " + rtc::Describe(e) +
         " (the process may have died; its name is stale)";
}

CORBA::ORB_ptr Client::orb() {
  Connect();
  return orb_.in();
}

PortableServer::POA_ptr Client::RootPoa() {
  CORBA::Object_var obj = orb()->resolve_initial_references("RootPOA");
  PortableServer::POA_var poa = PortableServer::POA::_narrow(obj);
  poa->the_POAManager()->activate();
  return poa._retn();
}

const std::string& Client::address() {
  Connect();
  return address_;
}

void Client::Connect() {
  if (!CORBA::is_nil(orb_)) return;
  address_ = rtc::NamingAddress(options_.nameservice);
  orb_ = rtc::ClientOrb("caliper-ctl", options_.timeout_s, address_);  // TLS when on a network
}

}  // namespace caliper::ctl
