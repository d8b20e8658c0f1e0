#include "csv_export.h"

#include <stdexcept>

#include "caliper/core/system.h"
#include "number_format.h"

namespace caliper::plotter {

std::string CsvHeader(const SampleStore& store, const std::vector<size_t>& series) {
  std::string header = "time [s]";
  for (const size_t s : series) {
    const SeriesInfo& info = store.series(s);
    header += "," + info.key + " [" + (info.unit.empty() ? "-" : info.unit) + "]";
  }
  return header;
}

size_t WriteCsv(const SampleStore& store, const std::vector<size_t>& series, std::ostream& out) {
  for (const size_t s : series)
    if (s >= store.series_count())
      throw std::out_of_range("no series " + std::to_string(s) + " to export");
  out << CsvHeader(store, series) << "\n";
  std::string line;
  for (size_t i = 0; i < store.size(); ++i) {
    line.clear();
    AppendNumber(&line, store.time(i));
    for (const size_t s : series) {
      line += ',';
      AppendNumber(&line, store.value(s, i));
    }
    line += '\n';
    out.write(line.data(), static_cast<std::streamsize>(line.size()));
  }
  return store.size();
}

size_t ExportCsvFile(const SampleStore& store, const std::vector<size_t>& series,
                     const std::string& path) {
  size_t rows = 0;
  core::WriteFileReplacing(path, [&](std::ostream& out) { rows = WriteCsv(store, series, out); });
  return rows;
}

}  // namespace caliper::plotter
