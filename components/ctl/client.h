#pragma once
// caliper-ctl's verb table entry and its names for the client library's session and errors
// (libs/client): usage errors exit 2, failures (client::Failure and its kinds) exit 1.

#include <functional>
#include <string>
#include <vector>

#include "caliper/client/session.h"
#include "caliper/core/arguments.h"

namespace caliper::ctl {

using client::Failure;
using core::RejectOptions;
using core::TakeFlag;
using core::TakeOption;
using core::UsageError;
/// The connection to a session (the ORB starts with the first verb that needs it, so that verbs
/// working on files alone, like inspect, run without a naming service).
using Client = client::Session;

/// One verb of the command line: `usage` (after `caliper-ctl `), a one-line summary for the
/// verb list, the group it is listed in, more lines for `VERB --help` (may be empty), and
/// whether it takes Ctrl-C itself (then SIGINT and SIGTERM are blocked in every thread and the
/// verb waits for them with sigwait).
struct Verb {
  std::string usage;
  std::string summary;
  std::function<int(Client&, std::vector<std::string>&)> run;
  std::string group = "components";
  std::string details;
  bool takes_interrupt = false;
};

}  // namespace caliper::ctl
