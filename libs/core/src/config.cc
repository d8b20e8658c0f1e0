#include "caliper/core/config.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <locale>
#include <sstream>

#include "caliper/core/numbers.h"

namespace caliper::core {

std::string Trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t\r\n");
  return s.substr(begin, end - begin + 1);
}

namespace {

bool ParseBool(const std::string& v, bool* out) {
  std::string lower = v;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  if (lower == "true" || lower == "yes" || lower == "on" || lower == "1") {
    *out = true;
    return true;
  }
  if (lower == "false" || lower == "no" || lower == "off" || lower == "0") {
    *out = false;
    return true;
  }
  return false;
}

bool ParseFinite(const std::string& v, double* out) {
  return ParseDouble(v, out) && std::isfinite(*out);
}

const char* TypeName(ConfigKey::Type t) {
  switch (t) {
    case ConfigKey::Type::kString: return "string";
    case ConfigKey::Type::kInt: return "integer";
    case ConfigKey::Type::kDouble: return "number";
    case ConfigKey::Type::kBool: return "true|false";
  }
  return "?";
}

// " in [MIN, MAX]" for a bounded number, " one of a|b|c" for a string with choices, else "".
std::string Domain(const ConfigKey& k) {
  const bool numeric = k.type == ConfigKey::Type::kInt || k.type == ConfigKey::Type::kDouble;
  const bool low = k.min > -1e300, high = k.max < 1e300;
  if (numeric && (low || high)) {
    std::ostringstream range;
    range << std::setprecision(15) << " in [" << (low ? k.min : -HUGE_VAL) << ", "
          << (high ? k.max : HUGE_VAL) << "]";
    return range.str();
  }
  if (k.type == ConfigKey::Type::kString && !k.choices.empty()) {
    std::string list;
    for (const auto& c : k.choices) list += (list.empty() ? "" : "|") + c;
    return " one of " + list;
  }
  return "";
}

}  // namespace

Config::Config(std::vector<ConfigKey> schema) : schema_(std::move(schema)) {
  for (const auto& k : schema_) values_[k.name] = k.default_value;
}

void Config::AddKeys(const std::vector<ConfigKey>& keys) {
  for (const auto& k : keys) {
    // a component may redeclare a common key (another default, other bounds): the last one wins
    auto it = std::find_if(schema_.begin(), schema_.end(),
                           [&](const ConfigKey& existing) { return existing.name == k.name; });
    if (it != schema_.end())
      *it = k;
    else
      schema_.push_back(k);
    values_[k.name] = k.default_value;
  }
}

const ConfigKey* Config::Find(const std::string& key) const {
  for (const auto& k : schema_)
    if (k.name == key) return &k;
  return nullptr;
}

void Config::Check(const ConfigKey& key, const std::string& value, const std::string& origin) {
  std::string why;
  switch (key.type) {
    case ConfigKey::Type::kString:
      if (!key.choices.empty() &&
          std::find(key.choices.begin(), key.choices.end(), value) == key.choices.end()) {
        why = "expected one of";
        for (const auto& c : key.choices) why += " " + c;
      }
      break;
    case ConfigKey::Type::kBool: {
      bool b;
      if (!ParseBool(value, &b)) why = "expected true or false";
      break;
    }
    case ConfigKey::Type::kInt: {
      long long i;
      if (!ParseInt(value, &i))
        why = "expected an integer";
      else if (i < key.min || i > key.max)
        why = "out of range";
      break;
    }
    case ConfigKey::Type::kDouble: {
      double d;
      if (!ParseFinite(value, &d))
        why = "expected a finite number";
      else if (d < key.min || d > key.max)
        why = "out of range";
      break;
    }
  }
  if (why.empty()) return;
  std::ostringstream msg;
  msg.imbue(std::locale::classic());  // bounds print as they are written, in any locale
  msg << origin << ": " << key.name << " = '" << value << "': " << why;
  if (key.type == ConfigKey::Type::kInt || key.type == ConfigKey::Type::kDouble) {
    msg << " (allowed " << key.min << " .. " << key.max << ")";
  }
  if (!key.help.empty()) msg << "; " << key.name << " is " << key.help;
  throw ConfigError(msg.str());
}

void Config::Set(const std::string& key, const std::string& value, const std::string& origin) {
  const ConfigKey* k = Find(key);
  if (k == nullptr) {
    warnings_.push_back(origin + ": unknown key '" + key + "' (ignored)");
    return;
  }
  Check(*k, value, origin);
  values_[key] = value;
}

void Config::SetAssignment(const std::string& assignment, const std::string& origin) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos)
    throw ConfigError(origin + ": '" + assignment + "' is not of the form key=value");
  Set(Trim(assignment.substr(0, eq)), Trim(assignment.substr(eq + 1)), origin);
}

void Config::LoadFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open configuration file");
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    line = Trim(line);
    if (line.empty()) continue;
    SetAssignment(line, path + ":" + std::to_string(number));
  }
}

const std::string& Config::GetString(const std::string& key) const {
  auto it = values_.find(key);
  if (it == values_.end()) throw ConfigError("no configuration key '" + key + "' is declared");
  return it->second;
}

long long Config::GetInt(const std::string& key) const {
  long long v = 0;
  if (!ParseInt(GetString(key), &v)) throw ConfigError(key + " is not an integer");
  return v;
}

double Config::GetDouble(const std::string& key) const {
  double v = 0;
  if (!ParseFinite(GetString(key), &v)) throw ConfigError(key + " is not a number");
  return v;
}

bool Config::GetBool(const std::string& key) const {
  bool v = false;
  if (!ParseBool(GetString(key), &v)) throw ConfigError(key + " is not true or false");
  return v;
}

bool Config::Has(const std::string& key) const { return Find(key) != nullptr; }

std::vector<std::pair<std::string, std::string>> Config::Items() const {
  std::vector<std::pair<std::string, std::string>> items;
  for (const auto& k : schema_) items.emplace_back(k.name, values_.at(k.name));
  return items;
}

std::string Config::Help() const {
  std::ostringstream out;
  size_t width = 0;
  for (const auto& k : schema_) width = std::max(width, k.name.size());
  for (const auto& k : schema_) {
    out << "  " << k.name << std::string(width - k.name.size() + 2, ' ') << k.help << " ("
        << TypeName(k.type) << Domain(k) << ", default '" << k.default_value << "')\n";
  }
  return out.str();
}

}  // namespace caliper::core
