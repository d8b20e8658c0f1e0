#pragma once
// The rule that turns a scene's name into the first part of its DAQ ids, shared by the Model,
// which names its channels with it, and its clients, which build ids from a scene's name.

#include <string>

namespace caliper::core {

/// `arm_v2` from `Arm V2!`: ASCII letters (lower-cased) and digits, every other run of bytes one
/// underscore, none at the ends; "model" when nothing is left (an empty or unnamed scene). The
/// same under every locale.
std::string IdSafe(const std::string& name);

}  // namespace caliper::core
