#pragma once
// CORBA face of the manager: converts, forwards to ManagerComponent, and turns its C++
// exceptions into the Cluster IDL's.

#include "caliper/cluster.hh"
#include "caliper/rtc/rtobject_servant.h"
#include "manager_component.h"

namespace caliper::manager {

class ManagerServant : public virtual POA_Caliper::Cluster::Manager, public rtc::RTObjectServant {
 public:
  ManagerServant(rtc::Runtime& runtime, ManagerComponent& component);

  Caliper::Cluster::Child* create(const char* type,
                                  const Caliper::RTC::NameValueList& config) override;
  Caliper::Cluster::ChildSeq* list() override;
  void destroy(const char* instance) override;
  CORBA::ULong capacity() override;
  CORBA::ULong running() override;

 private:
  ManagerComponent& component_;
};

}  // namespace caliper::manager
