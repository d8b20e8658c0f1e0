// ModelCore on its own, without CORBA: run states and their transitions, step requests in slices
// that leave the Model answering (and stop or pause ending them), every kind of exception in a
// step ending as a fault at the start of the failing step, and the bounds of what one call or
// one queue may take.
#include "caliper/simulation/model_core.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <future>
#include <iterator>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include "caliper/simulation/fault_injection.h"

namespace caliper::simulation {
namespace {

using namespace std::chrono_literals;

std::string Model(const std::string& file) {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(src ? src : ".") + "/models/" + file;
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Waits (at most 20 s) until `done` holds; false when it never did.
template <class F>
bool WaitFor(F done) {
  for (int i = 0; i < 2000; ++i) {
    if (done()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return done();
}

TEST(ModelCore, RunStatesAndTheirTransitions) {
  ModelCore core;
  EXPECT_EQ(core.status().state, RunState::kEmpty);
  EXPECT_THROW(core.Start(), NotAvailable);
  EXPECT_THROW(core.StepNow(1), NotAvailable);
  core.Load(Model("pendulum_tendon.dae"));
  EXPECT_EQ(core.status().state, RunState::kStopped);
  EXPECT_EQ(core.StepNow(5), 5u);
  EXPECT_EQ(core.status().state, RunState::kPaused);
  EXPECT_EQ(core.status().steps, 5u);
  core.Start();
  EXPECT_EQ(core.status().state, RunState::kRunning);
  try {
    core.StepNow(1);
    ADD_FAILURE() << "a step while running was accepted";
  } catch (const NotAvailable& e) {
    EXPECT_TRUE(Contains(e.what(), "running")) << e.what();
  }
  core.Tick();
  EXPECT_EQ(core.status().steps, 6u);
  core.Pause();
  EXPECT_EQ(core.status().state, RunState::kPaused);
  core.Tick();  // not running: no step
  EXPECT_EQ(core.status().steps, 6u);
  core.Stop();
  EXPECT_EQ(core.status().state, RunState::kStopped);
  EXPECT_EQ(core.status().steps, 0u);
  EXPECT_EQ(core.status().sim_time, 0.0);
  EXPECT_EQ(core.StepNow(0), 0u);
}

// A step request of four billion steps: status and reads answered meanwhile, a second request
// refused with the reason, writes queued, and pause ends it with the count of steps run.
TEST(ModelCore, HugeStepRequestLeavesTheModelAnsweringAndPauseEndsIt) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  auto request = std::async(std::launch::async, [&] { return core.StepNow(4000000000u); });
  ASSERT_TRUE(WaitFor([&] { return core.status().steps > 100; })) << "the steps never began";
  const Status during = core.status();
  EXPECT_EQ(during.state, RunState::kRunning);
  EXPECT_FALSE(core.Sample({"pendulum_tendon.pendulum.position"}).empty());
  try {
    core.StepNow(10);
    ADD_FAILURE() << "a second step request was accepted";
  } catch (const NotAvailable& e) {
    EXPECT_TRUE(Contains(e.what(), "4000000000")) << e.what();
  }
  EXPECT_THROW(core.Start(), NotAvailable);
  EXPECT_THROW(core.Load(Model("pendulum_tendon.dae")), NotAvailable);
  EXPECT_NO_THROW(core.SetCommands({{core.Actuators().at(0).name, 1.0}}));
  EXPECT_TRUE(WaitFor([&] { return core.status().steps > during.steps; }))
      << "the request did not go on between reads";
  core.Pause();
  ASSERT_EQ(request.wait_for(20s), std::future_status::ready) << "pause did not end the request";
  const uint64_t ran = request.get();
  EXPECT_GT(ran, 100u);
  EXPECT_LT(ran, 4000000000u);
  EXPECT_EQ(core.status().steps, ran);
  EXPECT_EQ(core.status().state, RunState::kPaused);
  // the queued command took effect at a step boundary
  EXPECT_EQ(core.ActuatorStates().at(0).command, 1.0);
  EXPECT_EQ(core.StepNow(3), 3u);  // a new request runs again
}

TEST(ModelCore, StopEndsAStepRequestAndRewinds) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  auto request = std::async(std::launch::async, [&] { return core.StepNow(4000000000u); });
  ASSERT_TRUE(WaitFor([&] { return core.status().steps > 10; }));
  core.Stop();
  ASSERT_EQ(request.wait_for(20s), std::future_status::ready) << "stop did not end the request";
  EXPECT_LT(request.get(), 4000000000u);
  EXPECT_EQ(core.status().state, RunState::kStopped);
  EXPECT_EQ(core.status().steps, 0u);
}

// Stop, reset and load rewind the commands too (as MuJoCo's reset zeroes its controls); pause
// keeps them. "Not driven" is checked against a Model that never had a command.
TEST(ModelCore, AControlCycleIsTheThreeCallsUnderOneLockAndARefusalChangesNothing) {
  const char* const kPosition = "pendulum_tendon.pendulum.position";
  std::vector<daq::Shape> shapes;
  std::vector<double> values;
  // one cycle reading `ids` into shapes and values: the steps taken
  auto cycle = [&](ModelCore& core, const std::vector<std::pair<std::string, double>>& commands,
                   std::vector<const char*> ids) {
    return core.ControlCycle(commands, 20, ids.data(), ids.size(), &shapes, &values);
  };
  ModelCore three, one;
  three.Load(Model("pendulum_tendon.dae"));
  one.Load(Model("pendulum_tendon.dae"));
  const std::string motor = one.Actuators().at(0).name;
  for (double volts : {6.0, 2.0, 4.5}) {
    three.SetCommands({{motor, volts}});
    ASSERT_EQ(three.StepNow(20), 20u);
    EXPECT_EQ(cycle(one, {{motor, volts}}, {kPosition}), 20u);
    EXPECT_EQ(shapes, std::vector<daq::Shape>{daq::Shape::Vector(3)});  // the body's position
    EXPECT_EQ(values, three.Sample({kPosition}).at(0).values);
  }
  const uint64_t steps = one.status().steps;
  EXPECT_THROW(cycle(one, {{motor, 1.0}}, {"no.such.id"}), UnknownId);
  EXPECT_THROW(cycle(one, {{motor, 1.0}, {"no_such_motor", 1.0}}, {kPosition}), UnknownId);
  EXPECT_THROW(cycle(one, {{motor, std::nan("")}}, {kPosition}), InvalidValue);
  EXPECT_EQ(one.status().steps, steps) << "a refused cycle stepped";
  EXPECT_EQ(one.ActuatorStates().at(0).command, 4.5) << "a refused cycle changed a command";
  one.Start();
  EXPECT_THROW(cycle(one, {{motor, 1.0}}, {kPosition}), NotAvailable);
  one.Pause();
  EXPECT_EQ(one.ActuatorStates().at(0).command, 4.5)
      << "a cycle refused while running changed a command";
}

TEST(ModelCore, StopResetAndLoadZeroEveryCommandAndPauseKeepsThem) {
  const char* const kPosition = "pendulum_tendon.pendulum.position";
  ModelCore idle;
  idle.Load(Model("pendulum_tendon.dae"));
  ASSERT_EQ(idle.StepNow(300), 300u);
  const std::vector<double> undriven = idle.Sample({kPosition}).at(0).values;

  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  const std::string motor = core.Actuators().at(0).name;
  auto drive = [&] {
    core.SetCommands({{motor, 6.0}});
    ASSERT_EQ(core.StepNow(300), 300u);
    ASSERT_EQ(core.ActuatorStates().at(0).command, 6.0);
    ASSERT_NE(core.Sample({kPosition}).at(0).values, undriven) << "the command moved nothing";
  };
  auto expect_not_driven = [&](const char* after) {
    EXPECT_EQ(core.ActuatorStates().at(0).command, 0.0) << "after " << after;
    ASSERT_EQ(core.StepNow(300), 300u);
    EXPECT_EQ(core.ActuatorStates().at(0).command, 0.0) << "after " << after;
    EXPECT_EQ(core.Sample({kPosition}).at(0).values, undriven) << "after " << after;
  };

  drive();
  core.SetRealTimeFactor(0);
  core.Start();
  core.Pause();
  EXPECT_EQ(core.ActuatorStates().at(0).command, 6.0) << "pause kept the command";
  core.Stop();
  EXPECT_EQ(core.status().state, RunState::kStopped);
  expect_not_driven("stop");

  core.Stop();
  drive();
  core.Reset();
  expect_not_driven("reset");

  core.Stop();
  drive();
  core.Load(Model("pendulum_tendon.dae"));
  expect_not_driven("load");
}

struct FaultCase {
  InjectedFault::Kind kind;
  const char* reason;  // a part of last_error
};

class StepFault : public ::testing::TestWithParam<FaultCase> {};

// The first scene built fails at step 5; the rewound one (reset) never does.
PhysicsFactory FailOnce(InjectedFault::Kind kind) { return FailFirstScene({kind, 5}); }

TEST_P(StepFault, EveryExceptionEndsAsAFaultAtTheStartOfTheFailingStep) {
  ModelCore core({}, {}, FailOnce(GetParam().kind));
  core.Load(Model("pendulum_tendon.dae"));
  const double dt = core.status().time_step;
  EXPECT_EQ(core.StepNow(10), 4u);  // steps 1 to 4 ran, the fifth failed
  Status s = core.status();
  EXPECT_EQ(s.state, RunState::kFaulted);
  EXPECT_EQ(s.steps, 4u);
  EXPECT_NEAR(s.sim_time, 4 * dt, 1e-12);
  EXPECT_TRUE(Contains(s.last_error, GetParam().reason)) << s.last_error;
  // a faulted Model refuses to run until reset, and answers reads
  EXPECT_THROW(core.Start(), NotAvailable);
  EXPECT_THROW(core.StepNow(1), NotAvailable);
  EXPECT_NO_THROW(core.Sample({"pendulum_tendon.pendulum.position"}));
  core.Reset();
  s = core.status();
  EXPECT_EQ(s.state, RunState::kStopped);
  EXPECT_EQ(s.steps, 0u);
  EXPECT_TRUE(s.last_error.empty());
  EXPECT_EQ(core.StepNow(10), 10u);
}

TEST_P(StepFault, ARunningModelFaultsWithoutTheExceptionEscaping) {
  ModelCore core({}, {}, FailOnce(GetParam().kind));
  core.Load(Model("pendulum_tendon.dae"));
  core.SetRealTimeFactor(0);
  core.Start();
  for (int i = 0; i < 10 && core.status().state == RunState::kRunning; ++i)
    EXPECT_NO_THROW(core.Advance(5ms));
  const Status s = core.status();
  EXPECT_EQ(s.state, RunState::kFaulted);
  EXPECT_EQ(s.steps, 4u);
  // commands sent to a faulted Model do not pile up for steps that will not come
  EXPECT_NO_THROW(core.SetCommands({{core.Actuators().at(0).name, 2.0}}));
  EXPECT_EQ(core.ActuatorStates().at(0).command, 2.0);
  // a new load brings it back too
  core.Load(Model("pendulum_tendon.dae"));
  EXPECT_EQ(core.status().state, RunState::kStopped);
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, StepFault,
    ::testing::Values(FaultCase{InjectedFault::Kind::kFault, "tension is not finite"},
                      FaultCase{InjectedFault::Kind::kBadAlloc, "bad_alloc"},
                      FaultCase{InjectedFault::Kind::kOutOfRange, "index 7 of 3"},
                      FaultCase{InjectedFault::Kind::kRuntime, "did not converge"},
                      FaultCase{InjectedFault::Kind::kUnknownType, "unknown type"}));

TEST(InjectedFault, ParsesKindAtStepAndRefusesTheRest) {
  EXPECT_EQ(ParseInjectedFault("").kind, InjectedFault::Kind::kNone);
  const InjectedFault f = ParseInjectedFault("bad_alloc@12");
  EXPECT_EQ(f.kind, InjectedFault::Kind::kBadAlloc);
  EXPECT_EQ(f.at_step, 12u);
  EXPECT_THROW(ParseInjectedFault("bad_alloc"), std::invalid_argument);
  EXPECT_THROW(ParseInjectedFault("meteor@3"), std::invalid_argument);
  EXPECT_THROW(ParseInjectedFault("bad_alloc@0"), std::invalid_argument);
  EXPECT_THROW(ParseInjectedFault("bad_alloc@x"), std::invalid_argument);
}

TEST(ModelCore, CallsAskingTooMuchAreRefusedWithTheLimit) {
  Limits limits;
  limits.ids_per_call = 3;
  limits.channels_per_list = 5;
  limits.pattern_length = 16;
  ModelCore core({}, limits);
  core.Load(Model("pendulum_tendon.dae"));
  const std::string id = "pendulum_tendon.pendulum.position";
  EXPECT_EQ(core.Sample({id, id, id}).size(), 3u);
  try {
    core.Sample({id, id, id, id});
    ADD_FAILURE() << "4 ids accepted";
  } catch (const LimitExceeded& e) {
    EXPECT_EQ(e.limit(), 3u);
    EXPECT_TRUE(Contains(e.what(), "4 ids")) << e.what();
  }
  try {
    core.Channels("*");
    ADD_FAILURE() << "an unbounded list was accepted";
  } catch (const LimitExceeded& e) {
    EXPECT_EQ(e.limit(), 5u);
    EXPECT_TRUE(Contains(e.what(), "narrow the pattern")) << e.what();
  }
  EXPECT_EQ(core.Channels("*.pendulum.mass").size(), 1u);
  EXPECT_THROW(core.Channels(std::string(17, '*')), LimitExceeded);

  EXPECT_THROW(core.Subscribe({id, id, id, id}, 1, 1), LimitExceeded);
}

TEST(ModelCore, SubscribedValuesAreBoundedInAll) {
  Limits limits;
  limits.subscribed_values = 7;
  ModelCore core({}, limits);
  core.Load(Model("pendulum_tendon.dae"));
  const std::string position = "pendulum_tendon.pendulum.position";  // 3 values
  const uint64_t a = core.Subscribe({position, position}, 1, 10);
  try {
    core.Subscribe({position}, 1, 10);
    ADD_FAILURE() << "9 subscribed values accepted with a bound of 7";
  } catch (const LimitExceeded& e) {
    EXPECT_EQ(e.limit(), 7u);
    EXPECT_TRUE(Contains(e.what(), "6 subscribed already")) << e.what();
  }
  EXPECT_NO_THROW(core.Subscribe({"pendulum_tendon.pendulum.mass"}, 1, 10));
  core.Unsubscribe(a);  // frees its values
  EXPECT_NO_THROW(core.Subscribe({position, position}, 1, 10));
}

TEST(ModelCore, AnExperimentOfTooManyStepsIsRefusedBeforeItRuns) {
  Limits limits;
  limits.experiment_steps = 100;
  ModelCore core({}, limits);
  std::ifstream in(Model("pendulum_tendon.dae"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  experiment::Experiment e;
  e.name = "long";
  e.scene = "pendulum_tendon.dae";
  e.record = {"pendulum_tendon.pendulum.position"};
  e.duration_s = 0.5;  // 500 steps of 1 ms
  try {
    core.RunExperiment(e, "pendulum_tendon.dae", bytes);
    ADD_FAILURE() << "500 steps ran with a bound of 100";
  } catch (const InvalidValue& error) {
    EXPECT_TRUE(Contains(error.what(), "at most 100")) << error.what();
  }
  EXPECT_EQ(core.status().steps, 0u);
  e.duration_s = 0.05;
  EXPECT_EQ(core.RunExperiment(e, "pendulum_tendon.dae", bytes).steps, 50u);
}

TEST(ModelCore, AGlobOfManyStarsIsRefused) {
  // fnmatch's work grows as the number of '*' to the power of the id's length
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  try {
    core.Channels("*a*a*a*a*a*a*a*a*b");  // 9 '*'
    ADD_FAILURE() << "a pattern of 9 '*' was matched";
  } catch (const LimitExceeded& e) {
    EXPECT_EQ(e.limit(), 8u);
  }
  EXPECT_FALSE(core.Channels("*.pendulum.*").empty());
}

TEST(ModelCore, WritesQueuedForTheNextStepAreBounded) {
  Limits limits;
  limits.pending_writes = 10;
  ModelCore core({}, limits);
  core.Load(Model("pendulum_tendon.dae"));
  const std::string motor = core.Actuators().at(0).name;
  core.Start();  // running, but nothing steps it here: writes queue
  for (int i = 0; i < 10; ++i) core.SetCommands({{motor, 0.1 * i}});
  try {
    core.SetCommands({{motor, 1.0}});
    ADD_FAILURE() << "an 11th queued write was accepted";
  } catch (const NotAvailable& e) {
    EXPECT_TRUE(Contains(e.what(), "at most 10")) << e.what();
  }
  // a parameter write does not queue: it applies between two steps at once
  EXPECT_NO_THROW(core.SetChannel("pendulum_tendon.pendulum.mass", {2.0}));
  EXPECT_EQ(core.Sample({"pendulum_tendon.pendulum.mass"}).at(0).values.at(0), 2.0);
  core.Tick();  // a step takes them all
  EXPECT_NO_THROW(core.SetCommands({{motor, 1.0}}));
}

TEST(ModelCore, AParameterCannotMakeOneStepRunForHours) {
  ModelCore core;
  core.Load(Model("pendulum_tendon.dae"));
  const std::string motor = core.Actuators().at(0).name;
  const std::string id = "pendulum_tendon." + motor + ".max_substep";
  ASSERT_FALSE(core.Channels(id).empty()) << id << " is not a channel";
  try {
    core.SetChannel(id, {1e-12});
    ADD_FAILURE() << "max_substep 1e-12 s was accepted";
  } catch (const InvalidValue& e) {
    EXPECT_TRUE(Contains(e.what(), "max_substep")) << e.what();
  }
  EXPECT_NO_THROW(core.SetChannel(id, {1e-4}));
  // while running too: the refusal reaches the caller, not only the log
  core.Start();
  EXPECT_THROW(core.SetChannel(id, {1e-12}), InvalidValue);
  EXPECT_THROW(core.SetChannel("pendulum_tendon.pendulum.mass", {-1.0}), InvalidValue);
}

}  // namespace
}  // namespace caliper::simulation
