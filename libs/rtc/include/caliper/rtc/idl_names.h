#pragma once
// Names of IDL enumerations for messages and displays (ctl, the Main Window): one place for all.

#include "caliper/model.hh"
#include "caliper/rtc.hh"

namespace caliper::rtc {

/// `CREATED`, `INACTIVE`, `ACTIVE`, `ERROR`.
const char* Name(Caliper::RTC::LifeCycleState state);
/// `RTC_OK`, `PRECONDITION_NOT_MET`, ...
const char* Name(Caliper::RTC::ReturnCode code);
/// `EMPTY`, `STOPPED`, `RUNNING`, `PAUSED`, `FAULTED`.
const char* Name(Caliper::Simulation::SimulationState state);

}  // namespace caliper::rtc
