#pragma once
// The plotter's data as CSV: a time column and one column per series, the unit of each in the
// header (`time [s],pendulum_tendon.pivot.position [rad]`), one row per sample held in the store
// (every one of them, not the thinned points that are drawn). No Qt.

#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

#include "sample_store.h"

namespace caliper::plotter {

/// `time [s],KEY [UNIT],...` for `series` (indices into the store); no unit is `[-]`.
std::string CsvHeader(const SampleStore& store, const std::vector<size_t>& series);

/// Writes the header and every sample held, oldest first: the time and the value of each of
/// `series` (shortest round-trip decimal form; `nan` where a series has no value). Returns the
/// rows written (store.size()). Throws std::out_of_range for an unknown series.
size_t WriteCsv(const SampleStore& store, const std::vector<size_t>& series, std::ostream& out);

/// WriteCsv into the file `path`, whole or not at all: an existing file is replaced only once
/// the new one is complete. Returns the rows written; throws std::runtime_error naming the path
/// and the reason (e.g. "No space left on device"), std::out_of_range for an unknown series.
size_t ExportCsvFile(const SampleStore& store, const std::vector<size_t>& series,
                     const std::string& path);

}  // namespace caliper::plotter
