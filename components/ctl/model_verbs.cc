#include "model_verbs.h"

#include <signal.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "caliper/client/data_feed.h"
#include "caliper/client/scene_transfer.h"
#include "caliper/model.hh"
#include "caliper/core/confined_path.h"
#include "caliper/core/system.h"
#include "caliper/rtc/idl_names.h"
#include "caliper/model_file/model_file.h"
#include "csv_recording.h"
#include "model_client.h"

namespace caliper::ctl {
namespace {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;

// load, step and save take as long as their work: no short call timeout for them [ms]
constexpr CORBA::ULong kLongCallMs = 3600 * 1000;

S::StringSeq ToSeq(const std::vector<std::string>& ids) {
  S::StringSeq out;
  out.length(static_cast<CORBA::ULong>(ids.size()));
  for (CORBA::ULong i = 0; i < ids.size(); ++i) out[i] = ids[i].c_str();
  return out;
}


// Channel metadata by id (one list call).
std::map<std::string, D::ChannelInfo> Channels(const ModelRef& m, const std::string& pattern) {
  D::ChannelInfoSeq_var list = Call(m, [&] { return m.model->list(pattern.c_str()); });
  std::map<std::string, D::ChannelInfo> out;
  for (CORBA::ULong i = 0; i < list->length(); ++i) out[list[i].id.in()] = list[i];
  return out;
}

std::string UnitOf(const std::map<std::string, D::ChannelInfo>& channels, const std::string& id) {
  const auto it = channels.find(id);
  return it == channels.end() ? "" : it->second.unit.in();
}

// `id = v unit`, `id = [a, b, c] unit`, or a matrix row by row under `id (RxC, unit) =`.
void PrintValue(const std::string& id, const std::string& unit, const D::Value& v) {
  const CORBA::ULong n = v.data.length();
  const std::string u = unit.empty() ? "" : " " + unit;
  if (n == 1) {
    std::cout << id << " = " << Num(v.data[0]) << u << "\n";
  } else if (v.rows == 1 || v.cols == 1 || v.rows * v.cols != n) {
    std::cout << id << " = [";
    for (CORBA::ULong i = 0; i < n; ++i) std::cout << (i ? ", " : "") << Num(v.data[i]);
    std::cout << "]" << u << "\n";
  } else {
    size_t width = 0;
    for (CORBA::ULong i = 0; i < n; ++i) width = std::max(width, Num(v.data[i]).size());
    std::cout << id << " (" << v.rows << "x" << v.cols << (unit.empty() ? "" : ", " + unit)
              << ") =\n";
    for (CORBA::ULong r = 0; r < v.rows; ++r) {
      std::cout << " ";
      for (CORBA::ULong c = 0; c < v.cols; ++c)
        std::cout << " " << std::right << std::setw(static_cast<int>(width))
                  << Num(v.data[r * v.cols + c]);
      std::cout << "\n";
    }
  }
}

// ------------------------------------------------------------------------ simulation control

// `VERB FILE [--send] [--model NAME]`: the Model, FILE made absolute here (the Model's process
// has another working directory), and whether it travels by content (client::SendsByContent).
struct FileVerb {
  std::string name, path;
  ModelRef m;
  bool by_content = false;
};
FileVerb TakeFileVerb(Client& client, std::vector<std::string>& args,
                      core::ConfinedPaths::Access access) {
  FileVerb v;
  v.name = TakeModel(args);
  const bool send_flag = TakeFlag(args, "--send");
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("expected one FILE");
  v.path = Absolute(args[0]);
  v.m = Connect(client, v.name);
  v.by_content = Call(v.m, [&] {
    return client::SendsByContent(v.m.model, v.path, v.m.local, send_flag, access);
  });
  return v;
}

int Load(Client& client, std::vector<std::string>& args) {
  const FileVerb v = TakeFileVerb(client, args, core::ConfinedPaths::Access::kRead);
  const std::string &name = v.name, &path = v.path;
  const ModelRef& m = v.m;
  const bool send = v.by_content;
  omniORB::setClientCallTimeout(m.model, kLongCallMs);
  client::SentScene sent;
  Call(m, [&] {
    try {
      sent = client::LoadScene(m.model, path, send);  // a URDF converted to COLLADA here
    } catch (const M::LoadFailed& e) {
      std::string message = (send ? path + " (sent by content): " : std::string()) + e.reason.in();
      M::SimulationStatus_var s = StatusOf(m);
      if (s->state != M::EMPTY)
        message += "\n  (" + name + " keeps " + s->scene.in() + ", " + rtc::Name(s->state) + ")";
      throw Failure(message);
    } catch (const std::runtime_error& e) {
      throw Failure(e.what());
    }
  });
  for (const auto& w : sent.warnings) std::cerr << "warning: " << w << "\n";
  M::SimulationStatus_var s = StatusOf(m);
  std::cout << name << ": loaded " << path << (send ? " (sent by content)" : "") << " ("
            << rtc::Name(s->state) << ", time step "
            << Num(s->time_step) << " s)\n";
  return 0;
}

// start, pause, stop and reset: the call, then the state and time it left.
int Control(Client& client, std::vector<std::string>& args, const std::string& verb) {
  const std::string name = TakeModel(args);
  NoArguments(args);
  ModelRef m = Connect(client, name);
  Call(m, [&] {
    if (verb == "start")
      m.model->start();
    else if (verb == "pause")
      m.model->pause();
    else if (verb == "stop")
      m.model->stop();
    else
      m.model->reset();
  });
  M::SimulationStatus_var s = StatusOf(m);
  std::cout << name << ": " << rtc::Name(s->state) << " at t = " << Num(s->sim_time, 10) << " s\n";
  return 0;
}

int Step(Client& client, std::vector<std::string>& args) {
  const std::string name = TakeModel(args);
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("expected N, the number of steps");
  const CORBA::ULong n = ParseCount(args[0], "N");
  ModelRef m = Connect(client, name);
  M::SimulationStatus_var before = StatusOf(m);
  omniORB::setClientCallTimeout(m.model, kLongCallMs);
  CORBA::ULong ran = 0;
  Call(m, [&] { ran = m.model->step(n); });
  M::SimulationStatus_var after = StatusOf(m);
  const unsigned long long done = ran;
  if (after->state == M::FAULTED)
    throw Failure(name + ": the simulation faulted after " + std::to_string(done) + " of " +
                  std::to_string(n) + " steps: " + after->last_error.in());
  if (ran < n)
    std::cout << name << ": ended early by a stop or pause from another client after " << ran
              << " of " << n << " steps\n";
  std::cout << name << ": " << done << " steps, t = " << Num(after->sim_time, 10) << " s (+"
            << Num(after->sim_time - before->sim_time, 10) << " s), " << rtc::Name(after->state)
            << "\n";
  return 0;
}

int Status(Client& client, std::vector<std::string>& args) {
  const std::string name = TakeModel(args);
  NoArguments(args);
  ModelRef m = Connect(client, name);
  M::SimulationStatus_var s = StatusOf(m);
  const bool running = s->state == M::RUNNING;
  Line("model", name + " (" + m.path + ")");
  Line("state", rtc::Name(s->state));
  Line("scene", std::strlen(s->scene) > 0 ? s->scene.in() : "(none)");
  Line("simulated time [s]", Num(s->sim_time, 12));
  Line("steps", std::to_string(s->steps));
  Line("time step [s]", Num(s->time_step));
  Line("real-time factor",
       (s->real_time_factor == 0 ? std::string("0 (as fast as possible)")
                                 : Num(s->real_time_factor)) +
           " requested, " +
           (running ? Num(s->achieved_real_time_factor, 4) + " achieved (over the last second)"
                    : "- achieved (not running)"));
  Line("last error", std::strlen(s->last_error) > 0 ? s->last_error.in() : "-");
  return 0;
}

int Save(Client& client, std::vector<std::string>& args) {
  const FileVerb v = TakeFileVerb(client, args, core::ConfinedPaths::Access::kWrite);
  const std::string &name = v.name, &path = v.path;
  const ModelRef& m = v.m;
  const bool fetch = v.by_content;
  omniORB::setClientCallTimeout(m.model, kLongCallMs);
  if (fetch) {
    M::Octets_var data = Call(m, [&] { return m.model->export_scene(); });
    try {
      core::WriteFileReplacing(path, [&](std::ostream& out) {
        out.write(reinterpret_cast<const char*>(data->get_buffer()), data->length());
      });
    } catch (const std::exception& e) {
      throw Failure(e.what());
    }
  } else {
    Call(m, [&] { m.model->save_scene(path.c_str()); });
  }
  std::cout << name << ": saved the scene with its current parameters to " << path
            << (fetch ? " (fetched by content)" : "") << "\n";
  return 0;
}

// ------------------------------------------------------------------------ parameters and motors

int Params(Client& client, std::vector<std::string>& args) {
  const std::string name = TakeModel(args);
  RejectOptions(args);
  if (args.size() > 1) throw UsageError("expected at most one PATTERN");
  std::string pattern = args.empty() ? "*" : args[0];
  if (pattern.find_first_of("*?[") == std::string::npos) pattern = "*" + pattern + "*";
  ModelRef m = Connect(client, name);
  D::ChannelInfoSeq_var list = Call(m, [&] { return m.model->list(pattern.c_str()); });
  if (list->length() == 0) {
    M::SimulationStatus_var s = StatusOf(m);
    std::cout << (s->state == M::EMPTY ? "(no scene is loaded)"
                                       : "(no id matches '" + pattern + "')")
              << "\n";
    return 0;
  }
  // the scalars' current values, in one call
  std::vector<std::string> scalars;
  for (CORBA::ULong i = 0; i < list->length(); ++i)
    if (list[i].rows * list[i].cols == 1) scalars.emplace_back(list[i].id.in());
  std::map<std::string, double> values;
  if (!scalars.empty()) {
    const S::StringSeq ids = ToSeq(scalars);
    D::ValueSeq_var read = Call(m, [&] { return m.model->get(ids); });
    for (CORBA::ULong i = 0; i < read->length() && i < scalars.size(); ++i)
      if (read[i].data.length() == 1) values[scalars[i]] = read[i].data[0];
  }
  size_t id_width = 2, unit_width = 4;
  for (CORBA::ULong i = 0; i < list->length(); ++i) {
    id_width = std::max(id_width, std::strlen(list[i].id));
    unit_width = std::max(unit_width, std::strlen(list[i].unit));
  }
  const int iw = static_cast<int>(id_width + 2), uw = static_cast<int>(unit_width + 2);
  std::cout << std::left << std::setw(iw) << "ID" << std::setw(uw) << "UNIT" << std::setw(7)
            << "SHAPE" << std::setw(8) << "ACCESS" << std::setw(9) << "KIND"
            << "VALUE\n";
  for (CORBA::ULong i = 0; i < list->length(); ++i) {
    const D::ChannelInfo& c = list[i];
    const std::string unit = std::strlen(c.unit) > 0 ? c.unit.in() : "-";
    const auto value = values.find(c.id.in());
    std::cout << std::setw(iw) << c.id.in() << std::setw(uw) << unit << std::setw(7)
              << (std::to_string(c.rows) + "x" + std::to_string(c.cols)) << std::setw(8)
              << (c.writable ? "rw" : "ro") << std::setw(9) << (c.is_static ? "static" : "dynamic")
              << (value != values.end() ? Num(value->second) : "") << "\n";
  }
  return 0;
}

int Get(Client& client, std::vector<std::string>& args) {
  const std::string name = TakeModel(args);
  RejectOptions(args);
  if (args.empty()) throw UsageError("expected at least one ID");
  ModelRef m = Connect(client, name);
  const S::StringSeq ids = ToSeq(args);
  D::ValueSeq_var values = Call(m, [&] { return m.model->get(ids); });
  const auto channels = Channels(m, "*");
  for (CORBA::ULong i = 0; i < values->length() && i < args.size(); ++i)
    PrintValue(args[i], UnitOf(channels, args[i]), values[i]);
  return 0;
}

int Set(Client& client, std::vector<std::string>& args) {
  const std::string name = TakeModel(args);
  RejectOptions(args);
  if (args.size() < 2) throw UsageError("expected an ID and its value (one per element)");
  const std::string id = args[0];
  D::Value value;
  value.data.length(static_cast<CORBA::ULong>(args.size() - 1));
  for (size_t i = 1; i < args.size(); ++i)
    value.data[static_cast<CORBA::ULong>(i - 1)] = ParseNumber(args[i], "VALUE");
  ModelRef m = Connect(client, name);
  // the shape the Model wants; an unknown id or a wrong count is the Model's to name
  const auto channels = Channels(m, id);
  const auto it = channels.find(id);
  value.rows = value.data.length();
  value.cols = 1;
  if (it != channels.end() && it->second.rows * it->second.cols == value.data.length()) {
    value.rows = it->second.rows;
    value.cols = it->second.cols;
  }
  Call(m, [&] { m.model->set(id.c_str(), value); });
  M::SimulationStatus_var s = StatusOf(m);
  PrintValue(id, UnitOf(channels, id), value);
  if (s->state == M::RUNNING) std::cout << "(applied at the next step boundary)\n";
  return 0;
}

int Motor(Client& client, std::vector<std::string>& args) {
  const std::string name = TakeModel(args);
  RejectOptions(args);
  if (args.size() == 1 || args.size() > 2) throw UsageError("expected NAME VALUE (or nothing)");
  const double value = args.empty() ? 0.0 : ParseNumber(args[1], "VALUE");
  ModelRef m = Connect(client, name);
  M::ActuatorInfoSeq_var info = Call(m, [&] { return m.model->actuators(); });
  if (args.empty()) {
    M::ActuatorStateSeq_var states = Call(m, [&] { return m.model->actuator_states(); });
    size_t width = 4;
    for (CORBA::ULong i = 0; i < info->length(); ++i)
      width = std::max(width, std::strlen(info[i].name));
    const int w = static_cast<int>(width + 2);
    std::cout << std::left << std::setw(w) << "NAME" << std::setw(18) << "KIND" << std::setw(w)
              << "TENDON" << std::setw(18) << "COMMAND"
              << "TENSION [N]\n";
    for (CORBA::ULong i = 0; i < info->length() && i < states->length(); ++i)
      std::cout << std::setw(w) << info[i].name.in() << std::setw(18) << info[i].kind.in()
                << std::setw(w) << info[i].tendon.in() << std::setw(18)
                << (Num(states[i].command) + " " + info[i].command_unit.in())
                << Num(states[i].tension) << "\n";
    return 0;
  }
  const std::string actuator = args[0];
  Call(m, [&] { m.model->set_command(actuator.c_str(), value); });
  std::string unit;
  for (CORBA::ULong i = 0; i < info->length(); ++i)
    if (actuator == info[i].name.in()) unit = info[i].command_unit.in();
  std::cout << actuator << " command = " << Num(value) << (unit.empty() ? "" : " " + unit) << "\n";
  return 0;
}

// ------------------------------------------------------------------------ record

// `recording:  45% (t = 0.450 of 1 s), 45 samples`; a complete recording shows 100 %.
std::string Progress(const CsvRecording& r, double start, double duration) {
  const double t = std::isnan(r.last_time()) ? start : r.last_time();
  std::ostringstream s;
  s << std::fixed;
  if (std::isfinite(duration)) {
    const bool complete = r.done() && r.error().empty();
    const double share = complete ? 1.0 : std::clamp((t - start) / duration, 0.0, 1.0);
    s << "recording: " << std::setprecision(0) << std::setw(3) << 100 * share
      << "% (t = " << std::setprecision(3) << t - start << " of " << Num(duration) << " s), "
      << r.samples() << " samples";
  } else {
    s << "recording: t = " << std::setprecision(3) << t - start << " s, " << r.samples()
      << " samples (Ctrl-C ends)";
  }
  return s.str();
}

// How a recording's wait ended: what was shown last, and why it stopped early (if it did).
struct RecordEnd {
  std::string shown, lost, interrupted, ended;
  D::SubscriptionStatus counts{};  // the Model's, as last read
};

// Shows the progress until the recording is complete, Ctrl-C, or the Model is lost or ends the
// subscription; then reads the Model's counts for the report.
RecordEnd WaitForRecording(const ModelRef& m, const std::string& name, client::DataFeed& feed,
                           const CsvRecording& recording, double start, double duration) {
  // Ctrl-C and SIGTERM are blocked in every thread (Main) and taken here
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  using Clock = std::chrono::steady_clock;
  auto last_progress = Clock::now() - std::chrono::seconds(1);
  auto last_check = Clock::now();
  RecordEnd end;
  std::string& shown = end.shown;
  std::string& lost = end.lost;
  std::string& interrupted = end.interrupted;
  std::string& ended = end.ended;
  // why no samples come, shown after the progress: a Model that is not running sends none, and
  // a recording with a duration would otherwise wait without a word until someone starts it
  std::string idle_note;
  uint64_t samples_at_check = 0;
  D::SubscriptionStatus& counts = end.counts;  // the Model's, as last read
  auto read_counts = [&] {
    try {
      counts = feed.Status();
    } catch (const client::UnknownIdError& e) {
      ended = e.what();  // the Model ended it (a consumer that missed a push deadline)
    }
  };
  while (true) {
    {
      std::lock_guard<std::mutex> lock(feed.mutex());
      if (recording.done()) break;
    }
    const timespec wait = {0, 100 * 1000 * 1000};
    const int sig = sigtimedwait(&signals, nullptr, &wait);
    if (sig == SIGINT || sig == SIGTERM) {
      interrupted = sig == SIGINT ? "interrupted (Ctrl-C)" : "terminated (SIGTERM)";
      break;
    }
    const auto t = Clock::now();
    if (t - last_progress >= std::chrono::milliseconds(250)) {
      std::lock_guard<std::mutex> lock(feed.mutex());
      const std::string text = Progress(recording, start, duration) + idle_note;
      if (text != shown) std::cerr << "\r" << text << std::flush;
      shown = text;
      last_progress = t;
    }
    if (t - last_check >= std::chrono::seconds(1)) {
      // a Model that went away, or ended the subscription, sends nothing more: say so instead
      // of waiting forever
      try {
        read_counts();
      } catch (const client::ConnectionError& e) {
        lost = e.what();
        break;
      }
      if (!ended.empty()) break;
      uint64_t samples = 0;
      {
        std::lock_guard<std::mutex> lock(feed.mutex());
        samples = recording.samples();
      }
      // a step request samples while the state is not RUNNING: only a Model that sent nothing
      // for a second counts as idle
      idle_note.clear();
      if (samples == samples_at_check) {
        try {
          M::SimulationStatus_var now_status = m.model->status();
          if (now_status->state != M::RUNNING)
            idle_note = " - " + name + " is " + rtc::Name(now_status->state) +
                        ": waiting until it runs (caliper-ctl start) or steps";
        } catch (const CORBA::SystemException& e) {
          lost = Client::Unreachable(m.path, e);
          break;
        }
      }
      samples_at_check = samples;
      last_check = t;
    }
  }
  if (lost.empty() && ended.empty()) {
    try {
      read_counts();  // what the Model dropped, if anything, for the report
    } catch (const client::ConnectionError& e) {
      lost = e.what();
    }
  }
  return end;
}

int Record(Client& client, std::vector<std::string>& args) {
  const std::string name = TakeModel(args);
  std::string value, csv_path;
  CORBA::ULong every = 1;
  double duration = std::numeric_limits<double>::infinity();
  if (TakeOption(args, "--every", &value)) every = ParseCount(value, "--every");
  if (TakeOption(args, "--duration", &value)) {
    duration = ParseNumber(value, "--duration");
    if (!(duration > 0) || !std::isfinite(duration))
      throw UsageError("--duration wants seconds of simulated time > 0, got '" + value + "'");
  }
  if (!TakeOption(args, "--csv", &csv_path)) throw UsageError("--csv FILE is required");
  RejectOptions(args);
  if (args.empty()) throw UsageError("expected at least one ID");

  ModelRef m = Connect(client, name);
  const S::StringSeq ids = ToSeq(args);
  // shapes (and an unknown id, named by the Model) from one sample; units from the list
  D::ValueSeq_var now = Call(m, [&] { return m.model->get(ids); });
  const auto channels = Channels(m, "*");
  std::vector<RecordedChannel> columns;
  for (CORBA::ULong i = 0; i < now->length() && i < args.size(); ++i)
    columns.push_back({args[i], UnitOf(channels, args[i]), now[i].rows, now[i].cols});
  M::SimulationStatus_var status = StatusOf(m);
  const double start = status->sim_time;

  std::ofstream file(csv_path);
  if (!file) throw Failure("cannot write " + csv_path + ": " + std::strerror(errno));
  CsvRecording recording(file, columns, start + duration);

  // lossless: stepping in lock-step or as fast as possible, the Model waits for this recorder;
  // the batches come on ORB threads
  client::DataFeed feed(client, m, args, every, true, [&](const client::Batch& b) {
    recording.Add(b.number, b.times, b.count, b.data, b.values_per_sample);
  });
  std::cerr << "recording " << args.size() << " id" << (args.size() == 1 ? "" : "s") << " ("
            << recording.values_per_sample() << " columns) every " << every << " step"
            << (every == 1 ? "" : "s") << " (" << Num(every * status->time_step) << " s) "
            << (std::isfinite(duration) ? "for " + Num(duration) + " s of simulated time"
                                        : "until Ctrl-C")
            << " to " << csv_path << "\n";
  std::cerr << "lossless: " << name << " waits for this recorder when it steps (step N, "
            << "lock-step, as fast as possible); at a real-time factor it does not, and samples "
            << "it drops are counted\n";
  if (status->state != M::RUNNING)
    std::cerr << name << " is " << rtc::Name(status->state)
              << ": samples come once it runs (caliper-ctl start) or steps\n";

  RecordEnd end = WaitForRecording(m, name, feed, recording, start, duration);
  const std::string &shown = end.shown, &lost = end.lost, &interrupted = end.interrupted,
                    &ended = end.ended;
  const D::SubscriptionStatus& counts = end.counts;
  feed.Close();
  file.flush();
  const bool written = static_cast<bool>(file);
  file.close();

  std::lock_guard<std::mutex> lock(feed.mutex());
  const std::string last = Progress(recording, start, duration);
  // blanks over the rest of a longer line shown before (one with the idle note)
  std::cerr << "\r" << last
            << std::string(shown.size() > last.size() ? shown.size() - last.size() : 0, ' ')
            << "\n";
  if (!interrupted.empty()) std::cerr << interrupted << "\n";
  std::cout << "wrote " << recording.samples() << " samples";
  if (recording.samples() > 0)
    std::cout << " (t = " << Num(recording.first_time(), 10) << " .. "
              << Num(recording.last_time(), 10) << " s)";
  std::cout << " to " << csv_path << "\n";
  if (recording.missing_batches() == 0)
    std::cout << "no gaps: " << feed.batches() << " batch"
              << (feed.batches() == 1 ? "" : "es") << ", numbered without a break\n";
  else
    std::cout << "gaps: " << recording.missing_batches() << " batches never arrived (numbers "
              << recording.gaps() << "); the samples they held are missing from the file\n";
  if (ended.empty() && lost.empty()) {
    if (counts.dropped_samples == 0)
      std::cout << "dropped: none (the Model's count";
    else
      std::cout << "dropped: " << counts.dropped_samples << " samples in "
                << counts.dropped_batches << " batches (the Model's count; a real-time run "
                << "does not wait for a recorder slower than the simulation";
    if (counts.waited > 0)
      std::cout << "; it waited " << Num(counts.waited, 3) << " s for this recorder";
    std::cout << ")\n";
  }
  if (!feed.stale().empty()) {
    std::cerr << "warning: ids no longer in the Model (a scene was loaded; their values are nan):";
    for (const auto& id : feed.stale()) std::cerr << " " << id;
    std::cerr << "\n";
  }
  if (!written) throw Failure("write error on " + csv_path);
  if (!lost.empty()) throw Failure(lost);
  if (!ended.empty()) throw Failure(ended);
  if (!recording.error().empty()) throw Failure(recording.error());
  return 0;
}

// ------------------------------------------------------------------------ edit

void PrintEditStatus(const M::EditStatus& s) {
  std::cout << "revision " << s.revision << "\n";
  if (std::strlen(s.last.in()) > 0) std::cout << "last: " << s.last.in() << "\n";
  std::cout << "undo: " << (std::strlen(s.undo.in()) > 0 ? s.undo.in() : "(nothing)") << "\n";
  std::cout << "redo: " << (std::strlen(s.redo.in()) > 0 ? s.redo.in() : "(nothing)") << "\n";
}

S::PathPoint PointArgs(const std::vector<std::string>& args, size_t at) {
  if (args.size() < at + 4) throw UsageError("expected BODY X Y Z (metres in the body's frame)");
  S::PathPoint p;
  p.body = (args[at] == "world" ? "" : args[at]).c_str();
  p.x = ParseNumber(args[at + 1], "X [m]");
  p.y = ParseNumber(args[at + 2], "Y [m]");
  p.z = ParseNumber(args[at + 3], "Z [m]");
  p.obstacle = "";
  return p;
}

CORBA::ULong IndexArg(const std::string& text) {
  const double v = ParseNumber(text, "INDEX");
  if (!(v >= 0) || v != std::floor(v) || v > 1e6)
    throw UsageError("INDEX must be a path element number (0 = the first attachment)");
  return static_cast<CORBA::ULong>(v);
}

void NeedArgs(const std::vector<std::string>& args, size_t n, const std::string& usage) {
  if (args.size() != n) throw UsageError("expected: edit " + usage);
}

// `edit` alone: the history and the selection.
int EditShowStatus(const ModelRef& m) {
  M::EditStatus_var s = Call(m, [&] { return m.model->edit_status(); });
  PrintEditStatus(s.in());
  M::Selection_var sel = Call(m, [&] { return m.model->current_selection(); });
  std::cout << "selected: "
            << (std::strlen(sel->kind.in()) == 0
                    ? std::string("(nothing)")
                    : std::string(sel->kind.in()) + " " + sel->name.in() +
                          (std::string(sel->kind.in()) == "path_point"
                               ? " element " + std::to_string(sel->index)
                               : ""))
            << "\n";
  return 0;
}

// `edit path TENDON`: its declared path in millimetres.
int EditShowPath(const ModelRef& m, const std::vector<std::string>& a) {
  NeedArgs(a, 1, "path TENDON");
  S::Description_var d = Call(m, [&] { return m.model->scene_description(); });
  for (CORBA::ULong i = 0; i < d->tendons.length(); ++i) {
    if (a[0] != d->tendons[i].name.in()) continue;
    const S::PathPointSeq& path = d->tendons[i].path;
    // millimetres to read; the edits take metres, as every length of the IDL
    std::cout << "ELEMENT  BODY / OBSTACLE        X [mm]      Y [mm]      Z [mm]   (edits take m)\n";
    for (CORBA::ULong k = 0; k < path.length(); ++k) {
      const bool wrap = std::strlen(path[k].obstacle.in()) > 0;
      std::cout << std::left << std::setw(9) << k << std::setw(22)
                << (wrap ? "wrap " + std::string(path[k].obstacle.in())
                         : std::strlen(path[k].body.in()) ? std::string(path[k].body.in())
                                                          : std::string("world"));
      if (!wrap)
        std::cout << std::right << std::setw(10) << Num(path[k].x * 1000, 4) << std::setw(12)
                  << Num(path[k].y * 1000, 4) << std::setw(12) << Num(path[k].z * 1000, 4)
                  << std::left;
      std::cout << "\n";
    }
    return 0;
  }
  throw Failure(m.name + ": no tendon '" + a[0] + "'");
}

// `edit delays`: the channels that read late, with their delays in ms and in time steps.
int EditShowDelays(const ModelRef& m, const std::vector<std::string>& a) {
  NeedArgs(a, 0, "delays");
  S::SensorDelaySeq_var delays = Call(m, [&] { return m.model->measurement_delays(); });
  if (delays->length() == 0) {
    std::cout << "no channel reads late (edit delay CHANNEL SECONDS sets one)\n";
    return 0;
  }
  M::SimulationStatus_var status = Call(m, [&] { return m.model->status(); });
  const double dt = status->time_step;  // [s]
  std::cout << "CHANNEL                              DELAY [ms]   STEPS (of " << Num(dt * 1e3)
            << " ms)\n";
  for (CORBA::ULong i = 0; i < delays->length(); ++i) {
    const S::SensorDelay& delay = delays[i];
    std::cout << std::left << std::setw(37) << delay.id.in() << std::right << std::setw(10)
              << Num(delay.delay * 1e3) << std::setw(8) << std::lround(delay.delay / dt)
              << std::left << "\n";
  }
  return 0;
}

// `edit kinds`: the actuator kinds with their parameters' defaults.
int EditShowKinds(const ModelRef& m, const std::vector<std::string>& a) {
  NeedArgs(a, 0, "kinds");
  M::ActuatorKindSeq_var kinds = Call(m, [&] { return m.model->actuator_kinds(); });
  for (CORBA::ULong i = 0; i < kinds->length(); ++i) {
    std::cout << kinds[i].kind.in()
              << (std::strlen(kinds[i].command_unit.in()) ? " (command in " +
                                                                 std::string(kinds[i].command_unit.in()) + ")"
                                                           : std::string(" (passive)"))
              << "\n";
    for (CORBA::ULong p = 0; p < kinds[i].parameters.length(); ++p)
      std::cout << "  " << kinds[i].parameters[p].in() << " = " << Num(kinds[i].defaults[p])
                << " " << kinds[i].units[p].in() << "\n";
  }
  return 0;
}

// `edit shapes BODY`: a body's collision shapes, in set_shape_dims' order.
int EditShowShapes(const ModelRef& m, const std::vector<std::string>& a) {
  NeedArgs(a, 1, "shapes BODY");
  S::VisualSeq_var shapes = Call(m, [&] { return m.model->body_shapes(a[0].c_str()); });
  static const char* const kKinds[] = {"box",  "sphere", "capsule",     "cylinder",
                                       "cone", "plane",  "convex_hull", "triangle_mesh"};
  for (CORBA::ULong i = 0; i < shapes->length(); ++i) {
    std::cout << i << " " << kKinds[shapes[i].geometry.kind] << " " << shapes[i].name.in();
    for (CORBA::ULong k = 0; k < shapes[i].geometry.dims.length(); ++k)
      std::cout << " " << Num(shapes[i].geometry.dims[k]);
    std::cout << (shapes[i].geometry.dims.length() ? " m" : "") << "\n";
  }
  return 0;
}

// `edit obstacle NAME BODY KIND X Y Z RADIUS [LENGTH]`: the obstacle to set.
S::Obstacle ObstacleArgs(const ModelRef& m, const std::vector<std::string>& a) {
  if (a.size() != 7 && a.size() != 8)
    throw UsageError("expected: edit obstacle NAME BODY sphere|cylinder X Y Z RADIUS [LENGTH]");
  S::Obstacle o;
  o.name = a[0].c_str();
  o.body = (a[1] == "world" ? "" : a[1]).c_str();
  o.kind = a[2].c_str();
  o.pose = {ParseNumber(a[3], "X [m]"), ParseNumber(a[4], "Y [m]"), ParseNumber(a[5], "Z [m]"),
            1, 0, 0, 0};
  // an obstacle moved and resized keeps its orientation (a cylinder's axis)
  S::Description_var d = Call(m, [&] { return m.model->scene_description(); });
  for (CORBA::ULong i = 0; i < d->obstacles.length(); ++i)
    if (a[0] == d->obstacles[i].name.in()) {
      o.pose.qw = d->obstacles[i].pose.qw;
      o.pose.qx = d->obstacles[i].pose.qx;
      o.pose.qy = d->obstacles[i].pose.qy;
      o.pose.qz = d->obstacles[i].pose.qz;
    }
  o.radius = ParseNumber(a[6], "RADIUS [m]");
  o.length = a.size() == 8 ? ParseNumber(a[7], "LENGTH [m]") : 0.0;
  return o;
}

// `edit pull BODY X Y Z`: a spring on the body's origin toward the target, renewed until the
// time is up or Ctrl-C, then released.
int EditPull(const ModelRef& m, const std::vector<std::string>& a,
             const std::string& stiffness_text, const std::string& hold_text) {
  NeedArgs(a, 4, "pull BODY X Y Z [--stiffness N_PER_M] (target, world metres)");
  M::Vector3 point{0, 0, 0};
  M::Vector3 target{ParseNumber(a[1], "X [m]"), ParseNumber(a[2], "Y [m]"),
                    ParseNumber(a[3], "Z [m]")};
  const double k = ParseNumber(stiffness_text, "--stiffness [N/m]");
  const double hold = ParseNumber(hold_text, "--for [s]");
  if (!(hold >= 0)) throw UsageError("--for needs seconds >= 0 (0: until Ctrl-C)");
  // the Model ends a pull that is not renewed within 2 s (a client gone mid-drag): renew it
  // every half second while this runs, and release it at the end
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  Call(m, [&] { m.model->pull(a[0].c_str(), point, target, k); });
  std::cerr << "pulling " << a[0] << "'s origin toward " << a[1] << " " << a[2] << " " << a[3]
            << " m " << (hold > 0 ? "for " + Num(hold) + " s" : std::string("until Ctrl-C"))
            << "\n";
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(hold);
  while (hold == 0 || std::chrono::steady_clock::now() < until) {
    const timespec wait = {0, 500 * 1000 * 1000};
    const int sig = sigtimedwait(&signals, nullptr, &wait);
    if (sig == SIGINT || sig == SIGTERM) break;
    Call(m, [&] { m.model->pull(a[0].c_str(), point, target, k); });
  }
  Call(m, [&] { m.model->release_pull(); });
  std::cerr << "pull released\n";
  return 0;
}

int Edit(Client& client, std::vector<std::string>& args) {
  const std::string name = TakeModel(args);
  std::string stiffness_text = "0", hold_text = "0";
  TakeOption(args, "--stiffness", &stiffness_text);
  TakeOption(args, "--for", &hold_text);
  RejectOptions(args);
  ModelRef m = Connect(client, name);
  if (args.empty()) return EditShowStatus(m);
  const std::string what = args[0];
  std::vector<std::string> a(args.begin() + 1, args.end());
  M::EditStatus_var s;
  if (what == "path") {
    return EditShowPath(m, a);
  } else if (what == "kinds") {
    return EditShowKinds(m, a);
  } else if (what == "delays") {
    return EditShowDelays(m, a);
  } else if (what == "move" || what == "insert") {
    if (a.size() == 4 && what == "insert" && a[2] == "--wrap") a.erase(a.begin() + 2);
    if (what == "insert" && a.size() == 3) {
      // insert TENDON INDEX OBSTACLE: a wrap
      S::PathPoint p;
      p.body = "";
      p.x = p.y = p.z = 0;
      p.obstacle = a[2].c_str();
      s = Call(m, [&] { return m.model->insert_path_point(a[0].c_str(), IndexArg(a[1]), p); });
    } else {
      NeedArgs(a, 6, what + " TENDON INDEX BODY X Y Z");
      const S::PathPoint p = PointArgs(a, 2);
      s = Call(m, [&] {
        return what == "move" ? m.model->move_path_point(a[0].c_str(), IndexArg(a[1]), p)
                              : m.model->insert_path_point(a[0].c_str(), IndexArg(a[1]), p);
      });
    }
  } else if (what == "remove-point") {
    NeedArgs(a, 2, "remove-point TENDON INDEX");
    s = Call(m, [&] { return m.model->remove_path_point(a[0].c_str(), IndexArg(a[1])); });
  } else if (what == "add-tendon") {
    if (a.size() != 10 && a.size() != 11)
      throw UsageError(
          "expected: edit add-tendon TENDON BODY_A X Y Z BODY_B X Y Z KIND [ACTUATOR]");
    const S::PathPoint from = PointArgs(a, 1), to = PointArgs(a, 5);
    const std::string actuator = a.size() == 11 ? a[10] : a[0];
    s = Call(m, [&] {
      return m.model->add_tendon(a[0].c_str(), from, to, 0.0015, actuator.c_str(), a[9].c_str());
    });
  } else if (what == "remove-tendon") {
    NeedArgs(a, 1, "remove-tendon TENDON");
    s = Call(m, [&] { return m.model->remove_tendon(a[0].c_str()); });
  } else if (what == "obstacle") {
    const S::Obstacle o = ObstacleArgs(m, a);
    s = Call(m, [&] { return m.model->set_obstacle(o); });
  } else if (what == "remove-obstacle") {
    NeedArgs(a, 1, "remove-obstacle NAME");
    s = Call(m, [&] { return m.model->remove_obstacle(a[0].c_str()); });
  } else if (what == "shape") {
    if (a.size() < 3) throw UsageError("expected: edit shape BODY INDEX DIM... (metres)");
    S::DoubleSeq dims;
    dims.length(static_cast<CORBA::ULong>(a.size() - 2));
    for (size_t i = 2; i < a.size(); ++i)
      dims[static_cast<CORBA::ULong>(i - 2)] = ParseNumber(a[i], "DIM [m]");
    s = Call(m, [&] { return m.model->set_shape_dims(a[0].c_str(), IndexArg(a[1]), dims); });
  } else if (what == "shapes") {
    return EditShowShapes(m, a);
  } else if (what == "mass") {
    NeedArgs(a, 2, "mass BODY KG");
    s = Call(m, [&] { return m.model->set_mass(a[0].c_str(), ParseNumber(a[1], "KG")); });
  } else if (what == "delay") {
    NeedArgs(a, 2, "delay CHANNEL SECONDS");
    s = Call(m, [&] {
      return m.model->set_measurement_delay(a[0].c_str(), ParseNumber(a[1], "SECONDS"));
    });
  } else if (what == "undo" || what == "redo") {
    NeedArgs(a, 0, what);
    s = Call(m, [&] { return what == "undo" ? m.model->undo() : m.model->redo(); });
  } else if (what == "pull") {
    return EditPull(m, a, stiffness_text, hold_text);
  } else if (what == "select") {
    if (a.empty() || a.size() > 3) throw UsageError("expected: edit select KIND NAME [INDEX] or none");
    if (a[0] == "none") a = {"", "", "0"};
    if (a.size() == 2) a.push_back("0");
    Call(m, [&] { m.model->select(a[0].c_str(), a[1].c_str(), IndexArg(a[2])); });
    return 0;
  } else {
    throw UsageError("unknown edit '" + what + "' (see caliper-ctl edit --help)");
  }
  PrintEditStatus(s.in());
  return 0;
}

}  // namespace

void AddModelVerbs(std::map<std::string, Verb>* verbs) {
  const std::string on = "  The Model is model0, or --model NAME.\n";
  auto add = [&](const std::string& name, const std::string& usage, const std::string& summary,
                 std::function<int(Client&, std::vector<std::string>&)> run,
                 const std::string& details, bool takes_interrupt = false) {
    Verb verb{usage, summary, std::move(run), "model", details + on};
    verb.takes_interrupt = takes_interrupt;
    (*verbs)[name] = verb;
  };
  add("load", "load FILE [--send] [--model NAME]",
      "load a scene (COLLADA .dae, .zae or URDF .urdf) into a Model", Load,
      "  On failure the Model keeps (and runs) the scene it had, and the importer's message\n"
      "  (file, line, element, problem) is printed. FILE is sent as an absolute path to a Model\n"
      "  on this host that reads it (below its model.read_dirs or write directory; for a URDF\n"
      "  its meshes too), else by content: to one on another host, with --send, or for files\n"
      "  elsewhere. By content a .dae or .zae goes as its bytes, a .urdf as the robot imported\n"
      "  here (meshes from its folder and the package path, $CALIPER_PACKAGE_PATH then\n"
      "  $ROS_PACKAGE_PATH) and converted to COLLADA (NAME.dae); its warnings are printed.\n");
  for (const std::string v : {"start", "pause", "stop"}) {
    const std::string summary = v == "start"   ? "run the simulation (at the real-time factor)"
                                : v == "pause" ? "pause the simulation"
                                               : "pause and rewind to the loaded state";
    add(
        v, v + " [--model NAME]", summary,
        [v](Client& c, std::vector<std::string>& a) { return Control(c, a, v); }, "");
  }
  const Verb lifecycle = (*verbs)["reset"];
  add(
      "reset", "reset NAME | reset [--model NAME]",
      "reset a component in ERROR; without NAME, rewind a Model keeping its run state",
      [lifecycle](Client& c, std::vector<std::string>& a) {
        std::vector<std::string> probe = a;
        std::string model;
        const bool has_model = TakeOption(probe, "--model", &model);
        RejectOptions(probe);
        if (!probe.empty() && has_model)
          throw UsageError("give NAME (a component's lifecycle) or --model NAME, not both");
        if (!probe.empty()) return lifecycle.run(c, a);
        return Control(c, a, "reset");
      },
      "  reset NAME: in NAME's execution context, from ERROR back to INACTIVE (any component).\n"
      "  reset [--model NAME]: rewinds the Model's simulation to the loaded state; a running\n"
      "  simulation keeps running.\n");
  (*verbs)["reset"].group = "components";
  add("step", "step N [--model NAME]", "run N steps now (while not running), then pause", Step,
      "  Returns when the N steps are done and prints the simulated time they advanced.\n"
      "  Exits 1 when the simulation faults on the way.\n");
  add("status", "status [--model NAME]",
      "a Model's state, scene, simulated time, steps, time step, real-time factor, last error",
      Status, "");
  add("params", "params [PATTERN] [--model NAME]",
      "list a Model's parameters and states: id, unit, shape, rw/ro, static/dynamic, value", Params,
      "  PATTERN is a glob (*, ?, [set]: fnmatch(3)); without one it matches the ids that\n"
      "  contain it.\n"
      "  VALUE is the current value of scalars.\n");
  add("get", "get ID... [--model NAME]", "print values with their units", Get,
      "  Vectors print on one line, matrices row by row.\n");
  add("set", "set ID VALUE... [--model NAME]",
      "write a parameter (as many values as its shape, row-major)", Set,
      "  Applied at the next step boundary while running, at once otherwise. Read-only ids,\n"
      "  NaN or infinite values and values the engine refuses fail with the reason.\n");
  add("motor", "motor [NAME VALUE] [--model NAME]",
      "set an actuator's command; without arguments list actuators, commands and tensions", Motor,
      "  VALUE is in the actuator's command unit (V for dc_motor_tendon).\n");
  add("record", "record ID... --csv FILE [--every N] [--duration T] [--model NAME]",
      "stream ids to a CSV file with units, for T s of simulated time or until Ctrl-C", Record,
      "  Subscribes to the Model's data acquisition: one sample every N steps (1), one column\n"
      "  per scalar element (`time [s],arm.hand.position[0] [m],...`). Progress goes to stderr;\n"
      "  at the end it reports the samples written, any gaps in batch numbers and the samples\n"
      "  the Model dropped. Lossless: stepping in lock-step (step N, an external execution\n"
      "  context) or as fast as possible, the Model waits for this recorder, so the file holds\n"
      "  every sample; at a real-time factor it does not wait, and what it drops is counted.\n"
      "  A recorder that misses the Model's push deadline (1 s; e.g. stopped) is dropped by\n"
      "  the Model: record then exits 1 with the Model's reason.\n",
      true);
  add("edit", "edit [WHAT ARGS...] [--model NAME]",
      "edit the running scene: tendon routes, obstacles, shapes, masses, measurement delays; "
      "undo, redo; pull",
      Edit,
      "  Without WHAT: the edit history (what undo and redo would do) and the GUI's selection.\n"
      "  Positions are metres in the named body's frame (`world` for the world); each edit is\n"
      "  checked as an imported file is and refused with the reason, and applies at the next\n"
      "  step boundary, the simulation going on from where it is. `save` writes the result.\n"
      "    path TENDON                        its elements: index, body or wrap, position [mm]\n"
      "    move TENDON INDEX BODY X Y Z       move an attachment or via point\n"
      "    insert TENDON INDEX BODY X Y Z     a via point before element INDEX\n"
      "    insert TENDON INDEX OBSTACLE       a wrap around OBSTACLE before element INDEX\n"
      "    remove-point TENDON INDEX          remove a via point or wrap\n"
      "    add-tendon TENDON BODY_A X Y Z BODY_B X Y Z KIND [ACTUATOR]\n"
      "                                       a tendon with an actuator of KIND at its defaults\n"
      "    remove-tendon TENDON               with its actuators\n"
      "    kinds                              actuator kinds with their parameters' defaults\n"
      "    obstacle NAME BODY sphere|cylinder X Y Z RADIUS [LENGTH]   add, or move and resize\n"
      "    remove-obstacle NAME               one no tendon wraps around\n"
      "    shapes BODY / shape BODY INDEX DIM...   list / set a collision shape's dimensions\n"
      "    mass BODY KG                       the inertia scales with the mass\n"
      "    delay CHANNEL SECONDS              every reader sees CHANNEL that late (whole time\n"
      "                                       steps); 0 removes the delay; CHANNEL.undelayed\n"
      "                                       reads the true value\n"
      "    delays                             the channels that read late: delay [ms], steps\n"
      "    undo / redo\n"
      "    pull BODY X Y Z [--stiffness K] [--for S]   spring the body's origin toward a world\n"
      "                                       point [m] until Ctrl-C (or S seconds), then release\n"
      "    select KIND NAME [INDEX] / select none   what the GUI shows as selected\n",
      true);
  add("save", "save FILE [--send] [--model NAME]",
      "export the scene with its current parameters as COLLADA", Save,
      "  Whatever was loaded (COLLADA or URDF), FILE is COLLADA with Caliper's technique.\n"
      "  FILE is written by the Model's process (sent as an absolute path) when it lies below\n"
      "  the Model's write directory (model.write_dir: the session's files/ folder when\n"
      "  `launch/caliper session` or `demo` started the Model); otherwise (a Model on another\n"
      "  host, --send, files elsewhere) the export comes back by content and is written here.\n");
}

}  // namespace caliper::ctl
