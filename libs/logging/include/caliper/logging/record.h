#pragma once
// A log record as it travels between processes and as one line of a session log file.

#include <cstdint>
#include <iosfwd>
#include <string>

namespace caliper::logging {

/// log4cpp's priority numbers (lower is more severe).
enum Priority : int {
  kFatal = 0,
  kAlert = 100,
  kCrit = 200,
  kError = 300,
  kWarn = 400,
  kNotice = 500,
  kInfo = 600,
  kDebug = 700,
};

struct Record {
  int64_t time_us = 0;    ///< wall-clock time of the event [us since 1970-01-01 UTC]
  int priority = kInfo;   ///< log4cpp priority
  std::string category;   ///< caliper.<component>.<area>
  std::string component;  ///< instance name, e.g. model0
  std::string host;
  long pid = 0;
  std::string source;     ///< unique per logging process: host:pid:start
  uint64_t seq = 0;       ///< 1, 2, 3, ... per source
  std::string message;
};

/// Field by field equality (the session file's round trip keeps every field).
bool operator==(const Record& a, const Record& b);
inline bool operator!=(const Record& a, const Record& b) { return !(a == b); }
/// The record as its session file line (FormatLine), e.g. for test failure messages.
std::ostream& operator<<(std::ostream& out, const Record& record);

/// `FATAL` ... `DEBUG` for a priority (the nearest level at or below it in severity).
std::string PriorityName(int priority);

/// Parses `fatal`..`debug` (any case) or a number; returns false when it is neither.
bool ParsePriority(const std::string& text, int* priority);

/// One tab-separated line without the newline: UTC time, priority, category, component, host,
/// pid, source, seq, message (tabs, newlines and backslashes in fields escaped as \t \n \\).
std::string FormatLine(const Record& record);

/// The inverse of FormatLine; false for a line that is not a record (a comment or a torn line).
bool ParseLine(const std::string& line, Record* record);

}  // namespace caliper::logging
