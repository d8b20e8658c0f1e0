#include "caliper/core/arguments.h"

#include <cctype>

#include "caliper/core/numbers.h"

namespace caliper::core {

namespace {

bool LooksLikeOption(const std::string& word) {
  double number = 0;
  return word.size() > 1 && word[0] == '-' && !ParseDouble(word, &number);
}

}  // namespace

std::string Arguments::Error() const {
  if (!missing_value.empty()) return "option " + missing_value + " needs a value";
  if (!unknown.empty()) return "unknown option '" + unknown + "'";
  return "";
}

std::string Arguments::Value(const std::string& option, const std::string& fallback) const {
  for (auto it = options.rbegin(); it != options.rend(); ++it)
    if (it->first == option) return it->second;
  return fallback;
}

std::vector<std::string> Arguments::Values(const std::string& option) const {
  std::vector<std::string> values;
  for (const auto& [name, value] : options)
    if (name == option) values.push_back(value);
  return values;
}

bool Arguments::Has(const std::string& option) const {
  for (const auto& o : options)
    if (o.first == option) return true;
  return false;
}

Arguments ParseArguments(const std::vector<std::string>& words, const ArgumentSpec& spec) {
  Arguments out;
  for (size_t i = 0; i < words.size(); ++i) {
    const std::string& word = words[i];
    if (spec.help.count(word) != 0) {
      out.help = true;
    } else if (spec.valued.count(word) != 0) {
      if (i + 1 >= words.size()) {
        out.missing_value = word;
        break;
      }
      out.options.emplace_back(word, words[++i]);
    } else if (spec.flags.count(word) != 0) {
      out.options.emplace_back(word, "");
    } else if (const int pass = spec.pass ? spec.pass(word) : 0; pass > 0) {
      if (i + pass > words.size()) {
        out.missing_value = word;
        break;
      }
      for (int k = 0; k < pass; ++k) out.passed.push_back(i + k);
      i += pass - 1;
    } else if (LooksLikeOption(word)) {
      out.unknown = word;
      break;
    } else if (spec.stop_at_positional) {
      out.positional.assign(words.begin() + static_cast<long>(i), words.end());
      break;
    } else {
      out.positional.push_back(word);
    }
  }
  return out;
}

bool TakeOption(std::vector<std::string>& args, const std::string& flag, std::string* value) {
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] != flag) continue;
    if (i + 1 >= args.size()) throw UsageError(flag + " needs a value");
    *value = args[i + 1];
    args.erase(args.begin() + static_cast<long>(i), args.begin() + static_cast<long>(i) + 2);
    return true;
  }
  return false;
}

bool TakeFlag(std::vector<std::string>& args, const std::string& flag) {
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == flag) {
      args.erase(args.begin() + static_cast<long>(i));
      return true;
    }
  }
  return false;
}

void RejectOptions(const std::vector<std::string>& args) {
  for (const auto& a : args)
    if (a.size() > 2 && a[0] == '-' && a[1] == '-' &&
        std::isalpha(static_cast<unsigned char>(a[2])))
      throw UsageError("unknown option '" + a + "'");
}

}  // namespace caliper::core
