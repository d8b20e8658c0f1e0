#pragma once
// Caliper's own data in <COLLADA><extra type="caliper"><technique profile="CALIPER">: simulation
// settings, wrap obstacles, tendon paths, actuators of any registered kind with their
// parameters in units, joint couplings (docs/collada-extension.md).

#include "document.h"
#include "import_context.h"

namespace caliper::collada::internal {

/// Reads the document's Caliper techniques into ctx.scene. Unknown elements warn with their name
/// and line; unknown kinds, parameters and units, missing required parameters, tendons with
/// fewer than two points and dangling names throw ImportError.
void ImportExtension(Context& ctx);

/// Reads one element holding the technique's children (a <technique profile="CALIPER">, or the
/// <caliper> element of another file format) into ctx.scene, with the same checks.
void ImportTechnique(Context& ctx, const Element& technique);

/// Writes the Caliper technique of a scene (settings, obstacles, tendons, actuators with every
/// parameter in its unit, couplings) under `technique`. Throws std::invalid_argument for an
/// actuator of an unknown kind.
void ExportExtension(const sgal::Scene& scene, Element* technique);

}  // namespace caliper::collada::internal
