// The C++ example controller as its own process: a PD loop bends the shipped arm's elbow to its
// target through the elbow's two tendon motors, in lock-step with the Model.
#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <cstdlib>

#include "caliper/model.hh"
#include "caliper/rtc/naming.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;
namespace M = ::Caliper::Simulation;

TEST(PdController, BendsTheElbowToItsTargetThroughTheTendonMotors) {
  TempDir dir;
  NamingService naming(dir.path());
  const std::string models = std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/models";
  const std::vector<std::string> common = {"--nameservice", naming.address(), "-o",
                                           "log.service=none", "-o",
                                           "log.spool_dir=" + dir.path() + "/spool"};
  std::vector<std::string> model_args = {Bin("caliper-model"), "-o",
                                         "model.scene=" + models + "/ecce_arm.dae", "-o",
                                         "exec.auto_activate=true"};
  model_args.insert(model_args.end(), common.begin(), common.end());
  Process model(model_args, dir.path() + "/model.out");

  int argc = 3;
  const char* args[] = {"test", "-ORBendPoint", "giop:tcp:127.0.0.1:"};
  CORBA::ORB_var orb = CORBA::ORB_init(argc, const_cast<char**>(args));
  M::Model_var arm;
  ASSERT_TRUE(WaitFor(
      [&] {
        try {
          CosNaming::NamingContext_var root = rtc::ResolveRoot(orb, naming.address());
          arm = M::Model::_narrow(rtc::FindComponent(root, "model0").object);
          return !CORBA::is_nil(arm);
        } catch (...) {
          return false;
        }
      },
      seconds(20)))
      << model.Output();
  auto elbow = [&] {
    Caliper::Scene::StringSeq ids;
    ids.length(1);
    ids[0] = "ecce_arm.elbow.position";
    Caliper::Daq::ValueSeq_var v = arm->get(ids);
    return v[0].data[0];
  };
  const double start = elbow();
  EXPECT_LT(std::abs(start), 0.05) << "the arm hangs straight at first";

  const double target = 0.8;
  std::vector<std::string> controller_args = {
      Bin("caliper-pd-controller"), "-o", "exec.auto_activate=true", "-o",
      "controller.lockstep=true", "-o", "controller.target=" + std::to_string(target), "-o",
      "exec.rate=200"};
  controller_args.insert(controller_args.end(), common.begin(), common.end());
  Process controller(controller_args, dir.path() + "/controller.out");
  // lock-step: the controller steps the Model 10 ms per tick; 4 s of simulated time suffice
  ASSERT_TRUE(WaitFor(
      [&] { return M::SimulationStatus_var(arm->status())->sim_time > 4.0; },
      seconds(60)))
      << controller.Output();
  EXPECT_NEAR(elbow(), target, 0.1) << controller.Output();
  M::SimulationStatus_var status = arm->status();
  EXPECT_EQ(status->state, M::PAUSED) << "stepped by the controller, not running on its own";

  // stopping the controller switches its motors off
  controller.Signal(SIGTERM);
  EXPECT_EQ(controller.Wait(seconds(10)), 0) << controller.Output();
  M::ActuatorStateSeq_var states = arm->actuator_states();
  for (CORBA::ULong i = 0; i < states->length(); ++i) {
    const std::string name = states[i].name.in();
    if (name == "elbow_flexor" || name == "elbow_extensor") {
      EXPECT_EQ(states[i].command, 0.0) << name;
    }
  }
  model.Signal(SIGTERM);
  EXPECT_EQ(model.Wait(seconds(10)), 0) << model.Output();
  orb->destroy();
}

}  // namespace
}  // namespace caliper::testing
