#include "caliper/rtc/peers.h"

#include "caliper/rtc/local_sockets.h"
#include "caliper/rtc/naming.h"

#include <omniORB4/IIOP.h>
#include <omniORB4/minorCode.h>
#include <omniORB4/omniIOR.h>
#include <omniORB4/omniObjRef.h>

namespace caliper::rtc {

std::string ClientOf(CORBA::Object_ptr ref) {
  if (CORBA::is_nil(ref)) return "(nil)";
  // a local client: its unix socket names its process (its IIOP address is a placeholder)
  if (const std::string socket = UnixSocketOf(ref); !socket.empty()) return "unix:" + socket;
  std::string client;
  VisitIiopProfiles(ref, [&](const IIOP::ProfileBody& body) {
    client = std::string(body.address.host.in()) + ":" + std::to_string(body.address.port);
    return true;
  });
  return client.empty() ? "(no IIOP address)" : client;
}

bool PeerGone(const CORBA::Exception& e) {
  if (CORBA::OBJECT_NOT_EXIST::_downcast(&e)) return true;
  const auto* transient = CORBA::TRANSIENT::_downcast(&e);
  return transient != nullptr && transient->minor() == omni::TRANSIENT_ConnectFailed;
}

bool PeerGone(const CORBA::Exception& e, CORBA::Object_ptr ref) {
  if (!PeerGone(e)) return false;
  if (CORBA::OBJECT_NOT_EXIST::_downcast(&e)) return true;
  // a local object: gone when nothing listens on its socket any more
  const std::string socket = UnixSocketOf(ref);
  return socket.empty() || !LocalSocketListening(socket);
}

std::string Unreachable(CORBA::Object_ptr ref, const char* what, const char* repository_id,
                        std::chrono::milliseconds timeout) {
  if (CORBA::is_nil(ref)) return std::string("the ") + what + " is nil";
  omniORB::setClientCallTimeout(ref, static_cast<CORBA::ULong>(timeout.count()));
  try {
    if (ref->_non_existent()) return std::string("the ") + what + " does not exist";
    if (!ref->_PR_getobj()->_remote_is_a(repository_id))
      return std::string("the object is not a ") + what + " (" + repository_id + ")";
  } catch (const CORBA::SystemException& e) {
    return std::string("the ") + what + " does not answer: " + Describe(e);
  }
  return "";
}

}  // namespace caliper::rtc
