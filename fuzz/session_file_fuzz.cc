// Fuzz target: session log files as the Log Viewer reads them (ReadSessionFile over
// logging::ParseLine). Properties: reading never throws for a readable file; every problem names
// the file and a line; each record read is written back by logging::FormatLine to a line that
// ParseLine reads to the same record (the export round trip; a priority between two levels comes
// back as its level).
#include <cstdint>
#include <string>

#include "caliper/logging/record.h"
#include "fuzz_input.h"
#include "session_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using caliper::fuzz::Check;
  const caliper::fuzz::InputFile input(data, size, "input.log");
  const std::string& path = input.path();
  const auto contents = caliper::log_viewer::ReadSessionFile(path);
  Check(contents.records.size() + contents.malformed <= contents.lines, "more records than lines");
  Check(contents.problems.size() <= caliper::log_viewer::SessionFileContents::kMaxProblems,
        "more problems than kMaxProblems");
  for (const auto& p : contents.problems)
    Check(p.rfind(path + ":", 0) == 0, "a problem that does not name the file: " + p);
  for (const auto& r : contents.records) {
    const std::string line = caliper::logging::FormatLine(r);
    caliper::logging::Record back;
    Check(caliper::logging::ParseLine(line, &back), "FormatLine wrote a line ParseLine refuses: " +
                                                        line.substr(0, 300));
    // a priority between two levels is written as the level's name (650 as DEBUG, read as 700)
    Check(caliper::logging::PriorityName(back.priority) ==
              caliper::logging::PriorityName(r.priority),
          "the round trip changed the priority's level: " + line.substr(0, 300));
    back.priority = r.priority;
    Check(back == r, "the round trip changed the record: " + line.substr(0, 300));
  }
  return 0;
}
