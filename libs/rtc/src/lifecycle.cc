#include "caliper/rtc/lifecycle.h"

#include <exception>

#include "caliper/logging/log.h"

namespace caliper::rtc {

const char* ToString(ReturnCode code) {
  switch (code) {
    case ReturnCode::kOk: return "RTC_OK";
    case ReturnCode::kError: return "RTC_ERROR";
    case ReturnCode::kBadParameter: return "BAD_PARAMETER";
    case ReturnCode::kUnsupported: return "UNSUPPORTED";
    case ReturnCode::kOutOfResources: return "OUT_OF_RESOURCES";
    case ReturnCode::kPreconditionNotMet: return "PRECONDITION_NOT_MET";
  }
  return "?";
}

const char* ToString(State state) {
  switch (state) {
    case State::kCreated: return "CREATED";
    case State::kInactive: return "INACTIVE";
    case State::kActive: return "ACTIVE";
    case State::kError: return "ERROR";
  }
  return "?";
}

Lifecycle::Lifecycle(Component* component, std::string log_area)
    : component_(component), log_area_(std::move(log_area)) {}

ReturnCode Lifecycle::Call(const char* hook, ReturnCode (Component::*fn)(), std::string* reason) {
  ReturnCode rc;
  try {
    rc = (component_->*fn)();
    if (rc != ReturnCode::kOk) *reason = std::string(hook) + " returned " + ToString(rc);
  } catch (const std::exception& e) {
    rc = ReturnCode::kError;
    *reason = std::string(hook) + " threw: " + e.what();
  } catch (...) {
    rc = ReturnCode::kError;
    *reason = std::string(hook) + " threw an unknown exception";
  }
  if (rc != ReturnCode::kOk) logging::Get(log_area_).error("%s", reason->c_str());
  return rc;
}

void Lifecycle::EnterErrorLocked(const std::string& reason) {
  state_ = State::kError;
  last_error_ = reason;
  logging::Get(log_area_).error("entering ERROR: %s", reason.c_str());
  std::string ignored;
  Call("on_aborting", &Component::OnAborting, &ignored);
}

ReturnCode Lifecycle::Initialize() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (initialized_ || finalized_) return ReturnCode::kPreconditionNotMet;
  std::string reason;
  const ReturnCode rc = Call("on_initialize", &Component::OnInitialize, &reason);
  if (rc != ReturnCode::kOk) {
    last_error_ = reason;
    return rc;
  }
  initialized_ = true;
  state_ = State::kInactive;
  return ReturnCode::kOk;
}

ReturnCode Lifecycle::Finalize() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!initialized_ || finalized_ || state_ == State::kActive)
    return ReturnCode::kPreconditionNotMet;
  std::string reason;
  const ReturnCode rc = Call("on_finalize", &Component::OnFinalize, &reason);
  finalized_ = true;
  state_ = State::kCreated;
  return rc;
}

ReturnCode Lifecycle::Transition(State from, const char* hook, ReturnCode (Component::*fn)(),
                                 State to) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finalized_ || state_ != from) return ReturnCode::kPreconditionNotMet;
  std::string reason;
  const ReturnCode rc = Call(hook, fn, &reason);
  if (rc != ReturnCode::kOk) {
    // a failing reset leaves the component in ERROR; any other failing transition enters it
    if (from == State::kError)
      last_error_ = reason;
    else
      EnterErrorLocked(reason);
    return rc;
  }
  state_ = to;
  return ReturnCode::kOk;
}

ReturnCode Lifecycle::Activate() {
  return Transition(State::kInactive, "on_activated", &Component::OnActivated, State::kActive);
}

ReturnCode Lifecycle::Deactivate() {
  return Transition(State::kActive, "on_deactivated", &Component::OnDeactivated, State::kInactive);
}

ReturnCode Lifecycle::Reset() {
  return Transition(State::kError, "on_reset", &Component::OnReset, State::kInactive);
}

void Lifecycle::Execute() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finalized_) return;
  std::string reason;
  if (state_ == State::kActive) {
    if (Call("on_execute", &Component::OnExecute, &reason) != ReturnCode::kOk ||
        Call("on_state_update", &Component::OnStateUpdate, &reason) != ReturnCode::kOk) {
      EnterErrorLocked(reason);
    }
  } else if (state_ == State::kError) {
    Call("on_error", &Component::OnError, &reason);
  }
}

ReturnCode Lifecycle::Startup() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!initialized_ || finalized_) return ReturnCode::kPreconditionNotMet;
  std::string reason;
  return Call("on_startup", &Component::OnStartup, &reason);
}

ReturnCode Lifecycle::Shutdown() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!initialized_ || finalized_) return ReturnCode::kPreconditionNotMet;
  std::string reason;
  return Call("on_shutdown", &Component::OnShutdown, &reason);
}

ReturnCode Lifecycle::RateChanged() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!initialized_ || finalized_) return ReturnCode::kPreconditionNotMet;
  std::string reason;
  const ReturnCode rc = Call("on_rate_changed", &Component::OnRateChanged, &reason);
  if (rc != ReturnCode::kOk && state_ != State::kError) EnterErrorLocked(reason);
  return rc;
}

State Lifecycle::state() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_;
}

bool Lifecycle::finalized() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return finalized_;
}

std::string Lifecycle::last_error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_error_;
}

}  // namespace caliper::rtc
