#pragma once
// A Component for the rtc tests: counts and logs every hook call and can be told, per hook, to
// fail (return a code), throw, or take a while.

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "caliper/rtc/lifecycle.h"

namespace caliper::rtc::testing {

enum Hook {
  kInitialize,
  kFinalize,
  kStartup,
  kShutdown,
  kActivated,
  kDeactivated,
  kAborting,
  kOnError,
  kReset,
  kExecute,
  kStateUpdate,
  kRateChanged,
  kHookCount
};

/// `on_initialize`, ... as Lifecycle names the hooks in its messages.
inline const char* HookName(Hook hook) {
  static const char* const kNames[kHookCount] = {
      "on_initialize", "on_finalize",    "on_startup",      "on_shutdown",
      "on_activated",  "on_deactivated", "on_aborting",     "on_error",
      "on_reset",      "on_execute",     "on_state_update", "on_rate_changed"};
  return kNames[hook];
}

class TestComponent : public Component {
 public:
  enum class Behaviour { kSucceed, kReturn, kThrow, kThrowUnknown };

  TestComponent() {
    for (auto& c : counts_) c = 0;
    for (auto& b : behaviours_) b = Behaviour::kSucceed;
  }

  /// The hook returns `code` from now on.
  void Fail(Hook hook, ReturnCode code = ReturnCode::kError) {
    codes_[hook] = code;
    behaviours_[hook] = Behaviour::kReturn;
  }
  /// The hook throws std::runtime_error("<hook> exploded") from now on.
  void Throw(Hook hook) { behaviours_[hook] = Behaviour::kThrow; }
  /// The hook throws an int from now on.
  void ThrowUnknown(Hook hook) { behaviours_[hook] = Behaviour::kThrowUnknown; }
  void Succeed(Hook hook) { behaviours_[hook] = Behaviour::kSucceed; }
  /// on_execute sleeps this long.
  void SetExecuteDuration(std::chrono::milliseconds d) {
    execute_ms_ = static_cast<int>(d.count());
  }

  int count(Hook hook) const { return counts_[hook]; }
  /// The hooks called so far, in order.
  std::vector<std::string> calls() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return calls_;
  }
  /// Waits until `hook` ran `n` times in all; false after `timeout`.
  bool WaitFor(Hook hook, int n, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return called_.wait_for(lock, timeout, [&] { return counts_[hook] >= n; });
  }
  bool WaitForExecutes(int n, std::chrono::milliseconds timeout) {
    return WaitFor(kExecute, n, timeout);
  }

  ReturnCode OnInitialize() override { return Run(kInitialize); }
  ReturnCode OnFinalize() override { return Run(kFinalize); }
  ReturnCode OnStartup() override { return Run(kStartup); }
  ReturnCode OnShutdown() override { return Run(kShutdown); }
  ReturnCode OnActivated() override { return Run(kActivated); }
  ReturnCode OnDeactivated() override { return Run(kDeactivated); }
  ReturnCode OnAborting() override { return Run(kAborting); }
  ReturnCode OnError() override { return Run(kOnError); }
  ReturnCode OnReset() override { return Run(kReset); }
  ReturnCode OnExecute() override {
    if (execute_ms_ > 0) std::this_thread::sleep_for(std::chrono::milliseconds(execute_ms_.load()));
    return Run(kExecute);
  }
  ReturnCode OnStateUpdate() override { return Run(kStateUpdate); }
  ReturnCode OnRateChanged() override { return Run(kRateChanged); }

 private:
  ReturnCode Run(Hook hook) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++counts_[hook];
      calls_.emplace_back(HookName(hook));
    }
    called_.notify_all();
    switch (behaviours_[hook].load()) {
      case Behaviour::kSucceed: return ReturnCode::kOk;
      case Behaviour::kReturn: return codes_[hook].load();
      case Behaviour::kThrow: throw std::runtime_error(std::string(HookName(hook)) + " exploded");
      case Behaviour::kThrowUnknown: throw 42;
    }
    return ReturnCode::kOk;
  }

  mutable std::mutex mutex_;
  std::condition_variable called_;
  std::array<std::atomic<int>, kHookCount> counts_;
  std::array<std::atomic<Behaviour>, kHookCount> behaviours_;
  std::array<std::atomic<ReturnCode>, kHookCount> codes_{};
  std::atomic<int> execute_ms_{0};
  std::vector<std::string> calls_;
};

}  // namespace caliper::rtc::testing
