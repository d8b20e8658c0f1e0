// Per-step cost of the engine-free actuator kinds, built through actuators::Make with their
// default parameters and options (plus what a kind requires), each driven along a plausible path
// for 100,000 steps of 1 ms. Prints one line per figure:
//   RATIO <name> <ns per step> (target <target>)
// measured in this run (the median of several repetitions; a comment line before it gives the
// fastest repetition too, the better figure on a shared machine), never compared with stored
// times. Options: --steps N, --repeats N, --only NAME (one case alone, for a profiler).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "caliper/actuators/actuator.h"
#include "caliper/sgal/scene.h"

namespace caliper::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDt = 1e-3;  // [s]
int steps = 100000;
int repeats = 5;

struct Case {
  std::string name;  // figure name
  std::string kind;  // actuator kind
  std::map<std::string, std::string> options;
  std::map<std::string, double> parameters;
  double length0 = 0;                     // mean path length [m]
  double amplitude = 0;                   // path length amplitude [m]
  double frequency = 1;                   // path motion [Hz]
  std::function<double(double)> command;  // command at time t [s]; none: passive
  double target_ns = 0;                   // 0: no target
};

volatile double sink = 0;  // keeps the tensions alive

struct Timing {
  double median;  // [ns]
  double best;    // [ns]
};

/// Time of one 1 ms step [ns] in one run of `steps` steps from Reset(). The command is updated
/// every step (SetCommand is part of what an adapter does per step).
double TimeOnce(const Case& c) {
  sgal::Actuator a;
  a.name = c.name;
  a.kind = c.kind;
  a.tendon = "t";
  a.options = c.options;
  a.parameters = c.parameters;
  std::unique_ptr<actuators::TendonActuator> actuator = actuators::Make(a);
  actuator->Reset(c.length0);
  // the path and the command, precomputed so that only the actuator is timed
  std::vector<double> length(steps), speed(steps), command(steps);
  for (int i = 0; i < steps; ++i) {
    const double t = i * kDt;
    const double w = 2 * kPi * c.frequency;
    length[i] = c.length0 + c.amplitude * std::sin(w * t);
    speed[i] = c.amplitude * w * std::cos(w * t);
    command[i] = c.command ? c.command(t) : 0.0;
  }
  double sum = 0;
  const auto begin = std::chrono::steady_clock::now();
  const bool commanded = static_cast<bool>(c.command);
  for (int i = 0; i < steps; ++i) {
    if (commanded) actuator->SetCommand(command[i]);
    sum += actuator->Step(length[i], speed[i], kDt);
  }
  const double ns =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - begin).count();
  sink = sink + sum;
  if (!std::isfinite(sum)) {
    std::fprintf(stderr, "%s: non-finite tension\n", c.name.c_str());
    std::exit(1);
  }
  return ns / steps;
}

/// Time of one 1 ms step [ns] over `repeats` runs: the median and the fastest.
Timing TimeCase(const Case& c) {
  std::vector<double> runs;
  for (int r = 0; r < repeats; ++r) runs.push_back(TimeOnce(c));
  std::sort(runs.begin(), runs.end());
  return {runs[runs.size() / 2], runs.front()};
}

/// The median over 2 * `repeats` pairs of runs, a then b, of time(b) / time(a): the two
/// alternate, so that the machine's drift over the run cancels.
double InterleavedRatio(const Case& a, const Case& b) {
  std::vector<double> ratios;
  for (int r = 0; r < 2 * repeats; ++r) {
    const double ta = TimeOnce(a);
    ratios.push_back(TimeOnce(b) / ta);
  }
  std::sort(ratios.begin(), ratios.end());
  return ratios[ratios.size() / 2];
}

