#pragma once
// The parameter checks and number texts of the DC motor, its thermal model and the
// dc_motor_tendon kind's driver, in one place. Private to libs/actuators.

#include <cmath>
#include <stdexcept>
#include <string>

#include "caliper/core/numbers.h"

namespace caliper::actuators::motor_detail {

using core::FormatDouble;
inline std::string Text(double v) { return FormatDouble(v); }

enum class Range { kFinite, kPositive, kNonNegative, kFraction, kWhole };

/// Throws std::invalid_argument "parameter 'NAME' must be RULE [UNIT], got VALUE" unless the
/// value is finite and in the range (kWhole: a whole number >= 0).
inline void Check(const char* name, const char* unit, double value, Range range) {
  bool ok = std::isfinite(value);
  const char* expected = "finite";
  switch (range) {
    case Range::kFinite:
      break;
    case Range::kPositive:
      ok = ok && value > 0;
      expected = "> 0";
      break;
    case Range::kNonNegative:
      ok = ok && value >= 0;
      expected = ">= 0";
      break;
    case Range::kFraction:
      ok = ok && value > 0 && value <= 1;
      expected = "in (0, 1]";
      break;
    case Range::kWhole:
      ok = ok && value >= 0 && value == std::floor(value);
      expected = "a whole number >= 0";
      break;
  }
  if (!ok)
    throw std::invalid_argument(std::string("parameter '") + name + "' must be " + expected +
                                " [" + unit + "], got " + FormatDouble(value));
}

}  // namespace caliper::actuators::motor_detail
