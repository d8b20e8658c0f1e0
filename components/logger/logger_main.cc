// caliper-logger: the Logging component.
#include "caliper/rtc/runtime.h"
#include "logger_component.h"
#include "logger_servant.h"

int main(int argc, char** argv) {
  using namespace caliper;
  rtc::ComponentType type;
  type.name = "logger";
  type.description = "Logging service: one log file per session, queries, live listeners.";
  type.category = "infrastructure";
  type.config_keys = logger::LoggerComponent::ConfigKeys();
  type.remote_logging = false;
  return rtc::RunComponentOf<logger::LoggerComponent, logger::LoggerServant>(argc, argv, type);
}
