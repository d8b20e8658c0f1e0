#include "caliper/core/confined_path.h"

#include <system_error>

#include "caliper/core/config.h"
#include "caliper/core/system.h"

namespace caliper::core {

namespace fs = std::filesystem;

namespace {

// the components of a normalised path, without the empty one a trailing separator leaves
std::vector<fs::path> Components(const fs::path& p) {
  std::vector<fs::path> out;
  for (const fs::path& c : p.lexically_normal())
    if (!c.empty()) out.push_back(c);
  return out;
}

std::string Quoted(const fs::path& p) { return "'" + p.string() + "'"; }

}  // namespace

std::vector<std::string> SplitSearchPath(const std::string& list) {
  std::vector<std::string> out;
  size_t begin = 0;
  while (begin <= list.size()) {
    size_t end = list.find(':', begin);
    if (end == std::string::npos) end = list.size();
    const std::string entry = Trim(list.substr(begin, end - begin));
    if (!entry.empty()) out.push_back(entry);
    begin = end + 1;
  }
  return out;
}

bool IsWithin(const fs::path& path, const fs::path& dir) {
  const std::vector<fs::path> p = Components(path);
  const std::vector<fs::path> d = Components(dir);
  if (d.size() > p.size()) return false;
  for (size_t i = 0; i < d.size(); ++i)
    if (p[i] != d[i]) return false;
  return true;
}

ConfinedPaths::ConfinedPaths(std::vector<std::string> dirs, std::string key, std::string what,
                             bool read_as_uri)
    : key_(std::move(key)), what_(std::move(what)), read_as_uri_(read_as_uri) {
  for (const std::string& d : dirs) {
    if (Trim(d).empty()) continue;
    fs::path p = fs::absolute(ExpandHome(Trim(d))).lexically_normal();
    if (!p.has_filename() && p != p.root_path()) p = p.parent_path();
    dirs_.push_back(p.string());
  }
}

std::string ConfinedPaths::Describe() const {
  if (dirs_.empty()) return "none";
  std::string out;
  for (const std::string& d : dirs_) out += (out.empty() ? "" : ", ") + d;
  return out;
}

fs::path ConfinedPaths::Resolve(const std::string& path, Access access) const {
  const std::string where = " (" + Describe() + "; set by " + key_ + ")";
  if (dirs_.empty())
    throw PathRefused(Quoted(path) + " is refused: no directory is configured where " + what_ +
                      " (set " + key_ + ")");
  if (path.empty()) throw PathRefused("an empty path is refused" + where);
  // longer than the kernel opens (PATH_MAX): refused without repeating it in the message
  if (path.size() >= 4096)
    throw PathRefused("a path of " + std::to_string(path.size()) +
                      " bytes is refused: longer than any the system opens (4095)" + where);

  // relative paths against the first directory; symbolic links and `..` as the kernel takes them
  fs::path given(path);
  if (given.is_relative()) given = fs::path(dirs_.front()) / given;
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(given, ec);
  if (ec) throw PathRefused(Quoted(path) + " cannot be resolved: " + ec.message() + where);
  const std::string shown =
      Quoted(path) + (resolved == fs::path(path) ? "" : " (resolved: " + Quoted(resolved) + ")");
  // a reader of URIs would cut the name at '#' or '?' or decode '%XX': another file than this
  if (read_as_uri_) {
    const std::string both = path + resolved.string();
    const size_t special = both.find_first_of("#?%");
    if (special != std::string::npos)
      throw PathRefused(shown + " holds '" + both[special] + "': " + what_ +
                        " with a library that reads file names as URIs, which would open " +
                        "another file; give a name without '#', '?' or '%'" + where);
  }

  const fs::path* inside = nullptr;
  std::vector<fs::path> allowed;
  for (const std::string& d : dirs_) {
    const fs::path dir = fs::weakly_canonical(d, ec);
    allowed.push_back(ec ? fs::path() : dir);
  }
  for (const fs::path& dir : allowed)
    if (!dir.empty() && IsWithin(resolved, dir)) {
      inside = &dir;
      break;
    }
  if (inside == nullptr)
    throw PathRefused(shown + " is outside the directories where " + what_ + where);
  if (Components(resolved).size() == Components(*inside).size())
    throw PathRefused(shown + " names the directory " + Quoted(*inside) +
                      " itself, not a file in it" + where);

  const fs::file_status status = fs::status(resolved, ec);
  if (!fs::exists(status)) {
    // what does not exist must not be a dangling symbolic link: writing through one would create
    // its target, wherever it points, and reading would read it once someone creates it
    for (fs::path p = resolved; !p.empty() && p != p.root_path(); p = p.parent_path()) {
      if (fs::exists(fs::status(p, ec))) break;
      if (fs::is_symlink(fs::symlink_status(p, ec)))
        throw PathRefused(shown + ": " + Quoted(p) + " is a symbolic link to a missing target" +
                          where);
    }
    return resolved;  // a missing file is the reader's (or the writer's) to report
  }
  // a directory, device or pipe is no file to read or write
  if (!fs::is_regular_file(status)) throw PathRefused(shown + " is not a regular file" + where);
  if (access == Access::kWrite && fs::hard_link_count(resolved, ec) > 1)
    throw PathRefused(shown + " has other hard links, which writing it would change too" + where);
  return resolved;
}

bool ConfinedPaths::Allows(const std::string& path, Access access) const {
  try {
    Resolve(path, access);
    return true;
  } catch (const PathRefused&) {
    return false;
  } catch (const fs::filesystem_error&) {
    return false;
  }
}

}  // namespace caliper::core
