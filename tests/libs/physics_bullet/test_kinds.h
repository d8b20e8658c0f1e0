#pragma once
// Actuator kinds for physics tests, registered through the public registry (which is also how a
// new kind plugs in without touching the engine).

#include <cmath>
#include <limits>

#include "caliper/actuators/actuator.h"

namespace caliper::testing {

/// Pulls with a constant tension [N] (the command); turns NaN after `nan_after` steps if > 0.
class ConstantTension : public actuators::TendonActuator {
 public:
  explicit ConstantTension(const sgal::Actuator& a)
      : tension_(actuators::ParameterOr(a, "tension", 0)),
        nan_after_(static_cast<int>(actuators::ParameterOr(a, "nan_after", 0))) {}
  void Reset(double) override { steps_ = 0; }
  double Step(double length, double, double) override {
    last_length_ = length;
    ++steps_;
    if (nan_after_ > 0 && steps_ > nan_after_) return std::numeric_limits<double>::quiet_NaN();
    return tension_;
  }
  double tension() const override { return tension_; }
  void SetCommand(double v) override { tension_ = v; }
  double command() const override { return tension_; }
  std::string command_unit() const override { return "N"; }
  std::vector<actuators::Quantity> Quantities() const override {
    return {{"seen_length", "m", false, false}};
  }
  double Get(const std::string& name) const override {
    if (name == "seen_length") return last_length_;
    throw std::out_of_range(name);
  }
  void Set(const std::string& name, double) override { throw std::out_of_range(name); }

 private:
  double tension_;
  int nan_after_;
  int steps_ = 0;
  double last_length_ = 0;
};

inline void RegisterTestKinds() {
  actuators::RegisterKind(
      "test_constant_tension",
      {{"tension", "N", 0, false, "constant tension"}, {"nan_after", "", 0, false, "steps"}},
      [](const sgal::Actuator& a) { return std::make_unique<ConstantTension>(a); });
}

}  // namespace caliper::testing
