#include "children.h"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "caliper/logging/log.h"

namespace caliper::manager {

namespace {

constexpr auto kReapPeriod = std::chrono::milliseconds(100);

double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

std::string EndState(int wait_status) {
  if (wait_status == -1) return "ended (reaped elsewhere, status unknown)";
  if (WIFEXITED(wait_status)) return "exited with code " + std::to_string(WEXITSTATUS(wait_status));
  if (WIFSIGNALED(wait_status)) return "killed by signal " + std::to_string(WTERMSIG(wait_status));
  return "ended";
}

// To the child's group (it leads one), or to the child alone when it left the group.
void SignalChild(pid_t pid, int sig) {
  if (kill(-pid, sig) != 0) kill(pid, sig);
}

// what a child that cannot start writes to its parent before _exit
struct ChildError {
  int stage;  // 0: opening the output file, 1: exec
  int error;  // errno
};

[[noreturn]] void ChildFail(int fd, int stage) {
  const ChildError e{stage, errno};
  if (write(fd, &e, sizeof e) < 0) {
    // the parent reads the exit code instead
  }
  _exit(127);
}

// Appends `value` in decimal to the NUL-terminated `buffer` (async-signal-safe).
void AppendNumber(char* buffer, long value) {
  char digits[24];
  int n = 0;
  do {
    digits[n++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value > 0);
  char* end = buffer + std::strlen(buffer);
  while (n > 0) *end++ = digits[--n];
  *end = '\0';
}

}  // namespace

Supervisor::Supervisor(SupervisorOptions options) : options_(std::move(options)) {
  thread_ = std::thread([this] { Run(); });
}

Supervisor::~Supervisor() {
  StopAll();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_thread_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

pid_t Supervisor::Start(const std::string& type, const std::vector<std::string>& argv) {
  std::future<pid_t> result;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) throw StartFailed("the manager is shutting down");
    requests_.push_back({type, argv, {}});
    result = requests_.back().result.get_future();
  }
  wake_.notify_all();
  return result.get();
}

void Supervisor::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    while (!requests_.empty()) {
      StartRequest request = std::move(requests_.front());
      requests_.pop_front();
      try {
        if (closed_) throw StartFailed("the manager is shutting down");
        const size_t now_running = RunningLocked();
        if (now_running >= options_.max_running)
          throw CapacityReached(std::to_string(now_running) + " of " +
                                std::to_string(options_.max_running) + " children run (" +
                                options_.capacity_key + " allows more)");
        const pid_t pid = Spawn(request.type, request.argv);
        Child& child = children_[pid] = Child{};  // a reused pid starts afresh
        child.status.type = request.type;
        child.status.pid = pid;
        child.status.output_file =
            options_.output_dir + "/" + request.type + "-" + std::to_string(pid) + ".out";
        child.started = Clock::now();
        request.result.set_value(pid);
      } catch (...) {
        request.result.set_exception(std::current_exception());
      }
    }
    const std::vector<std::string> messages = ReapLocked();
    if (!messages.empty()) {
      lock.unlock();
      for (const auto& m : messages) logging::Get("manager").error("%s", m.c_str());
      lock.lock();
    }
    if (stop_thread_) break;
    wake_.wait_for(lock, kReapPeriod, [&] { return stop_thread_ || !requests_.empty(); });
  }
}

pid_t Supervisor::Spawn(const std::string& type, const std::vector<std::string>& argv) {
  // everything the child needs is made here: between fork and exec it may only make
  // async-signal-safe calls (another thread may hold the allocator's lock)
  if (argv.empty()) throw StartFailed("nothing to start");
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const std::string prefix = options_.output_dir + "/" + type + "-";
  char output[PATH_MAX];
  if (prefix.size() + 32 > sizeof output) throw StartFailed("output path too long: " + prefix);
  std::strcpy(output, prefix.c_str());
  int report[2];
  if (pipe2(report, O_CLOEXEC) != 0)
    throw StartFailed(std::string("cannot make a pipe: ") + std::strerror(errno));
  sigset_t none;
  sigemptyset(&none);
  const pid_t parent = getpid();

  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);  // a Ctrl-C in the manager's terminal reaches the manager alone
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);  // the manager died before prctl
    sigprocmask(SIG_SETMASK, &none, nullptr);
    signal(SIGPIPE, SIG_DFL);
    AppendNumber(output, getpid());
    std::strcat(output, ".out");
    const int fd = open(output, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) ChildFail(report[1], 0);
    dup2(fd, 1);
    dup2(fd, 2);
    const int in = open("/dev/null", O_RDONLY);
    if (in >= 0) dup2(in, 0);
    close_range(3, ~0U, CLOSE_RANGE_CLOEXEC);  // none of the manager's sockets pass on
    execv(args[0], args.data());
    ChildFail(report[1], 1);
  }
  const int fork_error = errno;
  close(report[1]);
  if (pid < 0) {
    close(report[0]);
    throw StartFailed(std::string("cannot fork: ") + std::strerror(fork_error));
  }
  setpgid(pid, pid);  // also here, so that the group exists once Spawn returns
  ChildError e{};
  ssize_t n;
  do {
    n = read(report[0], &e, sizeof e);
  } while (n < 0 && errno == EINTR);
  close(report[0]);
  if (n == static_cast<ssize_t>(sizeof e)) {
    waitpid(pid, nullptr, 0);
    throw StartFailed((e.stage == 0 ? "cannot write " + prefix + "<pid>.out: "
                                    : "cannot run " + argv[0] + ": ") +
                      std::strerror(e.error));
  }
  return pid;
}

