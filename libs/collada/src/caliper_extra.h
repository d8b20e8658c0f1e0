#pragma once
// Where Caliper keeps its own data in a COLLADA document: <extra type="caliper"> holding
// <technique profile="CALIPER"> (docs/collada-extension.md).

#include <vector>

#include "document.h"

namespace caliper::collada::internal {

inline constexpr const char* kExtraType = "caliper";
inline constexpr const char* kProfile = "CALIPER";

/// The CALIPER techniques of an element's <extra type="caliper"> children, in order.
inline std::vector<const Element*> CaliperTechniques(const Element& owner) {
  std::vector<const Element*> out;
  for (const Element* extra : owner.Children("extra")) {
    if (extra->Attribute("type") != kExtraType) continue;
    for (const Element* technique : extra->Children("technique"))
      if (technique->Attribute("profile") == kProfile) out.push_back(technique);
  }
  return out;
}

/// The exact name a Caliper technique of `owner` keeps in <name> (Collada-DOM cuts name
/// attributes at the first blank); "" when there is none.
inline std::string CaliperName(const Element& owner) {
  for (const Element* technique : CaliperTechniques(owner))
    if (const Element* name = technique->Child("name"); name != nullptr) return name->text;
  return "";
}

/// Whether Collada-DOM keeps a name attribute as it is (it cuts at white space).
inline bool DomKeepsName(const std::string& name) {
  return name.find_first_of(" \t\r\n") == std::string::npos;
}

/// Adds <extra type="caliper"><technique profile="CALIPER"> to `owner`; returns the technique.
inline Element* AddCaliperTechnique(Element* owner) {
  Element* extra = owner->Add("extra");
  extra->Set("type", kExtraType);
  Element* technique = extra->Add("technique");
  technique->Set("profile", kProfile);
  return technique;
}

}  // namespace caliper::collada::internal
