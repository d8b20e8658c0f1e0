#include "units.h"

#include <cmath>
#include <cstring>
#include <vector>

#include "caliper/core/numbers.h"

namespace caliper::collada::internal {

namespace {

constexpr double kPi = 3.14159265358979323846;
// bounds that no real unit comes near and that keep the arithmetic exact: a written power, each
// exponent of a result, and the nesting of parentheses (the parser recurses per level)
constexpr int kMaxPower = 12;
constexpr int kMaxExponent = 24;
constexpr int kMaxDepth = 16;

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

// Why a result is out of bounds ("" when it is not): an exponent beyond kMaxExponent, or a scale
// that is not a normal positive double (1e-6^9999 underflowed to 0 before: found by fuzzing).
std::string OutOfRange(const Unit& u) {
  for (int d : u.dimension)
    if (d < -kMaxExponent || d > kMaxExponent)
      return "an exponent beyond " + std::to_string(kMaxExponent) + " in magnitude";
  if (!std::isnormal(u.scale) || u.scale < 0) return "a scale to SI that a double cannot hold";
  return "";
}

// operands within kMaxExponent and powers within kMaxPower: no int overflows
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
  Parser(std::string_view text, std::string* why) : text_(text), why_(why) {}

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
      const size_t begin = pos_;
      Unit next;
      if (!Factor(&next, bad)) return false;
      *out = Product(*out, next, sign);
      if (const std::string why = OutOfRange(*out); !why.empty())
        return Refuse(begin, why, bad);
    }
  }
  // factor := ( '(' expression ')' | symbol ) [ '^' integer ]
  bool Factor(Unit* out, std::string* bad) {
    SkipSpace();
    const size_t start = pos_;
    if (pos_ < text_.size() && text_[pos_] == '(') {
      if (depth_ == kMaxDepth)
        return Refuse(pos_, "more than " + std::to_string(kMaxDepth) + " nested parentheses", bad);
      ++pos_;
      ++depth_;
      const bool ok = Expression(out, bad);
      --depth_;
      if (!ok) return false;
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
      if (!core::ParseInt(digits, &exponent) || exponent < -kMaxPower || exponent > kMaxPower) {
        *bad = "^" + digits;
        if (why_ != nullptr)
          *why_ = "a power beyond " + std::to_string(kMaxPower) + " in magnitude";
        return false;
      }
      *out = Power(*out, static_cast<int>(exponent));
    }
    if (const std::string why = OutOfRange(*out); !why.empty()) return Refuse(start, why, bad);
    return true;
  }

  // the text from `at` on is the bad part, for the reason `why`
  bool Refuse(size_t at, const std::string& why, std::string* bad) {
    *bad = std::string(text_.substr(at));
    if (why_ != nullptr) *why_ = why;
    return false;
  }

  std::string_view text_;
  std::string* why_;
  size_t pos_ = 0;
  int depth_ = 0;
};

}  // namespace

bool ParseUnit(std::string_view text, Unit* out, std::string* bad, std::string* why) {
  std::string reason;
  const bool ok = Parser(text, &reason).Parse(out, bad);
  if (why != nullptr) *why = ok ? "" : reason;
  return ok;
}

}  // namespace caliper::collada::internal
