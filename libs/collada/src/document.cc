#include "document.h"

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xmlerror.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
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

const char* Chars(const xmlChar* s) { return reinterpret_cast<const char*>(s); }

// An attribute's name as written (with its prefix) and its value with the references replaced.
std::pair<std::string, std::string> AttributeOf(const xmlAttr* a) {
  std::string name = Chars(a->name);
  if (a->ns != nullptr && a->ns->prefix != nullptr) name = Chars(a->ns->prefix) + (":" + name);
  xmlChar* value = xmlNodeListGetString(a->doc, a->children, 1);
  std::pair<std::string, std::string> out(std::move(name), value == nullptr ? "" : Chars(value));
  xmlFree(value);
  return out;
}

// Gives each element its node in libxml2's tree; elements libxml2 does not have (made up by the
// DOM) get none. Children are matched by name in order, not by position: the DOM keeps typed
// children in schema order, which need not be the file's.
void AssignNodes(const Element& e, const xmlNode* node,
                 std::unordered_map<const Element*, const xmlNode*>* index) {
  (*index)[&e] = node;
  std::unordered_map<std::string_view, std::vector<const xmlNode*>> by_name;
  for (const xmlNode* c = node->children; c != nullptr; c = c->next)
    if (c->type == XML_ELEMENT_NODE) by_name[LocalName(Chars(c->name))].push_back(c);
  std::unordered_map<std::string_view, size_t> used;
  for (const auto& child : e.children) {
    const auto it = by_name.find(child->local_name());
    if (it == by_name.end()) continue;
    size_t& next = used[it->first];
    if (next >= it->second.size()) continue;
    AssignNodes(*child, it->second[next++], index);
  }
}

// the parser's context as the callbacks below get it
struct ParseState {
  startElementNsSAX2Func start = nullptr;  // libxml2's own tree builder
  XmlParse* out = nullptr;
};

ParseState* StateOf(void* context) {
  return static_cast<ParseState*>(static_cast<xmlParserCtxtPtr>(context)->_private);
}

// libxml2 reports each problem here (and prints none); the first fatal one is the reason
void KeepFirstFatalError(void* context, xmlErrorPtr error) {
  XmlParse* out = StateOf(context)->out;
  if (error == nullptr || error->level != XML_ERR_FATAL || !out->problem.empty()) return;
  out->line = error->line;
  out->problem = error->message == nullptr ? "not well-formed" : error->message;
  while (!out->problem.empty() && IsSpace(out->problem.back())) out->problem.pop_back();
}

// xmlNode keeps lines in 16 bits: from 65535 on each element's line is kept here
void StartElement(void* context, const xmlChar* name, const xmlChar* prefix, const xmlChar* uri,
                  int namespaces, const xmlChar** ns, int attributes, int defaulted,
                  const xmlChar** values) {
  ParseState* state = StateOf(context);
  state->start(context, name, prefix, uri, namespaces, ns, attributes, defaulted, values);
  const auto* ctxt = static_cast<xmlParserCtxtPtr>(context);
  if (ctxt->node != nullptr && ctxt->input != nullptr && ctxt->input->line >= 65535)
    state->out->big_lines[ctxt->node] = ctxt->input->line;
}

// Parses a document with libxml2, from `path` or, when given, from `text` (`path` then names it
// in messages). No network; libxml2's default limits (10 MB per text node, entity amplification),
// which the DOM's reader has too.
XmlParse ParseXml(const std::string& path, const std::string* text) {
  XmlParse out;
  xmlParserCtxtPtr ctxt = xmlNewParserCtxt();
  if (ctxt == nullptr) {
    out.problem = "libxml2 could not make a parser";
    return out;
  }
  ParseState state{ctxt->sax->startElementNs, &out};
  ctxt->_private = &state;
  ctxt->sax->serror = KeepFirstFatalError;
  ctxt->sax->startElementNs = StartElement;
  const int options = XML_PARSE_NONET | XML_PARSE_NOWARNING;
  xmlDocPtr doc =
      text == nullptr
          ? xmlCtxtReadFile(ctxt, path.c_str(), nullptr, options)
          : xmlCtxtReadMemory(ctxt, text->data(), static_cast<int>(text->size()), path.c_str(),
                              nullptr, options);
  const bool well_formed = doc != nullptr && ctxt->wellFormed != 0;
  xmlFreeParserCtxt(ctxt);
  if (well_formed) {
    out.doc.reset(doc);
    return out;
  }
  if (doc != nullptr) xmlFreeDoc(doc);
  if (out.problem.empty()) out.problem = "not well-formed";
  out.big_lines.clear();
  return out;
}

