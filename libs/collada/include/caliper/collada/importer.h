#pragma once
// COLLADA 1.4.x and 1.5 (.dae, .zae) to the engine-neutral scene description: visual scenes,
// physics models and scenes, 1.5 kinematics, and Caliper's own data in
// <extra type="caliper"><technique profile="CALIPER"> (docs/collada-extension.md). Everything
// comes out in SI units with Z up, whatever the file's <unit> and <up_axis>.

#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/sgal/scene.h"

namespace caliper::collada {

/// A file that cannot be imported. The message names the file, the line where it is known, the
/// element (and its id) and what is wrong: `arm.dae:42: rigid_body 'forearm': mass -1 kg; ...`.
class ImportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads a COLLADA file (.dae or .zae; 1.4.0 and 1.4.1 load as 1.4.1). Problems the importer can
/// work around (unsupported elements, guessed masses, static bodies made up for a file without
/// physics, unknown elements in the Caliper technique) are appended to `warnings` (may be null),
/// each naming the file and, where known, the line. The scene passes sgal::Validate(); anything
/// it would reject, and every broken reference, throws ImportError instead: never a half-loaded
/// scene.
sgal::Scene Import(const std::string& path, std::vector<std::string>* warnings);

}  // namespace caliper::collada
