#pragma once
// caliper-ctl's verbs for a Scene Renderer (caliper-renderer): screenshot. It finds the renderer
// by instance name (`--renderer NAME`, renderer0 by default).

#include <map>
#include <string>

#include "client.h"

namespace caliper::ctl {

/// Adds the renderer verbs to `verbs`.
void AddRendererVerbs(std::map<std::string, Verb>* verbs);

}  // namespace caliper::ctl
