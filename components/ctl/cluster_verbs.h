#pragma once
// caliper-ctl's verbs for cluster runs through the per-host managers (caliper-manager):
// managers, create, destroy. Managers are found in the naming service by their type; one that
// does not answer is reported, never fatal.

#include <map>
#include <string>

#include "client.h"

namespace caliper::ctl {

/// Adds the cluster verbs (group "cluster") to `verbs`.
void AddClusterVerbs(std::map<std::string, Verb>* verbs);

}  // namespace caliper::ctl
