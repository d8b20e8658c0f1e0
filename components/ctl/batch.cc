#include "batch.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <memory>
#include <set>
#include <sstream>
#include <thread>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include "batch_plan.h"
#include "cluster_verbs.h"
#include "caliper/client/experiments.h"
#include "caliper/client/model_pool.h"
#include "caliper/client/scene_transfer.h"
#include "caliper/core/config.h"
#include "caliper/core/numbers.h"
#include "caliper/core/system.h"
#include "caliper/experiment/experiment.h"
#include "caliper/model.hh"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"
#include "caliper/rtc/peers.h"
#include "csv_recording.h"

namespace caliper::ctl {

namespace {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

double Since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct BatchOptions {
  std::string file;
  std::string out;
  std::string models = "model*";  // instance glob
  double stall_s = 5;             // a busy Model silent this long loses its run
  double run_timeout_s = 3600;    // the longest a run call may take
  int max_attempts = 5;
  double wait_models_s = 10;      // how long to wait for a first Model
  unsigned long spawn = 0;        // Models to ask the managers for (0: use those bound)
  std::string status;             // a JSON file with the progress, rewritten every second
};

// One Model of the pool the batch uses, and its worker thread.
struct Slot {
  std::string name;  // model1@hostb
  size_t index = 0;  // in the pool
  std::mutex mutex;  // guards ticket, since, last_answer, sim_time, in_call
  std::optional<BatchPlan::Ticket> ticket;
  Clock::time_point since, last_answer;
  double sim_time = 0;  // of the run in flight, from the last status poll [s]
  bool in_call = false;
  std::thread thread;
};

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

class BatchRun {
 public:
  BatchRun(Client& client, BatchOptions options, std::vector<experiment::Experiment> runs)
      : client_(client), options_(std::move(options)), runs_(std::move(runs)),
        plan_(runs_.size(), options_.max_attempts), written_(runs_.size(), false),
        pool_([this] { return FindModels(); }, PoolOptions()) {
    pool_.on_joined = [this](size_t index) { Join(index); };
  }

  // Dispatch, then Finish also when Dispatch throws (its message printed); the exit code.
  int Run();

 private:
  void LoadScenes();
  // the Models matching --models (only those asked of the managers with --spawn)
  std::vector<client::ModelEntry> FindModels();
  client::ModelPool::Options PoolOptions() const;
  // a Model found: its slot and worker
  void Join(size_t index);
  void Work(Slot* slot);
  // the batch ends (done, or SIGINT / SIGTERM pending)
  bool Stopping() { return stop_ || Interrupted(); }
  // SIGINT or SIGTERM arrived (taking a pending one consumes it: latched here for every thread)
  bool Interrupted() {
    if (!interrupt_ && core::InterruptPending()) interrupt_ = true;
    return interrupt_;
  }
  void Attempt(Slot* slot, const BatchPlan::Ticket& ticket);
  void Watch();
  void Progress(bool last);
  // the progress as JSON in --status (replaced whole, so a reader never sees half of it)
  void WriteStatus(const std::string& state, size_t busy, size_t models, double rate,
                   double eta_s);
  int Dispatch();
  // Stops the workers (a worker stuck in a call to a lost Model is left: the process then
  // ends with _exit) and the Models asked of the managers.
  int Finish(int rc);
  void WriteRun(size_t run, const M::Recording& recording);
  void WriteSummary(double wall_s, const std::vector<Outcome>& outcomes);

