#include "corpus.h"

#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace caliper::testing {

namespace {
bool IsDir(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}
}  // namespace

std::string CorpusDir() {
  // a CALIPER_CORPUS that is set wins, also when it is not there (no fallback to the default)
  for (const char* var : {"CALIPER_CORPUS", "CALIPER_CORPUS_DEFAULT"}) {
    const char* dir = std::getenv(var);
    if (dir != nullptr && *dir != '\0') return IsDir(dir) ? dir : "";
  }
  return "";
}

int CsvTable::Column(const std::string& name) const {
  for (size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return static_cast<int>(i);
  ADD_FAILURE() << "no column '" << name << "'";
  return -1;
}

CsvTable ReadCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  CsvTable table;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line[0] == '#') {
      table.comments.push_back(line);
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (table.columns.empty()) {
      table.columns = cells;
      continue;
    }
    std::vector<double> row;
    for (const auto& c : cells) {
      char* end = nullptr;
      const double v = std::strtod(c.c_str(), &end);
      if (end == c.c_str()) throw std::runtime_error(path + ":" + std::to_string(number) + ": '" + c + "' is not a number");
      row.push_back(v);
    }
    if (row.size() != table.columns.size())
      throw std::runtime_error(path + ":" + std::to_string(number) + ": " + std::to_string(row.size()) + " cells, header has " + std::to_string(table.columns.size()));
    table.rows.push_back(std::move(row));
  }
  return table;
}

}  // namespace caliper::testing
