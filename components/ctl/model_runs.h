#pragma once
// What every client that runs experiments on Models shares (caliper-ctl batch,
// caliper-calibrate): finding the Models, sending a scene by content, converting experiments and
// recordings, and making a std::thread known to omniORB.

#include <omniORB4/CORBA.h>

#include <string>
#include <vector>

#include "caliper/experiment/experiment.h"
#include "caliper/model.hh"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"

namespace caliper::ctl {

using rtc::OmniThread;

/// True when SIGINT or SIGTERM is pending (for programs that block both in every thread and
/// look between steps of their work); takes the signal.
bool InterruptPending();

/// A Model bound in the naming service.
struct ModelEntry {
  std::string name;  // model1@hostb
  std::string path;  // hostb.host_cxt/model1.rtc
  CORBA::Object_var object;
};

/// The Models whose instance (model1) or INSTANCE@HOST matches the glob.
std::vector<ModelEntry> FindModels(CosNaming::NamingContext_ptr root, const std::string& glob);

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

/// The experiment as the Model's run_experiment takes it, with the scene's bytes.
::Caliper::Simulation::Experiment ToIdl(const experiment::Experiment& e,
                                        const std::string& scene_bytes);

/// The recording a run returned.
experiment::Recording FromIdl(const ::Caliper::Simulation::Recording& r);

}  // namespace caliper::ctl
