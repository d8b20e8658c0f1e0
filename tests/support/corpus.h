#pragma once
// Access to the shared reference corpus (../shared/corpus beside the clone, or $CALIPER_CORPUS)
// and a reader for its CSV tables.

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

namespace caliper::testing {

/// The corpus directory: $CALIPER_CORPUS when set, else ../shared/corpus beside the source tree
/// (CALIPER_CORPUS_DEFAULT, set by ctest); "" when that is absent (a user's clone without shared/).
std::string CorpusDir();

/// Skips the current test, saying why, when the corpus is absent.
#define CALIPER_REQUIRE_CORPUS()                                                          \
  do {                                                                                    \
    if (::caliper::testing::CorpusDir().empty())                                          \
      GTEST_SKIP() << "reference corpus not found ($CALIPER_CORPUS if set, else "         \
                      "../shared/corpus beside the source tree); set CALIPER_CORPUS to run"; \
  } while (0)

/// A numeric CSV table: header names and rows. Lines starting with '#' are comments.
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  std::vector<std::string> comments;
  /// Index of a column; fails the test (ADD_FAILURE) and returns -1 when absent.
  int Column(const std::string& name) const;
};

/// Reads a CSV file; throws std::runtime_error naming the file and line on a malformed row.
CsvTable ReadCsv(const std::string& path);

}  // namespace caliper::testing