/// Steps `c` through `seconds` of its path and command, each 1 ms interval cut into `split` steps
/// that see the same path as one 1 ms step would (the length at the interval's start moving at
/// its speed, the contract of TendonActuator::Step) and the same command. Fills the tension [N]
/// and the fibre length [m] at the end of every interval.
void RunSplit(const Case& c, double seconds, int split, std::vector<double>* tension,
              std::vector<double>* fiber_length) {
  sgal::Actuator a;
  a.name = c.name;
  a.kind = c.kind;
  a.tendon = "t";
  a.options = c.options;
  a.parameters = c.parameters;
  std::unique_ptr<actuators::TendonActuator> actuator = actuators::Make(a);
  actuator->Reset(c.length0);
  const int n = static_cast<int>(std::lround(seconds / kDt));
  const double h = kDt / split;
  const double w = 2 * kPi * c.frequency;
  tension->clear();
  fiber_length->clear();
  for (int i = 0; i < n; ++i) {
    const double t = i * kDt;
    const double length = c.length0 + c.amplitude * std::sin(w * t);
    const double speed = c.amplitude * w * std::cos(w * t);
    if (c.command) actuator->SetCommand(c.command(t));
    for (int j = 0; j < split; ++j) actuator->Step(length + speed * j * h, speed, h);
    tension->push_back(actuator->tension());
    fiber_length->push_back(actuator->Get("fiber_length"));
  }
}

/// For information (not a RATIO): the error of 1 ms and 0.5 ms steps against 1/64 ms steps over
/// 2 s of the case, so that the speed is not bought with accuracy; a second-order integrator
/// shows an observed order near 2.
void PrintAccuracy(const Case& c) {
  std::vector<double> ref_tension, ref_fiber, tension, fiber;
  RunSplit(c, 2.0, 64, &ref_tension, &ref_fiber);
  double tension_error[2] = {0, 0}, fiber_error[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    RunSplit(c, 2.0, k + 1, &tension, &fiber);
    for (size_t i = 0; i < tension.size(); ++i) {
      tension_error[k] = std::max(tension_error[k], std::abs(tension[i] - ref_tension[i]));
      fiber_error[k] = std::max(fiber_error[k], std::abs(fiber[i] - ref_fiber[i]));
    }
  }
  double peak = 0;
  for (double t : ref_tension) peak = std::max(peak, t);
  std::printf(
      "# %s accuracy against 1/64 ms steps over 2 s (tension peak %.1f N): 1 ms steps: tension "
      "%.3g N, fibre length %.3g m; 0.5 ms steps: %.3g N, %.3g m; observed order %.2f\n",
      c.name.c_str(), peak, tension_error[0], fiber_error[0], tension_error[1], fiber_error[1],
      std::log2(tension_error[0] / tension_error[1]));
}

/// For information (not a RATIO): what the engine saves before every step (SaveStepState) against
/// the whole state (SaveState), for the driven motor with a 10 s command delay under a command
/// every step (10,000 commands in flight) [ns per save, the fastest of `repeats` runs of 1000].
void PrintStepSave() {
  sgal::Actuator a;
  a.name = "delayed";
  a.kind = "dc_motor_tendon";
  a.tendon = "t";
  a.parameters = {{"command_delay", 10}};
  std::unique_ptr<actuators::TendonActuator> actuator = actuators::Make(a);
  actuator->SetTimeStep(kDt);
  actuator->Reset(0.3);
  for (int i = 0; i < 10500; ++i) {
    actuator->SetCommand(3 * std::sin(2 * kPi * 0.5 * i * kDt));
    actuator->Step(0.3, 0, kDt);
  }
  std::vector<double> buffer(actuator->StateSize());
  auto fastest = [&](bool whole) {
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < repeats; ++r) {
      const auto begin = std::chrono::steady_clock::now();
      for (int k = 0; k < 1000; ++k) {
        if (whole)
          actuator->SaveState(buffer.data());
        else
          actuator->SaveStepState(buffer.data());
        sink = sink + buffer[k % 8];
      }
      best = std::min(
          best, std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - begin)
                        .count() /
                    1000);
    }
    return best;
  };
  std::printf(
      "# saved before each step, dc_motor_tendon with a 10 s command delay under a command every "
      "step (%zu values in all): the whole state %.0f ns, the step's state %.1f ns\n",
      buffer.size(), fastest(true), fastest(false));
}

