#pragma once
// The parameters of the kind hill_muscle: one table of every curve set's parameters with their
// units, whether they are required and their help (muscle_parameters.cc), through which HillMuscle
// (muscle.cc) reads and writes them and RegisterMuscleKinds() registers them. Private to
// libs/actuators.

#include <vector>

#include "caliper/actuators/muscle.h"

namespace caliper::actuators::muscle_detail {

enum class Curves { kThelen, kMujoco, kMillard };

struct AllParameters {
  ThelenMuscleParameters thelen;
  MujocoMuscleParameters mujoco;
  MillardMuscleParameters millard;
  double default_activation = 0;  // [-]
};

enum class Applies { kBoth, kThelen, kMujoco, kMillard };  // kBoth: every curve set

struct ParameterEntry {
  const char* name;
  const char* unit;
  Applies applies;
  bool required;
  double& (*ref)(AllParameters&);
  const char* help;
};

// every parameter of every curve set, in the order they are registered; a name thelen2003 and
// millard2012 share has one entry per set (own defaults)
const std::vector<ParameterEntry>& ParameterTable();

// whether a parameter that applies to `applies` is one of the curve set `curves`
bool AppliesTo(Applies applies, Curves curves);

// the curve set's option value: "thelen2003", "mujoco" or "millard2012"
const char* CurvesName(Curves c);

}  // namespace caliper::actuators::muscle_detail
