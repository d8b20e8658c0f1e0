#pragma once
// A private temporary directory (mkdtemp under $TMPDIR, else /tmp), removed with everything in it
// when the object goes: where a scene is written to be read back or sent.

#include <string>

namespace caliper::core {

class ScratchDirectory {
 public:
  /// Makes $TMPDIR/PREFIX-XXXXXX; throws std::runtime_error naming it when it cannot.
  explicit ScratchDirectory(const std::string& prefix = "caliper");
  ~ScratchDirectory();
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace caliper::core