std::vector<Case> Cases() {
  std::vector<Case> cases;
  const auto constant = [](double v) { return [v](double) { return v; }; };
  // [V]: forward, held, backward, so that the motor drives, holds, is back-driven and slackens
  const auto driven = [](double t) { return 3 * std::sin(2 * kPi * 0.5 * t); };
  // [-]: excitation swinging between 0.1 and 0.9 (activation always moving)
  const auto excitation = [](double t) { return 0.5 + 0.4 * std::sin(2 * kPi * 2 * t); };

  // the benchmark tree's actuator (bench/tree_model.cc): default parameters and options (the
  // elastic element is then linear), 0.05 V as in physics_bench; target from issue #16
  cases.push_back(
      {"dc_motor_step_ns_per_1ms", "dc_motor_tendon", {}, {}, 0.3, 0.002, 1, constant(0.05), 150});
  // the same, driven by a voltage swinging +-3 V against a moving path
  cases.push_back(
      {"dc_motor_driven_step_ns_per_1ms", "dc_motor_tendon", {}, {}, 0.3, 0.01, 1, driven, 300});
  // the same with heat (a datasheet's thermal data), friction (Coulomb, Stribeck, viscous),
  // cogging and the driver's PWM and slew limit: RATIO dc_motor_realism_vs_plain divides it by
  // the figure above
  cases.push_back({"dc_motor_realistic_step_ns_per_1ms",
                   "dc_motor_tendon",
                   {},
                   {{"thermal_resistance_winding_housing", 1.6},
                    {"thermal_resistance_housing_ambient", 4.65},
                    {"thermal_time_constant_winding", 41.6},
                    {"thermal_time_constant_motor", 1120},
                    {"coulomb_friction", 1.5e-3},
                    {"static_friction", 2e-3},
                    {"viscous_friction", 1e-7},
                    {"cogging_amplitude", 3e-4},
                    {"cogging_count", 14},
                    {"pwm_levels", 1024},
                    {"slew_rate", 2000}},
                   0.3,
                   0.01,
                   1,
                   driven,
                   0});
  cases.push_back({"dc_motor_linear_step_ns_per_1ms",
                   "dc_motor_tendon",
                   {{"elastic", "linear"}},
                   {},
                   0.3,
                   0.01,
                   1,
                   driven,
                   300});
  cases.push_back({"dc_motor_zener_step_ns_per_1ms",
                   "dc_motor_tendon",
                   {{"elastic", "zener"}},
                   {},
                   0.3,
                   0.01,
                   1,
                   driven,
                   300});
  cases.push_back({"ligament_step_ns_per_1ms",
                   "ligament",
                   {},
                   {{"stiffness", 1000}, {"damping", 2}},
                   0.3,
                   0.01,
                   1,
                   nullptr,  // passive: takes no command
                   0});
  // OpenSim's defaults with the two required lengths; path around slack + optimal
  cases.push_back({"hill_thelen_rigid_step_ns_per_1ms",
                   "hill_muscle",
                   {{"curves", "thelen2003"}, {"tendon", "rigid"}},
                   {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}},
                   0.3,
                   0.02,
                   1,
                   excitation,
                   0});
  // arm26's SF muscle as MuJoCo 2.2.2 compiles it; path swinging through its length range
  cases.push_back({"hill_mujoco_step_ns_per_1ms",
                   "hill_muscle",
                   {{"curves", "mujoco"}},
                   {{"lengthrange_lo", 0.10242022997},
                    {"lengthrange_hi", 0.340386464984},
                    {"acc0", 0.558692074634}},
                   0.22,
                   0.1,
                   1,
                   excitation,
                   0});
  // the elastic tendon (fibre length integrated by a two-stage SDIRK, 1 ms sub-steps); an
  // accuracy line against fine steps follows its figure
  cases.push_back({"hill_thelen_elastic_step_ns_per_1ms",
                   "hill_muscle",
                   {{"curves", "thelen2003"}, {"tendon", "elastic"}},
                   {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}},
                   0.3,
                   0.02,
                   1,
                   excitation,
                   500});
  // Millard 2012 with OpenSim's defaults (damped, compliant tendon): Bezier curves solved per
  // evaluation; an accuracy line follows as for Thelen's
  cases.push_back({"hill_millard_elastic_step_ns_per_1ms",
                   "hill_muscle",
                   {{"curves", "millard2012"}, {"tendon", "elastic"}},
                   {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}},
                   0.3,
                   0.02,
                   1,
                   excitation,
                   0});
  return cases;
}

}  // namespace
}  // namespace caliper::bench

