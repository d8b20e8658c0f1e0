// The command delay every commanded kind has (`command_delay` [s], state `delayed_command`), here
// on hill_muscle in each of its forms: a delayed muscle is the same muscle fed its commands late
// by hand, bit for bit; commands in flight survive SaveState/RestoreState, and a step is put back
// by SaveStepState/RestoreStepState; the bounds of the line.
// dc_motor_tendon's driver delay is checked in motor_realism_test.cc (a delayed PD loop).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "caliper/actuators/actuator.h"
#include "make_muscle.h"

namespace caliper::actuators {
namespace {

using test_support::MakeMuscle;

struct Form {
  const char* name;
  std::map<std::string, std::string> options;
  std::map<std::string, double> parameters;
};

// the muscle's forms: each integrates the activation its own way
std::vector<Form> Forms() {
  const std::map<std::string, double> thelen = {{"optimal_fiber_length", 0.1},
                                                {"tendon_slack_length", 0.2}};
  return {{"thelen2003 rigid", {{"curves", "thelen2003"}}, thelen},
          {"thelen2003 elastic", {{"curves", "thelen2003"}, {"tendon", "elastic"}}, thelen},
          {"millard2012 elastic", {{"curves", "millard2012"}, {"tendon", "elastic"}}, thelen},
          {"thelen2003, MuJoCo's integrator",
           {{"curves", "thelen2003"}, {"integrator", "mujoco"}},
           thelen},
          {"mujoco",
           {{"curves", "mujoco"}},
           {{"lengthrange_lo", 0.10242022997},
            {"lengthrange_hi", 0.340386464984},
            {"acc0", 0.558692074634}}}};
}

double PathLength(const Form& form, int step) {
  const double mean =
      form.options.count("curves") && form.options.at("curves") == "mujoco" ? 0.22 : 0.3;
  return mean + 0.01 * std::sin(0.002 * step);
}

// a pulse train of excitations, changing every few steps (and twice within one step below)
double Excitation(int step) { return (step / 37) % 2 ? 0.9 : 0.1 + 0.001 * (step % 37); }

TEST(CommandDelay, AMuscleFollowsItsExcitationsLateByExactlyTheDelay) {
  const double dt = 1e-3;
  const int delay = 9;  // steps
  for (const Form& form : Forms()) {
    SCOPED_TRACE(form.name);
    std::map<std::string, double> delayed_parameters = form.parameters;
    delayed_parameters["command_delay"] = delay * dt;
    auto delayed = MakeMuscle(form.options, delayed_parameters);
    auto plain = MakeMuscle(form.options, form.parameters);
    for (auto* m : {delayed.get(), plain.get()}) {
      m->SetTimeStep(dt);
      m->Reset(PathLength(form, 0));
    }
    std::deque<double> issued(delay, 0.0);  // the plain muscle's excitations, 9 steps late
    double gap = 0;                         // to the undelayed activation
    auto undelayed = MakeMuscle(form.options, form.parameters);
    undelayed->SetTimeStep(dt);
    undelayed->Reset(PathLength(form, 0));
    for (int i = 0; i < 600; ++i) {
      const double length = PathLength(form, i);
      const double speed = 0.01 * 0.002 / dt * std::cos(0.002 * i);
      delayed->SetCommand(0.5);  // replaced by the next command before the same step
      delayed->SetCommand(Excitation(i));
      undelayed->SetCommand(Excitation(i));
      issued.push_back(Excitation(i));
      plain->SetCommand(issued.front());
      issued.pop_front();
      delayed->Step(length, speed, dt, speed);
      plain->Step(length, speed, dt, speed);
      undelayed->Step(length, speed, dt, speed);
      ASSERT_EQ(delayed->Get("activation"), plain->Get("activation")) << "step " << i;
      ASSERT_EQ(delayed->tension(), plain->tension()) << "step " << i;
      // the commanded excitation at once, the followed one as the plain muscle was given it
      ASSERT_EQ(delayed->command(), Excitation(i)) << "step " << i;
      ASSERT_EQ(delayed->Get("delayed_command"), plain->command()) << "step " << i;
      gap = std::max(gap, std::abs(delayed->Get("activation") - undelayed->Get("activation")));
    }
    EXPECT_GT(gap, 0.05);  // the delay changes what the muscle does
    EXPECT_EQ(delayed->Get("command_delay"), delay * dt);
    // without a delay the followed excitation is the command, from the moment it is given
    EXPECT_EQ(undelayed->Get("delayed_command"), undelayed->command());
  }
}

TEST(CommandDelay, ExcitationsInFlightSurviveSaveAndRestoreBitForBit) {
  const double dt = 1e-3;
  for (const Form& form : Forms()) {
    SCOPED_TRACE(form.name);
    std::map<std::string, double> parameters = form.parameters;
    parameters["command_delay"] = 0.02;
    auto a = MakeMuscle(form.options, parameters);
    auto b = MakeMuscle(form.options, parameters);
    a->SetTimeStep(dt);
    b->SetTimeStep(dt);
    a->Reset(PathLength(form, 0));
    b->Reset(PathLength(form, 0));
    std::vector<double> saved(a->StateSize());
    EXPECT_EQ(saved.size(), b->StateSize());
    for (int i = 0; i < 300; ++i) {
      a->SetCommand(Excitation(i));
      if (i == 150) {
        // 20 steps of excitations in flight, the newest given just now
        a->SaveState(saved.data());
        b->RestoreState(saved.data());
      }
      if (i > 150) b->SetCommand(Excitation(i));
      const double speed = 0.01 * 0.002 / dt * std::cos(0.002 * i);
      a->Step(PathLength(form, i), speed, dt, speed);
      if (i >= 150) {
        b->Step(PathLength(form, i), speed, dt, speed);
        ASSERT_EQ(a->Get("activation"), b->Get("activation")) << i;
        ASSERT_EQ(a->Get("delayed_command"), b->Get("delayed_command")) << i;
        ASSERT_EQ(a->tension(), b->tension()) << i;
      }
    }
  }
}

// What the engine saves before each step to put a failed one back: a few values whatever the
// line holds (2,000 excitations in flight here, 4,000 values of the whole state), and steps put
// back by them leave the muscle as the whole state does, bit for bit, going on alike. A step at a
// time step not told before lays the line out anew, which they cannot put back: refused.
TEST(CommandDelay, StepsArePutBackByAFewValuesWhateverTheLineHolds) {
  const double dt = 1e-3;
  for (const Form& form : Forms()) {
    SCOPED_TRACE(form.name);
    std::map<std::string, double> parameters = form.parameters;
    parameters["command_delay"] = 2.0;  // 2,000 steps
    auto a = MakeMuscle(form.options, parameters);
    auto b = MakeMuscle(form.options, parameters);
    for (auto* m : {a.get(), b.get()}) {
      m->SetTimeStep(dt);
      m->Reset(PathLength(form, 0));
    }
    auto step = [&](TendonActuator* m, int i) {
      const double speed = 0.01 * 0.002 / dt * std::cos(0.002 * i);
      m->Step(PathLength(form, i), speed, dt, speed);
    };
    for (int i = 0; i < 2500; ++i) {
      a->SetCommand(Excitation(i));
      step(a.get(), i);
    }
    a->SetCommand(Excitation(2500));
    const size_t n = a->StateSize();
    EXPECT_GT(n, 4000u);
    std::vector<double> whole(n, 0.0), step_state(n, -7.0), after(n, 0.0);
    a->SaveState(whole.data());
    a->SaveStepState(step_state.data());
    const auto written = static_cast<size_t>(
        std::count_if(step_state.begin(), step_state.end(), [](double v) { return v != -7.0; }));
    EXPECT_LT(written, 40u) << "of " << n;
    // three steps, then put back
    for (int i = 2500; i < 2503; ++i) step(a.get(), i);
    a->SaveState(after.data());
    EXPECT_NE(std::memcmp(whole.data(), after.data(), n * sizeof(double)), 0) << "they moved";
    a->RestoreStepState(step_state.data());
    a->SaveState(after.data());
    EXPECT_EQ(std::memcmp(whole.data(), after.data(), n * sizeof(double)), 0);
    b->RestoreState(whole.data());
    for (int i = 2500; i < 2700; ++i) {
      if (i > 2500) {
        a->SetCommand(Excitation(i));
        b->SetCommand(Excitation(i));
      }
      step(a.get(), i);
      step(b.get(), i);
      ASSERT_EQ(a->Get("activation"), b->Get("activation")) << i;
      ASSERT_EQ(a->Get("delayed_command"), Excitation(i - 2000)) << i;
      ASSERT_EQ(a->tension(), b->tension()) << i;
    }
    // a step at 2 ms without SetTimeStep: the line is laid out for 1,000 steps
    a->SaveStepState(step_state.data());
    step(a.get(), 2700);
    a->Step(PathLength(form, 2701), 0, 2 * dt, 0);
    EXPECT_THROW(a->RestoreStepState(step_state.data()), std::logic_error);
  }
}

// The delay lengthened and shortened live, beyond the line's old bound of 50 steps: at every
// step the muscle follows the newest excitation issued at least the delay then in force before,
// never an older one than it followed already (a by-hand history of every excitation). Its state
// grows and shrinks with the line; saved under a 300-step delay, it restores into a muscle with a
// 5-step one, which then goes on bit for bit as the one shortened live.
TEST(CommandDelay, ADelayChangedLiveFollowsTheNewestExcitationOldEnough) {
  const double dt = 1e-3;
  for (const Form& form : Forms()) {
    SCOPED_TRACE(form.name);
    auto live = MakeMuscle(form.options, form.parameters);
    live->SetTimeStep(dt);
    live->Reset(PathLength(form, 0));
    const std::size_t undelayed = live->StateSize();
    const double initial = live->Get("delayed_command");
    // the delay in steps from each step on
    const std::map<int, int> schedule = {{0, 120}, {200, 10}, {300, 300}, {500, 5}};
    std::vector<double> issued;  // by step
    int followed = -1;           // the step whose excitation the muscle follows, -1: none yet
    std::unique_ptr<TendonActuator> restored;
    std::vector<double> saved;
    for (int i = 0; i < 800; ++i) {
      if (schedule.count(i)) {
        const int steps = schedule.at(i);
        if (i == 500) {
          saved.assign(live->StateSize(), 0.0);
          live->SaveState(saved.data());
        }
        live->Set("command_delay", steps * dt);
        EXPECT_EQ(live->StateSize(), undelayed + 2 * steps) << "at step " << i;
        if (i == 500) {
          std::map<std::string, double> parameters = form.parameters;
          parameters["command_delay"] = steps * dt;
          restored = MakeMuscle(form.options, parameters);
          restored->SetTimeStep(dt);
          restored->Reset(PathLength(form, 0));
          ASSERT_TRUE(restored->Restorable(saved.data(), saved.size()));
          EXPECT_FALSE(restored->Restorable(saved.data(), saved.size() - 1));
          restored->RestoreState(saved.data());
          EXPECT_EQ(restored->StateSize(), live->StateSize());
        }
      }
      const int delay = std::prev(schedule.upper_bound(i))->second;
      issued.push_back(Excitation(i));
      live->SetCommand(Excitation(i));
      if (restored) restored->SetCommand(Excitation(i));
      const double speed = 0.01 * 0.002 / dt * std::cos(0.002 * i);
      live->Step(PathLength(form, i), speed, dt, speed);
      followed = std::max(followed, i - delay);
      ASSERT_EQ(live->Get("delayed_command"), followed >= 0 ? issued[followed] : initial)
          << "step " << i << ", a delay of " << delay << " steps";
      if (restored) {
        restored->Step(PathLength(form, i), speed, dt, speed);
        ASSERT_EQ(restored->Get("delayed_command"), live->Get("delayed_command")) << i;
        ASSERT_EQ(restored->Get("activation"), live->Get("activation")) << i;
        ASSERT_EQ(restored->tension(), live->tension()) << i;
      }
    }
  }
}

TEST(CommandDelay, TheLineIsBoundedAndBadDelaysAreRefusedWithTheMuscleNamed) {
  const Form form = Forms()[0];
  std::map<std::string, double> parameters = form.parameters;
  parameters["command_delay"] = 100.2;  // 100,200 steps of 1 ms
  auto m = MakeMuscle(form.options, parameters);
  try {
    m->SetTimeStep(1e-3);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("hill_muscle 'm'"), std::string::npos) << what;
    EXPECT_NE(what.find("100200 time steps"), std::string::npos) << what;
    EXPECT_NE(what.find("at most 100000 (100 s at this time step)"), std::string::npos) << what;
  }
  m->SetTimeStep(5e-3);  // 20,040 steps: within the line
  // live, the same bound; a refused value leaves the delay as it was
  parameters["command_delay"] = 0;
  auto live = MakeMuscle(form.options, parameters);
  live->SetTimeStep(1e-3);
  live->Set("command_delay", 100);
  EXPECT_THROW(live->Set("command_delay", 100.001), std::invalid_argument);
  for (const double bad : {-0.001, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    try {
      live->Set("command_delay", bad);
      FAIL() << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("'command_delay' must be >= 0 [s]"), std::string::npos)
          << e.what();
    }
    parameters["command_delay"] = bad;
    EXPECT_THROW(MakeMuscle(form.options, parameters), std::invalid_argument) << bad;
  }
  EXPECT_EQ(live->Get("command_delay"), 100);
  // listed with the muscle's quantities: a writable parameter and a state
  bool parameter = false;
  bool state = false;
  for (const Quantity& q : live->Quantities()) {
    if (q.name == "command_delay") parameter = q.unit == "s" && q.writable && q.is_static;
    if (q.name == "delayed_command") state = !q.writable && !q.is_static;
  }
  EXPECT_TRUE(parameter);
  EXPECT_TRUE(state);
}

}  // namespace
}  // namespace caliper::actuators
