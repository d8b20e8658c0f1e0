#include "manager_servant.h"

#include <type_traits>

#include "caliper/logging/log.h"
#include "caliper/rtc/reason.h"

namespace caliper::manager {

namespace C = ::Caliper::Cluster;

namespace {

void ToIdl(const ChildStatus& s, C::Child* out) {
  out->instance = s.instance.c_str();
  out->type = s.type.c_str();
  out->pid = static_cast<CORBA::Long>(s.pid);
  out->naming_path = s.naming_path.c_str();
  out->state = s.state.c_str();
  out->uptime = s.uptime;
}

// Runs a component call and turns its C++ exceptions into the IDL's; anything else becomes
// `Fallback` with the reason (CORBA::INTERNAL for operations that raise nothing).
template <class Fallback = void, class F>
auto Guard(F&& f) -> decltype(f()) {
  // reasons quote what the client sent (types, keys, names): bounded, whatever their size
  using rtc::BoundedReason;
  std::string reason;
  try {
    return f();
  } catch (const CapacityReached& e) {
    throw C::CapacityReached(BoundedReason(e.what()).c_str());
  } catch (const StartFailed& e) {
    throw C::StartFailed(BoundedReason(e.what()).c_str());
  } catch (const UnknownComponent& e) {
    throw C::UnknownComponent(BoundedReason(e.what()).c_str());
  } catch (const CORBA::Exception&) {
    throw;
  } catch (const std::exception& e) {
    reason = "internal error: " + BoundedReason(e.what());
  } catch (...) {
    reason = "internal error: an exception of unknown type";
  }
  logging::Get("manager").error("%s", reason.c_str());
  if constexpr (std::is_void_v<Fallback>)
    throw CORBA::INTERNAL(0, CORBA::COMPLETED_MAYBE);
  else
    throw Fallback(reason.c_str());
}

}  // namespace

ManagerServant::ManagerServant(rtc::Runtime& runtime, ManagerComponent& component)
    : rtc::RTObjectServant(runtime), component_(component) {}

C::Child* ManagerServant::create(const char* type, const Caliper::RTC::NameValueList& config) {
  return Guard<C::StartFailed>([&] {
    std::vector<std::pair<std::string, std::string>> entries;
    for (CORBA::ULong i = 0; i < config.length(); ++i)
      entries.emplace_back(config[i].name.in(), config[i].value.in());
    const ChildStatus child = component_.Create(type, entries);
    auto* out = new C::Child;
    ToIdl(child, out);
    return out;
  });
}

C::ChildSeq* ManagerServant::list() {
  return Guard([&] {
    const std::vector<ChildStatus> children = component_.supervisor().List();
    auto* out = new C::ChildSeq;
    out->length(static_cast<CORBA::ULong>(children.size()));
    for (CORBA::ULong i = 0; i < children.size(); ++i) ToIdl(children[i], &(*out)[i]);
    return out;
  });
}

void ManagerServant::destroy(const char* instance) {
  // children that never registered have no name yet: "" must not pick one of them
  if (*instance == '\0') throw C::UnknownComponent("no instance name given");
  Guard<C::UnknownComponent>([&] { component_.Destroy(instance); });
}

CORBA::ULong ManagerServant::capacity() {
  return Guard([&] { return static_cast<CORBA::ULong>(component_.supervisor().capacity()); });
}

CORBA::ULong ManagerServant::running() {
  return Guard([&] { return static_cast<CORBA::ULong>(component_.supervisor().running()); });
}

}  // namespace caliper::manager
