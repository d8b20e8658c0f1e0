#pragma once
// Caliper's logging API on log4cpp: categories `caliper.<component>.<area>`, records that carry the
// component instance, host and pid, and a console appender for the terminal.

#include <log4cpp/Appender.hh>
#include <log4cpp/Category.hh>

#include <string>

#include "caliper/logging/record.h"

namespace log4cpp {
class LoggingEvent;
}

namespace caliper::logging {

/// Who is logging: set once per process by Initialize().
struct Identity {
  std::string component_type;  ///< e.g. model; categories are caliper.<component_type>.<area>
  std::string instance;        ///< e.g. model0 (updated once the naming service gave the name)
  std::string host;
  long pid = 0;
  std::string source;          ///< host:pid:start-time, unique per process
};

/// Sets up the root category `caliper` with a console appender on stderr at `console_priority`.
void Initialize(const std::string& component_type, int console_priority);

/// Renames the instance once it is known (records made before keep the old name).
void SetInstance(const std::string& instance);

/// A copy of the current identity.
Identity CurrentIdentity();

/// The category `caliper.<component_type>.<area>`.
log4cpp::Category& Get(const std::string& area);

/// Adds an appender to the `caliper` root category (the category owns it).
void AddAppender(log4cpp::Appender* appender);

/// Turns a log4cpp event into a record with this process's identity (seq left 0).
Record MakeRecord(const log4cpp::LoggingEvent& event);

/// Closes every appender (flushing what they hold); call once before exit.
void Shutdown();

}  // namespace caliper::logging
