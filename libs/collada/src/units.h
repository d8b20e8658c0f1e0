#pragma once
// Unit expressions of the Caliper extension ("mm", "N m/rad", "kg m^2", "mohm"): a scale to SI
// and a dimension, so that a value given in any unit of the right kind converts to the unit a
// parameter declares.

#include <array>
#include <string>
#include <string_view>

namespace caliper::collada::internal {

/// A parsed unit: value_SI = value * scale; dimension = exponents of m, kg, s, A, rad.
struct Unit {
  double scale = 1;
  std::array<int, 5> dimension{};  // m, kg, s, A, rad

  bool SameDimension(const Unit& other) const { return dimension == other.dimension; }
};

/// Parses a unit expression: symbols (m, g, s, A, rad, deg, rev, N, Pa, J, W, V, ohm or Ω, H, C,
/// Hz, min, h, rpm, %) with SI prefixes (G M k d c m u µ n p), products by blanks, '*' or '.',
/// quotients by '/', powers by '^', parentheses; "", "1" and "-" are dimensionless. Returns false
/// and sets `bad` to the part it does not know, and `why` (when given) to "" for an unknown
/// symbol or to the bound that part breaks: powers of at most 12, exponents of the result of at
/// most 24 (in magnitude), a scale to SI that is a normal double, at most 16 nested parentheses.
bool ParseUnit(std::string_view text, Unit* out, std::string* bad, std::string* why = nullptr);

}  // namespace caliper::collada::internal
