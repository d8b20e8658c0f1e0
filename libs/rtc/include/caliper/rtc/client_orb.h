#pragma once
// The ORB of a client program (the Main Window, the plotter, the log viewer): one per process,
// listening on the loopback interface for the callbacks it serves (data consumers, listeners).

#include <omniORB4/CORBA.h>

namespace caliper::rtc {

/// The process's ORB: initialised on the first call (endpoint giop:tcp:127.0.0.1, per-thread call
/// timeouts enabled, `program` names it), the same ORB afterwards (also when the process
/// initialised one itself before: then its options stand).
CORBA::ORB_ptr ClientOrb(const char* program = "caliper");

}  // namespace caliper::rtc
