#include "document.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "dom_io.h"

namespace caliper::collada::internal {

namespace {

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

std::string_view LocalName(std::string_view name) {
  const size_t colon = name.find(':');
  return colon == std::string_view::npos ? name : name.substr(colon + 1);
}

bool EndsWithNoCase(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) !=
        std::tolower(static_cast<unsigned char>(suffix[i])))
      return false;
  return true;
}

// One start tag found by the scan of a document's text.
struct Tag {
  std::string_view name;  // local name
  int line = 0;
  size_t end = 0;  // index of the first tag after this element's subtree
};

// Scans an XML text for its start tags (comments, CDATA, processing instructions and the
// document type are skipped). Returns false with the problem's line and description when the
// tags do not nest or there is content after the root element.
bool ScanTags(const std::string& text, std::vector<Tag>* tags, int* bad_line, std::string* what) {
  std::vector<size_t> open;  // indices into tags
  int line = 1;
  size_t i = 0;
  bool root_closed = false;
  auto advance_to = [&](size_t to) {
    for (; i < to && i < text.size(); ++i)
      if (text[i] == '\n') ++line;
  };
  while (i < text.size()) {
    const size_t lt = text.find('<', i);
    if (lt == std::string::npos) {
      // only white space may follow the root element
      for (size_t k = i; k < text.size(); ++k) {
        if (!IsSpace(text[k]) && open.empty() && root_closed) {
          advance_to(k);
          *bad_line = line;
          *what = "content after the root element";
          return false;
        }
      }
      break;
    }
    if (open.empty() && root_closed) {
      for (size_t k = i; k < lt; ++k)
        if (!IsSpace(text[k])) {
          advance_to(k);
          *bad_line = line;
          *what = "content after the root element";
          return false;
        }
    }
    advance_to(lt);
    if (text.compare(lt, 4, "<!--") == 0) {
      const size_t end = text.find("-->", lt + 4);
      advance_to(end == std::string::npos ? text.size() : end + 3);
      continue;
    }
    if (text.compare(lt, 9, "<![CDATA[") == 0) {
      const size_t end = text.find("]]>", lt + 9);
      advance_to(end == std::string::npos ? text.size() : end + 3);
      continue;
    }
    if (text.compare(lt, 2, "<?") == 0 || text.compare(lt, 2, "<!") == 0) {
      const size_t end = text.find('>', lt + 2);
      advance_to(end == std::string::npos ? text.size() : end + 1);
      continue;
    }
    const bool closing = lt + 1 < text.size() && text[lt + 1] == '/';
    size_t name_begin = lt + (closing ? 2 : 1);
    size_t name_end = name_begin;
    while (name_end < text.size() && !IsSpace(text[name_end]) && text[name_end] != '>' &&
           text[name_end] != '/')
      ++name_end;
    // find the end of the tag, skipping quoted attribute values
    size_t k = name_end;
    char quote = 0;
    for (; k < text.size(); ++k) {
      const char c = text[k];
      if (quote != 0) {
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '>') {
        break;
      }
    }
    if (k >= text.size()) {
      *bad_line = line;
      *what = "unterminated tag";
      return false;
    }
    const std::string_view name = LocalName(std::string_view(text).substr(name_begin, name_end - name_begin));
    const bool self_closing = !closing && k > lt && text[k - 1] == '/';
    if (closing) {
      if (open.empty() || (*tags)[open.back()].name != name) {
        *bad_line = line;
        *what = open.empty() ? "closing tag </" + std::string(name) + "> without an opening tag"
                             : "opening and ending tag mismatch: <" +
                                   std::string((*tags)[open.back()].name) + "> line " +
                                   std::to_string((*tags)[open.back()].line) + " and </" +
                                   std::string(name) + ">";
        return false;
      }
      (*tags)[open.back()].end = tags->size();
      open.pop_back();
      if (open.empty()) root_closed = true;
    } else {
      if (open.empty() && root_closed) {
        *bad_line = line;
        *what = "a second root element <" + std::string(name) + ">";
        return false;
      }
      tags->push_back({name, line, 0});
      if (self_closing) {
        tags->back().end = tags->size();
        if (open.empty()) root_closed = true;
      } else {
        open.push_back(tags->size() - 1);
      }
    }
    advance_to(k + 1);
  }
  if (!open.empty()) {
    *bad_line = (*tags)[open.back()].line;
    *what = "<" + std::string((*tags)[open.back()].name) + "> is never closed";
    return false;
  }
  return true;
}

// Gives each element the line of its start tag; elements the scan does not find (dropped by the
// DOM or made up) keep none.
void AssignLines(const Element& e, const std::vector<Tag>& tags, size_t at,
                 std::unordered_map<const Element*, int>* lines) {
  (*lines)[&e] = tags[at].line;
  size_t cursor = at + 1;
  const size_t end = tags[at].end;
  for (const auto& child : e.children) {
    const std::string_view want = child->local_name();
    size_t j = cursor;
    while (j < end && tags[j].name != want) j = tags[j].end;
    if (j >= end) continue;
    AssignLines(*child, tags, j, lines);
    cursor = tags[j].end;
  }
}

}  // namespace

