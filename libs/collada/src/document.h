#pragma once
// A COLLADA document as plain data: the element tree that the version-specific Collada-DOM
// readers (dom141.cc, dom150.cc) produce and the writer (dom150.cc) consumes. The importer and
// exporter work on this tree only, so that no Collada-DOM type leaks out of those two sources.

#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

namespace caliper::collada::internal {

/// One XML element with its attributes, character data and children, in document order.
class Element {
 public:
  explicit Element(std::string element_name = "") : name(std::move(element_name)) {}

  std::string name;  // as written, with a namespace prefix if it had one (math:apply)
  std::vector<std::pair<std::string, std::string>> attributes;
  std::string text;             // character data; empty when `numbers` holds it
  std::vector<double> numbers;  // values of numeric lists (float_array, p, vcount, ...)
  bool numeric = false;         // whether `numbers` holds the character data
  std::vector<std::unique_ptr<Element>> children;
  Element* parent = nullptr;

  /// The name without a namespace prefix.
  std::string_view local_name() const;
  /// The value of an attribute, nullptr when absent.
  const std::string* FindAttribute(std::string_view attribute) const;
  /// The value of an attribute, `fallback` when absent.
  std::string Attribute(std::string_view attribute, const std::string& fallback = "") const;
  bool HasAttribute(std::string_view attribute) const {
    return FindAttribute(attribute) != nullptr;
  }
  /// The first child with this local name, nullptr when there is none.
  const Element* Child(std::string_view child_name) const;
  /// All children with this local name.
  std::vector<const Element*> Children(std::string_view child_name) const;
  /// The character data with surrounding white space removed.
  std::string Trimmed() const;
  /// `rigid_body 'forearm'`: the local name and the id, sid or name, for messages.
  std::string Describe() const;

  /// Builders for the exporter.
  Element* Add(std::string child_name);
  Element* Add(std::string child_name, std::string character_data);
  Element* Set(std::string attribute, std::string value);
};

/// Parses white-space separated numbers; returns false and sets `bad` to the first token that is
/// not a number.
bool ParseNumbers(std::string_view text, std::vector<double>* out, std::string* bad);

/// Formats a number so that it reads back to the same double (shortest form).
std::string FormatNumber(double value);
/// Numbers separated by single spaces.
std::string FormatNumbers(const double* values, size_t count);

/// A document that could not be read: the message as the DOM or our scan reported it, and the
/// line where known (0 otherwise).
class ReadError : public std::runtime_error {
 public:
  ReadError(const std::string& message, int line) : std::runtime_error(message), line_(line) {}
  int line() const { return line_; }

 private:
  int line_;
};

/// A COLLADA document loaded through Collada-DOM.
class Document {
 public:
  std::string path;                       // the file as given
  std::string version;                    // the schema the DOM loaded it with: "1.4.1" or "1.5.0"
  std::string declared_version;           // the version attribute of <COLLADA>
  bool zipped = false;                    // a .zae archive
  std::unique_ptr<Element> root;          // <COLLADA>
  std::vector<std::string> dom_warnings;  // what the DOM reported without failing

  /// Indexes the id attributes (call once the tree is complete).
  void IndexIds();
  /// The element with this id, nullptr when absent.
  const Element* FindId(std::string_view id) const;

  /// The line of an element in the file; 0 when unknown (the scan of the file's text did not
  /// find it, e.g. for an element the DOM made up). Collada-DOM keeps no line numbers: the first
  /// call scans the text once and indexes every start tag by its path from the root.
  int LineOf(const Element& element) const;
  /// The text the lines refer to (the .dae itself, or the .dae inside a .zae).
  void SetText(std::string text) { text_ = std::move(text); }
  /// Adds to the elements of a subtree the attributes their start tags in the text have and the
  /// DOM dropped; returns them as "name = value".
  std::vector<std::string> RestoreAttributes(Element* subtree);
  /// Collada-DOM cuts name attributes at the first blank: puts back the whole names from the
  /// text, where it has any with blanks.
  void RestoreNames();

 private:
  // finds each element's start tag in the text: its line and offset
  void IndexTags() const;

  std::unordered_map<std::string_view, const Element*> ids_;
  std::string text_;
  mutable bool tags_indexed_ = false;
  mutable std::unordered_map<const Element*, std::pair<int, size_t>> tags_;
};

/// The version attribute of the <COLLADA> element in a document's text; "" when it cannot be
/// found (a file that is not XML).
std::string SniffVersion(const std::string& text);

/// Reads a file's text as UTF-8 ("" when it cannot be read); UTF-16 with a byte order mark is
/// converted.
std::string ReadText(const std::string& path);

/// The first structural problem of an XML text (tags that do not match, content after the root
/// element, an unclosed element): its line and description; {0, ""} when none is found.
std::pair<int, std::string> FindXmlProblem(const std::string& text);

/// Loads `path` with the Collada-DOM of the document's schema version (sniffed, or tried in turn
/// for .zae archives). Throws ReadError when the DOM cannot load it.
Document ReadDocument(const std::string& path);

/// Writes a <COLLADA> tree through the 1.5.0 DOM. Throws std::runtime_error on failure.
void WriteDocument150(const Element& root, const std::string& path);

}  // namespace caliper::collada::internal
