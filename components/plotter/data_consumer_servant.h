#pragma once
// The DataConsumer the Model pushes DAQ sample batches to: converts each batch to a plain
// ReceivedBatch and hands it on. Runs on ORB threads; never throws into the ORB.

#include <functional>

#include "caliper/daq.hh"
#include "daq_link.h"

namespace caliper::plotter {

/// The servant of Caliper::Daq::DataConsumer (thin: convert and forward).
class DataConsumerServant : public virtual POA_Caliper::Daq::DataConsumer {
 public:
  /// `sink` receives every batch (on the ORB thread that delivered it).
  explicit DataConsumerServant(std::function<void(ReceivedBatch&&)> sink);

  void on_samples(const Caliper::Daq::SampleBatch& batch) override;

 private:
  std::function<void(ReceivedBatch&&)> sink_;
};

}  // namespace caliper::plotter
