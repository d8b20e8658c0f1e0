#pragma once
// The interface of a running physics scene (an engine adapter implements it) and the observer
// that receives only what changed.

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/sgal/scene.h"

namespace caliper::sgal {

/// A step that produced non-finite or exploding state: which element, at what time.
class SimulationFault : public std::runtime_error {
 public:
  SimulationFault(const std::string& what, std::string element, double time)
      : std::runtime_error(what), element_(std::move(element)), time_(time) {}
  const std::string& element() const { return element_; }
  double time() const { return time_; }  // [s]

 private:
  std::string element_;
  double time_;
};

struct BodyState {
  Pose pose;                                                    // world frame
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // [m/s]
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // [rad/s]
};

struct TendonState {
  std::vector<Eigen::Vector3d> points;  // current path in world coordinates [m]
  double length = 0;                    // [m]
  double speed = 0;                     // lengthening speed [m/s]
  double tension = 0;                   // [N]
  int contacts = 0;                     // points where it presses on bodies it is not routed over
};

/// A named scalar quantity of the scene: actuator states and parameters, body masses, ...
struct ParameterInfo {
  std::string id;    // e.g. motor1.current, upper_arm.mass
  std::string unit;  // SI, e.g. A, kg, N/m
  bool writable = false;
  bool is_static = false;  // a model parameter (true) or a state that changes every step (false)
};

/// What changes from step to step, to carry a running simulation over into an edited copy of its
/// scene (or to restore it later): bodies, joints' counted positions, actuators' internal states
/// and commands, the delayed channels' memory, time.
struct DynamicState {
  double time = 0;  // [s]
  uint64_t steps = 0;
  std::vector<BodyState> bodies;               // description().bodies order
  std::vector<double> joint_positions;         // description().constraints order [rad] or [m]
  std::vector<std::vector<double>> actuators;  // description().actuators order: their states
  std::vector<double> commands;                // description().actuators order
  /// What the delayed channels remember: for each of description().measurement_delays in order,
  /// its steps + 1 last values (steps = round(delay / time_step)), oldest first, in the
  /// parameter's unit. Empty: nothing known, each channel restarts as if its present value had
  /// been constant since ever (a state of another scene, an older recording).
  std::vector<double> measurements;
  /// The engine's own state, bit for bit (its numbers in its precision, tendon wrap sides); a
  /// restore into a scene built from the same description uses it and ignores `bodies`. Empty
  /// (a scene edit changed the description): the restore goes by `bodies`.
  std::vector<double> engine;
};

/// A spring pulling a point of a body towards a target (the GUI's Ctrl+drag), with damping on the
/// point's velocity: force = stiffness (target - point) - damping velocity.
struct Pull {
  int body = -1;                                      // index into description().bodies
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // in the body frame [m]
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // world [m]
  double stiffness = 0;                               // [N/m]
  double damping = 0;                                 // [N s/m]
};

class PhysicsScene {
 public:
  virtual ~PhysicsScene() = default;

  /// Advances by one fixed time step. Whatever fails inside the step (a non-finite tension, an
  /// exploding body, or any exception of any type from an actuator, a tendon path or the
  /// engine) ends at the last consistent state, the start of the failing step: the bodies, the
  /// tendons, every actuator's internal state, the delayed channels, time() and steps() as they
  /// were. Then it throws SimulationFault whose message names the element (an actuator and its
  /// kind, a tendon, a body or the engine's world) and what happened (the original exception's
  /// type and message), with element() that name ("world" for the engine) and time() the time
  /// the step would have reached [s]. Nothing else escapes.
  virtual void Step() = 0;
  virtual double time() const = 0;     // simulated time [s]
  virtual uint64_t steps() const = 0;
  virtual const Scene& description() const = 0;

  virtual std::vector<BodyState> BodyStates() const = 0;  // in description().bodies order
  /// The same into `out` (resized to the bodies), whose memory is reused: for a reader at every
  /// step (the DAQ's sampler), no allocation.
  virtual void ReadBodyStates(std::vector<BodyState>* out) const { *out = BodyStates(); }
  virtual std::vector<TendonState> TendonStates() const = 0;

