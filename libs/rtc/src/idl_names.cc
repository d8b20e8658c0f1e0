#include "caliper/rtc/idl_names.h"

namespace caliper::rtc {

namespace RTC = ::Caliper::RTC;
namespace M = ::Caliper::Simulation;

const char* Name(RTC::LifeCycleState s) {
  switch (s) {
    case RTC::CREATED_STATE: return "CREATED";
    case RTC::INACTIVE_STATE: return "INACTIVE";
    case RTC::ACTIVE_STATE: return "ACTIVE";
    case RTC::ERROR_STATE: return "ERROR";
  }
  return "?";
}

const char* Name(RTC::ReturnCode c) {
  switch (c) {
    case RTC::RTC_OK: return "RTC_OK";
    case RTC::RTC_ERROR: return "RTC_ERROR";
    case RTC::BAD_PARAMETER: return "BAD_PARAMETER";
    case RTC::UNSUPPORTED: return "UNSUPPORTED";
    case RTC::OUT_OF_RESOURCES: return "OUT_OF_RESOURCES";
    case RTC::PRECONDITION_NOT_MET: return "PRECONDITION_NOT_MET";
  }
  return "?";
}

const char* Name(M::SimulationState s) {
  switch (s) {
    case M::EMPTY: return "EMPTY";
    case M::STOPPED: return "STOPPED";
    case M::RUNNING: return "RUNNING";
    case M::PAUSED: return "PAUSED";
    case M::FAULTED: return "FAULTED";
  }
  return "?";
}

}  // namespace caliper::rtc
