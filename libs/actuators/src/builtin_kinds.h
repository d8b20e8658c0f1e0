#pragma once
// Registration of the kinds this library ships; each kind's source file defines one Register*().

namespace caliper::actuators {

void RegisterMotorKinds();   // dc_motor_tendon, ligament (motor_tendon.cc)
void RegisterMuscleKinds();  // hill_muscle (muscle.cc)

inline void RegisterBuiltinKinds() {
  RegisterMotorKinds();
  RegisterMuscleKinds();
}

}  // namespace caliper::actuators
