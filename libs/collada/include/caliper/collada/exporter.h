#pragma once
// The scene description to a COLLADA 1.5.0 document that Import() reads back to the same scene,
// and that other COLLADA tools show: a visual scene with every body's visuals and colours, a
// physics model (bodies, shapes, masses, inertias, materials, constraints with limits and
// springs), a physics scene (gravity, time step), and Caliper's own data (tendons, obstacles,
// actuators with their parameters and units, couplings, settings) in
// <extra type="caliper"><technique profile="CALIPER"> (docs/collada-extension.md).

#include <stdexcept>
#include <string>

#include "caliper/sgal/scene.h"

namespace caliper::collada {

/// A scene that cannot be written (an unknown actuator kind, a file that cannot be created).
class ExportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Writes `scene` to `path` (.dae). Throws ExportError naming the file and the problem.
void Export(const sgal::Scene& scene, const std::string& path);

}  // namespace caliper::collada
