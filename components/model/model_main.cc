// caliper-model: the Model component.
#include "caliper/physics_bullet/bullet_scene.h"
#include "caliper/rtc/runtime.h"
#include "model_component.h"
#include "model_servant.h"
#include "model_verify.h"

#include <cstring>

int main(int argc, char** argv) {
  using namespace caliper;
  // a thread waiting for the next step's jobs spins for about kThreadSpinTime (starts again with
  // GOMP_SPINCOUNT set to that many turns on this processor, unless the environment chose)
  physics_bullet::BoundThreadSpin(argv);
  // re-simulating a recording for caliper-ctl replay --verify: no session, no CORBA
  if (argc == 3 && std::strcmp(argv[1], "--verify") == 0) return model::VerifyMain(argv[2]);
  rtc::ComponentType type;
  type.name = "model";
  type.description = "Model: the physics of one tendon-driven robot scene, served over CORBA.";
  type.category = "simulation";
  type.config_keys = model::ModelComponent::ConfigKeys();
  return rtc::RunComponent(
      argc, argv, type,
      [](rtc::Runtime& rt) { return std::make_unique<model::ModelComponent>(rt); },
      [](rtc::Runtime& rt, rtc::Component& c) -> PortableServer::Servant {
        // the servant serves the component's core, which outlives it
        return new model::ModelServant(rt, static_cast<model::ModelComponent&>(c).core());
      });
}
