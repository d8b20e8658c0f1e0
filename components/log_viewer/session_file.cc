#include "session_file.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace caliper::log_viewer {

namespace {

// the start of a text, on one printable line
std::string Excerpt(const std::string& line, size_t max) {
  std::string out;
  for (char c : line.substr(0, max)) out += c == '\t' ? ' ' : (c < 32 && c >= 0 ? '?' : c);
  if (line.size() > max) out += "...";
  return out;
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
      out.problems.push_back(
          path + ":" + std::to_string(out.lines) + ": " +
          (complete ? "not a log record, skipped: '" + Excerpt(line, 100) + "'"
                    : "incomplete last line (is the file still being written?), skipped"));
    }
  }
  if (in.bad()) throw std::runtime_error("cannot read " + path + ": " + std::strerror(errno));
  return out;
}

void WriteSessionFile(const std::string& path, const std::vector<const logging::Record*>& records,
                      const std::string& comment) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  out << "# caliper session log";
  if (!comment.empty()) out << "; " << Excerpt(comment, 200);
  out << "\n# time(UTC)\tpriority\tcategory\tcomponent\thost\tpid\tsource\tseq\tmessage\n";
  for (const logging::Record* r : records) out << logging::FormatLine(*r) << '\n';
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
}

}  // namespace caliper::log_viewer
