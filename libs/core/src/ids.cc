#include "caliper/core/ids.h"

namespace caliper::core {

std::string IdSafe(const std::string& name) {
  std::string out;
  // ASCII by its codes, not <cctype>'s locale: a Qt client (which takes the environment's
  // locale) and the Model must make the same id of a name with bytes beyond ASCII
  for (const char c : name) {
    if ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'))
      out += c;
    else if (c >= 'A' && c <= 'Z')
      out += static_cast<char>(c - 'A' + 'a');
    else if (!out.empty() && out.back() != '_')
      out += '_';
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out.empty() ? "model" : out;
}

}  // namespace caliper::core
