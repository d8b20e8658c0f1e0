#pragma once
// The DataConsumer the Model pushes DAQ sample batches to: converts each batch to a plain
// ReceivedBatch and hands it on. Runs on ORB threads; never throws into the ORB.

#include <atomic>
#include <cstdint>
#include <functional>

#include "caliper/daq.hh"
#include "daq_link.h"

namespace caliper::plotter {

/// The servant of Caliper::Daq::DataConsumer (thin: convert and forward).
class DataConsumerServant : public virtual POA_Caliper::Daq::DataConsumer {
 public:
  /// `sink` receives every batch (on the ORB thread that delivered it).
  explicit DataConsumerServant(std::function<void(ReceivedBatch&&)> sink);

  /// Converts and forwards; a batch that fails to (any exception, from the conversion or the
  /// sink) is counted, logged and lost, and nothing reaches the ORB.
  void on_samples(const Caliper::Daq::SampleBatch& batch) override;

  /// Batches lost to an exception so far.
  uint64_t failures() const { return failures_.load(); }

 private:
  void Failed(const char* what) noexcept;

  std::function<void(ReceivedBatch&&)> sink_;
  std::atomic<uint64_t> failures_{0};
};

}  // namespace caliper::plotter
