#pragma once
// The manager component (caliper-manager): one per host, OpenRTM's rtcd in spirit. Starts
// components on request as child processes, caps how many run, reports the ones that died and
// takes its children down when it stops.
//
// Configuration (config/manager.conf):
//   manager.max_models     children that may run at once (0 = the number of cores)
//   manager.start_timeout  how long a child may take to register in the naming service [s]
//   manager.bin_dir        where the caliper-<type> programs are ('' = caliper-manager's own)
//   manager.output_dir     each child's stdout and stderr go to <type>-<pid>.out here
// A child gets the manager's naming service, corba.endpoint (without a fixed port) and
// log.spool_dir, is activated once bound, and inherits the environment ($CALIPER_HOST,
// $CALIPER_LISTEN).

#include <chrono>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "caliper/rtc/runtime.h"
#include "children.h"

namespace caliper::manager {

class ManagerComponent : public rtc::Component {
 public:
  explicit ManagerComponent(rtc::Runtime& runtime);

  rtc::ReturnCode OnInitialize() override;
  /// Stops every child (TERM, KILL after 5 s).
  rtc::ReturnCode OnFinalize() override;

  /// Starts a component of `type` with `-o KEY=VALUE` for each of `config` and returns once it
  /// is bound under this host in the naming service. Throws UnknownComponent for a type it does
  /// not start, CapacityReached, StartFailed (with the end of the child's output).
  ChildStatus Create(const std::string& type,
                     const std::vector<std::pair<std::string, std::string>>& config);
  /// Stops the child bound as `instance` and forgets it (and its name, should it stay bound).
  void Destroy(const std::string& instance);

  const Supervisor& supervisor() const { return *supervisor_; }
  static std::vector<core::ConfigKey> ConfigKeys();

 private:
  ChildStatus AwaitRegistration(pid_t pid);

  rtc::Runtime& runtime_;
  std::string bin_dir_;
  std::chrono::duration<double> start_timeout_;
  std::unique_ptr<Supervisor> supervisor_;
};

}  // namespace caliper::manager
