#pragma once
// COLLADA's scoped identifiers: SIDREFs ("id/sid/sid") resolved through the document, following
// the instance elements on the way (instance_node, instance_joint, instance_kinematics_model,
// ...), and <param> names resolved through <newparam> chains.

#include <string>
#include <vector>

#include "import_context.h"

namespace caliper::collada::internal {

/// The elements a SIDREF passes through, in order (instance elements included before the
/// element they lead to); empty when it does not resolve. `scope` is where "./" starts.
std::vector<const Element*> ResolveSidRef(const Context& ctx, const std::string& ref,
                                          const Element* scope = nullptr);

/// Follows a <newparam> (or any element holding a <SIDREF>) to what it points at, through
/// further <newparam>s, and an instance element to what it instantiates. `trail` receives the
/// elements passed. Returns nullptr when a link of the chain does not resolve.
const Element* FollowParam(const Context& ctx, const Element* start,
                           std::vector<const Element*>* trail);

/// The <newparam sid="name"> a <param> names: searched under `scope` first, then anywhere.
const Element* FindNewParam(const Context& ctx, const std::string& name, const Element* scope);

/// The nearest ancestor (or the element itself) with this local name.
const Element* Ancestor(const Element* e, std::string_view name);

}  // namespace caliper::collada::internal
