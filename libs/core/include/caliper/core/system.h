#pragma once
// Small facts about the process and the clock.

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>

namespace caliper::core {

/// Short host name (without domain), as used in naming contexts `<host>.host_cxt`; $CALIPER_HOST
/// when set (several simulated hosts on one machine).
std::string HostName();

/// Wall-clock time [us since 1970-01-01 UTC].
int64_t NowMicros();

/// `YYYY-mm-dd HH:MM:SS.uuu` in local time for a time stamp [us since epoch].
std::string FormatTime(int64_t time_us);

/// Expands a leading `~` to $HOME.
std::string ExpandHome(const std::string& path);

/// Creates a directory and its parents; throws std::runtime_error with the reason on failure.
void MakeDirectories(const std::string& path);

/// True when a process with this pid exists.
bool ProcessAlive(long pid);

/// Writes a file whole or not at all: `write` fills a temporary file beside `path`, which then
/// replaces `path` (an existing file stays as it was when anything fails). Throws
/// std::runtime_error naming the path and the reason (the system's, e.g. "No space left on
/// device"); exceptions from `write` leave `path` untouched and propagate.
void WriteFileReplacing(const std::string& path, const std::function<void(std::ostream&)>& write);

/// True when SIGINT or SIGTERM is pending (for programs that block both in every thread and
/// look between steps of their work); takes the signal.
bool InterruptPending();

/// The directory of this process's program (/proc/self/exe), "." when it cannot be read: where
/// its sibling programs are.
std::string ProgramDirectory();

}  // namespace caliper::core
