#include "sample_component.h"

#include <stdexcept>

#include "caliper/logging/log.h"

namespace caliper::sample {

std::vector<core::ConfigKey> SampleComponent::ConfigKeys() {
  using Type = core::ConfigKey::Type;
  return {
      {"sample.records_per_tick", Type::kInt, "1", "log records written per tick", 0, 1e6},
      {"sample.record_limit", Type::kInt, "0", "stop logging after this many records (0 = never)",
       0, 1e12},
      {"sample.fail_at_tick", Type::kInt, "0", "on_execute fails at this tick (0 = never)", 0,
       1e12},
  };
}

SampleComponent::SampleComponent(rtc::Runtime& runtime)
    : records_per_tick_(runtime.config().GetInt("sample.records_per_tick")),
      record_limit_(runtime.config().GetInt("sample.record_limit")),
      fail_at_tick_(runtime.config().GetInt("sample.fail_at_tick")) {}

rtc::ReturnCode SampleComponent::OnActivated() {
  logging::Get("lifecycle").info("activated after %lld records", static_cast<long long>(written_));
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode SampleComponent::OnDeactivated() {
  logging::Get("lifecycle").info("deactivated after %lld ticks", static_cast<long long>(ticks_));
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode SampleComponent::OnExecute() {
  ++ticks_;
  if (fail_at_tick_ != 0 && ticks_ == fail_at_tick_)
    throw std::runtime_error("configured to fail at tick " + std::to_string(ticks_));
  auto& records = logging::Get("records");
  for (int64_t i = 0; i < records_per_tick_; ++i) {
    if (record_limit_ != 0 && written_ >= record_limit_) break;
    ++written_;
    if (record_limit_ != 0)
      records.info("record %lld of %lld", static_cast<long long>(written_),
                   static_cast<long long>(record_limit_));
    else
      records.info("record %lld", static_cast<long long>(written_));
  }
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode SampleComponent::OnAborting() {
  logging::Get("lifecycle").warn("aborting at tick %lld", static_cast<long long>(ticks_));
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode SampleComponent::OnReset() {
  logging::Get("lifecycle").info("reset");
  return rtc::ReturnCode::kOk;
}

}  // namespace caliper::sample
