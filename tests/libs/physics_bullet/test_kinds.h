#pragma once
// Actuator kinds for physics tests, registered through the public registry (which is also how a
// new kind plugs in without touching the engine).

#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/actuators/actuator.h"

namespace caliper::testing {

/// Pulls with a constant tension [N] (the command); turns NaN after `nan_after` steps if > 0.
class ConstantTension : public actuators::TendonActuator {
 public:
  explicit ConstantTension(const sgal::Actuator& a)
      : tension_(actuators::ParameterOr(a, "tension", 0)),
        nan_after_(static_cast<int>(actuators::ParameterOr(a, "nan_after", 0))) {}
  void Reset(double) override { steps_ = 0; }
  double Step(double length, double, double, double) override {
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

/// A dc_motor_tendon (all its parameters and options) that fails on purpose after its own step
/// while its parameter `fail` is set: 1 throws std::runtime_error("injected fault"), 2
/// std::bad_alloc, 3 returns a NaN tension, 4 throws an int; 5 steps well, but the next reading
/// of one of its quantities (a delayed channel's, at the end of the step) throws
/// std::runtime_error("injected reading fault") once and sets `fail` back to 0; 6 throws
/// std::runtime_error("injected fault") and then, putting its step back, std::logic_error
/// ("injected restore fault") after the motor's state is back. Its state is the motor's.
class FaultyMotor : public actuators::TendonActuator {
 public:
  explicit FaultyMotor(const sgal::Actuator& a) : fail_(actuators::ParameterOr(a, "fail", 0)) {
    sgal::Actuator motor = a;
    motor.kind = "dc_motor_tendon";
    motor.parameters.erase("fail");
    motor_ = actuators::Make(motor);
  }
  void Reset(double length) override { motor_->Reset(length); }
  double Step(double length, double speed, double dt, double end_speed) override {
    const double tension = motor_->Step(length, speed, dt, end_speed);  // the motor has moved on
    switch (static_cast<int>(fail_)) {
      case 1:
      case 6:
        throw std::runtime_error("injected fault");
      case 2:
        throw std::bad_alloc();
      case 3:
        return std::numeric_limits<double>::quiet_NaN();
      case 4:
        throw 42;
      default:
        return tension;
    }
  }
  double tension() const override { return motor_->tension(); }
  size_t StateSize() const override { return motor_->StateSize(); }
  void SaveState(double* out) const override { motor_->SaveState(out); }
  bool Restorable(const double* in, size_t n) const override { return motor_->Restorable(in, n); }
  void RestoreState(const double* in) override { motor_->RestoreState(in); }
  void SaveStepState(double* out) const override { motor_->SaveStepState(out); }
  void RestoreStepState(const double* in) override {
    motor_->RestoreStepState(in);
    if (fail_ == 6) throw std::logic_error("injected restore fault");
  }
  void SetTimeStep(double dt) override { motor_->SetTimeStep(dt); }
  void SetCommand(double v) override { motor_->SetCommand(v); }
  double command() const override { return motor_->command(); }
  std::string command_unit() const override { return motor_->command_unit(); }
  std::vector<actuators::Quantity> Quantities() const override {
    auto q = motor_->Quantities();
    q.push_back({"fail", "", true, true});
    return q;
  }
  double Get(const std::string& name) const override {
    if (name == "fail") return fail_;
    if (fail_ == 5) {
      fail_ = 0;
      throw std::runtime_error("injected reading fault");
    }
    return motor_->Get(name);
  }
  void Set(const std::string& name, double value) override {
    if (name == "fail")
      fail_ = value;
    else
      motor_->Set(name, value);
  }

 private:
  std::unique_ptr<actuators::TendonActuator> motor_;
  mutable double fail_;  // a reading fault happens once
};

inline void RegisterTestKinds() {
  actuators::RegisterKind(
      "test_constant_tension",
      {{"tension", "N", 0, false, "constant tension"}, {"nan_after", "", 0, false, "steps"}},
      [](const sgal::Actuator& a) { return std::make_unique<ConstantTension>(a); });
  auto faulty = actuators::KindParameters("dc_motor_tendon");
  faulty.push_back(
      {"fail", "", 0, false,
       "0 none, 1 runtime_error, 2 bad_alloc, 3 NaN, 4 int, 5 a reading, 6 a step put back"});
  actuators::RegisterKind("test_faulty_motor", faulty, [](const sgal::Actuator& a) {
    return std::make_unique<FaultyMotor>(a);
  });
}

}  // namespace caliper::testing