std::vector<std::string> Supervisor::ReapLocked() {
  std::vector<std::string> messages;
  bool reaped = false;
  for (auto& [pid, child] : children_) {
    if (!child.status.running) continue;
    int status = 0;
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == 0 || (r < 0 && errno != ECHILD)) continue;
    child.status.running = false;
    child.wait_status = r == pid ? status : -1;  // ECHILD: someone else reaped it
    child.ended = Clock::now();
    reaped = true;
    if (child.stopping) continue;
    const ChildStatus s = StatusLocked(child);
    char after[32];
    std::snprintf(after, sizeof after, "%.1f", s.uptime);
    messages.push_back((s.instance.empty() ? s.type : s.instance) + " (pid " +
                       std::to_string(pid) + ") " + s.state + " after " + after + " s");
  }
  if (!reaped) return messages;
  // forget the oldest ended children beyond keep_ended
  std::vector<const Child*> ended;
  for (const auto& [pid, child] : children_)
    if (!child.status.running) ended.push_back(&child);
  std::sort(ended.begin(), ended.end(), [](auto* a, auto* b) { return a->ended < b->ended; });
  for (size_t i = 0; i + options_.keep_ended < ended.size(); ++i)
    children_.erase(ended[i]->status.pid);
  changed_.notify_all();
  return messages;
}

void Supervisor::Terminate(const std::vector<pid_t>& pids, std::unique_lock<std::mutex>& lock) {
  auto signal_running = [&](int sig) {
    for (pid_t pid : pids) {
      const auto it = children_.find(pid);
      if (it == children_.end() || !it->second.status.running) continue;
      it->second.stopping = true;
      SignalChild(pid, sig);
    }
  };
  auto all_ended = [&] {
    return std::none_of(pids.begin(), pids.end(), [&](pid_t pid) {
      const auto it = children_.find(pid);
      return it != children_.end() && it->second.status.running;
    });
  };
  signal_running(SIGTERM);
  if (changed_.wait_for(lock, options_.grace, all_ended)) return;
  signal_running(SIGKILL);
  changed_.wait_for(lock, options_.grace, all_ended);
}

void Supervisor::Stop(pid_t pid) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (children_.count(pid) == 0)
    throw UnknownComponent("no child with pid " + std::to_string(pid) + " (" + NamesLocked() + ")");
  Terminate({pid}, lock);
  const auto it = children_.find(pid);
  if (it != children_.end() && !it->second.status.running) children_.erase(it);
}

void Supervisor::StopAll() {
  std::unique_lock<std::mutex> lock(mutex_);
  closed_ = true;
  std::vector<pid_t> pids;
  for (const auto& [pid, child] : children_)
    if (child.status.running) pids.push_back(pid);
  Terminate(pids, lock);
}

void Supervisor::SetRegistered(pid_t pid, const std::string& instance,
                               const std::string& naming_path) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = children_.find(pid);
  if (it == children_.end()) return;
  it->second.status.instance = instance;
  it->second.status.naming_path = naming_path;
}

pid_t Supervisor::PidOf(const std::string& instance) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const Child* found = nullptr;
  for (const auto& [pid, child] : children_)
    if (child.status.instance == instance && (found == nullptr || child.status.running))
      found = &child;
  if (found == nullptr)
    throw UnknownComponent("no child named '" + instance + "' (" + NamesLocked() + ")");
  return found->status.pid;
}

std::optional<ChildStatus> Supervisor::Status(pid_t pid) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = children_.find(pid);
  if (it == children_.end()) return std::nullopt;
  return StatusLocked(it->second);
}

std::vector<ChildStatus> Supervisor::List() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<const Child*> order;
  for (const auto& [pid, child] : children_) order.push_back(&child);
  std::sort(order.begin(), order.end(), [](auto* a, auto* b) {
    if (a->status.running != b->status.running) return a->status.running;
    return a->started < b->started;
  });
  std::vector<ChildStatus> out;
  for (const Child* c : order) out.push_back(StatusLocked(*c));
  return out;
}

size_t Supervisor::running() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return RunningLocked();
}

size_t Supervisor::RunningLocked() const {
  return std::count_if(children_.begin(), children_.end(),
                       [](const auto& c) { return c.second.status.running; });
}

ChildStatus Supervisor::StatusLocked(const Child& child) const {
  ChildStatus s = child.status;
  if (s.running) {
    s.state = s.instance.empty() ? "starting" : "running";
    s.uptime = Seconds(Clock::now() - child.started);
  } else {
    s.state = EndState(child.wait_status);
    s.uptime = Seconds(child.ended - child.started);
  }
  return s;
}

std::string Supervisor::NamesLocked() const {
  std::string running, ended;
  for (const auto& [pid, child] : children_) {
    const std::string name = child.status.instance.empty()
                                 ? child.status.type + " pid " + std::to_string(pid)
                                 : child.status.instance;
    std::string& list = child.status.running ? running : ended;
    list += (list.empty() ? "" : ", ") + name;
  }
  if (running.empty() && ended.empty()) return "it runs none";
  return "running: " + (running.empty() ? "none" : running) +
         (ended.empty() ? "" : "; ended: " + ended);
}

std::string TailOfFile(const std::string& path, size_t lines) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return "";
  const std::streamoff size = in.tellg();
  in.seekg(std::max<std::streamoff>(0, size - 16384));
  std::ostringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  if (!s.empty() && s.back() == '\n') s.pop_back();
  size_t start = s.size();
  for (size_t n = 0; n < lines; ++n) {
    const size_t nl = start == 0 ? std::string::npos : s.rfind('\n', start - 1);
    if (nl == std::string::npos) return s;
    start = nl;
  }
  return s.substr(start + 1);
}

}  // namespace caliper::manager
