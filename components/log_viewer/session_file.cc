#include "session_file.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <ostream>
#include <stdexcept>
#include <vector>

#include "caliper/core/system.h"

namespace caliper::log_viewer {

namespace {

// the start of a text, on one printable line
std::string Excerpt(const std::string& line, size_t max) {
  std::string out;
  for (char c : line.substr(0, max)) out += c == '\t' ? ' ' : (c < 32 && c >= 0 ? '?' : c);
  if (line.size() > max) out += "...";
  return out;
}

// Why logging::ParseLine rejected `line` (checked in its order), or "" when that is not clear.
std::string WhatIsWrong(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  for (size_t tab; fields.size() < 8 && (tab = line.find('\t', start)) != std::string::npos;
       start = tab + 1)
    fields.push_back(line.substr(start, tab - start));
  fields.push_back(line.substr(start));
  if (fields.size() < 9)
    return "only " + std::to_string(fields.size()) + " of the 9 tab-separated fields";
  int y, mo, d, h, mi, s, us;  // logging's time format
  if (std::sscanf(fields[0].c_str(), "%4d-%2d-%2dT%2d:%2d:%2d.%6dZ", &y, &mo, &d, &h, &mi, &s,
                  &us) != 7)
    return "the time stamp '" + Excerpt(fields[0], 40) + "' is not YYYY-mm-ddTHH:MM:SS.uuuuuuZ";
  int priority = 0;
  if (!logging::ParsePriority(fields[1], &priority))
    return "the priority '" + Excerpt(fields[1], 40) + "' is not FATAL..DEBUG or a number";
  char* end = nullptr;
  std::strtol(fields[5].c_str(), &end, 10);
  if (*end != '\0') return "the pid '" + Excerpt(fields[5], 40) + "' is not a number";
  std::strtoull(fields[7].c_str(), &end, 10);
  if (*end != '\0' || fields[7].empty())
    return "the seq '" + Excerpt(fields[7], 40) + "' is not a number";
  return "";
}

}  // namespace

SessionFileContents ReadSessionFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  SessionFileContents out;
  std::string line;
  while (std::getline(in, line)) {
    ++out.lines;
    const bool complete = !in.eof();
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    logging::Record r;
    if (logging::ParseLine(line, &r)) {
      out.records.push_back(std::move(r));
      continue;
    }
    ++out.malformed;
    if (out.problems.size() < SessionFileContents::kMaxProblems) {
      std::string problem = path + ":" + std::to_string(out.lines) + ": ";
      if (complete) {
        const std::string why = WhatIsWrong(line);
        problem += "not a log record" + (why.empty() ? "" : " (" + why + ")") + ", skipped: '" +
                   Excerpt(line, 100) + "'";
      } else {
        problem += "incomplete last line (is the file still being written?), skipped";
      }
      out.problems.push_back(problem);
    }
  }
  if (in.bad()) throw std::runtime_error("cannot read " + path + ": " + std::strerror(errno));
  return out;
}

void WriteSessionFile(const std::string& path, const std::vector<const logging::Record*>& records,
                      const std::string& comment) {
  // a temporary file replaces `path` once whole: a failure leaves an existing file as it was
  core::WriteFileReplacing(path, [&](std::ostream& out) {
    out << "# caliper session log";
    if (!comment.empty()) out << "; " << Excerpt(comment, 200);
    out << "\n# time(UTC)\tpriority\tcategory\tcomponent\thost\tpid\tsource\tseq\tmessage\n";
    for (const logging::Record* r : records) out << logging::FormatLine(*r) << '\n';
  });
}

}  // namespace caliper::log_viewer
