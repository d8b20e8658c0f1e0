#include "listener_servant.h"

#include <exception>

#include "caliper/logging/log.h"
#include "caliper/rtc/log_service_sink.h"

namespace caliper::log_viewer {

std::vector<LiveRecord> FromIdl(const Caliper::Logging::StoredRecordSeq& records) {
  std::vector<LiveRecord> out;
  out.reserve(records.length());
  for (CORBA::ULong i = 0; i < records.length(); ++i)
    out.push_back(LiveRecord{records[i].serial, rtc::FromIdl(records[i].rec)});
  return out;
}

void ListenerServant::on_records(const Caliper::Logging::StoredRecordSeq& records) {
  // nothing escapes: an exception would reach the logger as UNKNOWN and cost the registration
  try {
    sink_(FromIdl(records));
  } catch (const std::exception& e) {
    Failed(records.length(), e.what());
  } catch (const CORBA::Exception& e) {
    Failed(records.length(), e._name());
  } catch (...) {
    Failed(records.length(), "an unknown exception");
  }
}

void ListenerServant::Failed(CORBA::ULong records, const char* why) noexcept {
  ++failures_;
  try {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      last_failure_ = why;
    }
    logging::Get("listener").error("%u pushed records not taken in: %s", records, why);
  } catch (...) {
    // out of memory while reporting: the count above is all that is left
  }
}

std::string ListenerServant::last_failure() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_failure_;
}

}  // namespace caliper::log_viewer
