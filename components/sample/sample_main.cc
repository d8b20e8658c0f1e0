// caliper-sample: a minimal component for demos and tests of the runtime and logging.
#include "caliper/rtc/rtobject_servant.h"
#include "sample_component.h"

int main(int argc, char** argv) {
  using namespace caliper;
  rtc::ComponentType type;
  type.name = "sample";
  type.description = "Sample component: logs numbered records while ACTIVE.";
  type.category = "example";
  type.config_keys = sample::SampleComponent::ConfigKeys();
  return rtc::RunComponentOf<sample::SampleComponent, rtc::DataFlowServant>(argc, argv, type);
}