// Collada-DOM dereferences a null pointer (daeMetaElement::place) when an element of a simple
// type holds an element of its own name (<p><p/></p>, <translate><translate/></translate>,
// <unit><unit/></unit>; found by fuzzing). The first element directly inside one of the same name,
// unless COLLADA nests it so (nodes, animations, FX arrays, MathML's apply); nullptr when none.
const xmlNode* SelfNested(const xmlNode* top) {
  static const std::string_view kNesting[] = {"node", "animation", "array", "apply"};
  std::vector<const xmlNode*> stack{top};
  while (!stack.empty()) {
    const xmlNode* n = stack.back();
    stack.pop_back();
    const std::string_view name = Chars(n->name);
    const bool may_nest =
        std::find(std::begin(kNesting), std::end(kNesting), name) != std::end(kNesting);
    for (const xmlNode* c = n->children; c != nullptr; c = c->next) {
      if (c->type != XML_ELEMENT_NODE) continue;
      const bool same_ns = c->ns == nullptr ? n->ns == nullptr
                                            : n->ns != nullptr && xmlStrEqual(c->ns->href, n->ns->href);
      if (!may_nest && same_ns && std::string_view(Chars(c->name)) == name) return c;
      stack.push_back(c);
    }
  }
  return nullptr;
}

}  // namespace

XmlParse PreScanXml(const std::string& name, const std::string* text) {
  XmlParse xml = ParseXml(name, text);
  if (!xml.doc) throw ReadError("malformed XML: " + xml.problem, xml.line);
  if (const xmlNode* nested = SelfNested(xmlDocGetRootElement(xml.doc.get())); nested != nullptr) {
    const auto big = xml.big_lines.find(nested);
    const std::string element = Chars(nested->name);
    throw ReadError("<" + element + "> inside <" + element +
                        ">: COLLADA does not nest this element in itself",
                    big != xml.big_lines.end() ? big->second : nested->line);
  }
  return xml;
}

namespace {

// libxml2's node and its subtree as elements.
std::unique_ptr<Element> ElementOf(const xmlNode* node) {
  auto e = std::make_unique<Element>(node->ns != nullptr && node->ns->prefix != nullptr
                                         ? Chars(node->ns->prefix) + (":" + std::string(Chars(node->name)))
                                         : std::string(Chars(node->name)));
  for (const xmlAttr* a = node->properties; a != nullptr; a = a->next)
    e->attributes.push_back(AttributeOf(a));
  for (const xmlNode* c = node->children; c != nullptr; c = c->next) {
    if (c->type == XML_ELEMENT_NODE) {
      e->children.push_back(ElementOf(c));
      e->children.back()->parent = e.get();
    } else if ((c->type == XML_TEXT_NODE || c->type == XML_CDATA_SECTION_NODE) &&
               c->content != nullptr) {
      e->text += Chars(c->content);
    }
  }
  return e;
}

}  // namespace

Document ReadPlainXml(const std::string& path) {
  XmlParse xml = ParseXml(path, nullptr);
  if (!xml.doc) throw ReadError("malformed XML: " + xml.problem, xml.line);
  const xmlNode* top = xmlDocGetRootElement(xml.doc.get());
  if (top == nullptr) throw ReadError("no root element", 0);
  Document doc;
  doc.path = path;
  doc.root = ElementOf(top);
  doc.SetXml(std::move(xml.doc), std::move(xml.big_lines));
  return doc;
}

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

void XmlDocFree::operator()(_xmlDoc* doc) const { xmlFreeDoc(doc); }

void Document::SetXml(XmlDocument xml, std::unordered_map<const _xmlNode*, int> big_lines) {
  xml_ = std::move(xml);
  big_lines_ = std::move(big_lines);
  nodes_indexed_ = false;
  nodes_.clear();
}

void Document::IndexNodes() const {
  if (nodes_indexed_) return;
  nodes_indexed_ = true;
  const xmlNode* top = xml_ ? xmlDocGetRootElement(xml_.get()) : nullptr;
  if (root && top != nullptr && LocalName(Chars(top->name)) == root->local_name())
    AssignNodes(*root, top, &nodes_);
}

int Document::LineOf(const Element& element) const {
  IndexNodes();
  const auto it = nodes_.find(&element);
  if (it == nodes_.end()) return 0;
  const auto big = big_lines_.find(it->second);
  return big != big_lines_.end() ? big->second : it->second->line;
}