int main(int argc, char** argv) {
  using namespace caliper::bench;
  std::string only;  // one case to time alone (for a profiler)
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--steps")
      steps = std::max(1, std::atoi(argv[++i]));
    else if (std::string(argv[i]) == "--repeats")
      repeats = std::max(1, std::atoi(argv[++i]));
    else if (std::string(argv[i]) == "--only")
      only = argv[++i];
  }
  if (!only.empty()) {
    for (const Case& c : Cases())
      if (c.name == only) {
        std::printf("# %s: median %.1f ns per step\n", c.name.c_str(), TimeCase(c).median);
        return 0;
      }
    std::fprintf(stderr, "actuators_bench: no case named '%s'\n", only.c_str());
    return 2;
  }
  std::printf("# actuator step cost, %d steps of 1 ms, median of %d runs\n", steps, repeats);
  const std::vector<Case> cases = Cases();
  for (const Case& c : cases) {
    const Timing t = TimeCase(c);
    std::printf("# %s: %s, best %.1f ns, median %.1f ns\n", c.name.c_str(), c.kind.c_str(), t.best,
                t.median);
    if (c.target_ns > 0)
      std::printf("RATIO %s %.1f (target %.0f)\n", c.name.c_str(), t.median, c.target_ns);
    else
      std::printf("RATIO %s %.1f\n", c.name.c_str(), t.median);
    if (c.kind == "hill_muscle" && c.options.count("tendon") && c.options.at("tendon") == "elastic")
      PrintAccuracy(c);
    std::fflush(stdout);
  }
  // heat, friction, cogging, PWM and slew on against the plain driven motor, run alternately
  auto named = [&](const char* name) {
    return *std::find_if(cases.begin(), cases.end(), [&](const Case& c) { return c.name == name; });
  };
  const double ratio = InterleavedRatio(named("dc_motor_driven_step_ns_per_1ms"),
                                        named("dc_motor_realistic_step_ns_per_1ms"));
  std::printf("RATIO dc_motor_realism_vs_plain %.3f (target 1.3)\n", ratio);
  // for information: each part alone against the plain motor, the same way
  const Case& realistic = named("dc_motor_realistic_step_ns_per_1ms");
  const std::vector<std::pair<const char*, std::vector<const char*>>> parts = {
      {"heat", {"thermal_"}},
      {"friction", {"coulomb_friction", "static_friction", "viscous_friction"}},
      {"cogging", {"cogging_"}},
      {"PWM and slew", {"pwm_levels", "slew_rate"}},
      {"all but cogging", {"thermal_", "coulomb_friction", "static_friction", "viscous_friction",
                           "pwm_levels", "slew_rate"}}};
  std::printf("# dc_motor_realism_vs_plain by part:");
  for (const auto& [part, prefixes] : parts) {
    Case c = realistic;
    c.parameters.clear();
    for (const auto& [name, value] : realistic.parameters)
      for (const char* prefix : prefixes)
        if (name.rfind(prefix, 0) == 0) c.parameters[name] = value;
    std::printf(" %s %.3f;", part, InterleavedRatio(named("dc_motor_driven_step_ns_per_1ms"), c));
    std::fflush(stdout);
  }
  std::printf("\n");
  PrintStepSave();
  return 0;
}
