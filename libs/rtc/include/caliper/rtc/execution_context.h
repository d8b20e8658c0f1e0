#pragma once
// Execution contexts: what makes a component's on_execute run. PERIODIC owns a thread that ticks
// at a rate and counts overruns; EXTERNAL is ticked from outside (lock-step simulation).
// Start and Stop may be called from any number of threads at once (several clients over CORBA):
// they take turns, each one whole (hook, thread start or join), so on_startup and on_shutdown
// alternate and the ticking thread is never replaced while it runs.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "caliper/rtc/lifecycle.h"

namespace caliper::rtc {

enum class ContextKind { kPeriodic, kExternal };

struct ContextStatistics {
  uint64_t ticks = 0;              ///< ticks executed since start
  uint64_t overruns = 0;           ///< periodic ticks longer than one period
  double last_execute_time_s = 0;  ///< duration of the last tick [s]
  double max_execute_time_s = 0;   ///< longest tick since start [s]
};

class ExecutionContext {
 public:
  /// `rate_hz` > 0: the tick rate of a periodic context, the nominal rate of an external one.
  ExecutionContext(Lifecycle* lifecycle, ContextKind kind, double rate_hz);
  ~ExecutionContext();

  /// Runs on_startup and, for PERIODIC, starts the thread; PRECONDITION_NOT_MET when running.
  /// Not from a hook of this context's own component (it would wait for itself).
  ReturnCode Start();
  /// Stops the thread (waiting for a tick in progress) and runs on_shutdown;
  /// PRECONDITION_NOT_MET when not running. Not from a hook of this context's own component.
  ReturnCode Stop();
  bool is_running() const;
  double rate() const;
  /// BAD_PARAMETER unless kMinRateHz <= rate_hz <= kMaxRateHz (the range of `exec.rate`: below
  /// it a period overflows the clock and the context would tick without pause); runs
  /// on_rate_changed.
  ReturnCode SetRate(double rate_hz);
  static constexpr double kMinRateHz = 1e-3;
  static constexpr double kMaxRateHz = 1e6;
  ContextKind kind() const { return kind_; }
  /// One tick now: EXTERNAL only (UNSUPPORTED on PERIODIC), and only while running.
  ReturnCode Tick();
  ContextStatistics statistics() const;
  Lifecycle& lifecycle() { return *lifecycle_; }

 private:
  void RunTick();
  void Loop();

  Lifecycle* lifecycle_;
  const ContextKind kind_;
  std::mutex control_;  // held through a whole Start or Stop: one at a time
  mutable std::mutex mutex_;  // guards the fields below; never held while a hook runs
  std::condition_variable wake_;
  double rate_hz_;
  bool running_ = false;
  ContextStatistics stats_;
  std::thread thread_;
};

}  // namespace caliper::rtc
