#pragma once
// A comma-decimal locale for tests of number parsing: a Qt application takes its C locale from
// the environment (LANG=de_DE.UTF-8 makes strtod read "1.5" as 1), and a program may also set
// the C++ global locale (streams). Tests switch to de_DE.UTF-8 for both and check that numbers
// read from files and command lines keep their value.

#include <gtest/gtest.h>

#include <string>

namespace caliper::testing {

/// Switches the process's C locale (setlocale) and C++ global locale to de_DE.UTF-8 while it
/// lives, back to "C" afterwards. Where the system lacks that locale it is compiled with
/// `localedef -i de_DE -f UTF-8` (sources from Debian's `locales` package) into a temporary
/// directory found through LOCPATH, once per process; no root needed.
class CommaDecimalLocale {
 public:
  CommaDecimalLocale();
  ~CommaDecimalLocale();
  CommaDecimalLocale(const CommaDecimalLocale&) = delete;
  CommaDecimalLocale& operator=(const CommaDecimalLocale&) = delete;

  /// Why the locale is not in use; "" when it is (strtod then reads "1,5" as 1.5).
  const std::string& problem() const { return problem_; }

 private:
  std::string problem_;
};

}  // namespace caliper::testing

/// Declares a CommaDecimalLocale `name` for the rest of the test; skips the test, saying why,
/// when the locale cannot be made (CI installs `locales` from launch/deps.txt and accepts no
/// such skip: tests/ci_allowed_skips.txt).
#define CALIPER_COMMA_DECIMAL_LOCALE(name)                                                      \
  ::caliper::testing::CommaDecimalLocale name;                                                  \
  do {                                                                                          \
    if (!name.problem().empty()) GTEST_SKIP() << "no comma-decimal locale: " << name.problem(); \
  } while (0)
