#pragma once
// Numbers read from outside (files, command lines, clients): the same text gives the same value
// under every locale. strtod, stod, atof and streams follow the process's locale, which a Qt
// application takes from the environment: under de_DE.UTF-8 they read "1.5" as 1. These use
// std::from_chars, which never looks at the locale.

#include <locale.h>

#include <locale>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace caliper::core {

/// Reads all of `text` as a decimal number: `1.5`, `-2e-3`, `+4`, `inf`, `nan` (case ignored).
/// False, with the reason in `why` when given ("'1,5' is not a number", "'1e400' is out of
/// range"), when `text` is empty, holds anything else (blanks included) or does not fit a double.
bool ParseDouble(std::string_view text, double* value, std::string* why = nullptr);

/// ParseDouble that throws std::invalid_argument with the reason.
double ToDouble(std::string_view text);

/// `value` as the shortest decimal text that ParseDouble reads back as the same double (`0.1`,
/// `1e-05`, `inf`, `nan`), under every locale: for messages, files and ids.
std::string FormatDouble(double value);

/// Reads all of `text` as a decimal integer (`-12`, `+7`); false, with the reason in `why` when
/// given ("'1.5' is not an integer"), when it is not one or does not fit.
bool ParseInt(std::string_view text, long long* value, std::string* why = nullptr);

/// Puts the calling thread in the "C" locale (uselocale(3)) while it lives, for libraries that
/// read or write numbers through the C library's locale-dependent functions or through streams
/// (Collada-DOM reads float arrays with sscanf and writes typed values with std::ostringstream).
/// Other threads keep their C locale. The C++ global locale is process-wide: when it is not the
/// classic one (a program called std::locale::global) it is swapped for the classic one until
/// the scope ends, which streams other threads open meanwhile see too; Qt leaves it classic.
class ClassicLocaleScope {
 public:
  ClassicLocaleScope();
  ~ClassicLocaleScope();
  ClassicLocaleScope(const ClassicLocaleScope&) = delete;
  ClassicLocaleScope& operator=(const ClassicLocaleScope&) = delete;

 private:
  locale_t previous_;                           // the thread's C locale
  std::optional<std::locale> previous_global_;  // the C++ global locale, when it was swapped
};

}  // namespace caliper::core
