#include "caliper/logging/message_pattern.h"

#include <re2/re2.h>

namespace caliper::logging {

MessagePattern::MessagePattern(const std::string& pattern, bool case_sensitive) {
  if (pattern.size() > kMaxPatternBytes)
    throw PatternError("regular expression too long: " + std::to_string(pattern.size()) +
                       " bytes, at most " + std::to_string(kMaxPatternBytes));
  RE2::Options options;
  options.set_log_errors(false);
  options.set_max_mem(kPatternMemoryBytes);
  options.set_case_sensitive(case_sensitive);
  // only whether it matches: no capturing groups needed
  options.set_never_capture(true);
  re_ = std::make_unique<RE2>(pattern, options);
  if (!re_->ok()) throw PatternError("bad regular expression '" + pattern + "': " + re_->error());
}

MessagePattern::~MessagePattern() = default;
MessagePattern::MessagePattern(MessagePattern&&) noexcept = default;
MessagePattern& MessagePattern::operator=(MessagePattern&&) noexcept = default;

bool MessagePattern::Search(std::string_view text) const {
  return RE2::PartialMatch(re2::StringPiece(text.data(), text.size()), *re_);
}

}  // namespace caliper::logging
