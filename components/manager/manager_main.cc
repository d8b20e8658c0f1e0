// caliper-manager: the per-host manager component.
#include "caliper/rtc/runtime.h"
#include "manager_component.h"
#include "manager_servant.h"

int main(int argc, char** argv) {
  using namespace caliper;
  rtc::ComponentType type;
  type.name = "manager";
  type.description =
      "Manager: starts, lists and stops Models on this host on request, capped per core.";
  type.category = "cluster";
  type.config_keys = manager::ManagerComponent::ConfigKeys();
  return rtc::RunComponentOf<manager::ManagerComponent, manager::ManagerServant>(argc, argv, type);
}
