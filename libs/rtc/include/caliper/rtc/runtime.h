#pragma once
// The process around a component: ORB and POA, configuration, naming, remote logging, signals and
// clean shutdown. A component's main() is one call to RunComponent().

#include <omniORB4/CORBA.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

#include "caliper/core/config.h"
#include "caliper/rtc/execution_context.h"
#include "caliper/rtc/lifecycle.h"

namespace caliper::rtc {

/// What kind of component a process is.
struct ComponentType {
  std::string name;         ///< `logger`, `model`, ...: config/<name>.conf, caliper.<name>.* logs
  std::string description;  ///< one line for --help and the profile
  std::string version = "0.1.0";
  std::string vendor = "Caliper";
  std::string category;
  std::vector<core::ConfigKey> config_keys;  ///< the component's own keys (common ones are added)
  bool remote_logging = true;  ///< send log records to the Logging component (not the logger itself)
};

class Runtime;
using ComponentFactory = std::function<std::unique_ptr<Component>(Runtime&)>;
/// Makes the servant (deriving from RTObjectServant) that serves the component.
using ServantFactory = std::function<PortableServer::Servant(Runtime&, Component&)>;

/// Everything a component and its servant may ask of the process.
class Runtime {
 public:
  const ComponentType& type() const { return type_; }
  const core::Config& config() const { return config_; }
  CORBA::ORB_ptr orb() const { return orb_.in(); }
  PortableServer::POA_ptr poa() const { return poa_.in(); }
  Lifecycle& lifecycle() { return *lifecycle_; }
  ExecutionContext& context() { return *context_; }
  /// Our own object reference and that of our execution context.
  CORBA::Object_ptr self() const { return self_.in(); }
  CORBA::Object_ptr context_ref() const { return context_ref_.in(); }
  /// The unique instance name (model0) once bound, the configured base name before.
  std::string instance() const;
  /// `host.host_cxt/model0.rtc`
  std::string naming_path() const;
  const std::string& naming_address() const { return naming_address_; }
  /// Ends the process cleanly soon (deactivate, stop, finalize, unbind); safe from any thread.
  void RequestExit();
  /// Activates a servant in the root POA (which then owns it) and returns its reference.
  CORBA::Object_ptr Activate(PortableServer::Servant servant);

 private:
  friend int RunComponent(int, char**, const ComponentType&, const ComponentFactory&,
                          const ServantFactory&);
  Runtime(ComponentType type, core::Config config);
  void WaitForExit();
  void BindUnique();
  void Rebind();
  void Unbind();

  ComponentType type_;
  core::Config config_;
  CORBA::ORB_var orb_;
  PortableServer::POA_var poa_;
  std::unique_ptr<Component> component_;
  std::unique_ptr<Lifecycle> lifecycle_;
  std::unique_ptr<ExecutionContext> context_;
  CORBA::Object_var self_;
  CORBA::Object_var context_ref_;
  std::string naming_address_;
  std::string host_;
  mutable std::mutex mutex_;
  std::condition_variable exit_cv_;
  bool exit_requested_ = false;
  std::string instance_;
  bool bound_ = false;
  bool rebind_warned_ = false;  // said once that re-registration fails, until it works again
};

/// Parses the command line and configuration, sets up CORBA and logging, creates, initializes,
/// binds and (if configured) activates the component, runs until SIGINT/SIGTERM or exit(), then
/// shuts down cleanly. Returns the process exit code: 0 after a clean shutdown, 2 for bad
/// configuration or arguments, 1 when the component could not start.
int RunComponent(int argc, char** argv, const ComponentType& type,
                 const ComponentFactory& make_component, const ServantFactory& make_servant);

/// RunComponent for the usual pair: ComponentT constructed from the Runtime, ServantT from the
/// Runtime and the component (or from the Runtime alone, for lifecycle-only servants).
template <class ComponentT, class ServantT>
int RunComponentOf(int argc, char** argv, const ComponentType& type) {
  return RunComponent(
      argc, argv, type, [](Runtime& rt) { return std::make_unique<ComponentT>(rt); },
      [](Runtime& rt, Component& c) -> PortableServer::Servant {
        if constexpr (std::is_constructible_v<ServantT, Runtime&, ComponentT&>)
          return new ServantT(rt, static_cast<ComponentT&>(c));
        else
          return new ServantT(rt);
      });
}

}  // namespace caliper::rtc
