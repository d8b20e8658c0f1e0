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

/// What a file says about itself beyond the scene, for tools that report on files.
struct FileInfo {
  std::string version;         // the version attribute of <COLLADA> (1.4.1, 1.5.0, ...)
  bool zipped = false;         // a .zae archive
  double meter = 1;            // metres per document unit, from <unit meter> (1 when absent)
  std::string unit_name;       // <unit name> as written ("" when absent; not trusted)
  std::string up_axis;         // <up_axis> as written (Y_UP when absent)
  std::string authoring_tool;  // the first contributor's <authoring_tool> ("" when absent)
};

/// Reads a COLLADA file (.dae or .zae; 1.4.0 and 1.4.1 load as 1.4.1). Problems the importer can
/// work around (unsupported elements, guessed masses, static bodies made up for a file without
/// physics, unknown elements in the Caliper technique) are appended to `warnings` (may be null),
/// each naming the file and, where known, the line. The scene passes sgal::Validate(); anything
/// it would reject, and every broken reference, throws ImportError instead: never a half-loaded
/// scene.
sgal::Scene Import(const std::string& path, std::vector<std::string>* warnings);

/// As above, and fills `info` (may be null) once the file's asset has been read, so that it is
/// filled as far as the file was read when ImportError is thrown later.
sgal::Scene Import(const std::string& path, std::vector<std::string>* warnings, FileInfo* info);

}  // namespace caliper::collada
