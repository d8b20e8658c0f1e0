#pragma once
// How files reach a Model: by path or by content. A Model reads only below its read
// directories and writes only below its write directory (its file_access), and a Model on
// another host shares no disk with us; everything else travels by content in one message. This
// is the one place that rule is written: caliper-ctl, the Main Window, batch runs, calibration
// and the Python package all load scenes through here.

#include <string>
#include <vector>

#include "caliper/core/confined_path.h"
#include "caliper/model.hh"

namespace caliper::client {

/// The bytes to send for a scene file by content: a .dae's or .zae's own, a .urdf's robot
/// imported here and exported as COLLADA (model_file::ContentToSend; its import warnings go to
/// `warnings` when not null). std::runtime_error when it cannot be read, imported or exported, or
/// exceeds what one message carries (rtc::kMaxMessageBytes less 1 MiB), naming the file and the
/// sizes.
std::string ReadScene(const std::string& path, std::vector<std::string>* warnings = nullptr);

/// The file name a scene sent by content carries: the file's own, NAME.dae for NAME.urdf (what
/// ReadScene sends for it).
std::string SceneFileName(const std::string& path);

/// A file's bytes as an IDL octet sequence.
::Caliper::Simulation::Octets ToOctets(const std::string& bytes);

/// Whether a Model on this host takes the absolute `path` itself: below its read directories
/// (kRead; for a URDF, its meshes and side file too) or its write directory (kWrite). Asks the
/// Model (file_access); CORBA exceptions pass.
bool ModelTakesPath(::Caliper::Simulation::Model_ptr model, const std::string& path,
                    core::ConfinedPaths::Access access);

/// The rule: a file goes by content to a Model on another host (it shares no disk with us), when
/// `force_content` is asked (--send), or when the Model would not take its path
/// (ModelTakesPath); by path otherwise.
bool SendsByContent(::Caliper::Simulation::Model_ptr model, const std::string& path, bool local,
                    bool force_content, core::ConfinedPaths::Access access);

/// How a scene was sent.
struct SentScene {
  bool by_content = false;
  std::string file_name;              ///< as the Model names it (NAME.dae for NAME.urdf)
  std::vector<std::string> warnings;  ///< the URDF's import warnings (converted here)
};

/// Loads the scene at the absolute `path` into the Model, by content or by path (SendsByContent
/// decides). std::runtime_error when the file cannot be read or converted here; the Model's own
/// exceptions (LoadFailed, ...) and CORBA's pass.
SentScene LoadScene(::Caliper::Simulation::Model_ptr model, const std::string& path,
                    bool by_content);

/// How a recording was opened for replay.
struct OpenedReplay {
  bool by_content = false;
  ::Caliper::Simulation::ReplayStatus status;
};

/// The Model replays the recording `file`. A file of this host goes by path when the Model is on
/// this host (`local`) and it lies below the Model's read or write directories, else by content
/// (a copy the Model keeps while it replays), also when `force_content` (--send). A name that is
/// no file here is the Model's own: a relative one starts from its write directory (where
/// `recording start NAME` writes), on its host. std::runtime_error when the file cannot be read
/// here or exceeds one message; the Model's exceptions (LoadFailed, ...) and CORBA's pass.
OpenedReplay OpenReplay(::Caliper::Simulation::Model_ptr model, const std::string& file,
                        bool local, bool force_content);

}  // namespace caliper::client
