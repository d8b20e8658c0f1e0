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

#include "caliper/core/numbers.h"
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
  size_t offset = 0;  // of the '<' in the text
  size_t end = 0;     // index of the first tag after this element's subtree
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
    const std::string_view name =
        LocalName(std::string_view(text).substr(name_begin, name_end - name_begin));
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
      tags->push_back({name, line, lt, 0});
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

// Gives each element the index of its start tag; elements the scan does not find (dropped by
// the DOM or made up) get none. Children are matched by name in order, not by position: the DOM
// keeps typed children in schema order, which need not be the file's.
void AssignTags(const Element& e, const std::vector<Tag>& tags, size_t at,
                std::unordered_map<const Element*, size_t>* index) {
  (*index)[&e] = at;
  std::unordered_map<std::string_view, std::vector<size_t>> by_name;
  for (size_t j = at + 1; j < tags[at].end; j = tags[j].end) by_name[tags[j].name].push_back(j);
  std::unordered_map<std::string_view, size_t> used;
  for (const auto& child : e.children) {
    const std::string_view name = child->local_name();
    const auto it = by_name.find(name);
    if (it == by_name.end()) continue;
    size_t& next = used[name];
    if (next >= it->second.size()) continue;
    AssignTags(*child, tags, it->second[next++], index);
  }
}

// Replaces the five predefined entities and character references.
std::string Unescape(std::string_view v) {
  std::string out;
  for (size_t i = 0; i < v.size(); ++i) {
    if (v[i] != '&') {
      out += v[i];
      continue;
    }
    const size_t semi = v.find(';', i);
    if (semi == std::string_view::npos) {
      out += v.substr(i);
      break;
    }
    const std::string_view entity = v.substr(i + 1, semi - i - 1);
    if (entity == "amp")
      out += '&';
    else if (entity == "lt")
      out += '<';
    else if (entity == "gt")
      out += '>';
    else if (entity == "quot")
      out += '"';
    else if (entity == "apos")
      out += '\'';
    else if (!entity.empty() && entity[0] == '#') {
      const long code = std::strtol(
          std::string(entity.substr(1)).c_str() + (entity.size() > 1 && entity[1] == 'x'), nullptr,
          entity.size() > 1 && entity[1] == 'x' ? 16 : 10);
      if (code < 0x80)
        out += static_cast<char>(code);
      else
        out += '?';
    } else {
      out += v.substr(i, semi - i + 1);
    }
    i = semi;
  }
  return out;
}

