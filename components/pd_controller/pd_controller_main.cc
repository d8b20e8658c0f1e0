// caliper-pd-controller: an example PD position controller for one joint of a Model.
#include "caliper/rtc/rtobject_servant.h"
#include "pd_controller_component.h"

int main(int argc, char** argv) {
  using namespace caliper;
  rtc::ComponentType type;
  type.name = "pd_controller";
  type.description = "PD position loop on one joint of a Model through its two tendon motors.";
  type.category = "controller";
  type.config_keys = pd_controller::PdControllerComponent::ConfigKeys();
  return rtc::RunComponentOf<pd_controller::PdControllerComponent, rtc::DataFlowServant>(argc, argv, type);
}
