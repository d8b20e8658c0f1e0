#include "comma_locale.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <clocale>
#include <cstdlib>
#include <filesystem>
#include <locale>
#include <mutex>
#include <stdexcept>

namespace caliper::testing {

namespace {

constexpr const char* kName = "de_DE.UTF-8";

// de_DE.UTF-8 compiled into a temporary directory, removed at exit
struct Compiled {
  std::string dir;      // holds de_DE.UTF-8/; "" when it could not be made
  std::string problem;  // why not
  ~Compiled() {
    std::error_code ignored;
    if (!dir.empty()) std::filesystem::remove_all(dir, ignored);
  }
};

const Compiled& CompileOnce() {
  static Compiled compiled;
  static std::once_flag once;
  std::call_once(once, [] {
    char dir[] = "/tmp/caliper-locale-XXXXXX";
    if (mkdtemp(dir) == nullptr) {
      compiled.problem = "cannot make a temporary directory";
      return;
    }
    const std::string command =
        std::string("localedef -i de_DE -f UTF-8 ") + dir + "/" + kName + " 2>&1";
    std::string output;
    int status = -1;
    if (FILE* p = popen(command.c_str(), "r"); p != nullptr) {
      char buffer[256];
      while (fgets(buffer, sizeof buffer, p) != nullptr) output += buffer;
      status = pclose(p);
    }
    compiled.dir = dir;
    // localedef exits 1 after mere warnings; the locale is there when LC_NUMERIC is
    if (!std::filesystem::exists(compiled.dir + "/" + kName + "/LC_NUMERIC"))
      compiled.problem = "`" + command + "` failed (status " + std::to_string(status) +
                         "; Debian's `locales` package has the de_DE sources): " + output;
  });
  return compiled;
}

// both locales, or neither
bool Use() {
  if (std::setlocale(LC_ALL, kName) == nullptr) return false;
  try {
    std::locale::global(std::locale(kName));
  } catch (const std::runtime_error&) {
    std::setlocale(LC_ALL, "C");
    return false;
  }
  return true;
}

}  // namespace

CommaDecimalLocale::CommaDecimalLocale() {
  if (!Use()) {
    const Compiled& compiled = CompileOnce();
    if (!compiled.problem.empty()) {
      problem_ = compiled.problem;
      return;
    }
    setenv("LOCPATH", compiled.dir.c_str(), 1);
    if (!Use()) {
      problem_ = std::string(kName) + " compiled into " + compiled.dir + " does not load";
      return;
    }
  }
  // what a locale-sensitive reader now does
  if (std::strtod("1,5", nullptr) != 1.5) {
    problem_ = std::string(kName) + " does not use a decimal comma here";
    std::locale::global(std::locale::classic());
  }
}

CommaDecimalLocale::~CommaDecimalLocale() {
  std::locale::global(std::locale::classic());  // also setlocale(LC_ALL, "C")
  std::setlocale(LC_ALL, "C");
}

}  // namespace caliper::testing
