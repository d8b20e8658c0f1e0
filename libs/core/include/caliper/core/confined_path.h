#pragma once
// Paths that clients send (over CORBA) confined to configured directories: a Model reads scenes
// only from its search path and writes only into its write directory, whatever path it is given.
//
// A path is resolved the way the kernel would open it: symbolic links followed, `.` and `..`
// taken physically (std::filesystem::weakly_canonical), relative paths against the first allowed
// directory. The result must lie inside an allowed directory, compared component by component
// (`/data/allowed-evil` is not inside `/data/allowed`). The file is then opened by that resolved
// path, never by the path as sent, so a link the check did not see is never followed; for a
// reader that takes file names as URIs, names that a URI would read otherwise are refused.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace caliper::core {

/// A path refused by a ConfinedPaths; the message names the path, the allowed directories and
/// the configuration key that lists them.
class PathRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Splits a search path of directories separated by ':' (as $PATH); empty entries are dropped.
std::vector<std::string> SplitSearchPath(const std::string& list);

/// True when `path` is `dir` or lies below it, comparing whole components of the two paths as
/// given (no file system access: pass resolved paths).
bool IsWithin(const std::filesystem::path& path, const std::filesystem::path& dir);

/// A set of directories that paths from clients must lie in.
class ConfinedPaths {
 public:
  enum class Access { kRead, kWrite };

  /// `dirs`: the allowed directories (relative ones against the working directory now; they are
  /// resolved again at every check, so one created or moved later counts as it is then); the
  /// first is the base of relative paths. `key`: the configuration key that lists them, named in
  /// refusals. `what`: who reads or writes, for messages (e.g. "the Model reads scenes").
  /// `read_as_uri`: the reader takes file names as URIs (Collada-DOM cuts them at '#' and '?' and
  /// decodes '%XX'), so a path holding '#', '?' or '%' is refused: it would open another file.
  ConfinedPaths(std::vector<std::string> dirs, std::string key, std::string what,
                bool read_as_uri = false);

  /// The resolved absolute path that `path` names, or PathRefused saying why not: it lies
  /// outside every allowed directory (after `..` and symbolic links), no directory is
  /// configured, it is empty, it names an allowed directory itself, or (`read_as_uri`) it holds
  /// '#', '?' or '%', as sent or resolved. kRead refuses what exists
  /// but is no regular file (a missing file is left to the reader to report); kWrite refuses the
  /// same, a dangling symbolic link (writing through it would create its target) and a file with
  /// other hard links (a write would change them too).
  std::filesystem::path Resolve(const std::string& path, Access access) const;

  /// Resolve() without the exception: true when it would accept `path`.
  bool Allows(const std::string& path, Access access) const;

  /// The allowed directories, absolute, as configured.
  const std::vector<std::string>& dirs() const { return dirs_; }

  /// The allowed directories separated by ", " ("none" when there is none), for messages.
  std::string Describe() const;

 private:
  std::vector<std::string> dirs_;
  std::string key_;
  std::string what_;
  bool read_as_uri_ = false;
};

}  // namespace caliper::core
