// Fuzz target: component configuration files (`key = value`, `#` comments) read by
// core::Config::LoadFile against a schema with a key of every type, bounds and choices.
// Properties: LoadFile either succeeds or throws ConfigError naming the file and line; every
// value it accepted reads back through its typed getter and lies within the key's bounds.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "caliper/core/config.h"
#include "fuzz_input.h"

namespace {

using caliper::core::ConfigKey;

std::vector<ConfigKey> Schema() {
  return {
      {"exec.rate", ConfigKey::Type::kDouble, "100", "the rate [Hz]", 0.001, 1e6, {}},
      {"exec.kind", ConfigKey::Type::kString, "periodic", "how steps are driven", -1e300, 1e300,
       {"periodic", "external"}},
      {"exec.auto_activate", ConfigKey::Type::kBool, "false", "activate at start", -1e300, 1e300,
       {}},
      {"model.scene", ConfigKey::Type::kString, "", "the scene file", -1e300, 1e300, {}},
      {"daq.max_subscriptions", ConfigKey::Type::kInt, "32", "per client", 1, 1000, {}},
      {"log.seq", ConfigKey::Type::kInt, "0", "any integer", -1e300, 1e300, {}},
      {"model.real_time_factor", ConfigKey::Type::kDouble, "1", "x", -1e300, 1e300, {}},
  };
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using caliper::fuzz::Check;
  const caliper::fuzz::InputFile input(data, size, "input.conf");
  const std::string& path = input.path();
  caliper::core::Config config(Schema());
  try {
    config.LoadFile(path);
  } catch (const caliper::core::ConfigError& e) {
    const std::string message = e.what();
    Check(message.rfind(path + ":", 0) == 0,
          "a ConfigError that does not start with the file: " + message.substr(0, 300));
    return 0;
  }
  for (const auto& w : config.warnings())
    Check(w.rfind(path + ":", 0) == 0, "a warning that does not name the file: " + w);
  for (const ConfigKey& key : Schema()) {
    try {
      switch (key.type) {
        case ConfigKey::Type::kInt: {
          const long long v = config.GetInt(key.name);
          Check(v >= key.min && v <= key.max, key.name + " out of its bounds");
          break;
        }
        case ConfigKey::Type::kDouble: {
          const double v = config.GetDouble(key.name);
          Check(std::isfinite(v) && v >= key.min && v <= key.max, key.name + " out of bounds");
          break;
        }
        case ConfigKey::Type::kBool: config.GetBool(key.name); break;
        case ConfigKey::Type::kString: config.GetString(key.name); break;
      }
    } catch (const std::exception& e) {
      Check(false, "an accepted value of " + key.name + " does not read back: " + e.what());
    }
  }
  config.Items();
  config.Help();
  return 0;
}
