#pragma once
// An example controller as its own process: a PD position loop on one joint of a Model, acting
// through an antagonistic pair of tendon motors. Each tick it reads the joint's position and
// velocity, computes u = kp (target - q) - kd q', and commands the flexor with bias + u and the
// extensor with bias - u (clamped to [0, max]), in one batched call.
//
// Configuration (config/pd_controller.conf):
//   controller.model     instance name of the Model (model0)
//   controller.joint     joint id prefix in the Model's channels (elbow)
//   controller.flexor, controller.extensor   actuator names
//   controller.target    joint target [rad]
//   controller.kp [V/rad], controller.kd [V s/rad], controller.bias [V], controller.max [V]
//   controller.lockstep  step the Model itself after each command (deterministic runs)
//   controller.steps_per_tick  Model steps per tick in lock-step

#include <string>

#include "caliper/model.hh"
#include "caliper/rtc/runtime.h"

namespace caliper::pd_controller {

class PdControllerComponent : public rtc::Component {
 public:
  explicit PdControllerComponent(rtc::Runtime& runtime);
  rtc::ReturnCode OnActivated() override;
  rtc::ReturnCode OnExecute() override;
  rtc::ReturnCode OnDeactivated() override;
  static std::vector<core::ConfigKey> ConfigKeys();

 private:
  rtc::Runtime& runtime_;
  Caliper::Simulation::Model_var model_;
  std::string position_id_, velocity_id_;
  uint64_t ticks_ = 0;
};

}  // namespace caliper::pd_controller