  Client& client_;
  BatchOptions options_;
  std::vector<experiment::Experiment> runs_;
  BatchPlan plan_;
  std::map<std::string, std::string> scenes_;  // path -> bytes
  std::mutex slots_mutex_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::mutex written_mutex_;
  std::condition_variable written_cv_;
  std::vector<bool> written_;
  std::vector<std::string> write_errors_;
  std::atomic<bool> stop_{false};
  std::vector<SpawnedModel> spawned_;  // asked of the managers; only these are used
  client::ModelPool pool_;             // last: its finder uses the members above
  Clock::time_point begin_ = Clock::now();
  Clock::time_point last_progress_;
  Clock::time_point last_status_;
  bool interrupted_ = false;  // by SIGINT or SIGTERM: unfinished runs are marked interrupted
  std::atomic<bool> interrupt_{false};
  bool status_warned_ = false;  // a --status file that cannot be written is said once
};

void BatchRun::LoadScenes() {
  for (const auto& e : runs_) {
    if (scenes_.count(e.scene)) continue;
    try {
      scenes_[e.scene] = client::ReadScene(e.scene);
    } catch (const std::runtime_error& error) {
      throw Failure(options_.file + ": experiment '" + e.name + "': " + error.what());
    }
  }
}

std::vector<client::ModelEntry> BatchRun::FindModels() {
  CosNaming::NamingContext_var root = client_.Root();
  std::vector<client::ModelEntry> entries = client::FindModels(root, options_.models);
  if (spawned_.empty()) return entries;
  std::vector<client::ModelEntry> ours;
  for (auto& e : entries)
    if (std::any_of(spawned_.begin(), spawned_.end(),
                    [&](const auto& m) { return m.path == e.path; }))
      ours.push_back(std::move(e));
  return ours;
}

client::ModelPool::Options BatchRun::PoolOptions() const {
  client::ModelPool::Options o;
  o.run_timeout_s = options_.run_timeout_s;
  o.attempts = options_.max_attempts;
  o.probe_timeout_s = 2;
  return o;
}

void BatchRun::Join(size_t index) {
  auto slot = std::make_unique<Slot>();
  slot->name = pool_.name(index);
  slot->index = index;
  Slot* raw = slot.get();
  std::lock_guard<std::mutex> lock(slots_mutex_);
  slots_.push_back(std::move(slot));
  raw->thread = std::thread([this, raw] { Work(raw); });
}

void BatchRun::Work(Slot* slot) {
  rtc::OmniThread omni;
  // the run call may take long; a dead peer is found by the watcher's status polls
  omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(options_.run_timeout_s * 1000));
  while (!Stopping() && !plan_.finished()) {
    if (pool_.down(slot->index)) {
      // back when it answers and no longer runs what it was given up on
      if (!pool_.Probe(slot->index)) std::this_thread::sleep_for(std::chrono::milliseconds(500));
      omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(options_.run_timeout_s * 1000));
      continue;
    }
    const auto ticket = plan_.Next(slot->name, std::chrono::milliseconds(200));
    if (ticket) Attempt(slot, *ticket);
  }
}

void BatchRun::Attempt(Slot* slot, const BatchPlan::Ticket& ticket) {
  M::Model_var model;
  {
    std::lock_guard<std::mutex> lock(slot->mutex);
    if (stop_) {
      plan_.Abandon(ticket);  // never sent: it costs the run nothing
      return;
    }
    slot->in_call = true;  // with the ticket: the end of Run sees both or neither
    slot->ticket = ticket;
    slot->since = slot->last_answer = Clock::now();
    slot->sim_time = 0;
  }
  model = pool_.model(slot->index);
  const M::Experiment idl = client::ToIdl(runs_[ticket.run], scenes_.at(runs_[ticket.run].scene));
  const auto begin = Clock::now();
  try {
    M::Recording_var r = model->run_experiment(idl);
    Outcome o;
    o.model = slot->name;
    o.wall_s = Since(begin);
    o.load_wall_s = r->load_wall_time;
    o.step_wall_s = r->step_wall_time;
    o.steps = r->steps;
    o.samples = r->times.length();
    if (plan_.Complete(ticket, o)) WriteRun(ticket.run, r.in());
  } catch (const M::RunFailed& e) {
    plan_.Fail(ticket, e.reason.in());
  } catch (const M::LoadFailed& e) {
    plan_.Fail(ticket, e.reason.in());
  } catch (const D::UnknownId& e) {
    plan_.Fail(ticket, e.reason.in());
  } catch (const D::InvalidParameter& e) {
    plan_.Fail(ticket, e.reason.in());
  } catch (const M::NotAvailable& e) {
    // busy with a run given up on earlier, or shutting down: set aside until it is idle. A
    // Model going away never ran the run: that costs the run no attempt (on scancel Slurm stops
    // the Models before this client hears of it; the runs are then interrupted, not failed)
    const std::string reason = e.reason.in();
    const bool leaving = reason.find("shutting down") != std::string::npos;
    if (Stopping() || leaving) plan_.Abandon(ticket, Stopping());
    else plan_.Retry(ticket, slot->name + ": " + reason);
    pool_.SetDown(slot->index, reason);
    // its status still answers while it shuts down, which would bring it back at once
    if (leaving) std::this_thread::sleep_for(std::chrono::milliseconds(500));
  } catch (const CORBA::SystemException& e) {
    // a Model that died during the run costs it an attempt (a run that kills every Model ends
    // failed); one that was gone before the call does not. Gone, not slow: nothing listens at
    // its address (omniORB also reports a failed connect for a live local Model after a call to
    // it timed out: that run is retried and counted)
    const bool gone_before = CORBA::TRANSIENT::_downcast(&e) != nullptr &&
                             rtc::PeerGone(e, model.in());
    if (Stopping() || gone_before) plan_.Abandon(ticket, Stopping());
    else plan_.Retry(ticket, slot->name + ": " + rtc::Describe(e));
    pool_.SetDown(slot->index, rtc::Describe(e));
  } catch (const CORBA::Exception& e) {
    plan_.Fail(ticket, slot->name + ": " + rtc::Describe(e));
  }
  std::lock_guard<std::mutex> lock(slot->mutex);
  slot->in_call = false;
  slot->ticket.reset();
}

