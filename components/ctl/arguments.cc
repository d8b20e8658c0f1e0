#include "arguments.h"

#include <cctype>

namespace caliper::ctl {

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

}  // namespace caliper::ctl
