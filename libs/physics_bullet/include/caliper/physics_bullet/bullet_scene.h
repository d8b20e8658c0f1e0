#pragma once
// The Bullet engine adapter: builds a btDiscreteDynamicsWorld from an sgal::Scene and steps it
// with the tendon actuators. The only place in Caliper that includes Bullet.

#include <memory>

#include "caliper/sgal/physics_scene.h"

namespace caliper::physics_bullet {

struct Options {
  /// Bend tendons around bodies they would pass through (see actuators/tendon_contact.h).
  bool tendon_body_contact = true;
  /// Poses beyond this distance from the origin [m] or speeds beyond this [m/s] count as an
  /// exploding simulation.
  double max_distance = 1e4;
  double max_speed = 1e3;
  /// A tendon tension beyond this [N] counts as an exploding actuator (a muscle driven past its
  /// curves by a path that jumped): the step that computed it faults, before the tension acts.
  double max_tension = 1e6;
  /// Threads that advance the tendons at the end of each step (their paths, contact with the
  /// bodies and actuators, one tendon per thread at a time): 1 serial; 0 every processor the
  /// process may run on; at most 8. The results are the same bits whatever the count.
  int threads = 1;
  /// With threads > 1: the engine times whole steps on one thread and on `threads` and takes
  /// them only where they save at least 5 % of a step (docs/physics.md). false: every step on
  /// `threads` (tests, and scenes known to gain).
  bool choose_threads = true;
  /// With threads > 1, Bullet's contact search for the next step runs at the end of this one,
  /// beside the tendons' work, rather than inside the next step: the same bits either way; off
  /// only to compare.
  bool search_contacts_ahead = true;
};

/// The threads Options::threads asks for: 0 is every processor this process may run on (its
/// affinity, which a batch system's allocation sets), and at most 8. Throws std::invalid_argument
/// for a negative count.
int ThreadCount(int threads);

/// How long a thread waiting for the next step's jobs spins before it sleeps, in the processes
/// that call BoundThreadSpin [s]. libgomp's own default, 300,000 turns, kept the second thread of
/// a real-time session spinning for about half of every 1 ms step (the shipped arm's Model at
/// 0.4-0.8 of a processor on two threads, 0.05-0.08 on one). 250 us covers the gap between two
/// steps run back to back (Bullet's part, about 60 us on the contact tree, with the wake-ups of a
/// loaded machine), so batch runs keep the threads' gain; 75 us lost it on this machine
/// (docs/physics.md).
constexpr double kThreadSpinTime = 250e-6;

/// The turns of libgomp's wait (GOMP_SPINCOUNT) that take `seconds` at `seconds_per_turn`,
/// rounded, within [kMinSpinTurns, kMaxSpinTurns]; kFallbackSpinTurns where seconds_per_turn is
/// not a positive finite time (a clock that could not measure it).
long SpinTurns(double seconds, double seconds_per_turn);
constexpr long kMinSpinTurns = 1000;
constexpr long kMaxSpinTurns = 300000;  // libgomp's default
/// 250 us on the machine the figures were measured on (AMD EPYC, 25 ns a turn).
constexpr long kFallbackSpinTurns = 10000;

/// One turn of libgomp's wait on this processor [s]: a relaxed load of the word it waits on and
/// the processor's pause hint (x86's `pause`: a number of the core's cycles that Intel's manual
/// gives as about 140 since Skylake, about 10 before; 25 ns on the AMD EPYC measured here;
/// libgomp's cpu_relax). The fastest
/// of timed runs of 2000 turns over at least 2 ms (8 to 64 runs), so that neither a preemption
/// nor a core still raising its clock as the program starts lengthens it.
double MeasureSpinTurn();

/// Call first in main, with main's argv, in a process that may step a scene on several threads.
/// libgomp reads its spin count from the environment once, as it loads, before main runs. Unless
/// the environment sets GOMP_SPINCOUNT or OMP_WAIT_POLICY (the user's choice, kept), this sets
/// GOMP_SPINCOUNT to the turns of kThreadSpinTime on this processor (SpinTurns of
/// MeasureSpinTurn) and executes the program again (/proc/self/exe) with the same
/// arguments: the same process, as its parent sees it. Returns where there is nothing to do, or
/// where the new start fails (then with a line on stderr, and libgomp's default spin).
void BoundThreadSpin(char** argv);

/// Builds the scene. Throws std::invalid_argument listing every problem sgal::Validate finds, or
/// an actuator that cannot be made (unknown kind, missing parameter), or a step whose work has no
/// bound (solver_iterations outside [1, 10^4], a time step an actuator cannot take in 10^4
/// sub-steps), or a measurement delay it cannot honour (sgal::MeasurementDelay: the message names
/// the id and why). A failing Step() puts back the bodies, tendons, actuators and delayed
/// channels (see sgal::PhysicsScene::Step); Bullet's contact cache (warm-start impulses) is not
/// rolled back, so after a fault a scene with contacts that steps on may differ in the last bits
/// from one that never faulted.
std::unique_ptr<sgal::PhysicsScene> MakeScene(const sgal::Scene& scene, Options options = {});

/// DynamicState::engine holds this many values per body first (the centre-of-mass transform and
/// the interpolation transform, 12 each; linear, angular and the two interpolation velocities,
/// 3 each), then per tendon: the length at the start of the last step (-1: not measured), its mean
/// and end lengthening speeds, and the wrap sides (their count, 0 or the path's element count,
/// then -1, 0 or +1 each).
constexpr size_t kEngineValuesPerBody = 36;

/// The engine as recordings name it ("bullet 3.24 float", and the dynamic state's layout): a
/// replay is exact only on the same.
std::string EngineId();

}  // namespace caliper::physics_bullet
