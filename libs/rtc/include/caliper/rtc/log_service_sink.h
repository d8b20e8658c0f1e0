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

/// IDL record for a C++ one and back.
Caliper::Logging::Record ToIdl(const logging::Record& r);
logging::Record FromIdl(const Caliper::Logging::Record& r);

}  // namespace caliper::rtc