std::string_view Element::local_name() const { return LocalName(name); }

const std::string* Element::FindAttribute(std::string_view attribute) const {
  for (const auto& [k, v] : attributes)
    if (k == attribute) return &v;
  return nullptr;
}

std::string Element::Attribute(std::string_view attribute, const std::string& fallback) const {
  const std::string* v = FindAttribute(attribute);
  return v == nullptr ? fallback : *v;
}

const Element* Element::Child(std::string_view child_name) const {
  for (const auto& c : children)
    if (c->local_name() == child_name) return c.get();
  return nullptr;
}

std::vector<const Element*> Element::Children(std::string_view child_name) const {
  std::vector<const Element*> out;
  for (const auto& c : children)
    if (c->local_name() == child_name) out.push_back(c.get());
  return out;
}

std::string Element::Trimmed() const {
  size_t b = 0, e = text.size();
  while (b < e && IsSpace(text[b])) ++b;
  while (e > b && IsSpace(text[e - 1])) --e;
  return text.substr(b, e - b);
}

std::vector<double> Element::Numbers() const {
  if (numeric) return numbers;
  std::vector<double> out;
  std::string bad;
  if (!ParseNumbers(text, &out, &bad))
    throw std::invalid_argument("'" + bad + "' is not a number");
  return out;
}

std::string Element::Describe() const {
  std::string d(local_name());
  for (const char* key : {"id", "sid", "name"}) {
    const std::string* v = FindAttribute(key);
    if (v != nullptr && !v->empty()) return d + " '" + *v + "'";
  }
  return d;
}

Element* Element::Add(std::string child_name) {
  children.push_back(std::make_unique<Element>(std::move(child_name)));
  children.back()->parent = this;
  return children.back().get();
}

Element* Element::Add(std::string child_name, std::string character_data) {
  Element* e = Add(std::move(child_name));
  e->text = std::move(character_data);
  return e;
}

Element* Element::Set(std::string attribute, std::string value) {
  for (auto& [k, v] : attributes)
    if (k == attribute) {
      v = std::move(value);
      return this;
    }
  attributes.emplace_back(std::move(attribute), std::move(value));
  return this;
}

bool ParseNumbers(std::string_view text, std::vector<double>* out, std::string* bad) {
  size_t i = 0;
  const size_t n = text.size();
  while (true) {
    while (i < n && IsSpace(text[i])) ++i;
    if (i >= n) return true;
    size_t j = i;
    while (j < n && !IsSpace(text[j])) ++j;
    const std::string token(text.substr(i, j - i));
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') {
      *bad = token;
      return false;
    }
    out->push_back(v);
    i = j;
  }
}