void BatchRun::WriteRun(size_t run, const M::Recording& r) {
  std::vector<RecordedChannel> channels;
  for (CORBA::ULong i = 0; i < r.channels.length(); ++i)
    channels.push_back({r.channels[i].id.in(), r.channels[i].unit.in(), r.channels[i].rows,
                        r.channels[i].cols});
  const std::string path = options_.out + "/runs/" + runs_[run].name + ".csv";
  std::string error;
  try {
    core::WriteFileReplacing(path, [&](std::ostream& out) {
      CsvRecording csv(out, channels);
      csv.Add(1, r.times.get_buffer(), r.times.length(), r.data.get_buffer(), r.values_per_sample);
      if (!csv.error().empty()) throw std::runtime_error(csv.error());
    });
  } catch (const std::exception& e) {
    error = path + ": " + e.what();
  }
  std::lock_guard<std::mutex> lock(written_mutex_);
  written_[run] = true;
  if (!error.empty()) write_errors_.push_back(error);
  written_cv_.notify_all();
}

void BatchRun::Watch() {
  // one status poll per busy Model; a Model silent for stall_s loses its run (it may still
  // finish it: the first result counts)
  omniORB::setClientThreadCallTimeout(1000);
  std::vector<Slot*> slots;
  {
    std::lock_guard<std::mutex> lock(slots_mutex_);
    for (auto& s : slots_) slots.push_back(s.get());
  }
  for (Slot* slot : slots) {
    M::Model_var model;
    std::optional<BatchPlan::Ticket> ticket;
    Clock::time_point last;
    {
      std::lock_guard<std::mutex> lock(slot->mutex);
      ticket = slot->ticket;
      last = slot->last_answer;
    }
    model = pool_.model(slot->index);
    if (!ticket) continue;
    std::string failure;
    try {
      M::SimulationStatus_var s = model->status();
      std::lock_guard<std::mutex> lock(slot->mutex);
      slot->last_answer = Clock::now();
      if (slot->ticket && slot->ticket->token == ticket->token) slot->sim_time = s->sim_time;
      continue;
    } catch (const CORBA::Exception& e) {
      failure = rtc::Describe(e);
    }
    const double silent = Since(last);
    if (silent >= options_.stall_s) {
      plan_.Retry(*ticket, slot->name + ": no answer for " + Fixed(silent, 1) + " s (" + failure +
                               ")");
      pool_.SetDown(slot->index, failure);
    }
  }
}

