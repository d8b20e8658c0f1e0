#include "data_consumer_servant.h"

#include <exception>

#include "caliper/logging/log.h"

namespace caliper::plotter {

DataConsumerServant::DataConsumerServant(std::function<void(ReceivedBatch&&)> sink)
    : sink_(std::move(sink)) {}

void DataConsumerServant::on_samples(const Caliper::Daq::SampleBatch& batch) {
  try {
    ReceivedBatch b;
    b.subscription = batch.subscription;
    b.number = batch.batch;
    b.values_per_sample = batch.values_per_sample;
    b.model_layout = batch.layout;
    b.times.assign(batch.times.get_buffer(), batch.times.get_buffer() + batch.times.length());
    b.data.assign(batch.data.get_buffer(), batch.data.get_buffer() + batch.data.length());
    for (CORBA::ULong i = 0; i < batch.stale_ids.length(); ++i)
      b.stale_ids.emplace_back(batch.stale_ids[i].in());
    // a short data array would be read past its end: keep the whole samples only
    if (b.values_per_sample > 0 && b.data.size() < b.times.size() * b.values_per_sample)
      b.times.resize(b.data.size() / b.values_per_sample);
    sink_(std::move(b));
  } catch (const std::exception& e) {
    Failed(e.what());
  } catch (...) {
    Failed("an exception of unknown type");
  }
}

void DataConsumerServant::Failed(const char* what) noexcept {
  // this batch is lost, the next one may not be; the log gets the first and every 100th loss
  const uint64_t n = ++failures_;
  if (n != 1 && n % 100 != 0) return;
  try {
    logging::Get("plotter").error("a DAQ sample batch was lost (%llu so far): %s",
                                  static_cast<unsigned long long>(n), what);
  } catch (...) {
    // logging failed too: the count stays
  }
}

}  // namespace caliper::plotter
