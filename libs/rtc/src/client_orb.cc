#include "caliper/rtc/client_orb.h"

namespace caliper::rtc {

CORBA::ORB_ptr ClientOrb(const char* program) {
  // omniORB returns the existing ORB when there is one (its arguments are then ignored);
  // per-thread call timeouts (omniORB::setClientThreadCallTimeout) need supportPerThreadTimeOut
  const char* args[] = {program, "-ORBendPoint", "giop:tcp:127.0.0.1:",
                        "-ORBsupportPerThreadTimeOut", "1", nullptr};
  int argc = 5;
  return CORBA::ORB_init(argc, const_cast<char**>(args));
}

}  // namespace caliper::rtc
