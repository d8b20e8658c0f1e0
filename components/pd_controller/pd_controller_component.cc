#include "pd_controller_component.h"

#include <algorithm>

#include "caliper/client/model.h"
#include "caliper/logging/log.h"
#include "caliper/rtc/naming.h"

namespace caliper::pd_controller {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;

std::vector<core::ConfigKey> PdControllerComponent::ConfigKeys() {
  using Type = core::ConfigKey::Type;
  return {
      {"controller.model", Type::kString, "model0", "instance name of the Model"},
      {"controller.joint", Type::kString, "elbow", "joint whose position is controlled"},
      {"controller.flexor", Type::kString, "elbow_flexor", "actuator that increases the angle"},
      {"controller.extensor", Type::kString, "elbow_extensor", "actuator that decreases it"},
      {"controller.target", Type::kDouble, "1.0", "joint target [rad]", -10, 10},
      {"controller.kp", Type::kDouble, "20", "proportional gain [V/rad]", 0, 1e4},
      {"controller.kd", Type::kDouble, "1", "derivative gain [V s/rad]", 0, 1e4},
      {"controller.bias", Type::kDouble, "1", "co-contraction voltage on both motors [V]", 0, 100},
      {"controller.max", Type::kDouble, "6", "largest motor voltage [V]", 0, 100},
      {"controller.lockstep", Type::kBool, "false", "step the Model after each command"},
      {"controller.steps_per_tick", Type::kInt, "10", "Model steps per tick in lock-step", 1,
       1e6},
  };
}

PdControllerComponent::PdControllerComponent(rtc::Runtime& runtime) : runtime_(runtime) {}

rtc::ReturnCode PdControllerComponent::OnActivated() {
  const auto& c = runtime_.config();
  CosNaming::NamingContext_var root = rtc::ResolveRoot(runtime_.orb(), runtime_.naming_address());
  // the client library finds it (host/instance too) and says what is wrong when it cannot
  model_ = client::FindModel(root, c.GetString("controller.model")).model._retn();
  // channel ids are <model name>.<joint>.position: find the joint's among the Model's channels
  D::ChannelInfoSeq_var channels = model_->list(("*." + c.GetString("controller.joint") + ".position").c_str());
  if (channels->length() == 0)
    throw std::runtime_error("the Model has no joint '" + c.GetString("controller.joint") + "'");
  position_id_ = channels[0].id.in();
  velocity_id_ = position_id_.substr(0, position_id_.size() - 8) + "velocity";
  logging::Get("pd").notice("controlling %s toward %.3f rad through %s and %s",
                            position_id_.c_str(), c.GetDouble("controller.target"),
                            c.GetString("controller.flexor").c_str(),
                            c.GetString("controller.extensor").c_str());
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode PdControllerComponent::OnExecute() {
  const auto& c = runtime_.config();
  Caliper::Scene::StringSeq ids;
  ids.length(2);
  ids[0] = position_id_.c_str();
  ids[1] = velocity_id_.c_str();
  D::ValueSeq_var values = model_->get(ids);
  const double q = values[0].data[0], qd = values[1].data[0];
  const double u = c.GetDouble("controller.kp") * (c.GetDouble("controller.target") - q) -
                   c.GetDouble("controller.kd") * qd;
  const double bias = c.GetDouble("controller.bias"), max = c.GetDouble("controller.max");
  M::CommandSeq commands;
  commands.length(2);
  commands[0].actuator = c.GetString("controller.flexor").c_str();
  commands[0].value = std::clamp(bias + u, 0.0, max);
  commands[1].actuator = c.GetString("controller.extensor").c_str();
  commands[1].value = std::clamp(bias - u, 0.0, max);
  model_->set_commands(commands);
  if (c.GetBool("controller.lockstep"))
    model_->step(static_cast<CORBA::ULong>(c.GetInt("controller.steps_per_tick")));
  if (++ticks_ % 50 == 0)
    logging::Get("pd").info("%s = %.4f rad, u = %.3f V", position_id_.c_str(), q, u);
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode PdControllerComponent::OnDeactivated() {
  if (CORBA::is_nil(model_)) return rtc::ReturnCode::kOk;
  try {
    M::CommandSeq off;
    off.length(2);
    off[0].actuator = runtime_.config().GetString("controller.flexor").c_str();
    off[0].value = 0;
    off[1].actuator = runtime_.config().GetString("controller.extensor").c_str();
    off[1].value = 0;
    model_->set_commands(off);
  } catch (const CORBA::Exception&) {
    // the Model is gone: nothing to switch off
  }
  return rtc::ReturnCode::kOk;
}

}  // namespace caliper::pd_controller
