#pragma once
// Helpers for tests that run real Caliper processes: child processes, a private omniNames on a
// free loopback port, caliper-ctl runs, and waiting for conditions.

#include <sys/resource.h>
#include <sys/types.h>

#include <chrono>
#include <functional>
#include <string>
#include <vector>

namespace caliper::testing {

/// A unique, empty temporary directory, removed by the destructor.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// A child process whose stdout and stderr go to a file; killed (SIGKILL) if still running when
/// destroyed.
class Process {
 public:
  Process(const std::vector<std::string>& argv, const std::string& output_file);
  ~Process();
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  pid_t pid() const { return pid_; }
  bool Running();
  void Signal(int sig);
  /// Exit code (128 + signal when killed), or -1 when still running after `timeout`.
  int Wait(std::chrono::milliseconds timeout);
  /// What the process has printed so far.
  std::string Output() const;

 private:
  pid_t pid_ = -1;
  int status_ = -1;
  std::string output_file_;
};

/// Why a test that opens X windows cannot run here ("" when DISPLAY is set): `what` says what
/// needs X, e.g. "the renderer needs X with GLX".
std::string NoDisplay(const std::string& what);

/// A free TCP port on 127.0.0.1 (bound once to port 0 by the kernel, then released).
int FreePort();

/// A private omniNames in its own data directory.
class NamingService {
 public:
  explicit NamingService(const std::string& dir);
  ~NamingService();
  std::string address() const;
  int port() const { return port_; }
  void Stop();
  /// Starts again on the same port; `fresh` uses an empty data directory (all bindings lost).
  void Start(bool fresh);

 private:
  std::string dir_;
  int port_;
  int generation_ = 0;
  Process* process_ = nullptr;
};

struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// Runs a program to completion (at most `timeout`), capturing stdout and stderr separately.
CommandResult RunCommand(const std::vector<std::string>& argv,
                  std::chrono::milliseconds timeout = std::chrono::seconds(20));

/// Runs build/bin/caliper-ctl --nameservice ADDRESS args...
CommandResult Ctl(const std::string& address, const std::vector<std::string>& args);

/// Path of a Caliper program in the build tree ($CALIPER_BIN_DIR).
std::string Bin(const std::string& name);

/// Polls `condition` every 20 ms until it holds or `timeout` passes; returns its last value.
bool WaitFor(const std::function<bool()>& condition, std::chrono::milliseconds timeout);

/// Whether `text` contains `part`.
inline bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The whole content of a file ("" when missing).
std::string ReadFile(const std::string& path);

/// The files in `dir` whose names start with `prefix`.
std::vector<std::string> ListFiles(const std::string& dir, const std::string& prefix);

/// While it lives, no file this process writes may grow past `bytes`: a write beyond fails with
/// EFBIG ("File too large"), the way a full disk fails it (SIGXFSZ is ignored meanwhile).
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes);
  ~FileSizeLimit();
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit saved_{};
  void (*handler_)(int) = nullptr;
};

}  // namespace caliper::testing
