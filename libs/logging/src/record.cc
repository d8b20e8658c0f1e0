#include "caliper/logging/record.h"

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <strings.h>

#include <charconv>
#include <ostream>
#include <cstdint>
#include <string_view>

namespace caliper::logging {

namespace {

struct Level {
  int priority;
  const char* name;
};
constexpr Level kLevels[] = {{kFatal, "FATAL"}, {kAlert, "ALERT"},   {kCrit, "CRIT"},
                             {kError, "ERROR"}, {kWarn, "WARN"},     {kNotice, "NOTICE"},
                             {kInfo, "INFO"},   {kDebug, "DEBUG"}};

void AppendEscaped(const std::string& field, std::string* out) {
  for (char c : field) {
    switch (c) {
      case '\t': *out += "\\t"; break;
      case '\n': *out += "\\n"; break;
      case '\r': *out += "\\r"; break;
      case '\\': *out += "\\\\"; break;
      default: *out += c;
    }
  }
}

std::string Unescape(std::string_view field) {
  std::string out;
  out.reserve(field.size());
  for (size_t i = 0; i < field.size(); ++i) {
    if (field[i] == '\\' && i + 1 < field.size()) {
      const char c = field[++i];
      out += c == 't' ? '\t' : c == 'n' ? '\n' : c == 'r' ? '\r' : c;
    } else {
      out += field[i];
    }
  }
  return out;
}

// the digits text[from, from + n) as a number; false when one is not a digit
bool Digits(std::string_view text, size_t from, size_t n, int* value) {
  int v = 0;
  for (size_t i = from; i < from + n; ++i) {
    if (text[i] < '0' || text[i] > '9') return false;
    v = v * 10 + (text[i] - '0');
  }
  *value = v;
  return true;
}

// a whole field of decimal digits (no sign, no spaces) that fits `T`
template <class T>
bool Number(std::string_view field, T* value) {
  if (field.empty() || field[0] < '0' || field[0] > '9') return false;
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), *value);
  return error == std::errc() && end == field.data() + field.size();
}

// days since 1970-01-01 of a date in the proleptic Gregorian calendar (H. Hinnant's algorithm)
int64_t DaysFromCivil(int y, int m, int d) {
  y -= m <= 2;
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const int64_t yoe = y - era * 400;
  const int64_t doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

// YYYY-mm-ddTHH:MM:SS.uuuuuuZ, exactly as FormatLine writes it
bool ParseTime(std::string_view text, int64_t* time_us) {
  if (text.size() != 27 || text[4] != '-' || text[7] != '-' || text[10] != 'T' ||
      text[13] != ':' || text[16] != ':' || text[19] != '.' || text[26] != 'Z')
    return false;
  int y, mo, d, h, mi, s, us;
  if (!Digits(text, 0, 4, &y) || !Digits(text, 5, 2, &mo) || !Digits(text, 8, 2, &d) ||
      !Digits(text, 11, 2, &h) || !Digits(text, 14, 2, &mi) || !Digits(text, 17, 2, &s) ||
      !Digits(text, 20, 6, &us))
    return false;
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (mo < 1 || mo > 12 || h > 23 || mi > 59 || s > 60) return false;
  const bool leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
  if (d < 1 || d > kDays[mo - 1] + (mo == 2 && leap ? 1 : 0)) return false;
  const int64_t seconds = DaysFromCivil(y, mo, d) * 86400 + h * 3600 + mi * 60 + s;
  *time_us = seconds * 1000000 + us;
  return true;
}

}  // namespace

bool operator==(const Record& a, const Record& b) {
  return a.time_us == b.time_us && a.priority == b.priority && a.category == b.category &&
         a.component == b.component && a.host == b.host && a.pid == b.pid &&
         a.source == b.source && a.seq == b.seq && a.message == b.message;
}

std::ostream& operator<<(std::ostream& out, const Record& record) {
  return out << FormatLine(record);
}

std::string PriorityName(int priority) {
  for (const auto& level : kLevels)
    if (priority <= level.priority) return level.name;
  return "DEBUG";
}

bool ParsePriority(const std::string& text, int* priority) {
  for (const auto& level : kLevels) {
    if (strcasecmp(text.c_str(), level.name) == 0) {
      *priority = level.priority;
      return true;
    }
  }
  if (strcasecmp(text.c_str(), "warning") == 0) {
    *priority = kWarn;
    return true;
  }
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0') return false;
  *priority = static_cast<int>(value);
  return true;
}

std::string FormatLine(const Record& r) {
  // floor division: a time before 1970 has a second below it and microseconds 0..999999
  int64_t micros = r.time_us % 1000000;
  int64_t whole = r.time_us / 1000000;
  if (micros < 0) {
    micros += 1000000;
    whole -= 1;
  }
  const time_t seconds = static_cast<time_t>(whole);
  struct tm utc;
  gmtime_r(&seconds, &utc);
  // four digits of year, as ParseTime reads them (strftime's %Y writes the year 433 as "433":
  // a record read from a session file did not read back once exported; found by fuzzing)
  char stamp[64];
  std::snprintf(stamp, sizeof stamp, "%04d-%02d-%02dT%02d:%02d:%02d.%06dZ", utc.tm_year + 1900,
                utc.tm_mon + 1, utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec,
                static_cast<int>(micros));
  std::string line = stamp;
  line += '\t';
  line += PriorityName(r.priority);
  for (const std::string* field : {&r.category, &r.component, &r.host}) {
    line += '\t';
    AppendEscaped(*field, &line);
  }
  line += '\t' + std::to_string(r.pid) + '\t';
  AppendEscaped(r.source, &line);
  line += '\t' + std::to_string(r.seq) + '\t';
  AppendEscaped(r.message, &line);
  return line;
}

bool ParseLine(const std::string& line, Record* r) {
  if (line.empty() || line[0] == '#') return false;
  std::string_view fields[9];
  const std::string_view text(line);
  size_t start = 0;
  for (int i = 0; i < 8; ++i) {
    const size_t tab = text.find('\t', start);
    if (tab == std::string_view::npos) return false;
    fields[i] = text.substr(start, tab - start);
    start = tab + 1;
  }
  fields[8] = text.substr(start);
  if (!ParseTime(fields[0], &r->time_us)) return false;
  if (!ParsePriority(std::string(fields[1]), &r->priority)) return false;
  if (!Number(fields[5], &r->pid) || !Number(fields[7], &r->seq)) return false;
  r->category = Unescape(fields[2]);
  r->component = Unescape(fields[3]);
  r->host = Unescape(fields[4]);
  r->source = Unescape(fields[6]);
  r->message = Unescape(fields[8]);
  return true;
}

}  // namespace caliper::logging
