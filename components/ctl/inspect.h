#pragma once
// `caliper-ctl inspect`: the report of what a scene file holds, with no session and no CORBA.

#include <ostream>
#include <string>
#include <vector>

#include "caliper/collada/importer.h"
#include "caliper/sgal/scene.h"

namespace caliper::ctl {

/// Writes a human-readable report of an imported scene: the file's version, units and up axis,
/// the simulation settings, then counts and lists of materials, bodies (type, mass, principal
/// moments, shapes), constraints (kind, bodies, limits, springs), couplings, wrap obstacles,
/// tendons (their paths), actuators (kind, tendon, parameters with their units, options) and
/// the importer's warnings.
void PrintSceneReport(const std::string& path, const sgal::Scene& scene,
                      const collada::FileInfo& info, const std::vector<std::string>& warnings,
                      std::ostream& out);

}  // namespace caliper::ctl
