#pragma once
// Experiments on Models: an experiment file's runs (libs/experiment) as the Model's
// run_experiment takes them, and the recordings they return. A run loads its scene afresh from
// the bytes it carries, so the same experiment gives the same bits on any Model.

#include <string>

#include "caliper/experiment/experiment.h"
#include "caliper/model.hh"

namespace caliper::client {

/// The experiment as the Model's run_experiment takes it, with the scene's bytes (ReadScene).
::Caliper::Simulation::Experiment ToIdl(const experiment::Experiment& e,
                                        const std::string& scene_bytes);

/// The recording a run returned: channels with units and shapes, times [s], values.
experiment::Recording FromIdl(const ::Caliper::Simulation::Recording& r);

}  // namespace caliper::client
