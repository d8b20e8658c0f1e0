#include "caliper/logging/record.h"

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <strings.h>
#include <vector>

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

std::string Unescape(const std::string& field) {
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

bool ParseTime(const std::string& text, int64_t* time_us) {
  int y, mo, d, h, mi, s, us;
  if (std::sscanf(text.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d.%6dZ", &y, &mo, &d, &h, &mi, &s, &us) != 7)
    return false;
  struct tm t = {};
  t.tm_year = y - 1900;
  t.tm_mon = mo - 1;
  t.tm_mday = d;
  t.tm_hour = h;
  t.tm_min = mi;
  t.tm_sec = s;
  *time_us = static_cast<int64_t>(timegm(&t)) * 1000000 + us;
  return true;
}

}  // namespace

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
  const time_t seconds = static_cast<time_t>(r.time_us / 1000000);
  struct tm utc;
  gmtime_r(&seconds, &utc);
  char stamp[40];
  const size_t n = strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &utc);
  std::snprintf(stamp + n, sizeof stamp - n, ".%06dZ", static_cast<int>(r.time_us % 1000000));
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
  std::vector<std::string> fields;
  size_t start = 0;
  for (int i = 0; i < 8; ++i) {
    const size_t tab = line.find('\t', start);
    if (tab == std::string::npos) return false;
    fields.push_back(line.substr(start, tab - start));
    start = tab + 1;
  }
  fields.push_back(line.substr(start));
  char* end = nullptr;
  if (!ParseTime(fields[0], &r->time_us)) return false;
  if (!ParsePriority(fields[1], &r->priority)) return false;
  r->category = Unescape(fields[2]);
  r->component = Unescape(fields[3]);
  r->host = Unescape(fields[4]);
  r->pid = std::strtol(fields[5].c_str(), &end, 10);
  if (*end != '\0') return false;
  r->source = Unescape(fields[6]);
  r->seq = std::strtoull(fields[7].c_str(), &end, 10);
  if (*end != '\0' || fields[7].empty()) return false;
  r->message = Unescape(fields[8]);
  return true;
}

}  // namespace caliper::logging
