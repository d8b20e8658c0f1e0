#pragma once
// A COLLADA document as plain data: the element tree that the version-specific Collada-DOM
// readers (dom141.cc, dom150.cc) produce and the writer (dom150.cc) consumes. The importer and
// exporter work on this tree only, so that no Collada-DOM type leaks out of those two sources.

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

struct _xmlDoc;
struct _xmlNode;

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

/// A document that could not be read: the message as libxml2 or the DOM reported it, and the
/// line where known (0 otherwise).
class ReadError : public std::runtime_error {
 public:
  ReadError(const std::string& message, int line) : std::runtime_error(message), line_(line) {}
  int line() const { return line_; }

 private:
  int line_;
};

/// libxml2's tree of a document (xmlFreeDoc frees it).
struct XmlDocFree {
  void operator()(_xmlDoc* doc) const;
};
using XmlDocument = std::unique_ptr<_xmlDoc, XmlDocFree>;

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

  /// The line of an element's start tag in the file; 0 when unknown (libxml2's tree of the file
  /// has no such element, e.g. one the DOM made up). Collada-DOM keeps no line numbers: the first
  /// call matches the DOM's elements to libxml2's nodes by their path from the root.
  int LineOf(const Element& element) const;
  /// libxml2's tree of the file (of the .dae inside a .zae) and the lines of its elements from
  /// line 65535 on (xmlNode keeps 16 bits).
  void SetXml(XmlDocument xml, std::unordered_map<const _xmlNode*, int> big_lines);
  /// Adds to the elements of a subtree the attributes their start tags in the file have and the
  /// DOM dropped; returns them as "name = value".
  std::vector<std::string> RestoreAttributes(Element* subtree);
  /// Collada-DOM cuts name attributes at the first blank: puts back the whole names from the
  /// file.
  void RestoreNames();
  /// Collada-DOM reads a word of a numeric list that is not a number (`1 abc -1`) as a made-up
  /// value and says nothing: reads each numeric list again from the file's text (decimal numbers
  /// in float_array, integers in int_array, p, vcount and h) and keeps those values. Throws
  /// ReadError naming the element and the word, with the element's line.
  void CheckNumbers();

 private:
  // matches each element to its node in libxml2's tree
  void IndexNodes() const;
  // calls `visit` with each element of `subtree` (depth first) that has a node in libxml2's tree,
  // and that node
  void ForEachInFile(Element* subtree, const std::function<void(Element*, const _xmlNode*)>& visit);

  std::unordered_map<std::string_view, const Element*> ids_;
  XmlDocument xml_;
  std::unordered_map<const _xmlNode*, int> big_lines_;
  mutable bool nodes_indexed_ = false;
  mutable std::unordered_map<const Element*, const _xmlNode*> nodes_;
};

/// What libxml2 made of a document: its tree (null when not well-formed) and the lines of its
/// elements from line 65535 on (xmlNode keeps 16 bits).
struct XmlParse {
  XmlDocument doc;
  int line = 0;
  std::string problem;
  std::unordered_map<const _xmlNode*, int> big_lines;
};

/// The check a COLLADA document passes before Collada-DOM reads it (malformed XML can make the
/// DOM's reader loop without end, an element directly inside one of its own name makes it
/// dereference a null pointer): libxml2 reads the file `name` or, when given, `text` (`name` then
/// names it, e.g. "x.zae:scene/robot.dae"). Throws ReadError with the reason (libxml2's, or the
/// element nested in itself) and its line; returns libxml2's tree.
XmlParse PreScanXml(const std::string& name, const std::string* text);

/// Reads an XML file that is not COLLADA (a URDF, a side file of Caliper data) into the same
/// element tree, every element with its line: attributes, character data (never numeric) and
/// children as written. Throws ReadError with libxml2's reason and line when it is not
/// well-formed.
Document ReadPlainXml(const std::string& path);

/// Loads `path` with the Collada-DOM of the document's schema version (its version attribute, or
/// each in turn for .zae archives) once libxml2 found it well-formed. Throws ReadError when
/// libxml2 or the DOM cannot read it.
Document ReadDocument(const std::string& path);

/// Writes a <COLLADA> tree through the 1.5.0 DOM. Throws std::runtime_error on failure.
void WriteDocument150(const Element& root, const std::string& path);

}  // namespace caliper::collada::internal