void BatchRun::WriteStatus(const std::string& state, size_t busy, size_t models, double rate,
                           double eta_s) {
  if (options_.status.empty()) return;
  last_status_ = Clock::now();
  boost::property_tree::ptree tree;
  tree.put("state", state);
  tree.put("file", options_.file);
  tree.put("out", options_.out);
  tree.put("runs_total", plan_.size());
  tree.put("runs_done", plan_.done());
  tree.put("runs_failed", plan_.failed());
  tree.put("models", models);
  tree.put("models_busy", busy);
  tree.put("sim_s_per_s", Fixed(rate, 3));
  tree.put("eta_s", eta_s >= 0 ? Fixed(eta_s, 1) : std::string());
  tree.put("wall_s", Fixed(Since(begin_), 3));
  tree.put("updated_unix_s", std::time(nullptr));
  try {
    core::WriteFileReplacing(options_.status, [&](std::ostream& out) {
      boost::property_tree::write_json(out, tree);
    });
  } catch (const std::exception& e) {
    if (!status_warned_) std::cerr << "warning: --status " << options_.status << ": " << e.what()
                                   << " (said once)\n";
    status_warned_ = true;
  }
}

void BatchRun::Progress(bool last) {
  const bool tty = isatty(STDERR_FILENO) != 0;
  const bool status_due = !options_.status.empty() && Since(last_status_) >= 1;
  if (!last && !status_due && !tty && Since(last_progress_) < 5) return;
  const bool print = last || tty || Since(last_progress_) >= 5;
  if (print) last_progress_ = Clock::now();
  const size_t total = plan_.size(), done = plan_.done(), failed = plan_.failed();
  // simulated seconds: steps of finished runs times their step, plus runs in flight
  double sim_done = 0, sim_left = 0;
  const auto outcomes = plan_.outcomes();
  for (size_t i = 0; i < outcomes.size(); ++i) {
    if (outcomes[i].state == Outcome::State::kDone) sim_done += runs_[i].duration_s;
    else if (outcomes[i].state != Outcome::State::kFailed) sim_left += runs_[i].duration_s;
  }
  size_t busy = 0, models = 0;
  {
    std::lock_guard<std::mutex> lock(slots_mutex_);
    for (auto& s : slots_) {
      std::lock_guard<std::mutex> slot_lock(s->mutex);
      models += pool_.down(s->index) ? 0 : 1;
      if (s->ticket) {
        ++busy;
        sim_done += s->sim_time;
        sim_left -= s->sim_time;
      }
    }
  }
  const double wall = Since(begin_);
  const double rate = wall > 0 ? sim_done / wall : 0;
  const int width = 24;
  const int filled = total ? static_cast<int>(width * (done + failed) / total) : width;
  std::ostringstream line;
  line << "[" << std::string(filled, '#') << std::string(width - filled, '.') << "] "
       << (done + failed) << "/" << total << " runs";
  if (failed) line << " (" << failed << " failed)";
  line << ", " << busy << "/" << models << " Models busy, " << Fixed(rate, 2) << " sim-s/s";
  const double eta = rate > 0 && sim_left > 0 ? std::max(0.0, sim_left) / rate : -1;
  if (eta >= 0) line << ", ETA " << Fixed(eta, 0) << " s";
  else if (last) line << ", " << Fixed(wall, 1) << " s";
  if (status_due || last) WriteStatus(last ? "finishing" : "running", busy, models, rate, eta);
  if (print)
    std::cerr << (tty ? "\r\033[K" : "") << line.str() << (tty && !last ? "" : "\n") << std::flush;
}

