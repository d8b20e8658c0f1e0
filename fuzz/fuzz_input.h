#pragma once
// What the fuzz targets share: the input as a file for the parsers that read files, and a check
// that stops the run (a finding) with a message.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace caliper::fuzz {

/// The input written to a file of this process, removed again when this goes out of scope: under
/// $TMPDIR, else /dev/shm when writable (a file per input on /tmp held the file-reading targets
/// at a tenth of their speed), else /tmp, named caliper-fuzz-PID-NAME. Aborts when the file cannot
/// be written: a run without its input would test nothing. A finding (an abort) leaves the file.
class InputFile {
 public:
  InputFile(const uint8_t* data, size_t size, const std::string& name);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// The input cut at each line `@@` (the separator "\n@@\n"), for the targets that read several
/// files (a file and the files it names): at most `count` parts, the last one keeping any further
/// separators; fewer when the input has fewer.
std::vector<std::string> Parts(const uint8_t* data, size_t size, size_t count);

/// Prints `what` and aborts when `ok` is false: libFuzzer saves the input as a crash, the replay
/// fails.
void Check(bool ok, const std::string& what);

}  // namespace caliper::fuzz
