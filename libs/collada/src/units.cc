#include "units.h"

#include <climits>
#include <cmath>
#include <cstring>
#include <vector>

#include "caliper/core/numbers.h"

namespace caliper::collada::internal {

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Symbol {
  const char* name;
  double scale;
  std::array<int, 5> dimension;  // m, kg, s, A, rad
  bool prefixable;
};

// kg is the SI base; grams take the prefixes
const Symbol kSymbols[] = {
    {"m", 1, {1, 0, 0, 0, 0}, true},
    {"g", 1e-3, {0, 1, 0, 0, 0}, true},
    {"s", 1, {0, 0, 1, 0, 0}, true},
    {"A", 1, {0, 0, 0, 1, 0}, true},
    {"rad", 1, {0, 0, 0, 0, 1}, true},
    {"deg", kPi / 180, {0, 0, 0, 0, 1}, false},
    {"\xc2\xb0", kPi / 180, {0, 0, 0, 0, 1}, false},  // °
    {"rev", 2 * kPi, {0, 0, 0, 0, 1}, false},
    {"rpm", 2 * kPi / 60, {0, 0, -1, 0, 1}, false},
    {"N", 1, {1, 1, -2, 0, 0}, true},
    {"Pa", 1, {-1, 1, -2, 0, 0}, true},
    {"J", 1, {2, 1, -2, 0, 0}, true},
    {"W", 1, {2, 1, -3, 0, 0}, true},
    {"V", 1, {2, 1, -3, -1, 0}, true},
    {"ohm", 1, {2, 1, -3, -2, 0}, true},
    {"Ohm", 1, {2, 1, -3, -2, 0}, true},
    {"\xce\xa9", 1, {2, 1, -3, -2, 0}, true},  // Ω
    {"H", 1, {2, 1, -2, -2, 0}, true},
    {"C", 1, {0, 0, 1, 1, 0}, true},
    {"Hz", 1, {0, 0, -1, 0, 0}, true},
    {"min", 60, {0, 0, 1, 0, 0}, false},
    {"h", 3600, {0, 0, 1, 0, 0}, false},
    {"%", 0.01, {0, 0, 0, 0, 0}, false},
    {"1", 1, {0, 0, 0, 0, 0}, false},
    {"-", 1, {0, 0, 0, 0, 0}, false},
};

struct Prefix {
  const char* name;
  double scale;
};
const Prefix kPrefixes[] = {{"G", 1e9},         {"M", 1e6},  {"k", 1e3},  {"d", 1e-1},
                            {"c", 1e-2},        {"m", 1e-3}, {"u", 1e-6}, {"\xc2\xb5", 1e-6},
                            {"\xce\xbc", 1e-6}, {"n", 1e-9}, {"p", 1e-12}};

bool LookUp(const std::string& token, Unit* out) {
  for (const auto& s : kSymbols)
    if (token == s.name) {
      out->scale = s.scale;
      out->dimension = s.dimension;
      return true;
    }
  for (const auto& p : kPrefixes) {
    const size_t n = std::strlen(p.name);
    if (token.size() <= n || token.compare(0, n, p.name) != 0) continue;
    const std::string rest = token.substr(n);
    for (const auto& s : kSymbols)
      if (s.prefixable && rest == s.name) {
        out->scale = p.scale * s.scale;
        out->dimension = s.dimension;
        return true;
      }
  }
  return false;
}

Unit Power(const Unit& u, int exponent) {
  Unit r;
  r.scale = std::pow(u.scale, exponent);
  for (size_t i = 0; i < r.dimension.size(); ++i) r.dimension[i] = u.dimension[i] * exponent;
  return r;
}

Unit Product(const Unit& a, const Unit& b, int sign) {
  Unit r;
  r.scale = sign > 0 ? a.scale * b.scale : a.scale / b.scale;
  for (size_t i = 0; i < r.dimension.size(); ++i)
    r.dimension[i] = a.dimension[i] + sign * b.dimension[i];
  return r;
}

class Parser {
 public:
  explicit Parser(std::string_view text) : text_(text) {}

  bool Parse(Unit* out, std::string* bad) {
    SkipSpace();
    if (pos_ >= text_.size()) {
      *out = Unit{};
      return true;
    }
    if (!Expression(out, bad)) return false;
    SkipSpace();
    if (pos_ < text_.size()) {
      *bad = std::string(text_.substr(pos_));
      return false;
    }
    return true;
  }

 private:
  void SkipSpace() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t')) ++pos_;
  }
  bool AtFactorStart() const {
    if (pos_ >= text_.size()) return false;
    const char c = text_[pos_];
    return c != ')' && c != '/' && c != '*' && c != '^';
  }
  // expression := factor { ('*' | '.' | ' ' | '/') factor }
  bool Expression(Unit* out, std::string* bad) {
    if (!Factor(out, bad)) return false;
    while (true) {
      SkipSpace();
      if (pos_ >= text_.size() || text_[pos_] == ')') return true;
      int sign = 1;
      if (text_[pos_] == '/') {
        sign = -1;
        ++pos_;
      } else if (text_[pos_] == '*' || text_[pos_] == '.') {
        ++pos_;
      } else if (text_.compare(pos_, 2, "\xc2\xb7") == 0) {  // ·
        pos_ += 2;
      }
      SkipSpace();
      if (!AtFactorStart()) {
        *bad = std::string(text_.substr(pos_));
        return false;
      }
      Unit next;
      if (!Factor(&next, bad)) return false;
      *out = Product(*out, next, sign);
    }
  }
  // factor := ( '(' expression ')' | symbol ) [ '^' integer ]
  bool Factor(Unit* out, std::string* bad) {
    SkipSpace();
    if (pos_ < text_.size() && text_[pos_] == '(') {
      ++pos_;
      if (!Expression(out, bad)) return false;
      SkipSpace();
      if (pos_ >= text_.size() || text_[pos_] != ')') {
        *bad = "(" + std::string(text_.substr(pos_));
        return false;
      }
      ++pos_;
    } else {
      const size_t begin = pos_;
      while (pos_ < text_.size()) {
        const char c = text_[pos_];
        if (c == ' ' || c == '\t' || c == '/' || c == '*' || c == '^' || c == '(' || c == ')')
          break;
        if (c == '.' && pos_ > begin) break;
        if (text_.compare(pos_, 2, "\xc2\xb7") == 0) break;
        ++pos_;
      }
      const std::string token(text_.substr(begin, pos_ - begin));
      if (token.empty() || !LookUp(token, out)) {
        *bad = token.empty() ? std::string(text_.substr(begin)) : token;
        return false;
      }
    }
    if (pos_ < text_.size() && text_[pos_] == '^') {
      ++pos_;
      const size_t begin = pos_;
      if (pos_ < text_.size() && (text_[pos_] == '-' || text_[pos_] == '+')) ++pos_;
      while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') ++pos_;
      const std::string digits(text_.substr(begin, pos_ - begin));
      if (digits.empty() || digits == "-" || digits == "+") {
        *bad = "^" + digits;
        return false;
      }
      long long exponent = 0;
      if (!core::ParseInt(digits, &exponent) || exponent < INT_MIN || exponent > INT_MAX) {
        *bad = "^" + digits;
        return false;
      }
      *out = Power(*out, static_cast<int>(exponent));
    }
    return true;
  }

  std::string_view text_;
  size_t pos_ = 0;
};

}  // namespace

bool ParseUnit(std::string_view text, Unit* out, std::string* bad) {
  return Parser(text).Parse(out, bad);
}

}  // namespace caliper::collada::internal
