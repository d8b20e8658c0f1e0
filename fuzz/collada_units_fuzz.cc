// Fuzz target: the unit expressions of the Caliper extension (ParseUnit: "N m/rad", "kg m^2",
// "mohm", parentheses, powers). Properties: a parsed unit has a finite, positive scale; a refused
// one says which part it does not know; parsing is deterministic.
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_input.h"
#include "units.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using caliper::fuzz::Check;
  using caliper::collada::internal::ParseUnit;
  using caliper::collada::internal::Unit;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Unit unit;
  std::string bad;
  const bool ok = ParseUnit(text, &unit, &bad);
  if (ok) {
    Check(std::isfinite(unit.scale) && unit.scale > 0,
          "ParseUnit accepted '" + std::string(text) + "' with the scale " +
              std::to_string(unit.scale));
  }
  Unit again;
  std::string bad_again;
  Check(ParseUnit(text, &again, &bad_again) == ok && bad_again == bad &&
            (!ok || (again.dimension == unit.dimension && again.scale == unit.scale)),
        "ParseUnit gave two answers for '" + std::string(text) + "'");
  return 0;
}
