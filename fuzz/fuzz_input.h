#pragma once
// What the fuzz targets share: the input as a file for the parsers that read files, and a check
// that stops the run (a finding) with a message.

#include <cstddef>
#include <cstdint>
#include <string>

namespace caliper::fuzz {

/// Writes `size` bytes to a file of this process (under $TMPDIR, else /dev/shm when writable,
/// else /tmp; the directory is removed at exit) named `name`, replacing what the previous input left there, and returns
/// its path. Aborts when the file cannot be written: a run without its input would test nothing.
std::string WriteInput(const uint8_t* data, size_t size, const std::string& name);

/// Prints `what` and aborts when `ok` is false: libFuzzer saves the input as a crash, the replay
/// fails.
void Check(bool ok, const std::string& what);

}  // namespace caliper::fuzz
