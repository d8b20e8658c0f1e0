#pragma once
// Fault injection (a fail point, as storage and distributed systems use them to test their fault
// paths): a physics scene that throws a chosen kind of exception at a chosen step, so that tests
// of a real Model process can check that a fault anywhere in a step ends as FAULTED. Off unless
// the Model's `model.inject_fault` key names one; never in a normal session.

#include <cstdint>
#include <memory>
#include <string>

#include "caliper/sgal/physics_scene.h"
#include "caliper/simulation/model_core.h"

namespace caliper::simulation {

struct InjectedFault {
  enum class Kind { kNone, kFault, kBadAlloc, kOutOfRange, kRuntime, kUnknownType };
  Kind kind = Kind::kNone;
  uint64_t at_step = 0;  // the step that throws (1 = the first)
};

/// `KIND@STEP` (KIND: simulation_fault, bad_alloc, out_of_range, runtime_error, unknown) or ""
/// for none; throws std::invalid_argument naming what is wrong.
InjectedFault ParseInjectedFault(const std::string& text);

/// Wraps `inner`: its step number `fault.at_step` throws before stepping (the engine stays at
/// the start of that step, as PhysicsScene::Step promises).
std::unique_ptr<sgal::PhysicsScene> WithInjectedFault(std::unique_ptr<sgal::PhysicsScene> inner,
                                                      InjectedFault fault);

/// A factory for ModelCore whose first scene built fails as `fault` says; later ones (a reset,
/// a reload) do not, so that the Model can be seen to come back.
PhysicsFactory FailFirstScene(InjectedFault fault, physics_bullet::Options options = {});

}  // namespace caliper::simulation
