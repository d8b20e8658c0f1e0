#include "caliper/rtc/rtobject_servant.h"

#include <unistd.h>

#include "caliper/core/system.h"

namespace caliper::rtc {

namespace idl = ::Caliper::RTC;

idl::ReturnCode ToIdl(ReturnCode code) {
  switch (code) {
    case ReturnCode::kOk: return idl::RTC_OK;
    case ReturnCode::kError: return idl::RTC_ERROR;
    case ReturnCode::kBadParameter: return idl::BAD_PARAMETER;
    case ReturnCode::kUnsupported: return idl::UNSUPPORTED;
    case ReturnCode::kOutOfResources: return idl::OUT_OF_RESOURCES;
    case ReturnCode::kPreconditionNotMet: return idl::PRECONDITION_NOT_MET;
  }
  return idl::RTC_ERROR;
}

idl::LifeCycleState ToIdl(State state) {
  switch (state) {
    case State::kCreated: return idl::CREATED_STATE;
    case State::kInactive: return idl::INACTIVE_STATE;
    case State::kActive: return idl::ACTIVE_STATE;
    case State::kError: return idl::ERROR_STATE;
  }
  return idl::ERROR_STATE;
}

idl::ReturnCode RTObjectServant::initialize() { return ToIdl(runtime_.lifecycle().Initialize()); }

idl::ReturnCode RTObjectServant::finalize() {
  // as in OpenRTM: finalize is refused while an execution context still runs the component
  if (runtime_.context().is_running() && runtime_.lifecycle().state() == State::kActive)
    return idl::PRECONDITION_NOT_MET;
  return ToIdl(runtime_.lifecycle().Finalize());
}

idl::ReturnCode RTObjectServant::exit() {
  // also once finalized: a finalized component serves nothing, and no other call ends its process
  runtime_.RequestExit();
  return idl::RTC_OK;
}

CORBA::Boolean RTObjectServant::is_alive(idl::ExecutionContext_ptr exec_context) {
  if (runtime_.lifecycle().finalized()) return false;
  return CORBA::is_nil(exec_context) || exec_context->_is_equivalent(runtime_.context_ref());
}

idl::ComponentProfile* RTObjectServant::get_component_profile() {
  auto* profile = new idl::ComponentProfile;
  const auto& type = runtime_.type();
  profile->instance_name = runtime_.instance().c_str();
  profile->type_name = type.name.c_str();
  profile->description = type.description.c_str();
  profile->version = type.version.c_str();
  profile->vendor = type.vendor.c_str();
  profile->category = type.category.c_str();
  auto items = runtime_.config().Items();
  items.emplace_back("host", core::HostName());
  items.emplace_back("pid", std::to_string(getpid()));
  items.emplace_back("naming.path", runtime_.naming_path());
  profile->properties.length(static_cast<CORBA::ULong>(items.size()));
  for (CORBA::ULong i = 0; i < items.size(); ++i) {
    profile->properties[i].name = items[i].first.c_str();
    profile->properties[i].value = items[i].second.c_str();
  }
  return profile;
}

idl::ExecutionContextList* RTObjectServant::get_owned_contexts() {
  auto* list = new idl::ExecutionContextList;
  list->length(1);
  (*list)[0] = idl::ExecutionContext::_narrow(runtime_.context_ref());
  return list;
}

char* RTObjectServant::get_last_error() {
  return CORBA::string_dup(runtime_.lifecycle().last_error().c_str());
}

bool ExecutionContextServant::Owns(idl::LightweightRTObject_ptr comp) {
  return !CORBA::is_nil(comp) && comp->_is_equivalent(runtime_.self());
}

CORBA::Boolean ExecutionContextServant::is_running() { return runtime_.context().is_running(); }
idl::ReturnCode ExecutionContextServant::start() { return ToIdl(runtime_.context().Start()); }
idl::ReturnCode ExecutionContextServant::stop() { return ToIdl(runtime_.context().Stop()); }
CORBA::Double ExecutionContextServant::get_rate() { return runtime_.context().rate(); }

idl::ReturnCode ExecutionContextServant::set_rate(CORBA::Double rate) {
  return ToIdl(runtime_.context().SetRate(rate));
}

idl::ExecutionContextKind ExecutionContextServant::get_kind() {
  return runtime_.context().kind() == ContextKind::kPeriodic ? idl::PERIODIC : idl::EXTERNAL;
}

idl::ReturnCode ExecutionContextServant::activate_component(idl::LightweightRTObject_ptr comp) {
  if (!Owns(comp)) return idl::BAD_PARAMETER;
  return ToIdl(runtime_.lifecycle().Activate());
}

idl::ReturnCode ExecutionContextServant::deactivate_component(idl::LightweightRTObject_ptr comp) {
  if (!Owns(comp)) return idl::BAD_PARAMETER;
  return ToIdl(runtime_.lifecycle().Deactivate());
}

idl::ReturnCode ExecutionContextServant::reset_component(idl::LightweightRTObject_ptr comp) {
  if (!Owns(comp)) return idl::BAD_PARAMETER;
  return ToIdl(runtime_.lifecycle().Reset());
}

idl::LifeCycleState ExecutionContextServant::get_component_state(
    idl::LightweightRTObject_ptr comp) {
  if (!Owns(comp)) return idl::CREATED_STATE;
  return ToIdl(runtime_.lifecycle().state());
}

idl::ReturnCode ExecutionContextServant::tick() { return ToIdl(runtime_.context().Tick()); }

idl::ContextStatistics ExecutionContextServant::get_statistics() {
  const auto s = runtime_.context().statistics();
  idl::ContextStatistics out;
  out.ticks = s.ticks;
  out.overruns = s.overruns;
  out.last_execute_time_s = s.last_execute_time_s;
  out.max_execute_time_s = s.max_execute_time_s;
  return out;
}

}  // namespace caliper::rtc