void Document::ForEachInFile(Element* subtree,
                             const std::function<void(Element*, const _xmlNode*)>& visit) {
  IndexNodes();
  std::vector<Element*> stack{subtree};
  while (!stack.empty()) {
    Element* e = stack.back();
    stack.pop_back();
    for (auto& c : e->children) stack.push_back(c.get());
    const auto it = nodes_.find(e);
    if (it != nodes_.end()) visit(e, it->second);  // one the DOM made up is not in the file
  }
}

std::vector<std::string> Document::RestoreAttributes(Element* subtree) {
  std::vector<std::string> restored;
  ForEachInFile(subtree, [&](Element* e, const xmlNode* node) {
    for (const xmlAttr* a = node->properties; a != nullptr; a = a->next) {
      auto [name, value] = AttributeOf(a);
      if (e->HasAttribute(name)) continue;
      restored.push_back(name + " = " + value);
      e->attributes.emplace_back(std::move(name), std::move(value));
    }
  });
  return restored;
}

void Document::RestoreNames() {
  if (!root) return;
  ForEachInFile(root.get(), [&](Element* e, const xmlNode* node) {
    if (!e->HasAttribute("name")) return;
    for (const xmlAttr* a = node->properties; a != nullptr; a = a->next)
      if (a->ns == nullptr && std::string_view(Chars(a->name)) == "name")
        e->Set("name", AttributeOf(a).second);
  });
}

void Document::CheckNumbers() {
  if (!root) return;
  ForEachInFile(root.get(), [&](Element* e, const xmlNode* node) {
    if (!e->numeric) return;
    xmlChar* content = xmlNodeGetContent(node);
    const std::string text = content == nullptr ? "" : Chars(content);
    xmlFree(content);
    const bool decimals = e->local_name() == "float_array";
    std::vector<double> values;
    values.reserve(e->numbers.size());
    const std::string_view all(text);
    for (size_t i = 0; i < all.size();) {
      while (i < all.size() && IsSpace(all[i])) ++i;
      size_t j = i;
      while (j < all.size() && !IsSpace(all[j])) ++j;
      if (j == i) break;
      const std::string_view word = all.substr(i, j - i);
      std::string why;
      double value = 0;
      long long integer = 0;
      const bool ok = decimals ? core::ParseDouble(word, &value, &why)
                               : core::ParseInt(word, &integer, &why);
      if (!ok && word.size() > 64)  // a word of megabytes is not repeated whole
        why = "'" + std::string(word.substr(0, 64)) + "...' (" + std::to_string(word.size()) +
              " characters) is not " + (decimals ? "a number" : "an integer");
      if (!ok)
        throw ReadError(e->Describe() + ": " + why + " (value " +
                            std::to_string(values.size() + 1) + " of the list)",
                        LineOf(*e));
      values.push_back(decimals ? value : static_cast<double>(integer));
      i = j;
    }
    e->numbers = std::move(values);
  });
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
  std::lock_guard<std::mutex> lock(DomMutex());
  // malformed XML never reaches the DOM (its reader can loop forever on some: a start tag left
  // open inside character data, found by fuzzing): libxml2 reads the file first and says what
  // is wrong where; its tree also gives the elements' lines, which the DOM does not keep (the
  // documents inside a .zae get the same check from CheckZaeArchive, before the DOM unzips them)
  XmlParse xml;
  if (!doc.zipped) {
    xml = PreScanXml(path, nullptr);
    const xmlNode* top = xmlDocGetRootElement(xml.doc.get());
    for (const xmlAttr* a = top->properties; a != nullptr; a = a->next)
      if (a->ns == nullptr && std::string_view(Chars(a->name)) == "version")
        doc.declared_version = AttributeOf(a).second;
  }
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
  const core::ClassicLocaleScope classic;  // the DOM reads numbers with sscanf and streams
  DomLoad load;
  for (int attempt : attempts) {
    load = attempt == 150 ? LoadWithDom150(path, doc.zipped) : LoadWithDom141(path, doc.zipped);
    if (load.root || !load.wrong_version) {
      doc.version = attempt == 150 ? "1.5.0" : "1.4.1";
      break;
    }
  }
  // a .zae: the .dae the DOM extracted from it
  if (doc.zipped && !load.text.empty()) xml = ParseXml(load.extracted_path, &load.text);
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
    if (!xml.problem.empty()) message = "malformed XML (" + xml.problem + "): " + message;
    throw ReadError(message, xml.line);
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
  doc.SetXml(std::move(xml.doc), std::move(xml.big_lines));
  doc.RestoreNames();
  doc.CheckNumbers();
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
