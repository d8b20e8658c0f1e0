#pragma once
// The OpenRTM component lifecycle, without CORBA: a component's hooks and the state machine that
// calls them. CREATED -> INACTIVE <-> ACTIVE; a failing hook leads to ERROR, which only reset leaves.

#include <mutex>
#include <string>

namespace caliper::rtc {

enum class ReturnCode { kOk, kError, kBadParameter, kUnsupported, kOutOfResources, kPreconditionNotMet };
enum class State { kCreated, kInactive, kActive, kError };

/// `RTC_OK`, `PRECONDITION_NOT_MET`, ... as in the IDL.
const char* ToString(ReturnCode code);
/// `CREATED`, `INACTIVE`, `ACTIVE`, `ERROR`.
const char* ToString(State state);

/// What a component implements. Every hook defaults to doing nothing successfully. A hook that
/// returns anything but kOk, or throws, fails; the exception's message becomes the reason.
class Component {
 public:
  virtual ~Component() = default;
  virtual ReturnCode OnInitialize() { return ReturnCode::kOk; }
  virtual ReturnCode OnFinalize() { return ReturnCode::kOk; }
  virtual ReturnCode OnStartup() { return ReturnCode::kOk; }
  virtual ReturnCode OnShutdown() { return ReturnCode::kOk; }
  virtual ReturnCode OnActivated() { return ReturnCode::kOk; }
  virtual ReturnCode OnDeactivated() { return ReturnCode::kOk; }
  virtual ReturnCode OnAborting() { return ReturnCode::kOk; }
  virtual ReturnCode OnError() { return ReturnCode::kOk; }
  virtual ReturnCode OnReset() { return ReturnCode::kOk; }
  virtual ReturnCode OnExecute() { return ReturnCode::kOk; }
  virtual ReturnCode OnStateUpdate() { return ReturnCode::kOk; }
  virtual ReturnCode OnRateChanged() { return ReturnCode::kOk; }
};

/// Drives one component through its states; thread-safe (hooks run under one lock, so a tick
/// never overlaps a transition).
///
/// Transitions, as in OpenRTM-aist:
/// - Initialize: CREATED -> INACTIVE when on_initialize succeeds (else stays CREATED).
/// - Activate: INACTIVE -> ACTIVE via on_activated; failure -> ERROR.
/// - Deactivate: ACTIVE -> INACTIVE via on_deactivated; failure -> ERROR.
/// - Reset: ERROR -> INACTIVE via on_reset; failure stays in ERROR.
/// - Execute (a tick): ACTIVE runs on_execute then on_state_update, failure of either -> ERROR;
///   ERROR runs on_error.
/// - Entering ERROR runs on_aborting.
/// - Finalize: not while ACTIVE, not before Initialize; runs on_finalize, then nothing else runs.
/// Illegal requests answer kPreconditionNotMet and change nothing.
class Lifecycle {
 public:
  /// `log_area` names the log category of the messages about failing hooks.
  explicit Lifecycle(Component* component, std::string log_area = "rtc");

  ReturnCode Initialize();
  ReturnCode Finalize();
  ReturnCode Activate();
  ReturnCode Deactivate();
  ReturnCode Reset();
  /// One tick of the execution context.
  void Execute();
  /// Execution-context events; ignored before Initialize and after Finalize.
  ReturnCode Startup();
  ReturnCode Shutdown();
  ReturnCode RateChanged();

  State state() const;
  bool finalized() const;
  /// Why the component last entered ERROR ("" if it never did).
  std::string last_error() const;

 private:
  ReturnCode Call(const char* hook, ReturnCode (Component::*fn)(), std::string* reason);
  void EnterErrorLocked(const std::string& reason);
  ReturnCode Transition(State from, const char* hook, ReturnCode (Component::*fn)(), State to);

  Component* component_;
  std::string log_area_;
  mutable std::mutex mutex_;
  State state_ = State::kCreated;
  bool initialized_ = false;
  bool finalized_ = false;
  std::string last_error_;
};

}  // namespace caliper::rtc
