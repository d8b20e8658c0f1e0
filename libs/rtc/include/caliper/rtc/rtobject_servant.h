#pragma once
// The CORBA face of the lifecycle: LightweightRTObject and ExecutionContext servants.
// A component's servant derives from its IDL skeleton and from RTObjectServant.

#include "caliper/rtc.hh"
#include "caliper/rtc/runtime.h"

namespace caliper::rtc {

/// IDL return code for a C++ one.
Caliper::RTC::ReturnCode ToIdl(ReturnCode code);
/// IDL state for a C++ one.
Caliper::RTC::LifeCycleState ToIdl(State state);

class RTObjectServant : public virtual POA_Caliper::RTC::LightweightRTObject {
 public:
  explicit RTObjectServant(Runtime& runtime) : runtime_(runtime) {}

  Caliper::RTC::ReturnCode initialize() override;
  Caliper::RTC::ReturnCode finalize() override;
  Caliper::RTC::ReturnCode exit() override;
  CORBA::Boolean is_alive(Caliper::RTC::ExecutionContext_ptr exec_context) override;
  Caliper::RTC::ComponentProfile* get_component_profile() override;
  Caliper::RTC::ExecutionContextList* get_owned_contexts() override;
  char* get_last_error() override;

 protected:
  Runtime& runtime_;
};

class ExecutionContextServant : public virtual POA_Caliper::RTC::ExecutionContext {
 public:
  explicit ExecutionContextServant(Runtime& runtime) : runtime_(runtime) {}

  CORBA::Boolean is_running() override;
  Caliper::RTC::ReturnCode start() override;
  Caliper::RTC::ReturnCode stop() override;
  CORBA::Double get_rate() override;
  Caliper::RTC::ReturnCode set_rate(CORBA::Double rate) override;
  Caliper::RTC::ExecutionContextKind get_kind() override;
  Caliper::RTC::ReturnCode activate_component(Caliper::RTC::LightweightRTObject_ptr comp) override;
  Caliper::RTC::ReturnCode deactivate_component(Caliper::RTC::LightweightRTObject_ptr comp) override;
  Caliper::RTC::ReturnCode reset_component(Caliper::RTC::LightweightRTObject_ptr comp) override;
  Caliper::RTC::LifeCycleState get_component_state(Caliper::RTC::LightweightRTObject_ptr comp) override;
  Caliper::RTC::ReturnCode tick() override;
  Caliper::RTC::ContextStatistics get_statistics() override;

 private:
  bool Owns(Caliper::RTC::LightweightRTObject_ptr comp);
  Runtime& runtime_;
};

/// The servant of a component that serves nothing but the lifecycle.
class DataFlowServant : public virtual POA_Caliper::RTC::DataFlowComponent, public RTObjectServant {
 public:
  using RTObjectServant::RTObjectServant;
};

}  // namespace caliper::rtc
