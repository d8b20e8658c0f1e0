#pragma once
// Session log files as the Logging component writes them (one logging::FormatLine per record,
// `#` comment lines): read for browsing a past session, written for exporting a selection so that
// it can be opened again. No Qt, no CORBA.

#include <cstddef>
#include <string>
#include <vector>

#include "caliper/logging/record.h"

namespace caliper::log_viewer {

/// What reading a session file gave.
struct SessionFileContents {
  std::vector<logging::Record> records;  ///< the records, in file order
  size_t lines = 0;                      ///< lines read (comments and blank lines included)
  size_t malformed = 0;                  ///< lines that are neither a record nor a comment
  /// One message per malformed line, `PATH:LINE: ...`; at most kMaxProblems of them.
  std::vector<std::string> problems;

  static constexpr size_t kMaxProblems = 20;
};

/// Reads a session log. Comment lines (`#`) and blank lines are skipped silently; any other line
/// that logging::ParseLine rejects is skipped and reported with the file's path, the line's
/// number and, where it is clear, the field that is wrong (too few fields, the time stamp, the
/// priority, the pid or the seq). Throws std::runtime_error naming the path when the file cannot
/// be read.
SessionFileContents ReadSessionFile(const std::string& path);

/// Writes `records` as a session log: a `#` header (with `comment` when not empty) and one
/// logging::FormatLine per record. The file is written whole or not at all (an existing file
/// stays as it was on failure). Throws std::runtime_error naming the path and the reason.
void WriteSessionFile(const std::string& path, const std::vector<const logging::Record*>& records,
                      const std::string& comment = "");

}  // namespace caliper::log_viewer