  /// Sets an actuator's input (voltage, duty, excitation). Throws std::out_of_range for an
  /// unknown name, std::invalid_argument for a non-finite value.
  virtual void SetCommand(const std::string& actuator, double value) = 0;

  virtual std::vector<ParameterInfo> Parameters() const = 0;
  /// Throws std::out_of_range for an unknown id.
  virtual double GetParameter(const std::string& id) const = 0;
  /// Position of an id in Parameters() for repeated reads without string lookups (-1: unknown).
  virtual int ParameterIndex(const std::string& id) const = 0;
  /// The value of Parameters()[index]; throws std::out_of_range for a bad index.
  virtual double GetParameter(int index) const = 0;
  /// Throws std::out_of_range (unknown), std::invalid_argument (read-only or bad value, or one
  /// that would make a single step take more than a bounded amount of work, such as an
  /// actuator's max_substep below time_step / 10^4 or a time step that needs more sub-steps:
  /// the message gives the reason and the bound).
  virtual void SetParameter(const std::string& id, double value) = 0;

  virtual DynamicState SaveDynamicState() const = 0;
  /// Puts the scene in `state`, which must have this scene's numbers of bodies, constraints and
  /// actuators, each actuator's state size and no measurements or as many as its delayed
  /// channels hold (else std::invalid_argument saying which); an actuator whose state is empty
  /// keeps its own (one that a scene edit just added).
  virtual void RestoreDynamicState(const DynamicState& state) = 0;
  /// From the next step on, applies the pull until ClearPull(); std::out_of_range for a body
  /// index that is not a moving body, std::invalid_argument for non-finite numbers.
  virtual void SetPull(const Pull& pull) = 0;
  virtual void ClearPull() = 0;
  /// Drops what the engine keeps between steps beyond the dynamic state (contact caches and
  /// their warm-start impulses, the order its broad phase found pairs in), leaving it as a scene
  /// built afresh, restored with the same exact state and reset the same way is: from there both
  /// step bit for bit alike (recording keyframes do this).
  virtual void ResetCaches() = 0;
};

/// Receives the bodies whose pose changed beyond a tolerance since it was last told.
class SceneObserver {
 public:
  virtual ~SceneObserver() = default;
  /// `bodies` are indices into the description's bodies; `states[i]` belongs to `bodies[i]`.
  virtual void OnTransforms(uint64_t step, double time, const std::vector<int>& bodies,
                            const std::vector<BodyState>& states) = 0;
};

/// Tracks the last pose each observer saw and reports only the changed ones.
class ChangeFilter {
 public:
  ChangeFilter(double position_tolerance = 1e-6, double angle_tolerance = 1e-5);
  /// Indices of bodies that moved beyond the tolerances since the last call; remembers them.
  std::vector<int> Changed(const std::vector<BodyState>& states);

 private:
  double position_tolerance_;  // [m]
  double angle_tolerance_;     // [rad]
  std::vector<Pose> last_;
};

/// In-process observers of a running scene: after each step, Notify() tells every observer the
/// bodies that moved beyond the tolerances since it was last told (each observer has its own
/// filter, so one added late first receives every body).
class ObserverHub {
 public:
  explicit ObserverHub(double position_tolerance = 1e-6, double angle_tolerance = 1e-5)
      : position_tolerance_(position_tolerance), angle_tolerance_(angle_tolerance) {}
  /// Adds an observer (not owned; it must outlive the hub or be removed) and returns its id.
  int Add(SceneObserver* observer);
  void Remove(int id);
  /// Reports the changed bodies of `scene` to each observer; observers with nothing new are not
  /// called.
  void Notify(const PhysicsScene& scene);

 private:
  struct Entry {
    int id;
    SceneObserver* observer;
    ChangeFilter filter;
  };
  double position_tolerance_;
  double angle_tolerance_;
  int next_id_ = 1;
  std::vector<Entry> entries_;
};

}  // namespace caliper::sgal
