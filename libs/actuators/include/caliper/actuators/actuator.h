#pragma once
// Engine-free actuator models acting along a tendon. An engine adapter evaluates the tendon path,
// calls Step() with its length and lengthening speed, and applies the returned tension along the
// path. New kinds register a factory; the engine code never changes for them. SI units.

#include <cstddef>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/sgal/scene.h"

namespace caliper::actuators {

/// The most internal sub-steps (or solver stages of the same cost) one Step() may take: a
/// parameter or a time step that would need more is refused, so that no value can make a single
/// physics step run for hours.
inline constexpr int kMaxSubstepsPerStep = 10000;

/// A named scalar an actuator exposes: a parameter (static, usually writable) or a state.
struct Quantity {
  std::string name;  // e.g. current, resistance, activation
  std::string unit;  // SI: A, ohm, N/m, "" for dimensionless
  bool writable = false;
  bool is_static = false;  // model parameter (true) or state that changes each step (false)
};

/// A parameter a kind takes from sgal::Actuator::parameters.
struct ParameterSpec {
  std::string name;
  std::string unit;
  double default_value = 0;
  bool required = false;  // no default: the model file must give it
  std::string help;
};

class TendonActuator {
 public:
  virtual ~TendonActuator() = default;

  /// Sets the internal state for a tendon path of this length at rest (t = 0); tension() is then
  /// the tension at rest at that length, which the engine applies through its first step.
  virtual void Reset(double path_length) = 0;

  /// Advances the internal state by dt [s] while the path moves: it is path_length [m] at the
  /// start of the step and lengthens at path_speed [m/s] through it (path_length + path_speed dt
  /// at the end). Returns the tension [N] (>= 0) at the END of the step, where the path's
  /// lengthening speed is end_speed [m/s].
  ///
  /// The engine couples actuators and bodies in Stormer-Verlet order, second order in dt: the
  /// bodies advance over a step on the tension at its start (the last Step's result), then each
  /// actuator advances over the same step on the path the bodies took. So that the whole stays
  /// second order, a kind integrates its states at least to second order with the path length at
  /// each stage's own time, not held at its start value; and a kind whose tension depends on the
  /// path's speed directly (a damper in series, a rigid tendon's force-velocity curve) takes
  /// end_speed for the tension it returns (path_speed, the mean, lags it by half a step).
  virtual double Step(double path_length, double path_speed, double dt, double end_speed) = 0;
  /// Step() on a path moving steadily: its speed at the end is its mean speed.
  double Step(double path_length, double path_speed, double dt) {
    return Step(path_length, path_speed, dt, path_speed);
  }

  /// The tension of the last Step [N].
  virtual double tension() const = 0;

  /// How many values SaveState() writes at most. It may change with a parameter or the time step
  /// (a command delay's line holds as many commands as the delay has steps) and with
  /// RestoreState(), never within Step() or with a command: a caller that keeps a buffer for
  /// it sizes the buffer again after Set(), SetTimeStep() and RestoreState(). The default, 0,
  /// is for kinds whose Step() changes nothing.
  virtual std::size_t StateSize() const { return 0; }
  /// Writes StateSize() values: everything Step() changes (states, outputs, solver start values
  /// and caches whose contents change results), so that RestoreState() puts the actuator back
  /// where a repeated Step() gives the same result bit for bit. Parameters and the command are
  /// not part of it. Called for a saved state (a recording's keyframe, a scene edit) and, unless
  /// the kind says less in SaveStepState(), before every physics step: no allocation. A kind may
  /// leave values it will not read back unwritten (the unused slots of a command delay line):
  /// a caller that compares or stores states zeroes its buffer first.
  virtual void SaveState(double* out) const { (void)out; }
  /// Whether RestoreState() can read the `n` values at `in`, which SaveState() of this kind with
  /// these options wrote, perhaps under other parameters (a state saved before a live edit of
  /// the command delay, in a recording's keyframe or carried over by a scene edit). The
  /// default: exactly StateSize() values.
  virtual bool Restorable(const double* in, std::size_t n) const {
    (void)in;
    return n == StateSize();
  }
  /// Reads back the values SaveState() wrote (StateSize() of them, or any count Restorable()
  /// accepted).
  virtual void RestoreState(const double* in) { (void)in; }

  /// What the engine saves before every step to put a failed step back: at most StateSize()
  /// values, read back only by RestoreStepState() of the same actuator after Step() calls alone
  /// (no parameter, time step or state written between). The default is the whole state; a
  /// kind whose state holds much that a step only reads (a command delay's line) saves less,
  /// and may throw std::logic_error from RestoreStepState() where that contract was broken (a
  /// Step() at a time step SetTimeStep() did not tell), after putting back what it can.
  virtual void SaveStepState(double* out) const { SaveState(out); }
  virtual void RestoreStepState(const double* in) { RestoreState(in); }

  /// The time step the engine will call Step() with [s]. Kinds whose work per step depends on
  /// a parameter (internal sub-steps) refuse with std::invalid_argument a time step that would
  /// need more than kMaxSubstepsPerStep of them, naming the smallest parameter value that would
  /// do, and then refuse such parameter values in Set() while this time step holds. Unchanged
  /// when it throws. The default accepts any time step.
  virtual void SetTimeStep(double dt) { (void)dt; }

  /// The input: voltage [V], PWM duty [-] or excitation [-] depending on the kind.
  virtual void SetCommand(double value) = 0;
  virtual double command() const = 0;
  virtual std::string command_unit() const = 0;

  /// Parameters and states, by name.
  virtual std::vector<Quantity> Quantities() const = 0;
  /// Throws std::out_of_range for an unknown name.
  virtual double Get(const std::string& name) const = 0;
  /// A reader of quantity `name` for callers that read it often (the DAQ's channels): the name
  /// is looked up once, here, not at each read. It reads what Get(name) would, and lives as long
  /// as this actuator. Throws as Get does. The default calls Get(name) at each read.
  virtual std::function<double()> Reader(const std::string& name) const {
    Get(name);  // an unknown name throws now, not at a read
    return [this, name] { return Get(name); };
  }
  /// Throws std::out_of_range (unknown) or std::invalid_argument (read-only, out of range).
  virtual void Set(const std::string& name, double value) = 0;
};

using Factory = std::function<std::unique_ptr<TendonActuator>(const sgal::Actuator&)>;

/// Registers a kind (a later registration of the same kind replaces it).
void RegisterKind(const std::string& kind, std::vector<ParameterSpec> parameters, Factory factory);

/// Makes the model of an actuator description. Throws std::invalid_argument naming the actuator,
/// and the unknown kind, the missing parameter or the unknown parameter name.
std::unique_ptr<TendonActuator> Make(const sgal::Actuator& description);

/// The registered kinds and their parameters (for documentation, importers, exporters).
std::vector<std::string> Kinds();
const std::vector<ParameterSpec>& KindParameters(const std::string& kind);

/// The value of a parameter from a description, or the kind's default.
double ParameterOr(const sgal::Actuator& a, const std::string& name, double fallback);

}  // namespace caliper::actuators
