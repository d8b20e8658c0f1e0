#include "import_context.h"

#include "caliper/collada/importer.h"

namespace caliper::collada::internal {

std::string Context::Where(const Element* e) const {
  std::string where = doc.path;
  if (e == nullptr) return where;
  const int line = doc.LineOf(*e);
  if (line > 0) where += ":" + std::to_string(line);
  return where + ": " + e->Describe();
}

void Context::Warn(const Element* e, const std::string& message) const {
  if (warnings_ != nullptr) warnings_->push_back(Where(e) + ": " + message);
}

void Context::WarnRepeated(const std::string& kind, const Element* e, const std::string& message) {
  if (repeated_[kind]++ == 0) Warn(e, message);
}

void Context::ReportRepeated() {
  for (const auto& [kind, times] : repeated_)
    if (times > 1) Warn(nullptr, std::to_string(times - 1) + " more: " + kind);
}

void Context::Fail(const Element* e, const std::string& message) const {
  throw ImportError(Where(e) + ": " + message);
}

const Element* Context::TryResolve(const std::string& url) const {
  if (url.empty()) return nullptr;
  if (url[0] == '#') return doc.FindId(std::string_view(url).substr(1));
  if (url.find('#') != std::string::npos || url.find('/') != std::string::npos) return nullptr;
  return doc.FindId(url);
}

const Element& Context::Resolve(const Element& from, const std::string& url) const {
  if (url.empty()) Fail(&from, "empty reference");
  const size_t hash = url.find('#');
  if (hash != std::string::npos && hash > 0)
    Fail(&from, "reference '" + url +
                    "' points into another document; external references are not supported");
  const Element* e = TryResolve(url);
  if (e == nullptr) Fail(&from, "dangling reference '" + url + "': no element has that id");
  return *e;
}

std::vector<double> Context::Numbers(const Element& e, size_t count) const {
  std::vector<double> values;
  if (e.numeric) {
    values = e.numbers;
  } else {
    std::string bad;
    if (!ParseNumbers(e.text, &values, &bad)) Fail(&e, "'" + bad + "' is not a number");
  }
  if (count > 0 && values.size() != count)
    Fail(&e, "needs " + std::to_string(count) + " numbers, has " + std::to_string(values.size()));
  return values;
}

double Context::Number(const Element* e, double fallback) const {
  if (e == nullptr) return fallback;
  return Numbers(*e, 1)[0];
}

Eigen::Vector3d Context::Vector3(const Element& e) const {
  const auto v = Numbers(e, 3);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

bool Context::Bool(const Element* e, bool fallback) const {
  if (e == nullptr) return fallback;
  const std::string t = e->Trimmed();
  if (t == "true" || t == "1") return true;
  if (t == "false" || t == "0") return false;
  Fail(e, "'" + t + "' is not a boolean (true or false)");
}

size_t Context::Count(const Element& e, const char* attribute, size_t fallback) const {
  const std::string* v = e.FindAttribute(attribute);
  if (v == nullptr) return fallback;
  size_t n = 0;
  bool digits = !v->empty();
  for (char c : *v) {
    if (c < '0' || c > '9') {
      digits = false;
      break;
    }
    n = n * 10 + static_cast<size_t>(c - '0');
  }
  if (!digits) Fail(&e, std::string("attribute ") + attribute + "=\"" + *v + "\" is not a count");
  return n;
}

std::string Context::UniqueBodyName(const std::string& preferred) const {
  const std::string base = preferred.empty() ? "body" : preferred;
  if (body_source.count(base) == 0) return base;
  for (int i = 2;; ++i) {
    const std::string name = base + "_" + std::to_string(i);
    if (body_source.count(name) == 0) return name;
  }
}

size_t Context::AddBody(sgal::Body body, const Element* source,
                        const std::vector<std::string>& aliases) {
  body_source[body.name] = source;
  for (const auto& a : aliases)
    if (!a.empty()) body_alias.emplace(a, body.name);
  scene.bodies.push_back(std::move(body));
  return scene.bodies.size() - 1;
}

std::string Context::FindBody(const std::string& name) const {
  if (body_source.count(name) > 0) return name;
  const auto it = body_alias.find(name);
  if (it != body_alias.end()) return it->second;
  if (!name.empty() && name[0] == '#') return FindBody(name.substr(1));
  return "";
}

}  // namespace caliper::collada::internal