void BatchRun::WriteSummary(double wall_s, const std::vector<Outcome>& outcomes) {
  core::WriteFileReplacing(options_.out + "/summary.csv", [&](std::ostream& out) {
    out << "name,status,model,attempts,duration [s],steps,samples,wall_time [s],"
           "load_wall_time [s],step_wall_time [s],retries,reason\n";
    out << std::setprecision(6);
    for (size_t i = 0; i < outcomes.size(); ++i) {
      const Outcome& o = outcomes[i];
      std::string retries;
      for (const auto& r : o.retries) retries += (retries.empty() ? "" : "; ") + r.reason;
      // stopped (Ctrl-C, SIGTERM from Slurm's scancel or time limit): said as such
      const bool cut = interrupted_ && (o.state == Outcome::State::kPending ||
                                        o.state == Outcome::State::kRunning);
      const std::string status = cut ? "interrupted" : ToString(o.state);
      const bool ran = o.state == Outcome::State::kRunning || o.stopped;
      const std::string reason =
          cut ? (ran ? "stopped while it ran" : "never started") +
                    std::string(": the batch was interrupted (SIGINT or SIGTERM)")
              : o.reason;
      out << CsvField(runs_[i].name) << "," << status << "," << CsvField(o.model) << ","
          << o.attempts << "," << runs_[i].duration_s << "," << o.steps << "," << o.samples << ","
          << o.wall_s << "," << o.load_wall_s << "," << o.step_wall_s << "," << CsvField(retries)
          << "," << CsvField(reason) << "\n";
    }
  });
  size_t retries = 0;
  double sim = 0, step_wall = 0, run_wall = 0;
  for (size_t i = 0; i < outcomes.size(); ++i) {
    const Outcome& o = outcomes[i];
    retries += o.retries.size();
    for (const auto& r : o.retries) std::cout << "retry: " << runs_[i].name << ": " << r.reason << "\n";
    if (o.state == Outcome::State::kFailed)
      std::cout << "failed: " << runs_[i].name << " on " << o.model << ": " << o.reason << "\n";
    if (o.state == Outcome::State::kDone) {
      sim += runs_[i].duration_s;
      step_wall += o.step_wall_s;
      run_wall += o.wall_s;
    }
  }
  std::cout << plan_.done() << " of " << outcomes.size() << " runs done, " << plan_.failed()
            << " failed, " << retries << " retr" << (retries == 1 ? "y" : "ies") << "; "
            << Fixed(sim, 3) << " simulated s in " << Fixed(wall_s, 2) << " s of wall time ("
            << Fixed(wall_s > 0 ? sim / wall_s : 0, 2) << " sim-s/s)";
  if (step_wall > 0)
    std::cout << "; per-run overhead " << Fixed(100 * (run_wall - step_wall) / step_wall, 1)
              << " % over stepping";
  std::cout << "\nresults: " << options_.out << "/runs/*.csv, summary: " << options_.out
            << "/summary.csv\n";
}

int BatchRun::Run() {
  rtc::OmniThread omni;
  int rc = 1;
  try {
    rc = Dispatch();
  } catch (const std::exception& e) {
    // the workers and the spawned Models must end before the error goes up
    std::cerr << "caliper-ctl batch: " << e.what() << "\n";
    WriteStatus("failed", 0, 0, 0, -1);
  }
  return Finish(rc);
}

int BatchRun::Finish(int rc) {
  stop_ = true;
  StopModels(client_, spawned_, std::cerr);
  bool stuck = false;
  {
    std::lock_guard<std::mutex> lock(slots_mutex_);
    for (auto& s : slots_) {
      bool in_call;
      {
        std::lock_guard<std::mutex> slot_lock(s->mutex);
        in_call = s->in_call;
      }
      if (in_call) {
        stuck = true;  // a call to a Model that no longer answers: not worth waiting for
        std::cerr << "note: " << s->name << " still has a call open; not waiting for it\n";
        s->thread.detach();
      } else {
        s->thread.join();
      }
    }
  }
  if (stuck) {
    std::cout.flush();
    std::cerr.flush();
    _exit(rc);
  }
  return rc;
}

