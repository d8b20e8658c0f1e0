#pragma once
// `caliper-ctl batch`: runs a file of experiments on every Model it finds (or those named by a
// glob), lock-step and as fast as possible, one run per Model at a time. A run lost with its
// Model (killed, link down, no answer) goes to another one; each run's recording is written once,
// with a summary listing every retry and its reason.

#include <map>
#include <string>

#include "client.h"

namespace caliper::ctl {

void AddBatchVerb(std::map<std::string, Verb>* verbs);

}  // namespace caliper::ctl
