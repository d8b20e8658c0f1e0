#include "listener_servant.h"

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
  inbox_->Push(FromIdl(records));
}

}  // namespace caliper::log_viewer
