#include <map>
#include <mutex>

#include "caliper/actuators/actuator.h"
#include "builtin_kinds.h"

namespace caliper::actuators {

namespace {

struct Entry {
  std::vector<ParameterSpec> parameters;
  Factory factory;
};

std::mutex& RegistryMutex() {
  static std::mutex m;
  return m;
}

std::map<std::string, Entry>& Registry() {
  static std::map<std::string, Entry> registry;
  return registry;
}

void EnsureBuiltins() {
  static std::once_flag once;
  std::call_once(once, [] { RegisterBuiltinKinds(); });
}

}  // namespace

void RegisterKind(const std::string& kind, std::vector<ParameterSpec> parameters,
                  Factory factory) {
  std::lock_guard<std::mutex> lock(RegistryMutex());
  Registry()[kind] = Entry{std::move(parameters), std::move(factory)};
}

std::unique_ptr<TendonActuator> Make(const sgal::Actuator& a) {
  EnsureBuiltins();
  Factory factory;
  std::vector<ParameterSpec> specs;
  {
    std::lock_guard<std::mutex> lock(RegistryMutex());
    const auto it = Registry().find(a.kind);
    if (it == Registry().end()) {
      std::string known;
      for (const auto& [k, e] : Registry()) known += (known.empty() ? "" : ", ") + k;
      throw std::invalid_argument("actuator '" + a.name + "': unknown kind '" + a.kind +
                                  "' (known: " + known + ")");
    }
    factory = it->second.factory;
    specs = it->second.parameters;
  }
  for (const auto& spec : specs)
    if (spec.required && a.parameters.count(spec.name) == 0)
      throw std::invalid_argument("actuator '" + a.name + "' (" + a.kind +
                                  "): missing parameter '" + spec.name + "' [" + spec.unit +
                                  "]: " + spec.help);
  for (const auto& [name, value] : a.parameters) {
    bool known = false;
    for (const auto& spec : specs) known |= spec.name == name;
    if (!known)
      throw std::invalid_argument("actuator '" + a.name + "' (" + a.kind +
                                  "): unknown parameter '" + name + "'");
  }
  return factory(a);
}

std::vector<std::string> Kinds() {
  EnsureBuiltins();
  std::lock_guard<std::mutex> lock(RegistryMutex());
  std::vector<std::string> kinds;
  for (const auto& [k, e] : Registry()) kinds.push_back(k);
  return kinds;
}

const std::vector<ParameterSpec>& KindParameters(const std::string& kind) {
  EnsureBuiltins();
  std::lock_guard<std::mutex> lock(RegistryMutex());
  const auto it = Registry().find(kind);
  if (it == Registry().end()) throw std::out_of_range("unknown actuator kind '" + kind + "'");
  return it->second.parameters;
}

double ParameterOr(const sgal::Actuator& a, const std::string& name, double fallback) {
  const auto it = a.parameters.find(name);
  return it == a.parameters.end() ? fallback : it->second;
}

}  // namespace caliper::actuators
