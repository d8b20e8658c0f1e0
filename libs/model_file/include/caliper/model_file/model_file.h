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

/// The files besides `path` that importing it reads, as Import would find them: for a URDF the
/// mesh files its <mesh filename> elements name (package://, file:// and relative references
/// resolved as urdf::ResolveMesh does; references that resolve to no file are left out, Import
/// reports them) and its side file NAME.caliper.xml when there is one; none for COLLADA. For a
/// reader that confines the files it reads (the Model's model.read_dirs): check these too before
/// importing. Throws collada::ImportError when the URDF is no well-formed XML.
std::vector<std::string> FilesRead(const std::string& path);

/// A model file as a Model takes it by content (load_scene_data, run_experiment): one COLLADA
/// document, since the meshes of a URDF are other files that would not travel with it.
struct Content {
  std::string file_name;  ///< the name to send: the file's own (.dae, .zae) or NAME.dae
  std::string bytes;      ///< the file's bytes, or the imported robot exported as COLLADA
};

/// The content to send for `path`: a .dae or .zae file's own bytes; a .urdf imported here (meshes
/// included; warnings appended to `warnings`, may be null) and exported as COLLADA with the
/// Caliper technique (collada::Export, through a private temporary file), named NAME.dae. Throws
/// collada::ImportError (a file that cannot be read or imported, another ending) or
/// collada::ExportError, naming the file.
Content ContentToSend(const std::string& path, std::vector<std::string>* warnings);

}  // namespace caliper::model_file
