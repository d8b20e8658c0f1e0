#pragma once
// Regular expressions that come from outside the process (log queries, `caliper-ctl log --grep`,
// the Log Viewer's text filter), compiled one way everywhere: RE2 syntax, linear time in the text
// searched, bounded memory, no recursion, a bounded pattern length and RE2's own error text.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

namespace re2 {
class RE2;
}

namespace caliper::logging {

/// Longest regular expression accepted from outside [bytes].
constexpr size_t kMaxPatternBytes = 1024;

/// Memory one compiled expression may use, program and matching state together [bytes]; a
/// pattern that needs more is refused (RE2's `set_max_mem`).
constexpr int64_t kPatternMemoryBytes = 4 << 20;

/// What a bad pattern is told: too long, or RE2's reason and the pattern.
class PatternError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A compiled regular expression in RE2 syntax (https://github.com/google/re2/wiki/Syntax): no
/// backreferences, no lookaround. `^` and `$` match at the start and end of the text only, `.`
/// does not match a newline. Matching is safe from several threads at once.
class MessagePattern {
 public:
  /// Compiles `pattern`; throws PatternError with "regular expression too long: N bytes, at most
  /// kMaxPatternBytes" or "bad regular expression '<pattern>': <RE2's reason>".
  explicit MessagePattern(const std::string& pattern, bool case_sensitive = true);
  ~MessagePattern();
  MessagePattern(MessagePattern&&) noexcept;
  MessagePattern& operator=(MessagePattern&&) noexcept;

  /// Whether the expression matches anywhere in `text`.
  bool Search(std::string_view text) const;

 private:
  std::unique_ptr<re2::RE2> re_;
};

}  // namespace caliper::logging
