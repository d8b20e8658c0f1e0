#include "fuzz_input.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace caliper::fuzz {

namespace {

// the directory of this process's inputs, made on first use and removed at exit; the string is
// never destroyed (the exit handler, registered before the string is complete, runs after the
// destructor a plain static would have)
const std::string& InputDir() {
  static const std::string& dir = *new std::string([] {
    // memory, not disk: a file per input on /tmp held the config target at a tenth of its speed
    const char* tmp = std::getenv("TMPDIR");
    std::string base = tmp != nullptr && *tmp != '\0' ? tmp : "/tmp";
    if ((tmp == nullptr || *tmp == '\0') && access("/dev/shm", W_OK) == 0) base = "/dev/shm";
    std::string d = base + "/caliper-fuzz-" + std::to_string(getpid());
    std::error_code ec;
    std::filesystem::create_directories(d, ec);
    if (ec) {
      std::fprintf(stderr, "fuzz: cannot make %s: %s\n", d.c_str(), ec.message().c_str());
      std::abort();
    }
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(InputDir(), ignored);
    });
    return d;
  }());
  return dir;
}

}  // namespace

std::string WriteInput(const uint8_t* data, size_t size, const std::string& name) {
  const std::string path = InputDir() + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  const bool ok = f != nullptr && std::fwrite(data, 1, size, f) == size;
  if (f == nullptr || std::fclose(f) != 0 || !ok) {
    std::fprintf(stderr, "fuzz: cannot write the input to %s\n", path.c_str());
    std::abort();
  }
  return path;
}

void Check(bool ok, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz: check failed: %s\n", what.c_str());
  std::abort();
}

}  // namespace caliper::fuzz
