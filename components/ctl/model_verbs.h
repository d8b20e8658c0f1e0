#pragma once
// caliper-ctl's verbs for a Model (caliper-model): load, start, pause, stop, reset, step, status,
// params, get, set, motor, record, save. Each finds the Model by instance name (`--model NAME`,
// model0 by default); the Model's user exceptions print their reason and exit 1.

#include <map>
#include <string>

#include "client.h"

namespace caliper::ctl {

/// Adds the Model verbs to `verbs`. `reset` is shared with the lifecycle verb already in the
/// table: `reset NAME` still resets a component, `reset [--model NAME]` rewinds a Model.
void AddModelVerbs(std::map<std::string, Verb>* verbs);

}  // namespace caliper::ctl
