#include "model_client.h"

#include <limits.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>

#include "caliper/core/numbers.h"
#include "caliper/core/system.h"

namespace caliper::ctl {

std::string TakeModel(std::vector<std::string>& args) {
  std::string name = "model0";
  TakeOption(args, "--model", &name);
  return name;
}

std::string Num(double v, int precision) {
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

void Line(const std::string& label, const std::string& value, int label_width) {
  std::cout << std::left << std::setw(label_width) << label << value << "\n";
}

std::string Absolute(const std::string& path) {
  if (path.empty() || path[0] == '/') return path;
  char cwd[PATH_MAX];
  if (getcwd(cwd, sizeof cwd) == nullptr) return path;
  return std::string(cwd) + "/" + path;
}

double ParseNumber(const std::string& text, const std::string& what) {
  double v = 0;
  std::string why;
  if (!core::ParseDouble(text, &v, &why)) throw UsageError(what + ": " + why);
  return v;
}

unsigned long long ParseWhole(const std::string& text, const std::string& what,
                              unsigned long long max) {
  // at most 19 digits: stoull cannot overflow
  const bool digits =
      !text.empty() && text.size() <= 19 && std::all_of(text.begin(), text.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c));
      });
  const unsigned long long v = digits ? std::stoull(text) : 0;
  if (v < 1 || v > max)
    throw UsageError(what + ": '" + text + "' is not a whole number from 1 to " +
                     std::to_string(max));
  return v;
}

CORBA::ULong ParseCount(const std::string& text, const std::string& what) {
  return static_cast<CORBA::ULong>(
      ParseWhole(text, what, std::numeric_limits<CORBA::ULong>::max()));
}

void NoArguments(const std::vector<std::string>& args) {
  RejectOptions(args);
  if (!args.empty()) throw UsageError("unexpected argument '" + args[0] + "'");
}

}  // namespace caliper::ctl
