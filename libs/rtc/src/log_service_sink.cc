#include "caliper/rtc/log_service_sink.h"

#include <cctype>
#include <cstdint>
#include <cstdio>

#include "caliper/rtc/naming.h"

namespace caliper::rtc {

Caliper::Logging::Record ToIdl(const logging::Record& r) {
  Caliper::Logging::Record out;
  out.time_us = r.time_us;
  out.priority = r.priority;
  out.category = r.category.c_str();
  out.instance = r.component.c_str();
  out.host = r.host.c_str();
  out.pid = static_cast<CORBA::Long>(r.pid);
  out.source = r.source.c_str();
  out.seq = r.seq;
  out.message = r.message.c_str();
  return out;
}

logging::Record FromIdl(const Caliper::Logging::Record& r) {
  logging::Record out;
  out.time_us = r.time_us;
  out.priority = r.priority;
  out.category = r.category.in();
  out.component = r.instance.in();
  out.host = r.host.in();
  out.pid = r.pid;
  out.source = r.source.in();
  out.seq = r.seq;
  out.message = r.message.in();
  return out;
}

LogServiceSink::LogServiceSink(CORBA::ORB_ptr orb, std::string naming_address, std::string service)
    : orb_(CORBA::ORB::_duplicate(orb)),
      naming_address_(std::move(naming_address)),
      service_(std::move(service)) {}

void LogServiceSink::Send(const std::vector<logging::Record>& batch) {
  try {
    if (CORBA::is_nil(logger_)) {
      CosNaming::NamingContext_var root = ResolveRoot(orb_, naming_address_);
      ComponentEntry entry = FindComponent(root, service_);
      logger_ = Caliper::Logging::LogService::_narrow(entry.object);
      if (CORBA::is_nil(logger_)) throw logging::SinkUnavailable(service_ + " is not a logger");
    }
    Caliper::Logging::RecordSeq records;
    records.length(static_cast<CORBA::ULong>(batch.size()));
    for (CORBA::ULong i = 0; i < batch.size(); ++i) records[i] = ToIdl(batch[i]);
    logger_->submit(records);
  } catch (const CORBA::Exception& e) {
    logger_ = Caliper::Logging::LogService::_nil();
    throw logging::SinkUnavailable(service_ + ": " + Describe(e));
  } catch (const std::runtime_error& e) {  // Unreachable, NotFound
    logger_ = Caliper::Logging::LogService::_nil();
    throw logging::SinkUnavailable(e.what());
  }
}

std::string SessionSpoolDirectory(const std::string& base, const std::string& naming_address) {
  // FNV-1a (64 bit): stable across builds and machines, unlike std::hash
  uint64_t hash = 14695981039346656037ull;
  for (const unsigned char c : naming_address) hash = (hash ^ c) * 1099511628211ull;
  // the address's tail (the session's folder, or host and port), made a file name
  std::string readable = naming_address.size() > 48
                             ? naming_address.substr(naming_address.size() - 48)
                             : naming_address;
  for (char& c : readable)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-') c = '_';
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return base + "/" + readable + "-" + hex;
}

}  // namespace caliper::rtc
