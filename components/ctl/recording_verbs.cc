#include "recording_verbs.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>

#include "caliper/collada/importer.h"
#include "caliper/core/numbers.h"
#include "caliper/core/system.h"
#include "caliper/client/scene_transfer.h"
#include "caliper/model.hh"
#include "caliper/recording/recording.h"
#include "model_client.h"

namespace caliper::ctl {
namespace {

namespace M = ::Caliper::Simulation;

// open_replay and seek re-simulate up to a keyframe interval: no short call timeout [ms]
constexpr CORBA::ULong kLongCallMs = 600 * 1000;
// the recording summaries' labels are longer than the Model's status labels
constexpr int kLabelWidth = 30;

ModelRef ConnectWithLongCalls(Client& client, std::vector<std::string>& args) {
  ModelRef m = Connect(client, TakeModel(args));
  omniORB::setClientCallTimeout(m.model, kLongCallMs);
  return m;
}

// Where the Model reads or writes, for the message when it refuses a path.
std::string WhereModelWrites(const ModelRef& m) {
  try {
    M::FileAccess_var files = m.model->file_access();
    return std::strlen(files->write_dir) > 0 ? std::string(files->write_dir.in())
                                             : std::string("(none: model.write_dir is not set)");
  } catch (const CORBA::Exception&) {
    return "(unknown)";
  }
}

double BytesPerSimulatedMinute(unsigned long long bytes, double seconds) {
  return seconds > 0 ? bytes / seconds * 60 : 0;
}

void PrintRecordStatus(const M::RecordStatus& s, double time_step_s, bool final = false) {
  const double seconds = s.steps * time_step_s;
  Line("recording", s.recording ? "yes" : "no", kLabelWidth);
  Line("file (on the Model's host)", std::strlen(s.path) > 0 ? s.path.in() : "-", kLabelWidth);
  if (std::strlen(s.path) > 0) {
    Line("first step", std::to_string(s.first_step), kLabelWidth);
    Line("steps recorded", std::to_string(s.steps), kLabelWidth);
    Line("simulated time recorded [s]", Num(seconds, 9), kLabelWidth);
    Line("size [bytes]",
         std::to_string(s.bytes) + (final ? "" : " (at the last commit, <= 0.5 s ago)"),
         kLabelWidth);
    Line("bytes per simulated minute",
         seconds > 0 ? Num(BytesPerSimulatedMinute(s.bytes, seconds), 4) : "-", kLabelWidth);
  }
  Line("error", std::strlen(s.error) > 0 ? s.error.in() : "-", kLabelWidth);
}

double TimeStepOf(const ModelRef& m) {
  M::SimulationStatus_var st = StatusOf(m);
  return st->time_step;
}

int RecordingStart(const ModelRef& m, std::vector<std::string>& args) {
  M::RecordOptions o;
  o.keyframe_every = 100;
  o.channels_every = 1;
  o.max_bytes = 0;
  std::vector<std::string> channels;
  std::string value;
  while (TakeOption(args, "--channel", &value)) channels.push_back(value);
  if (TakeOption(args, "--every", &value)) o.channels_every = ParseCount(value, "--every");
  if (TakeOption(args, "--keyframe-every", &value))
    o.keyframe_every = static_cast<CORBA::ULong>(ParseWhole(value, "--keyframe-every", 1000ull));
  if (TakeOption(args, "--max-mb", &value)) {
    double mb = 0;
    std::string why;
    if (!core::ParseDouble(value, &mb, &why) || !(mb > 0) || mb > 1e9)
      throw UsageError("--max-mb wants megabytes > 0 (10^6 bytes), got '" + value + "'");
    o.max_bytes = static_cast<CORBA::ULongLong>(mb * 1e6);
  }
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("expected: recording start FILE [options]");
  o.channels.length(static_cast<CORBA::ULong>(channels.size()));
  for (CORBA::ULong i = 0; i < channels.size(); ++i) o.channels[i] = channels[i].c_str();
  // relative names start from the Model's write directory (the session's files/); the Model
  // adds .caliper to a name without an extension
  const std::string& path = args[0];
  M::RecordStatus_var s;
  try {
    s = Call(m, [&] { return m.model->start_recording(path.c_str(), o); });
  } catch (const Failure& e) {
    const std::string why = e.what();
    // a path outside the write directory: say where the Model does write
    if (why.find("start_recording:") != std::string::npos)
      throw Failure(why + "\n  the Model writes recordings only below its write directory " +
                    WhereModelWrites(m) + " (model.write_dir)");
    throw;
  }
  std::cout << m.name << ": recording to " << s->path.in() << "\n";
  PrintRecordStatus(s.in(), TimeStepOf(m));
  return 0;
}

int RecordingStop(const ModelRef& m) {
  const double dt = TimeStepOf(m);
  M::RecordStatus_var before = Call(m, [&] { return m.model->recording_status(); });
  M::RecordStatus_var s = Call(m, [&] { return m.model->stop_recording(); });
  if (std::strlen(s->path) == 0) {
    if (std::strlen(s->error) > 0)
      throw Failure(m.name + ": not recording; the last recording stopped early: " + s->error.in());
    throw Failure(m.name + ": not recording");
  }
  // the stop commits the rest: on this host the file's final size is at hand
  unsigned long long bytes = before->bytes;
  std::error_code ec;
  if (m.local) {
    const auto size = std::filesystem::file_size(s->path.in(), ec);
    if (!ec) bytes = size;
  }
  s->bytes = bytes;
  std::cout << m.name << ": stopped recording " << s->path.in() << "\n";
  PrintRecordStatus(s.in(), dt, m.local);
  return 0;
}

int Recording(Client& client, std::vector<std::string>& args) {
  if (args.empty() || args[0].rfind("--", 0) == 0)
    throw UsageError("expected: recording start FILE | stop | status");
  const std::string what = args[0];
  args.erase(args.begin());
  ModelRef m = ConnectWithLongCalls(client, args);
  if (what == "start") return RecordingStart(m, args);
  NoArguments(args);
  if (what == "stop") return RecordingStop(m);
  if (what == "status") {
    M::RecordStatus_var s = Call(m, [&] { return m.model->recording_status(); });
    PrintRecordStatus(s.in(), TimeStepOf(m));
    return 0;
  }
  throw UsageError("unknown 'recording " + what + "' (start, stop or status)");
}

// ------------------------------------------------------------------------ replay on a Model

void PrintReplayStatus(const M::ReplayStatus& s) {
  Line("replaying", s.replaying ? "yes" : "no", kLabelWidth);
  if (!s.replaying) return;
  Line("file (on the Model's host)", s.path.in(), kLabelWidth);
  Line("time / end [s]", Num(s.time, 9) + " / " + Num(s.end_time, 9), kLabelWidth);
  Line("step / last", std::to_string(s.step) + " / " + std::to_string(s.last_step), kLabelWidth);
  Line("first step", std::to_string(s.first_step), kLabelWidth);
  Line("start time [s]", Num(s.start_time, 9), kLabelWidth);
}

// ------------------------------------------------------------------------ the file alone

std::string FileSize(const std::string& path, unsigned long long* bytes) {
  std::error_code ec;
  *bytes = std::filesystem::file_size(path, ec);
  if (ec) *bytes = 0;
  // a killed writer leaves its last commits in the write-ahead log beside the file
  const auto wal = std::filesystem::file_size(path + "-wal", ec);
  const bool with_wal = !ec && wal > 0;
  if (with_wal) *bytes += wal;
  return std::to_string(*bytes) + (with_wal ? " (with its write-ahead log)" : "");
}

int Info(const std::string& path) {
  recording::Reader reader(path);
  const recording::Header& h = reader.header();
  const uint64_t last = reader.last_step();
  Line("file", path, kLabelWidth);
  Line("model", h.model_name, kLabelWidth);
  const auto scenes = reader.scenes();
  Line("scene",
       h.scene_file_name + (scenes.size() > 1
                                ? " (and " + std::to_string(scenes.size() - 1) + " edited versions)"
                                : std::string()),
       kLabelWidth);
  Line("time step [s]", Num(h.time_step), kLabelWidth);
  Line("steps",
       std::to_string(last - h.first_step) + " (" + std::to_string(h.first_step) + " to " +
           std::to_string(last) + ")",
       kLabelWidth);
  Line("duration [s]", Num(reader.duration(), 9), kLabelWidth);
  Line("keyframes",
       std::to_string(reader.keyframe_steps().size()) + " (every " +
           std::to_string(h.keyframe_every) + " steps)",
       kLabelWidth);
  if (h.channels.empty()) {
    Line("channels", "none", kLabelWidth);
  } else {
    Line("channels",
         std::to_string(h.channels.size()) + " (a sample every " +
             std::to_string(h.channels_every) + " steps)",
         kLabelWidth);
    // ids are often longer than the label column: one per line, the unit after a space
    for (const auto& c : h.channels)
      std::cout << "  " << c.id << " [" << c.unit << "]"
                << (c.rows * c.cols > 1
                        ? " " + std::to_string(c.rows) + "x" + std::to_string(c.cols)
                        : std::string())
                << "\n";
  }
  std::map<std::string, size_t> kinds;
  for (const auto& e : reader.Events(0, last + 1)) ++kinds[e.kind];
  std::string events;
  for (const auto& [kind, n] : kinds)
    events += (events.empty() ? "" : ", ") + std::to_string(n) + " " + kind;
  Line("events", events.empty() ? "none" : events, kLabelWidth);
  Line("log records", std::to_string(reader.Log().size()), kLabelWidth);
  unsigned long long bytes = 0;
  Line("file size [bytes]", FileSize(path, &bytes), kLabelWidth);
  Line("bytes per simulated minute",
       reader.duration() > 0 ? Num(BytesPerSimulatedMinute(bytes, reader.duration()), 4) : "-",
       kLabelWidth);
  return 0;
}

// Re-simulates in a Model process started for it (caliper-model --verify, beside this program
// or in $CALIPER_BIN_DIR), so that caliper-ctl links no physics.
int Verify(const std::string& path) {
  const char* dir = std::getenv("CALIPER_BIN_DIR");
  const std::string model =
      (dir != nullptr && *dir != '\0' ? std::string(dir) : core::ProgramDirectory()) +
      "/caliper-model";
  std::cout.flush();
  const pid_t pid = fork();
  if (pid < 0) throw Failure(std::string("cannot start ") + model + ": " + std::strerror(errno));
  if (pid == 0) {
    execl(model.c_str(), model.c_str(), "--verify", path.c_str(), static_cast<char*>(nullptr));
    std::cerr << "caliper-ctl replay: cannot run " << model << ": " << std::strerror(errno)
              << "\n";
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status) == 0 ? 0 : 1;
  throw Failure(model + " --verify ended by signal " + std::to_string(WTERMSIG(status)));
}

int Replay(Client& client, std::vector<std::string>& args) {
  std::string file;
  if (TakeOption(args, "--info", &file)) {
    NoArguments(args);
    return Info(file);
  }
  if (TakeOption(args, "--verify", &file)) {
    NoArguments(args);
    return Verify(file);
  }
  if (TakeOption(args, "--csv", &file)) {
    RejectOptions(args);
    if (args.size() != 1) throw UsageError("expected: replay --csv FILE OUT.csv");
    recording::Reader(file).ExportCsv(args[0]);
    std::cout << "wrote the channels of " << file << " to " << args[0] << "\n";
    return 0;
  }
  ModelRef m = ConnectWithLongCalls(client, args);
  // the Model's refusals of commands during a replay name `replay --fork`
  if (TakeFlag(args, "--fork")) args.insert(args.begin(), "fork");
  const bool send = TakeFlag(args, "--send");
  RejectOptions(args);
  if (args.empty()) throw UsageError("expected: replay FILE | seek SECONDS | fork | status");
  const std::string what = args[0];
  M::ReplayStatus_var s;
  if (what == "seek") {
    if (args.size() != 2) throw UsageError("expected: replay seek SECONDS");
    const double t = ParseNumber(args[1], "SECONDS");
    s = Call(m, [&] { return m.model->seek(t); });
  } else if (what == "fork") {
    if (args.size() != 1) throw UsageError("replay fork takes no arguments");
    M::ReplayStatus_var at = Call(m, [&] { return m.model->replay_status(); });
    Call(m, [&] { m.model->fork(); });
    std::cout << m.name << ": forked at " << Num(at->time, 9) << " s (step " << at->step
              << "); commands, parameter writes and edits are accepted again\n";
    return 0;
  } else if (what == "status") {
    if (args.size() != 1) throw UsageError("replay status takes no arguments");
    s = Call(m, [&] { return m.model->replay_status(); });
  } else {
    if (args.size() != 1) throw UsageError("expected one FILE");
    const std::string path = Absolute(what);
    client::OpenedReplay opened;
    try {
      opened = Call(m, [&] { return client::OpenReplay(m.model, what, m.local, send); });
    } catch (const std::runtime_error& e) {
      if (dynamic_cast<const Failure*>(&e) != nullptr) throw;
      throw Failure(e.what());  // the file, read here
    }
    s = new M::ReplayStatus(opened.status);
    std::cout << m.name << ": replaying " << (opened.by_content ? path : std::string(s->path.in()))
              << (opened.by_content ? " (sent by content)" : "")
              << " (paused; start, pause, step and rtf play it)\n";
  }
  PrintReplayStatus(s.in());
  return 0;
}

// The speed of a run or a replay (there was no verb for set_real_time_factor before replays).
int Rtf(Client& client, std::vector<std::string>& args) {
  ModelRef m = ConnectWithLongCalls(client, args);
  RejectOptions(args);
  if (args.size() > 1) throw UsageError("expected at most one FACTOR");
  if (args.size() == 1) {
    const double f = ParseNumber(args[0], "FACTOR");
    Call(m, [&] { m.model->set_real_time_factor(f); });
  }
  M::SimulationStatus_var s = StatusOf(m);
  std::cout << m.name << ": real-time factor "
            << (s->real_time_factor == 0 ? std::string("0 (as fast as possible)")
                                         : Num(s->real_time_factor))
            << " requested\n";
  return 0;
}

// The file-alone forms throw these: their messages name the file.
template <class F>
int FileErrors(F&& f, Client& client, std::vector<std::string>& args) {
  try {
    return f(client, args);
  } catch (const recording::RecordingError& e) {
    throw Failure(e.what());
  } catch (const collada::ImportError& e) {
    throw Failure(e.what());
  }
}

}  // namespace

void AddRecordingVerbs(std::map<std::string, Verb>* verbs) {
  const std::string on = "  The Model is model0, or --model NAME.\n";
  Verb rec{
      "recording start FILE [--channel ID]... [--every N] [--keyframe-every N] [--max-mb M]\n"
      "          | recording stop | recording status   [--model NAME]",
      "record the session to one SQLite file on the Model's host; stop; how it goes", Recording,
      "model",
      "  start: the Model writes FILE from the present step on: the scene, a full-state\n"
      "  keyframe every N steps (--keyframe-every, 100), every command, parameter write,\n"
      "  pull and edit with its step, the Model's log and the channels ID (--channel, as\n"
      "  often as needed) every N steps (--every, 1). It commits at least every 0.5 s, so\n"
      "  a killed Model loses at most that. FILE (NAME.caliper; .caliper is added to a name\n"
      "  without an extension) must not exist; a relative FILE starts from the Model's write\n"
      "  directory (model.write_dir: the session's files/ when the launcher started it), an\n"
      "  absolute one must lie below it.\n"
      "  --max-mb M ends the recording, as a full disk does, beyond M megabytes (10^6\n"
      "  bytes); the simulation goes on and `recording status` says why it ended.\n"
      "  A load, stop or reset of the simulation ends a recording too.\n"
      "  stop: ends it and prints steps, simulated seconds, bytes and bytes per simulated\n"
      "  minute. status: the same while recording, and why the last recording ended early.\n" +
          on};
  (*verbs)["recording"] = rec;
  Verb replay{
      "replay FILE [--send] | replay seek SECONDS | replay fork | replay status   [--model NAME]\n"
      "          | replay --info FILE | replay --verify FILE | replay --csv FILE OUT.csv",
      "play a recording in a Model, seek, fork; a recording's summary, verification, CSV",
      [](Client& c, std::vector<std::string>& a) { return FileErrors(Replay, c, a); }, "model",
      "  replay FILE: the Model loads the recording at its start, paused: by path when FILE\n"
      "  lies below its read directories or its write directory on this host, else (another\n"
      "  host, files elsewhere, --send) by content, as a copy it keeps while it replays it,\n"
      "  so a recording of an earlier session replays in today's. A NAME that is no file\n"
      "  here is the Model's: relative, it starts from its write directory (where\n"
      "  `recording start NAME` writes), also on another host. Play it with the usual\n"
      "  verbs: start (at the real-time factor), pause, step N, rtf F (speed; 0 as fast as\n"
      "  possible); it pauses at its end; stop and reset go back to its start. Observers and\n"
      "  `record` (the DAQ) see it as a running Model. Commands, parameter writes and edits\n"
      "  are refused until fork.\n"
      "  seek SECONDS: to the moment nearest SECONDS of simulated time, from a keyframe.\n"
      "  fork (or --fork): the Model simulates on from where the replay stands; commands,\n"
      "  parameter writes and edits are allowed again.\n"
      "  status: simulated time and end [s], step and last step.\n"
      "  These need no session (the file is read here):\n"
      "  --info FILE: model, scene, duration [s], steps, keyframes, channels with units, events\n"
      "  by kind, file size and bytes per simulated minute.\n"
      "  --verify FILE: re-simulates the recording from its start in a Model of this process\n"
      "  and compares every keyframe and channel sample bit for bit (progress on stderr);\n"
      "  exits 1 naming the first divergence.\n"
      "  --csv FILE OUT.csv: the recorded channels as CSV, `time [s]` then a column per\n"
      "  element with its unit.\n" +
          on};
  (*verbs)["replay"] = replay;
  (*verbs)["rtf"] =
      Verb{"rtf [FACTOR] [--model NAME]",
           "set (or print) the real-time factor: 1 real time, 0 as fast as possible", Rtf, "model",
           "  The speed of a run and of a replay (0.1 is ten times slower than real\n"
           "  time); it applies at once, also while running.\n" +
               on};
}

}  // namespace caliper::ctl
