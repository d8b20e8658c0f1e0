#pragma once
// Numbers as text the way the plotter writes them (CSV cells, layout values): the shortest
// decimal form that reads back to the same double. No Qt.

#include <string>

namespace caliper::plotter {

/// Appends `v` in its shortest round-trip decimal form; NaN is `nan` (never `-nan`).
void AppendNumber(std::string* out, double v);

/// `v` in its shortest round-trip decimal form (as AppendNumber).
std::string FormatNumber(double v);

}  // namespace caliper::plotter
