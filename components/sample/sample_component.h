#pragma once
// The sample component: a minimal component that shows the lifecycle and exercises logging.
// While ACTIVE it logs `sample.records_per_tick` numbered records per tick (category
// caliper.sample.records) until `sample.record_limit` have been written; with
// `sample.fail_at_tick` = N its on_execute fails at the N-th tick, which moves it to ERROR.

#include <cstdint>

#include "caliper/rtc/runtime.h"

namespace caliper::sample {

class SampleComponent : public rtc::Component {
 public:
  explicit SampleComponent(rtc::Runtime& runtime);

  rtc::ReturnCode OnActivated() override;
  rtc::ReturnCode OnDeactivated() override;
  rtc::ReturnCode OnExecute() override;
  rtc::ReturnCode OnAborting() override;
  rtc::ReturnCode OnReset() override;

  static std::vector<core::ConfigKey> ConfigKeys();

 private:
  int64_t records_per_tick_;
  int64_t record_limit_;
  int64_t fail_at_tick_;
  int64_t ticks_ = 0;
  int64_t written_ = 0;
};

}  // namespace caliper::sample
