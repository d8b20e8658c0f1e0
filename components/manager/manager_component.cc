#include "manager_component.h"

#include <limits.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <thread>

#include "caliper/core/system.h"
#include "caliper/logging/log.h"
#include "caliper/rtc.hh"
#include "caliper/rtc/naming.h"

namespace caliper::manager {

namespace {

namespace RTC = ::Caliper::RTC;

const char* const kStartable = "model";  // the types create() starts
constexpr auto kPollPeriod = std::chrono::milliseconds(50);

// `giop:tcp:ADDR:` for `giop:tcp:ADDR:PORT`: children cannot share the manager's fixed port.
std::string WithoutPort(const std::string& endpoint) {
  const size_t colon = endpoint.rfind(':');
  if (colon == std::string::npos || colon + 1 == endpoint.size()) return endpoint;
  const bool port = std::all_of(endpoint.begin() + static_cast<long>(colon) + 1, endpoint.end(),
                                [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
  return port ? endpoint.substr(0, colon + 1) : endpoint;
}

std::string Property(const RTC::ComponentProfile& profile, const std::string& name) {
  for (CORBA::ULong i = 0; i < profile.properties.length(); ++i)
    if (name == profile.properties[i].name.in()) return profile.properties[i].value.in();
  return "";
}

}  // namespace

std::vector<core::ConfigKey> ManagerComponent::ConfigKeys() {
  using Type = core::ConfigKey::Type;
  return {
      {"manager.max_models", Type::kInt, "0", "children that may run at once (0 = the number of "
       "cores)", 0, 100000},
      {"manager.start_timeout", Type::kDouble, "20",
       "how long a child may take to register in the naming service [s]", 0.1, 3600},
      {"manager.bin_dir", Type::kString, "",
       "where the caliper-<type> programs are ('' = the directory of caliper-manager)"},
      {"manager.output_dir", Type::kString, "~/.cache/caliper/manager",
       "each child's stdout and stderr go to <type>-<pid>.out here"},
  };
}

ManagerComponent::ManagerComponent(rtc::Runtime& runtime)
    : runtime_(runtime),
      bin_dir_(runtime.config().GetString("manager.bin_dir")),
      start_timeout_(runtime.config().GetDouble("manager.start_timeout")) {
  if (bin_dir_.empty()) bin_dir_ = core::ProgramDirectory();
  SupervisorOptions options;
  const long long max = runtime.config().GetInt("manager.max_models");
  options.max_running =
      max > 0 ? static_cast<size_t>(max) : std::max(1u, std::thread::hardware_concurrency());
  options.capacity_key = "manager.max_models";
  options.output_dir = core::ExpandHome(runtime.config().GetString("manager.output_dir"));
  supervisor_ = std::make_unique<Supervisor>(options);
}

rtc::ReturnCode ManagerComponent::OnInitialize() {
  core::MakeDirectories(core::ExpandHome(runtime_.config().GetString("manager.output_dir")));
  logging::Get("manager").info("starts up to %zu children from %s", supervisor_->capacity(),
                               bin_dir_.c_str());
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode ManagerComponent::OnFinalize() {
  supervisor_->StopAll();
  return rtc::ReturnCode::kOk;
}

ChildStatus ManagerComponent::Create(
    const std::string& type, const std::vector<std::pair<std::string, std::string>>& config) {
  if (type != kStartable)
    throw UnknownComponent("'" + type + "' is not a type this manager starts (it starts: " +
                           kStartable + ")");
  // where a child listens and registers is the manager's choice, not a client's
  if (config.size() > 256) throw StartFailed("more than 256 configuration keys");
  // what a client may choose of a child: an allow-list, so that a key added later (a timeout, a
  // message size, a test's fail point) is not a client's to set until it is listed here
  for (const auto& [key, value] : config) {
    if (key == "corba.endpoint" || key == "naming.service")
      throw StartFailed("the key '" + key + "' is set by the manager (" +
                        "its Models listen and register where it does)");
    // the directories paths may lead into are the host's choice (docs/cluster.md, "Trust model")
    if (key == "model.read_dirs" || key == "model.write_dir" || key == "model.confine_scene")
      throw StartFailed("the key '" + key + "' is set on the manager's host, not by a client " +
                        "(it bounds the files a Model reads and writes for its clients)");
    const bool allowed =
        (key.rfind("model.", 0) == 0 && key != "model.inject_fault") ||
        key == "exec.kind" || key == "exec.rate" || key == "log.level" ||
        key == "naming.update.interval";
    if (!allowed)
      throw StartFailed("the key '" + key + "' is not one a client may set (model.*, exec.kind, " +
                        "exec.rate, log.level, naming.update.interval)");
  }
  const core::Config& own = runtime_.config();
  std::vector<std::string> argv = {
      bin_dir_ + "/caliper-" + type, "--nameservice", runtime_.naming_address(),
      "-o", "corba.endpoint=" + WithoutPort(own.GetString("corba.endpoint")),
      "-o", "exec.auto_activate=true",
      "-o", "log.spool_dir=" + own.GetString("log.spool_dir")};
  for (const auto& [key, value] : config) argv.insert(argv.end(), {"-o", key + "=" + value});
  // a client's model.scene is read only from the Model's search path, as load_scene is
  argv.insert(argv.end(), {"-o", "model.confine_scene=true"});
  const pid_t pid = supervisor_->Start(type, argv);
  const ChildStatus child = AwaitRegistration(pid);
  logging::Get("manager").info("started %s (pid %d) as %s", type.c_str(), static_cast<int>(pid),
                               child.naming_path.c_str());
  return child;
}

ChildStatus ManagerComponent::AwaitRegistration(pid_t pid) {
  const auto deadline = std::chrono::steady_clock::now() + start_timeout_;
  const std::string host = core::HostName(), wanted = std::to_string(pid);
  std::vector<CORBA::Object_var> others;  // bound objects that answered with another pid
  auto failure = [&](const ChildStatus& s, const std::string& what) {
    return StartFailed("caliper-" + s.type + " (pid " + wanted + ") " + what + "; the end of " +
                       s.output_file + ":\n" + TailOfFile(s.output_file, 10));
  };
  while (true) {
    const std::optional<ChildStatus> status = supervisor_->Status(pid);
    if (!status) throw StartFailed("pid " + wanted + " was destroyed while it started");
    if (!status->running) throw failure(*status, status->state + " before it registered");
    try {
      CosNaming::NamingContext_var root =
          rtc::ResolveRoot(runtime_.orb(), runtime_.naming_address());
      for (const auto& e : rtc::ListComponents(root)) {
        if (e.host != host || std::any_of(others.begin(), others.end(), [&](const auto& o) {
              return o->_is_equivalent(e.object);
            }))
          continue;
        std::string child_pid;
        try {
          RTC::LightweightRTObject_var comp = RTC::LightweightRTObject::_narrow(e.object);
          if (CORBA::is_nil(comp)) continue;
          RTC::ComponentProfile_var profile = comp->get_component_profile();
          child_pid = Property(profile.in(), "pid");
        } catch (const CORBA::Exception&) {
          continue;  // a stale name of a process that died, asked again next time
        }
        if (child_pid == wanted) {
          supervisor_->SetRegistered(pid, e.instance, e.path);
          if (const auto s = supervisor_->Status(pid)) return *s;
        }
        others.push_back(CORBA::Object::_duplicate(e.object));
      }
    } catch (const rtc::Unreachable&) {
      // the naming service is away for now: the deadline tells
    } catch (const CORBA::Exception&) {
    }
    if (std::chrono::steady_clock::now() >= deadline) {
      supervisor_->Stop(pid);
      char limit[32];
      std::snprintf(limit, sizeof limit, "%g", start_timeout_.count());
      throw failure(*status, std::string("did not register in the naming service within ") +
                                 limit + " s (stopped it)");
    }
    std::this_thread::sleep_for(kPollPeriod);
  }
}

void ManagerComponent::Destroy(const std::string& instance) {
  const pid_t pid = supervisor_->PidOf(instance);
  supervisor_->Stop(pid);
  logging::Get("manager").info("destroyed %s (pid %d)", instance.c_str(), static_cast<int>(pid));
  // a child that was killed (by us, or before) leaves its name behind
  try {
    CosNaming::NamingContext_var root = rtc::ResolveRoot(runtime_.orb(), runtime_.naming_address());
    const CosNaming::Name name = rtc::ComponentName(core::HostName(), instance);
    CORBA::Object_var bound = root->resolve(name);
    if (!rtc::ObjectAlive(bound)) root->unbind(name);
  } catch (const std::exception&) {
  } catch (const CORBA::Exception&) {
    // unbound already (the usual case), or the naming service is away
  }
}

}  // namespace caliper::manager
