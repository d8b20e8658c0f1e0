#pragma once
// Delivers log batches to the Logging component found in the naming service.

#include <omniORB4/CORBA.h>

#include <string>

#include "caliper/logging.hh"
#include "caliper/logging/batching_appender.h"

namespace caliper::rtc {

class LogServiceSink : public logging::RecordSink {
 public:
  /// `service` is the logger's instance name (logger0); looked up again after every failure, so a
  /// restarted logger on a new port is found.
  LogServiceSink(CORBA::ORB_ptr orb, std::string naming_address, std::string service);
  void Send(const std::vector<logging::Record>& batch) override;

 private:
  CORBA::ORB_var orb_;
  std::string naming_address_;
  std::string service_;
  Caliper::Logging::LogService_var logger_;
};

/// Where a component of the session at `naming_address` spools its records: a folder of `base`
/// of that session alone (a readable form of the address and a hash of it). Records spooled
/// while a session's logger was gone are delivered only into that session's log, never into the
/// next session's (whose address differs: a launcher session's naming service listens in the
/// session's own folder); they wait there, kept with their session.
std::string SessionSpoolDirectory(const std::string& base, const std::string& naming_address);

/// IDL record for a C++ one and back.
Caliper::Logging::Record ToIdl(const logging::Record& r);
logging::Record FromIdl(const Caliper::Logging::Record& r);

}  // namespace caliper::rtc
