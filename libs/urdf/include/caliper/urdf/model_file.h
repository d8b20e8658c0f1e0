#pragma once
// One entry point for every model file Caliper loads: COLLADA (.dae, .zae) and URDF (.urdf), by
// the file's ending. What loads a model (the Model component, caliper-ctl, batch runs, tests)
// goes through here, so each accepts both.

#include <string>
#include <vector>

#include "caliper/collada/importer.h"
#include "caliper/sgal/scene.h"

namespace caliper::model_file {

enum class Format { kUnknown, kCollada, kUrdf };

/// The format a file name says (case-insensitive ending): .dae and .zae COLLADA, .urdf URDF.
Format FormatOf(const std::string& path);

/// "*.dae, *.zae or *.urdf", for messages and file dialogs.
const char* AcceptedEndings();

/// Imports a model file of either format. Throws collada::ImportError (urdf::ImportError for a
/// URDF) naming the file; a file of another ending is refused with the endings accepted.
sgal::Scene Import(const std::string& path, std::vector<std::string>* warnings);

}  // namespace caliper::model_file
