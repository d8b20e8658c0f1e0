#pragma once
// The code that dom141.cc and dom150.cc share, as templates over the version's DOM classes
// (`Dom` names them: FloatArray, IntArray, P, Vcount, H, Collada). Included by those two sources
// only: it pulls in dae.h.

#include <dae.h>
#include <dae/daeDocument.h>
#include <dae/daeErrorHandler.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "document.h"
#include "dom_io.h"
#include "dom_paths.h"

namespace caliper::collada::internal {

/// Collects what the DOM reports while it is installed; restores the previous handler after.
class CollectingErrorHandler : public daeErrorHandler {
 public:
  CollectingErrorHandler() : previous_(daeErrorHandler::get()) {
    daeErrorHandler::setErrorHandler(this);
  }
  ~CollectingErrorHandler() override { daeErrorHandler::setErrorHandler(previous_); }
  void handleError(daeString message) override { errors.push_back(Clean(message)); }
  void handleWarning(daeString message) override { warnings.push_back(Clean(message)); }

  std::vector<std::string> errors;
  std::vector<std::string> warnings;

 private:
  static std::string Clean(daeString message) {
    std::string m = message == nullptr ? "" : message;
    for (char& c : m)
      if (c == '\n' || c == '\r') c = ' ';
    while (!m.empty() && m.back() == ' ') m.pop_back();
    return m;
  }
  daeErrorHandler* previous_;
};

template <typename T, typename Array>
void CopyNumbers(const Array& values, Element* out) {
  out->numbers.resize(values.getCount());
  for (size_t i = 0; i < values.getCount(); ++i) out->numbers[i] = static_cast<double>(values[i]);
  out->numeric = true;
}

/// Copies a DOM element and its subtree; numeric lists keep their parsed values.
template <typename Dom>
void ConvertElement(daeElement* in, Element* out) {
  out->name = in->getElementName() != nullptr ? in->getElementName() : "";
  const size_t count = in->getAttributeCount();
  for (size_t i = 0; i < count; ++i) {
    const std::string name = in->getAttributeName(i);
    if (name.empty() || !in->isAttributeSet(name.c_str())) continue;
    out->attributes.emplace_back(name, in->getAttribute(i));
  }
  if (auto* a = daeSafeCast<typename Dom::FloatArray>(in)) {
    CopyNumbers<double>(a->getValue(), out);
  } else if (auto* a = daeSafeCast<typename Dom::IntArray>(in)) {
    CopyNumbers<double>(a->getValue(), out);
  } else if (auto* a = daeSafeCast<typename Dom::P>(in)) {
    CopyNumbers<double>(a->getValue(), out);
  } else if (auto* a = daeSafeCast<typename Dom::Vcount>(in)) {
    CopyNumbers<double>(a->getValue(), out);
  } else if (auto* a = daeSafeCast<typename Dom::H>(in)) {
    CopyNumbers<double>(a->getValue(), out);
  } else if (in->hasCharData()) {
    in->getCharData(out->text);
  }
  daeTArray<daeSmartRef<daeElement>> children;
  in->getChildren(children);
  out->children.reserve(children.getCount());
  for (size_t i = 0; i < children.getCount(); ++i) {
    auto child = std::make_unique<Element>();
    child->parent = out;
    ConvertElement<Dom>(children[i], child.get());
    out->children.push_back(std::move(child));
  }
}

/// Empties a DAE of its documents when it goes out of scope.
class DomDocumentsClosed {
 public:
  explicit DomDocumentsClosed(DAE* dae) : dae_(dae) {}
  ~DomDocumentsClosed() { dae_->clear(); }
  DomDocumentsClosed(const DomDocumentsClosed&) = delete;
  DomDocumentsClosed& operator=(const DomDocumentsClosed&) = delete;