// The attributes of the start tag at `offset`.
std::vector<std::pair<std::string, std::string>> TagAttributes(const std::string& text,
                                                               size_t offset) {
  std::vector<std::pair<std::string, std::string>> out;
  size_t i = offset + 1;
  while (i < text.size() && !IsSpace(text[i]) && text[i] != '>' && text[i] != '/') ++i;
  while (i < text.size()) {
    while (i < text.size() && IsSpace(text[i])) ++i;
    if (i >= text.size() || text[i] == '>' || text[i] == '/') break;
    const size_t name_begin = i;
    while (i < text.size() && !IsSpace(text[i]) && text[i] != '=' && text[i] != '>') ++i;
    const std::string name = text.substr(name_begin, i - name_begin);
    while (i < text.size() && IsSpace(text[i])) ++i;
    if (i >= text.size() || text[i] != '=') break;
    ++i;
    while (i < text.size() && IsSpace(text[i])) ++i;
    if (i >= text.size() || (text[i] != '"' && text[i] != '\'')) break;
    const char quote = text[i++];
    const size_t close = text.find(quote, i);
    if (close == std::string::npos) break;
    out.emplace_back(name, Unescape(std::string_view(text).substr(i, close - i)));
    i = close + 1;
  }
  return out;
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
    const std::string_view token = text.substr(i, j - i);
    double v = 0;
    if (!core::ParseDouble(token, &v)) {
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

void Document::IndexTags() const {
  if (tags_indexed_) return;
  tags_indexed_ = true;
  std::vector<Tag> tags;
  int bad_line = 0;
  std::string what;
  ScanTags(text_, &tags, &bad_line, &what);
  // subtrees a failed scan left open end at the last tag found
  for (auto& t : tags)
    if (t.end == 0) t.end = tags.size();
  std::unordered_map<const Element*, size_t> index;
  if (root && !tags.empty() && tags[0].name == root->local_name())
    AssignTags(*root, tags, 0, &index);
  for (const auto& [e, i] : index) tags_[e] = {tags[i].line, tags[i].offset};
}

int Document::LineOf(const Element& element) const {
  IndexTags();
  const auto it = tags_.find(&element);
  return it == tags_.end() ? 0 : it->second.first;
}

std::vector<std::string> Document::RestoreAttributes(Element* subtree) {
  IndexTags();
  std::vector<std::string> restored;
  std::vector<Element*> stack{subtree};
  while (!stack.empty()) {
    Element* e = stack.back();
    stack.pop_back();
    for (auto& c : e->children) stack.push_back(c.get());
    const auto it = tags_.find(e);
    if (it == tags_.end()) continue;
    for (auto& [name, value] : TagAttributes(text_, it->second.second)) {
      if (e->HasAttribute(name)) continue;
      restored.push_back(name + " = " + value);
      e->attributes.emplace_back(name, value);
    }
  }
  return restored;
}

void Document::RestoreNames() {
  // cheap test first: a name attribute with a blank in its value
  bool blanks = false;
  for (size_t at = text_.find(" name=\""); at != std::string::npos && !blanks;
       at = text_.find(" name=\"", at + 7)) {
    const size_t close = text_.find('"', at + 7);
    blanks = close != std::string::npos && text_.find_first_of(" \t", at + 7) < close;
  }
  if (!blanks || !root) return;
  IndexTags();
  std::vector<Element*> stack{root.get()};
  while (!stack.empty()) {
    Element* e = stack.back();
    stack.pop_back();
    for (auto& c : e->children) stack.push_back(c.get());
    const auto it = tags_.find(e);
    if (it == tags_.end() || !e->HasAttribute("name")) continue;
    for (const auto& [name, value] : TagAttributes(text_, it->second.second))
      if (name == "name") e->Set("name", value);
  }
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
  const std::string tag =
      text.substr(root, end == std::string::npos ? std::string::npos : end - root);
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
  // malformed XML never reaches the DOM: its reader can loop forever on some (a start tag left
  // open inside character data, found by fuzzing)
  if (!doc.zipped) {
    const auto [line, what] = FindXmlProblem(text);
    if (line > 0) throw ReadError("malformed XML: " + what, line);
  }
  std::lock_guard<std::mutex> lock(DomMutex());
  const core::ClassicLocaleScope classic;  // the DOM reads numbers with sscanf and streams
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
    if (w.find("attribute xmlns:") != std::string::npos ||
        w.find("attribute xsi:") != std::string::npos)
      continue;
    doc.dom_warnings.push_back(w);
  }
  doc.root = std::move(load.root);
  if (doc.declared_version.empty()) doc.declared_version = doc.root->Attribute("version");
  doc.SetText(doc.zipped ? std::move(load.text) : std::move(text));
  doc.RestoreNames();
  // Collada-DOM types elements inside a technique by their name where COLLADA has a global
  // element of that name (param, translate, ...), and drops the attributes that type lacks:
  // inside Caliper's techniques they come back from the file's text
  std::vector<std::string> restored;
  std::vector<Element*> stack{doc.root.get()};
  while (!stack.empty()) {
    Element* e = stack.back();
    stack.pop_back();
    if (e->local_name() == "technique" && e->Attribute("profile") == "CALIPER" &&
        e->parent != nullptr && e->parent->local_name() == "extra" &&
        e->parent->Attribute("type") == "caliper") {
      for (auto& r : doc.RestoreAttributes(e)) restored.push_back(std::move(r));
      continue;
    }
    for (auto& c : e->children) stack.push_back(c.get());
  }
  if (!restored.empty()) {
    std::vector<std::string> kept;
    for (auto& w : doc.dom_warnings) {
      const bool fixed = std::any_of(restored.begin(), restored.end(), [&](const std::string& r) {
        return w.find("unable to create an attribute " + r + " ") != std::string::npos;
      });
      if (!fixed) kept.push_back(std::move(w));
    }
    doc.dom_warnings = std::move(kept);
  }
  doc.IndexIds();
  return doc;
}

void WriteDocument150(const Element& root, const std::string& path) {
  std::lock_guard<std::mutex> lock(DomMutex());
  const core::ClassicLocaleScope classic;  // the DOM writes numbers with printf and streams
  WriteWithDom150(root, path);
}

}  // namespace caliper::collada::internal
