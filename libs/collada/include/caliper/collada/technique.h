#pragma once
// Caliper's own data (settings, wrap obstacles, tendons, actuators, joint couplings;
// docs/collada-extension.md) read from an XML file that is not COLLADA: a <caliper> element inside
// a URDF, or a side file next to one. The same reader as COLLADA's technique, so the elements, the
// units and the checks are the same whatever file holds them.

#include <string>
#include <vector>

#include "caliper/collada/importer.h"
#include "caliper/sgal/scene.h"

namespace caliper::collada {

/// Reads every element named `element` directly under the root of the XML file `path` (or the
/// root itself when it has that name) as a Caliper technique into `scene`, whose bodies and
/// constraints the technique refers to by name. Lengths are metres unless a unit attribute says
/// otherwise. Unknown elements warn (with their line) into `warnings` (may be null); anything
/// else wrong throws ImportError `path:line: element 'name': reason`, and `scene` is then left as
/// it was. Returns how many such elements there were.
size_t ImportTechniqueXml(const std::string& path, const std::string& element, sgal::Scene* scene,
                          std::vector<std::string>* warnings);

}  // namespace caliper::collada
