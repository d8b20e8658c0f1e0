#include "fuzz_input.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace caliper::fuzz {

namespace {

std::string Directory() {
  const char* tmp = std::getenv("TMPDIR");
  if (tmp != nullptr && *tmp != '\0') return tmp;
  return access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
}

}  // namespace

InputFile::InputFile(const uint8_t* data, size_t size, const std::string& name)
    : path_(Directory() + "/caliper-fuzz-" + std::to_string(getpid()) + "-" + name) {
  std::FILE* f = std::fopen(path_.c_str(), "wb");
  const bool ok = f != nullptr && std::fwrite(data, 1, size, f) == size;
  if (f == nullptr || std::fclose(f) != 0 || !ok) {
    std::fprintf(stderr, "fuzz: cannot write the input to %s\n", path_.c_str());
    std::abort();
  }
}

InputFile::~InputFile() { std::remove(path_.c_str()); }

std::vector<std::string> Parts(const uint8_t* data, size_t size, size_t count) {
  static const std::string kSeparator = "\n@@\n";
  const std::string all(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> out;
  size_t from = 0;
  while (out.size() + 1 < count) {
    const size_t at = all.find(kSeparator, from);
    if (at == std::string::npos) break;
    out.push_back(all.substr(from, at - from));
    from = at + kSeparator.size();
  }
  out.push_back(all.substr(from));
  return out;
}

void Check(bool ok, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz: check failed: %s\n", what.c_str());
  std::abort();
}

}  // namespace caliper::fuzz
