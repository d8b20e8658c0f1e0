#pragma once
// Component configuration: `key = value` files (rtc.conf style), `-o key=value` overrides, and a
// schema that types, bounds and documents every key.

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace caliper::core {

/// A configuration value that is malformed or out of range; the message names where it came from.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One key a component understands.
struct ConfigKey {
  enum class Type { kString, kInt, kDouble, kBool };
  std::string name;           ///< dotted key, e.g. `exec.rate`
  Type type = Type::kString;
  std::string default_value;  ///< must itself be valid
  std::string help;           ///< one line, with the unit in brackets where there is one
  double min = -1e300;        ///< inclusive bounds for kInt and kDouble
  double max = 1e300;
  std::vector<std::string> choices;  ///< for kString: the allowed values (empty: any)
};

/// Typed configuration validated against a schema.
class Config {
 public:
  explicit Config(std::vector<ConfigKey> schema);

  /// Adds keys to the schema (a component adds its own to the common ones).
  void AddKeys(const std::vector<ConfigKey>& keys);

  /// Reads a `key = value` file; `#` starts a comment. Throws ConfigError naming file and line.
  void LoadFile(const std::string& path);

  /// Sets one value; `origin` (e.g. `-o` or `file:line`) goes into error messages.
  /// Unknown keys are kept and reported by warnings(); bad values throw ConfigError.
  void Set(const std::string& key, const std::string& value, const std::string& origin);

  /// Parses `key=value` (the `-o` argument). Throws ConfigError when there is no `=`.
  void SetAssignment(const std::string& assignment, const std::string& origin);

  const std::string& GetString(const std::string& key) const;
  long long GetInt(const std::string& key) const;
  double GetDouble(const std::string& key) const;
  bool GetBool(const std::string& key) const;
  bool Has(const std::string& key) const;

  /// Messages about unknown keys, in the order they were met.
  const std::vector<std::string>& warnings() const { return warnings_; }

  /// All known keys with their values, for profiles and `--help`.
  std::vector<std::pair<std::string, std::string>> Items() const;

  /// A table of every key, its default and help, for `--help`.
  std::string Help() const;

 private:
  const ConfigKey* Find(const std::string& key) const;
  static void Check(const ConfigKey& key, const std::string& value, const std::string& origin);

  std::vector<ConfigKey> schema_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> warnings_;
};

/// Trims white space from both ends.
std::string Trim(const std::string& s);

}  // namespace caliper::core