int BatchRun::Dispatch() {
  LoadScenes();
  fs::create_directories(options_.out + "/runs");
  client_.Root();  // fails early with the address when the naming service is not there
  if (options_.spawn > 0) {
    std::string why;
    spawned_ = SpawnModels(client_, options_.spawn, std::cerr, &why);
    if (spawned_.empty()) throw Failure("no Model could be started: " + why);
    if (!why.empty())
      std::cerr << "started " << spawned_.size() << " of " << options_.spawn << " Models; " << why
                << "\n";
  }
  const auto waited = Clock::now();
  while (true) {
    pool_.Refresh(false);
    {
      std::lock_guard<std::mutex> lock(slots_mutex_);
      if (!slots_.empty()) break;
    }
    if (Since(waited) > options_.wait_models_s)
      throw Failure("no Model matching '" + options_.models + "' in " + client_.address() +
                    " after " + Fixed(options_.wait_models_s, 0) +
                    " s (start some: launch/caliper node, caliper-ctl create --count N)");
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  {
    std::lock_guard<std::mutex> lock(slots_mutex_);
    std::cerr << runs_.size() << " runs on " << slots_.size() << " Model"
              << (slots_.size() == 1 ? "" : "s") << " (more join as they appear); results in "
              << options_.out << "\n";
  }
  begin_ = last_progress_ = Clock::now();
  auto last_discovery = Clock::now(), last_watch = Clock::now();
  bool interrupted = false;
  while (!plan_.finished()) {
    plan_.WaitForChange(std::chrono::milliseconds(100));
    if (Interrupted()) {
      interrupted = interrupted_ = true;
      break;
    }
    if (Since(last_watch) < 0.5) continue;
    last_watch = Clock::now();
    Watch();
    if (Since(last_discovery) > 2) {
      pool_.Refresh(false);
      last_discovery = Clock::now();
    }
    Progress(false);
  }
  stop_ = true;
  // after an interruption runs still in flight may end while the summary is written: closed, the
  // plan keeps them unfinished (interrupted), and their results write no file
  plan_.Close();
  const std::vector<Outcome> summary = plan_.outcomes();  // no run ends any more
  {
    // every run that ended well has its file before the summary says so
    std::unique_lock<std::mutex> lock(written_mutex_);
    written_cv_.wait_for(lock, std::chrono::seconds(30), [&] {
      for (size_t i = 0; i < summary.size(); ++i)
        if (summary[i].state == Outcome::State::kDone && !written_[i]) return false;
      return true;
    });
  }
  const double wall = Since(begin_);
  Progress(true);
  WriteSummary(wall, summary);
  for (const auto& e : write_errors_) std::cerr << "error: " << e << "\n";
  const int rc = interrupted ? 130 : (plan_.failed() || !write_errors_.empty() ? 1 : 0);
  double sim_done = 0;
  for (size_t i = 0; i < summary.size(); ++i)
    if (summary[i].state == Outcome::State::kDone) sim_done += runs_[i].duration_s;
  WriteStatus(interrupted ? "interrupted" : rc == 0 ? "done" : "failed", 0, 0,
              wall > 0 ? sim_done / wall : 0, -1);
  return rc;
}

// The runs named in `only` (NAME,NAME,... or @FILE with one name per line), in the file's order;
// a name the file does not make is an error.
std::vector<experiment::Experiment> SelectRuns(std::vector<experiment::Experiment> runs,
                                               const std::string& only) {
  std::vector<std::string> names;
  if (!only.empty() && only.front() == '@') {
    std::ifstream in(only.substr(1));
    if (!in) throw Failure("--only: cannot read " + only.substr(1));
    for (std::string line; std::getline(in, line);)
      if (const std::string name = core::Trim(line); !name.empty()) names.push_back(name);
  } else {
    std::stringstream in(only);
    for (std::string name; std::getline(in, name, ',');)
      if (!core::Trim(name).empty()) names.push_back(core::Trim(name));
  }
  if (names.empty()) throw UsageError("--only: no run named in '" + only + "'");
  std::set<std::string> wanted(names.begin(), names.end()), known;
  std::vector<experiment::Experiment> kept;
  for (auto& r : runs) {
    known.insert(r.name);
    if (wanted.count(r.name)) kept.push_back(std::move(r));
  }
  for (const auto& n : wanted)
    if (!known.count(n))
      throw UsageError("--only: the experiment file makes no run named '" + n + "'");
  return kept;
}

int Batch(Client& client, std::vector<std::string>& args) {
  BatchOptions options;
  std::string value;
  if (TakeOption(args, "--out", &value)) options.out = value;
  TakeOption(args, "--models", &options.models);
  auto number = [&](const std::string& flag, double* target, double low) {
    if (!TakeOption(args, flag, &value)) return;
    double v = 0;
    if (!core::ParseDouble(value, &v) || !(v >= low))
      throw UsageError(flag + " takes a number >= " + Fixed(low, 1));
    *target = v;
  };
  double attempts = options.max_attempts;
  number("--stall-timeout", &options.stall_s, 0.5);
  number("--run-timeout", &options.run_timeout_s, 1);
  number("--max-attempts", &attempts, 1);
  if (options.run_timeout_s > 4e6) throw UsageError("--run-timeout: at most 4000000 s");
  if (attempts > 1000) throw UsageError("--max-attempts: at most 1000");
  number("--wait-models", &options.wait_models_s, 0);
  double spawn = 0;
  number("--spawn", &spawn, 1);
  if (spawn != std::floor(spawn) || spawn > 10000)
    throw UsageError("--spawn takes a whole number of Models from 1 to 10000");
  options.spawn = static_cast<unsigned long>(spawn);
  options.max_attempts = static_cast<int>(attempts);
  TakeOption(args, "--status", &options.status);
  std::string only;
  const bool select = TakeOption(args, "--only", &only);
  const bool list = TakeFlag(args, "--list");
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("expected one experiment FILE");
  options.file = args[0];
  std::vector<experiment::Experiment> runs;
  try {
    runs = experiment::LoadFile(options.file);
  } catch (const experiment::FormatError& e) {
    throw Failure(e.what());
  }
  if (select) runs = SelectRuns(std::move(runs), only);
  if (list) {
    for (const auto& r : runs) std::cout << r.name << "\n";
    return 0;
  }
  if (options.out.empty()) {
    const std::time_t now = std::time(nullptr);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
    options.out = fs::path(options.file).stem().string() + "-" + stamp;
  }
  BatchRun run(client, options, std::move(runs));
  return run.Run();
}

}  // namespace

