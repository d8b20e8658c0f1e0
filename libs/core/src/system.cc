#include "caliper/core/system.h"

#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace caliper::core {

std::string HostName() {
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) != 0) return "localhost";
  std::string host(buf);
  const auto dot = host.find('.');
  if (dot != std::string::npos) host.erase(dot);
  return host.empty() ? "localhost" : host;
}

int64_t NowMicros() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

std::string FormatTime(int64_t time_us) {
  const time_t seconds = static_cast<time_t>(time_us / 1000000);
  struct tm local;
  localtime_r(&seconds, &local);
  char buf[64];
  const size_t n = strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &local);
  snprintf(buf + n, sizeof buf - n, ".%03d", static_cast<int>((time_us % 1000000) / 1000));
  return buf;
}

std::string ExpandHome(const std::string& path) {
  if (path.empty() || path[0] != '~') return path;
  const char* home = std::getenv("HOME");
  return std::string(home ? home : "") + path.substr(1);
}

void MakeDirectories(const std::string& path) {
  std::string partial;
  for (size_t i = 0; i <= path.size(); ++i) {
    if (i == path.size() || path[i] == '/') {
      if (!partial.empty() && mkdir(partial.c_str(), 0755) != 0 && errno != EEXIST) {
        throw std::runtime_error("cannot create directory " + partial + ": " + strerror(errno));
      }
    }
    if (i < path.size()) partial += path[i];
  }
}

bool ProcessAlive(long pid) {
  return pid > 0 && (kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}

void WriteFileReplacing(const std::string& path,
                        const std::function<void(std::ostream&)>& write) {
  const std::string temporary = path + ".part-" + std::to_string(::getpid());
  const auto fail = [&](const char* what) {
    const int error = errno;
    std::remove(temporary.c_str());
    throw std::runtime_error("cannot write " + path + ": " + what +
                             (error != 0 ? std::string(" (") + std::strerror(error) + ")" : ""));
  };
  errno = 0;
  std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
  if (!out) fail("cannot create a file there");
  try {
    write(out);
  } catch (...) {
    out.close();
    std::remove(temporary.c_str());
    throw;
  }
  out.flush();
  if (!out) fail("write failed");
  out.close();
  if (out.fail()) fail("write failed on close");
  if (std::rename(temporary.c_str(), path.c_str()) != 0) fail("cannot replace it");
}

}  // namespace caliper::core
