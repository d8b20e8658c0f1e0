#pragma once
// The reason a servant gives in a user exception, bounded: a message that quotes what a client
// sent (a 10 MB id, a 10 MB path) keeps its head and tail and says how much it left out, so that
// replies and log lines stay small whatever a client sends.

#include <string>

namespace caliper::rtc {

/// The longest reason a servant sends [bytes].
constexpr size_t kMaxReasonBytes = 2048;

/// `text`, or its head and tail (whole UTF-8 characters) around "... (N of M bytes left out) ..."
/// when it is longer than kMaxReasonBytes: a message that quotes a long input in its middle keeps
/// what it says after it.
inline std::string BoundedReason(const std::string& text) {
  if (text.size() <= kMaxReasonBytes) return text;
  // not inside a UTF-8 character: move over continuation bytes (10xxxxxx)
  auto continuation = [&](size_t i) {
    return (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80;
  };
  size_t head = kMaxReasonBytes / 2;
  while (head > 0 && continuation(head)) --head;
  size_t tail = text.size() - kMaxReasonBytes / 2 + 64;
  while (tail < text.size() && continuation(tail)) ++tail;
  return text.substr(0, head) + "... (" + std::to_string(tail - head) + " of " +
         std::to_string(text.size()) + " bytes left out) ..." + text.substr(tail);
}

}  // namespace caliper::rtc
