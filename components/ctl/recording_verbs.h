#pragma once
// caliper-ctl's verbs for session recordings (issue #14): `recording start|stop|status` on a
// Model, `replay FILE|seek|fork|status` on a Model, and `replay --info|--verify|--csv FILE`
// worked here on the file alone (libs/recording and an in-process Model for --verify, no
// session needed).

#include <map>
#include <string>

#include "client.h"

namespace caliper::ctl {

/// Adds `recording` and `replay` to `verbs`.
void AddRecordingVerbs(std::map<std::string, Verb>* verbs);

}  // namespace caliper::ctl