 private:
  DAE* dae_;
};

/// The DAE of the version `Dom` describes that reads every .dae of the process (callers hold
/// DomMutex()). Making a DAE registers the schema's element types and took 1.9 ms, ten times the
/// load of a small file (the COLLADA fuzz target ran at 300 inputs/s); it is emptied after each
/// load and never destroyed (a DAE's destructor removes the DOM's temporary directory: a .zae
/// still gets a DAE of its own, as before).
template <typename Dom>
DAE& SharedDae() {
  static DAE* const dae = new DAE(nullptr, nullptr, Dom::kVersion);
  return *dae;
}

/// Opens `path` with a DAE of the version `Dom` describes.
template <typename Dom>
DomLoad LoadWithDom(const std::string& path, bool zipped) {
  // the DOM must open the file named, and extract a .zae only inside its temporary directory
  CheckDomPath(path);
  if (zipped) CheckZaeArchive(path);
  DomLoad result;
  CollectingErrorHandler handler;
  {
    std::unique_ptr<DAE> own;
    if (zipped) own = std::make_unique<DAE>(nullptr, nullptr, Dom::kVersion);
    DAE& dae = zipped ? *own : SharedDae<Dom>();
    const DomDocumentsClosed closed(&dae);
    daeElement* root = dae.open(path);
    if (root != nullptr && daeSafeCast<typename Dom::Collada>(root) != nullptr) {
      result.root = std::make_unique<Element>();
      ConvertElement<Dom>(root, result.root.get());
      // a .zae: the DOM extracted the document; keep its text for line numbers
      for (int i = 0; i < dae.getDocCount(); ++i) {
        daeDocument* doc = dae.getDoc(i);
        if (doc == nullptr || !doc->isZAERootDocument()) continue;
        result.extracted_path = cdom::uriToNativePath(doc->getExtractedFileURI().str());
        std::ifstream in(result.extracted_path, std::ios::binary);
        std::ostringstream text;
        text << in.rdbuf();
        result.text = text.str();
      }
    }
  }
  result.errors = handler.errors;
  result.warnings = handler.warnings;
  for (const auto& e : result.errors)
    if (e.find("invalid COLLADA version") != std::string::npos) result.wrong_version = true;
  return result;
}

/// Copies a tree into the DOM under `out` (already created with the same name). Inside an
/// `opaque` element (a Caliper technique) every element is created untyped: the DOM would
/// otherwise make a <param> or <translate> there its COLLADA type and drop attributes that type
/// does not have.
inline void BuildDomElement(const Element& in, daeElement* out, bool opaque) {
  for (const auto& [name, value] : in.attributes) out->setAttribute(name.c_str(), value.c_str());
  if (in.numeric)
    out->setCharData(FormatNumbers(in.numbers.data(), in.numbers.size()));
  else if (!in.text.empty())
    out->setCharData(in.text);
  const bool inner_opaque =
      opaque || (in.local_name() == "technique" && in.Attribute("profile") == "CALIPER");
  for (const auto& child : in.children) {
    // a name COLLADA does not have gives an untyped element, which is then renamed
    daeElement* c = out->add(inner_opaque ? "caliper-untyped" : child->name.c_str());
    if (c == nullptr)
      throw std::runtime_error("the COLLADA " + std::string(out->getElementName()) +
                               " element takes no <" + child->name + ">");
    if (inner_opaque) c->setElementName(child->name.c_str());
    BuildDomElement(*child, c, inner_opaque);
  }
}

/// Writes a <COLLADA> tree with a DAE of the version `Dom` describes.
template <typename Dom>
void WriteWithDom(const Element& root, const std::string& path) {
  CheckDomPath(path);
  CollectingErrorHandler handler;
  bool ok = false;
  {
    DAE dae(nullptr, nullptr, Dom::kVersion);
    daeElement* dom_root = dae.add(path);
    if (dom_root == nullptr)
      throw std::runtime_error("the DOM cannot create a document for " + path);
    BuildDomElement(root, dom_root, false);
    ok = dae.writeTo(path, path);
  }
  if (!ok || !handler.errors.empty()) {
    std::string why = handler.errors.empty() ? "write failed" : handler.errors.front();
    throw std::runtime_error(path + ": " + why);
  }
}

}  // namespace caliper::collada::internal
