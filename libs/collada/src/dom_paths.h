#pragma once
// What Collada-DOM is given to open, checked first: it takes file names as URIs, and it extracts a
// .zae archive into a temporary directory trusting the names inside.

#include <string>

namespace caliper::collada::internal {

/// Throws std::runtime_error when Collada-DOM would open another file than `path` names: it reads a
/// file name as a URI, cutting it at '#' and '?', decoding '%XX', and taking a first component with
/// a ':' as a URI scheme.
void CheckDomPath(const std::string& path);

/// Throws std::runtime_error naming the entry when Collada-DOM could not extract the .zae archive
/// `path` into its temporary directory and stay there, or would read a file outside it: an entry
/// whose name is empty, absolute, has a `..` component, a NUL, or more bytes than the DOM reads
/// (255); a symbolic link; two entries of one name; a manifest.xml whose first element is not
/// <dae_root> (the DOM loops without end on it) or whose root document is absolute, has `..`, '#',
/// '?' or '%'; a document the DOM would read (each .dae entry, and the root document) that fails
/// the check a .dae file gets first (PreScanXml: malformed XML, an element nested in itself),
/// named with its line and element. Archives inside (which the DOM extracts too) are checked the
/// same way, at most kMaxZaeDepth deep; the entries may extract to kMaxZaeBytes in all.
void CheckZaeArchive(const std::string& path);

constexpr int kMaxZaeDepth = 3;
constexpr unsigned long long kMaxZaeBytes = 256ULL << 20;
constexpr unsigned long kMaxZaeEntries = 10000;

}  // namespace caliper::collada::internal
