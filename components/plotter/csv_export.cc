#include "csv_export.h"

#include <charconv>
#include <cmath>
#include <stdexcept>

namespace caliper::plotter {

namespace {

// shortest decimal that reads back to the same double
void AppendNumber(std::string* line, double v) {
  if (std::isnan(v)) {
    *line += "nan";
    return;
  }
  char buffer[32];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, v);
  line->append(buffer, r.ptr);
}

}  // namespace

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

}  // namespace caliper::plotter
