#include "caliper/core/numbers.h"

#include <charconv>
#include <clocale>
#include <system_error>

namespace caliper::core {

namespace {

// std::from_chars reads no leading '+'; one is allowed when a digit, '.', 'i' or 'n' follows
std::string_view WithoutPlus(std::string_view text) {
  if (text.size() > 1 && text[0] == '+' && text[1] != '+' && text[1] != '-') return text.substr(1);
  return text;
}

template <class T>
bool Parse(std::string_view text, T* value, std::string* why, const char* kind) {
  const std::string_view digits = WithoutPlus(text);
  T parsed{};
  const char* end = digits.data() + digits.size();
  const auto [ptr, ec] = std::from_chars(digits.data(), end, parsed);
  if (!text.empty() && ec == std::errc() && ptr == end) {
    *value = parsed;
    return true;
  }
  if (why != nullptr) {
    const bool range = ec == std::errc::result_out_of_range && ptr == end;
    *why = "'" + std::string(text) + "' is " +
           (range ? std::string("out of range") : std::string("not ") + kind);
  }
  return false;
}

}  // namespace

bool ParseDouble(std::string_view text, double* value, std::string* why) {
  return Parse(text, value, why, "a number");
}

double ToDouble(std::string_view text) {
  double value = 0;
  std::string why;
  if (!ParseDouble(text, &value, &why)) throw std::invalid_argument(why);
  return value;
}

std::string FormatDouble(double value) {
  char text[32];  // the longest shortest form of a double takes 24
  const auto end = std::to_chars(text, text + sizeof text, value);
  return std::string(text, end.ptr);
}

bool ParseInt(std::string_view text, long long* value, std::string* why) {
  return Parse(text, value, why, "an integer");
}

namespace {

// std::locale::global also sets the C locale of the whole process: this keeps that one as it was
void SetGlobalKeepingC(const std::locale& locale) {
  const char* c = std::setlocale(LC_ALL, nullptr);
  const std::string c_name = c == nullptr ? "C" : c;
  std::locale::global(locale);
  std::setlocale(LC_ALL, c_name.c_str());
}

}  // namespace

ClassicLocaleScope::ClassicLocaleScope() {
  // made once, never freed: every scope of every thread shares it
  static const locale_t classic = newlocale(LC_ALL_MASK, "C", static_cast<locale_t>(nullptr));
  previous_ = uselocale(classic);
  if (std::locale() != std::locale::classic()) {
    previous_global_ = std::locale();
    SetGlobalKeepingC(std::locale::classic());
  }
}

ClassicLocaleScope::~ClassicLocaleScope() {
  if (previous_global_) SetGlobalKeepingC(*previous_global_);
  uselocale(previous_);
}

}  // namespace caliper::core
