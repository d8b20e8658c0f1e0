#pragma once
// A hill_muscle actuator on tendon "t" from its options and parameters, through the registry as a
// scene would make it (shared by the muscle tests).

#include <map>
#include <memory>
#include <string>
#include <utility>

#include "caliper/actuators/actuator.h"

namespace caliper::actuators::test_support {

inline std::unique_ptr<TendonActuator> MakeMuscle(std::map<std::string, std::string> options,
                                                  std::map<std::string, double> parameters) {
  sgal::Actuator a;
  a.name = "m";
  a.kind = "hill_muscle";
  a.tendon = "t";
  a.options = std::move(options);
  a.parameters = std::move(parameters);
  return Make(a);
}

}  // namespace caliper::actuators::test_support
