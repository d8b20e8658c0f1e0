#include "number_format.h"

#include <charconv>
#include <cmath>

namespace caliper::plotter {

void AppendNumber(std::string* out, double v) {
  if (std::isnan(v)) {
    *out += "nan";
    return;
  }
  char buffer[32];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, v);
  out->append(buffer, r.ptr);
}

std::string FormatNumber(double v) {
  std::string text;
  AppendNumber(&text, v);
  return text;
}

}  // namespace caliper::plotter
