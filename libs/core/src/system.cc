#include "caliper/core/system.h"

#include <signal.h>
#include <fcntl.h>
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
  // several "hosts" on one machine (network namespaces share the UTS name) name themselves
  const char* forced = std::getenv("CALIPER_HOST");
  if (forced != nullptr && *forced != '\0') return forced;
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
  // a symbolic link keeps pointing where it did: the file it names is the one replaced
  std::string target = path;
  struct stat existing = {};
  const bool exists = ::stat(path.c_str(), &existing) == 0;
  if (exists) {
    char* resolved = ::realpath(path.c_str(), nullptr);
    if (resolved != nullptr) {
      target = resolved;
      std::free(resolved);
    }
  }
  const std::string temporary = target + ".part-" + std::to_string(::getpid());
  const auto fail = [&](const char* what, int error) {
    std::remove(temporary.c_str());
    throw std::runtime_error("cannot write " + path + ": " + what +
                             (error != 0 ? std::string(" (") + std::strerror(error) + ")" : ""));
  };
  // created here and now (never an existing file or a link planted under that name)
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC,
                        exists ? (existing.st_mode & 07777) : 0666);
  if (fd < 0) {
    const int error = errno;
    throw std::runtime_error("cannot write " + path + ": cannot create a file there (" +
                             std::strerror(error) + ")");
  }
  ::close(fd);
  std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
  if (!out) fail("cannot open the new file", errno);
  errno = 0;
  try {
    write(out);
  } catch (...) {
    out.close();
    std::remove(temporary.c_str());
    throw;
  }
  if (!out) fail("write failed", errno);  // the stream's buffer was written out meanwhile
  errno = 0;
  out.flush();
  if (!out) fail("write failed", errno);
  errno = 0;
  out.close();
  if (out.fail()) fail("write failed on close", errno);
  if (exists) ::chmod(temporary.c_str(), existing.st_mode & 07777);  // despite the umask
  if (std::rename(temporary.c_str(), target.c_str()) != 0) fail("cannot replace it", errno);
}

bool InterruptPending() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  const timespec none = {0, 0};
  return sigtimedwait(&set, nullptr, &none) > 0;
}

std::string ProgramDirectory() {
  char path[4096];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return ".";
  const std::string exe(path, static_cast<size_t>(n));
  return exe.substr(0, exe.rfind('/'));
}

}  // namespace caliper::core
