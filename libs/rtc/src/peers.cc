#include "caliper/rtc/peers.h"

#include <omniORB4/IIOP.h>
#include <omniORB4/minorCode.h>
#include <omniORB4/omniIOR.h>
#include <omniORB4/omniObjRef.h>

namespace caliper::rtc {

std::string ClientOf(CORBA::Object_ptr ref) {
  if (CORBA::is_nil(ref)) return "(nil)";
  std::string client;
  omniIOR* ior = ref->_PR_getobj()->_getIOR();
  const IOP::TaggedProfileList& profiles = ior->iopProfiles();
  for (CORBA::ULong i = 0; i < profiles.length() && client.empty(); ++i) {
    if (profiles[i].tag != IOP::TAG_INTERNET_IOP) continue;
    try {
      IIOP::ProfileBody body;
      IIOP::unmarshalProfile(profiles[i], body);
      client = std::string(body.address.host.in()) + ":" + std::to_string(body.address.port);
    } catch (const CORBA::SystemException&) {
      // a malformed profile: try the next one
    }
  }
  ior->release();
  return client.empty() ? "(no IIOP address)" : client;
}

bool PeerGone(const CORBA::Exception& e) {
  if (CORBA::OBJECT_NOT_EXIST::_downcast(&e)) return true;
  const auto* transient = CORBA::TRANSIENT::_downcast(&e);
  return transient != nullptr && transient->minor() == omni::TRANSIENT_ConnectFailed;
}

}  // namespace caliper::rtc