std::string FormatNumber(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "INF" : "-INF";
  if (value == 0) return "0";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string FormatNumbers(const double* values, size_t count) {
  std::string out;
  out.reserve(count * 10);
  for (size_t i = 0; i < count; ++i) {
    if (i > 0) out += ' ';
    out += FormatNumber(values[i]);
  }
  return out;
}

void Document::IndexIds() {
  ids_.clear();
  if (!root) return;
  std::vector<const Element*> stack{root.get()};
  while (!stack.empty()) {
    const Element* e = stack.back();
    stack.pop_back();
    if (const std::string* id = e->FindAttribute("id"); id != nullptr && !id->empty())
      ids_.emplace(std::string_view(*id), e);
    for (const auto& c : e->children) stack.push_back(c.get());
  }
}

const Element* Document::FindId(std::string_view id) const {
  const auto it = ids_.find(id);
  return it == ids_.end() ? nullptr : it->second;
}

int Document::LineOf(const Element& element) const {
  if (!lines_indexed_) {
    lines_indexed_ = true;
    std::vector<Tag> tags;
    int bad_line = 0;
    std::string what;
    ScanTags(text_, &tags, &bad_line, &what);
    // subtrees a failed scan left open end at the last tag found
    for (auto& t : tags)
      if (t.end == 0) t.end = tags.size();
    if (root && !tags.empty() && tags[0].name == root->local_name())
      AssignLines(*root, tags, 0, &lines_);
  }
  const auto it = lines_.find(&element);
  return it == lines_.end() ? 0 : it->second;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::ostringstream buffer;
  buffer << in.rdbuf();
  std::string raw = buffer.str();
  const bool le = raw.size() >= 2 && static_cast<unsigned char>(raw[0]) == 0xff &&
                  static_cast<unsigned char>(raw[1]) == 0xfe;
  const bool be = raw.size() >= 2 && static_cast<unsigned char>(raw[0]) == 0xfe &&
                  static_cast<unsigned char>(raw[1]) == 0xff;
  if (!le && !be) return raw;
  // UTF-16: keep the ASCII subset, which is all the markup and numbers (other characters
  // become '?', one per code unit, so lines keep their count)
  std::string text;
  text.reserve(raw.size() / 2);
  for (size_t i = 2; i + 1 < raw.size(); i += 2) {
    const unsigned lo = static_cast<unsigned char>(raw[le ? i : i + 1]);
    const unsigned hi = static_cast<unsigned char>(raw[le ? i + 1 : i]);
    text += hi == 0 && lo < 0x80 ? static_cast<char>(lo) : '?';
  }
  return text;
}

std::string SniffVersion(const std::string& text) {
  const size_t root = text.find("<COLLADA");
  if (root == std::string::npos) return "";
  const size_t end = text.find('>', root);
  const std::string tag = text.substr(root, end == std::string::npos ? std::string::npos : end - root);
  size_t at = 0;
  while ((at = tag.find("version", at)) != std::string::npos) {
    // the attribute itself, not xmlns or another name ending in "version"
    const bool starts = at > 0 && IsSpace(tag[at - 1]);
    size_t k = at + 7;
    while (k < tag.size() && IsSpace(tag[k])) ++k;
    if (starts && k < tag.size() && tag[k] == '=') {
      ++k;
      while (k < tag.size() && IsSpace(tag[k])) ++k;
      if (k < tag.size() && (tag[k] == '"' || tag[k] == '\'')) {
        const size_t close = tag.find(tag[k], k + 1);
        if (close != std::string::npos) return tag.substr(k + 1, close - k - 1);
      }
    }
    at += 7;
  }
  return "";
}

std::pair<int, std::string> FindXmlProblem(const std::string& text) {
  std::vector<Tag> tags;
  int line = 0;
  std::string what;
  if (ScanTags(text, &tags, &line, &what)) return {0, ""};
  return {line, what};
}

std::mutex& DomMutex() {
  static std::mutex m;
  return m;
}

Document ReadDocument(const std::string& path) {
  Document doc;
  doc.path = path;
  doc.zipped = EndsWithNoCase(path, ".zae");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw ReadError("cannot open the file", 0);
  }
  std::string text = doc.zipped ? "" : ReadText(path);
  doc.declared_version = doc.zipped ? "" : SniffVersion(text);
  std::vector<int> attempts;
  const std::string& v = doc.declared_version;
  if (v.rfind("1.5", 0) == 0) {
    attempts = {150};
  } else if (v.rfind("1.4", 0) == 0) {
    attempts = {141};
  } else if (!v.empty()) {
    throw ReadError("COLLADA version '" + v + "' is not supported (1.4.x and 1.5 are)", 0);
  } else {
    attempts = {150, 141};
  }
  std::lock_guard<std::mutex> lock(DomMutex());
  DomLoad load;
  for (int attempt : attempts) {
    load = attempt == 150 ? LoadWithDom150(path) : LoadWithDom141(path);
    if (load.root || !load.wrong_version) {
      doc.version = attempt == 150 ? "1.5.0" : "1.4.1";
      break;
    }
  }
  std::vector<std::string> errors;
  for (const auto& e : load.errors) {
    // a .zae is first read as XML, which fails twice before the DOM unzips it
    if (doc.zipped && (e.find("Document is empty") != std::string::npos ||
                       e.find("Error parsing XML in daeLIBXMLPlugin::read") != std::string::npos))
      continue;
    // the DOM's summary adds nothing to the reason before it
    if (e.rfind("Failed to load ", 0) == 0 && !errors.empty()) continue;
    errors.push_back(e);
  }
  if (!load.root || !errors.empty()) {
    std::string message;
    for (const auto& e : errors) message += (message.empty() ? "" : "; ") + e;
    if (message.empty()) message = "Collada-DOM could not load the document";
    if (load.wrong_version) message = "not a COLLADA 1.4 or 1.5 document: " + message;
    const auto [line, what] = FindXmlProblem(doc.zipped ? load.text : text);
    if (line > 0) message = "malformed XML (" + what + "): " + message;
    throw ReadError(message, line);
  }
  for (const auto& w : load.warnings) {
    // the schema location attributes of XML Schema instances are harmless
    if (w.find("attribute xmlns:") != std::string::npos || w.find("attribute xsi:") != std::string::npos)
      continue;
    doc.dom_warnings.push_back(w);
  }
  doc.root = std::move(load.root);
  if (doc.declared_version.empty()) doc.declared_version = doc.root->Attribute("version");
  doc.SetText(doc.zipped ? std::move(load.text) : std::move(text));
  doc.IndexIds();
  return doc;
}

void WriteDocument150(const Element& root, const std::string& path) {
  std::lock_guard<std::mutex> lock(DomMutex());
  WriteWithDom150(root, path);
}

}  // namespace caliper::collada::internal