void AddBatchVerb(std::map<std::string, Verb>* verbs) {
  Verb verb{
      "batch FILE [--out DIR] [--models GLOB] [--spawn N] [--stall-timeout S]\n"
      "          [--max-attempts N] [--run-timeout S] [--wait-models S] [--status FILE]\n"
      "          [--only NAMES|@FILE] [--list]",
      "run a file of experiments on every Model in the naming service, as fast as possible",
      Batch, "cluster",
      "  FILE is JSON: a scene, parameter overrides (\"set\"), a command schedule (\"commands\"\n"
      "  or \"commands_csv\"), the ids to \"record\", \"duration_s\", \"every_n_steps\", a\n"
      "  \"sweep\" over values, and a list of \"experiments\" (docs/cluster.md). Scenes are\n"
      "  sent by content: the Models need no shared disk (a .urdf scene is imported here, meshes\n"
      "  included, and sent as COLLADA). Each Model runs one experiment at a time from a fresh\n"
      "  load, so results are bit-identical wherever they run.\n"
      "  --models GLOB    Models to use, by instance (model*) or INSTANCE@HOST (*@nodeb);\n"
      "                   Models that appear later join in\n"
      "  --spawn N        ask the managers for N Models (the freest first), use only those and\n"
      "                   stop them at the end\n"
      "  --stall-timeout  a busy Model that does not answer for S s (5) loses its run to another\n"
      "  --max-attempts   tries per run before it is reported failed (5)\n"
      "  --run-timeout    the longest one run may take [s] (3600)\n"
      "  --wait-models    how long to wait for a first Model [s] (10)\n"
      "  --status FILE    the progress as JSON, rewritten every second: state (running,\n"
      "                   finishing, done, failed, interrupted), runs_total, runs_done,\n"
      "                   runs_failed, models, models_busy, sim_s_per_s, eta_s, wall_s\n"
      "                   (launch/caliper slurm status reads it)\n"
      "  --only NAMES     run only these runs: NAME,NAME,... or @FILE (one name per line)\n"
      "  --list           print the names of the runs (after --only) and exit\n"
      "  --out DIR        DIR/runs/NAME.csv (time [s] and the ids with units, in the shortest\n"
      "                   text that reads back exactly) and\n"
      "                   DIR/summary.csv (status, Model, attempts, times, every retry with its\n"
      "                   reason); default FILE-DATE-TIME. Progress goes to stderr.\n"
      "  A physics fault fails its run with the Model's report (not retried). Exit 0 when every\n"
      "  run is done, 1 when any failed, 130 on Ctrl-C or SIGTERM (the summary is written first,\n"
      "  the runs that did not finish marked interrupted).\n",
      true};
  (*verbs)["batch"] = verb;
}

}  // namespace caliper::ctl
