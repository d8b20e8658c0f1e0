#include "caliper/rtc/execution_context.h"

namespace caliper::rtc {

using Clock = std::chrono::steady_clock;

ExecutionContext::ExecutionContext(Lifecycle* lifecycle, ContextKind kind, double rate_hz)
    : lifecycle_(lifecycle), kind_(kind), rate_hz_(rate_hz) {}

ExecutionContext::~ExecutionContext() {
  if (is_running()) Stop();
}

ReturnCode ExecutionContext::Start() {
  std::lock_guard<std::mutex> control(control_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (running_) return ReturnCode::kPreconditionNotMet;
    running_ = true;
    stats_ = ContextStatistics();
  }
  lifecycle_->Startup();
  // the previous thread was joined by the Stop that ended it, under the same control lock
  if (kind_ == ContextKind::kPeriodic) thread_ = std::thread([this] { Loop(); });
  return ReturnCode::kOk;
}

ReturnCode ExecutionContext::Stop() {
  std::lock_guard<std::mutex> control(control_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!running_) return ReturnCode::kPreconditionNotMet;
    running_ = false;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  lifecycle_->Shutdown();
  return ReturnCode::kOk;
}

bool ExecutionContext::is_running() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_;
}

double ExecutionContext::rate() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rate_hz_;
}

ReturnCode ExecutionContext::SetRate(double rate_hz) {
  if (!(rate_hz >= kMinRateHz && rate_hz <= kMaxRateHz)) return ReturnCode::kBadParameter;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    rate_hz_ = rate_hz;
  }
  wake_.notify_all();
  lifecycle_->RateChanged();
  return ReturnCode::kOk;
}

ReturnCode ExecutionContext::Tick() {
  if (kind_ != ContextKind::kExternal) return ReturnCode::kUnsupported;
  if (!is_running()) return ReturnCode::kPreconditionNotMet;
  RunTick();
  return ReturnCode::kOk;
}

void ExecutionContext::RunTick() {
  const auto begin = Clock::now();
  lifecycle_->Execute();
  const double seconds = std::chrono::duration<double>(Clock::now() - begin).count();
  std::lock_guard<std::mutex> lock(mutex_);
  ++stats_.ticks;
  stats_.last_execute_time_s = seconds;
  if (seconds > stats_.max_execute_time_s) stats_.max_execute_time_s = seconds;
}

void ExecutionContext::Loop() {
  auto next = Clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  while (running_) {
    const auto period = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(1.0 / rate_hz_));
    lock.unlock();
    RunTick();
    lock.lock();
    next += period;
    const auto now = Clock::now();
    if (now > next) {
      // the tick took longer than its period: count it and do not try to catch up
      ++stats_.overruns;
      next = now;
      continue;
    }
    wake_.wait_until(lock, next, [&] { return !running_; });
  }
}

ContextStatistics ExecutionContext::statistics() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace caliper::rtc
