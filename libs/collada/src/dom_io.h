#pragma once
// The two doors to Collada-DOM, one per schema version (dom141.cc, dom150.cc). Callers hold
// DomMutex(): the DOM reports through one process-wide error handler.

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "document.h"

namespace caliper::collada::internal {

/// What one attempt to load a file gave.
struct DomLoad {
  std::unique_ptr<Element> root;      // null when the DOM failed
  std::vector<std::string> errors;    // the DOM's error messages
  std::vector<std::string> warnings;  // its warnings
  std::string extracted_path;         // .zae: the .dae the DOM extracted (while it exists)
  std::string text;                   // .zae: that .dae's text, for line numbers
  bool wrong_version = false;         // the DOM said the file is of the other schema version
};

/// `zipped`: a .zae, read with a DAE of its own (the DOM extracts it to a temporary directory
/// that the DAE's destructor removes); a .dae is read with one DAE per version for the process.
DomLoad LoadWithDom141(const std::string& path, bool zipped);
DomLoad LoadWithDom150(const std::string& path, bool zipped);

/// Writes a tree whose root is <COLLADA> through the 1.5.0 DOM; throws std::runtime_error.
void WriteWithDom150(const Element& root, const std::string& path);

/// Serialises every use of the DOM in this process.
std::mutex& DomMutex();

}  // namespace caliper::collada::internal
