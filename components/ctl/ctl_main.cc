// caliper-ctl: the command line client, in the spirit of rtshell.
#include <signal.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "caliper/actuators/actuator.h"
#include "caliper/collada/exporter.h"
#include "caliper/collada/importer.h"
#include "caliper/model_file/model_file.h"
#include "caliper/core/arguments.h"
#include "caliper/core/numbers.h"
#include "caliper/core/system.h"
#include "caliper/logging.hh"
#include "caliper/logging/message_pattern.h"
#include "caliper/logging/record.h"
#include "caliper/rtc.hh"
#include "caliper/rtc/log_service_sink.h"
#include "caliper/rtc/idl_names.h"
#include "caliper/rtc/naming.h"
#include "client.h"
#include "cluster_verbs.h"
#include "inspect.h"
#include "batch.h"
#include "model_verbs.h"
#include "recording_verbs.h"
#include "renderer_verbs.h"

namespace caliper::ctl {
namespace {

namespace RTC = ::Caliper::RTC;
namespace LogIdl = ::Caliper::Logging;

RTC::LifeCycleState StateOf(RTC::LightweightRTObject_ptr comp) {
  RTC::ExecutionContextList_var ecs = comp->get_owned_contexts();
  if (ecs->length() == 0) throw Failure("the component owns no execution context");
  return ecs[0]->get_component_state(comp);
}

std::string OneName(std::vector<std::string>& args) {
  if (args.size() != 1) throw UsageError("expected exactly one component name");
  return args[0];
}

int List(Client& client, std::vector<std::string>& args) {
  if (!args.empty()) throw UsageError("ls takes no arguments");
  CosNaming::NamingContext_var root = client.Root();
  const auto entries = rtc::ListComponents(root);
  std::cout << std::left << std::setw(17) << "NAME" << std::setw(12) << "STATE" << std::setw(15)
            << "TYPE" << std::setw(8) << "PID" << "PATH\n";
  for (const auto& e : entries) {
    std::string state = "UNREACHABLE", type = "-", pid = "-";
    try {
      RTC::LightweightRTObject_var comp = RTC::LightweightRTObject::_narrow(e.object);
      if (!CORBA::is_nil(comp)) {
        state = rtc::Name(StateOf(comp));
        RTC::ComponentProfile_var profile = comp->get_component_profile();
        type = profile->type_name.in();
        for (CORBA::ULong i = 0; i < profile->properties.length(); ++i)
          if (std::string(profile->properties[i].name) == "pid")
            pid = profile->properties[i].value.in();
      }
    } catch (const CORBA::Exception&) {
    } catch (const Failure&) {
    }
    std::cout << std::setw(17) << e.instance << std::setw(12) << state << std::setw(15) << type
              << std::setw(8) << pid << e.path << "\n";
  }
  if (entries.empty()) std::cout << "(no components bound in " << client.address() << ")\n";
  return 0;
}

int State(Client& client, std::vector<std::string>& args) {
  std::string path;
  RTC::LightweightRTObject_var comp = client.Component(OneName(args), &path);
  try {
    const auto state = StateOf(comp);
    std::cout << rtc::Name(state) << "\n";
    if (state == RTC::ERROR_STATE) {
      CORBA::String_var why = comp->get_last_error();
      std::cout << "reason: " << why.in() << "\n";
    }
    return 0;
  } catch (const CORBA::Exception& e) {
    throw Failure(Client::Unreachable(path, e));
  }
}

int Transition(Client& client, std::vector<std::string>& args, const std::string& verb) {
  std::string path;
  const std::string name = OneName(args);
  RTC::LightweightRTObject_var comp = client.Component(name, &path);
  try {
    RTC::ReturnCode rc;
    if (verb == "exit") {
      rc = comp->exit();
    } else {
      RTC::ExecutionContextList_var ecs = comp->get_owned_contexts();
      if (ecs->length() == 0) throw Failure(path + " owns no execution context");
      RTC::ExecutionContext_ptr ec = ecs[0];
      rc = verb == "activate"     ? ec->activate_component(comp)
           : verb == "deactivate" ? ec->deactivate_component(comp)
                                  : ec->reset_component(comp);
    }
    if (rc != RTC::RTC_OK) {
      std::string msg = verb + " " + name + ": " + rtc::Name(rc);
      if (verb != "exit") msg += std::string(" (state is ") + rtc::Name(StateOf(comp)) + ")";
      CORBA::String_var why = comp->get_last_error();
      if (rc == RTC::RTC_ERROR && std::strlen(why.in()) > 0) msg += "; reason: " + std::string(why);
      throw Failure(msg);
    }
    if (verb == "exit")
      std::cout << name << ": exiting\n";
    else
      std::cout << name << ": " << rtc::Name(StateOf(comp)) << "\n";
    return 0;
  } catch (const CORBA::Exception& e) {
    throw Failure(Client::Unreachable(path, e));
  }
}

void Print(const LogIdl::StoredRecord& s) {
  const auto& r = s.rec;
  std::cout << core::FormatTime(r.time_us) << " " << std::left << std::setw(7)
            << logging::PriorityName(r.priority) << std::setw(10) << r.instance.in() << " ["
            << r.category.in() << "] " << r.message.in() << "\n";
}

class FollowListener : public virtual POA_Caliper::Logging::LogListener {
 public:
  FollowListener(const LogIdl::RecordFilter& filter, CORBA::ULongLong* printed_serial)
      : filter_(filter), printed_(printed_serial) {
    if (std::strlen(filter_.regex) > 0) pattern_.emplace(filter_.regex.in());
  }
  void on_records(const LogIdl::StoredRecordSeq& records) override {
    std::lock_guard<std::mutex> lock(mutex_);
    for (CORBA::ULong i = 0; i < records.length(); ++i) {
      const auto& s = records[i];
      if (s.serial <= *printed_ || !Matches(s.rec)) continue;
      Print(s);
      *printed_ = s.serial;
    }
    std::cout.flush();
  }
  std::mutex mutex_;

 private:
  bool Matches(const LogIdl::Record& r) const {
    if (r.priority > filter_.max_priority) return false;
    if (std::string(r.category).rfind(filter_.category_prefix.in(), 0) != 0) return false;
    if (std::strlen(filter_.instance) > 0 && std::string(r.instance) != filter_.instance.in())
      return false;
    if (pattern_ && !pattern_->Search(r.message.in())) return false;
    return true;
  }
  LogIdl::RecordFilter filter_;
  std::optional<logging::MessagePattern> pattern_;
  CORBA::ULongLong* printed_;
};

int Log(Client& client, std::vector<std::string>& args) {
  LogIdl::RecordFilter q;
  q.max_priority = logging::kDebug;
  q.category_prefix = "";
  q.instance = "";
  q.regex = "";
  q.from_time_us = 0;
  q.to_time_us = 0;
  q.after_serial = 0;
  q.limit = 50;
  std::string value, service = "logger0";
  if (TakeOption(args, "--min-priority", &value)) {
    int p;
    if (!logging::ParsePriority(value, &p))
      throw UsageError("--min-priority: '" + value + "' is not fatal|error|warn|info|debug");
    q.max_priority = p;
  }
  if (TakeOption(args, "--category", &value)) q.category_prefix = value.c_str();
  if (TakeOption(args, "--component", &value)) q.instance = value.c_str();
  if (TakeOption(args, "--grep", &value)) {
    try {
      logging::MessagePattern check(value);
    } catch (const logging::PatternError& e) {
      throw UsageError(std::string("--grep: ") + e.what());
    }
    q.regex = value.c_str();
  }
  if (TakeOption(args, "--limit", &value)) q.limit = static_cast<CORBA::ULong>(std::stoul(value));
  TakeOption(args, "--service", &service);
  const bool follow = TakeFlag(args, "--follow");
  if (!args.empty()) throw UsageError("unexpected argument '" + args[0] + "'");

  rtc::ComponentEntry entry = client.Find(service);
  try {
    LogIdl::LogService_var logger = LogIdl::LogService::_narrow(entry.object);
    if (CORBA::is_nil(logger)) throw Failure(entry.path + " is not a Logging component");
    CORBA::ULongLong printed = 0;
    FollowListener* listener = nullptr;
    CORBA::ULongLong listener_id = 0;
    if (follow) {
      // listen first, then print the backlog: nothing falls between the two
      PortableServer::POA_var poa = client.RootPoa();
      listener = new FollowListener(q, &printed);
      PortableServer::ObjectId_var id = poa->activate_object(listener);
      listener->_remove_ref();  // the POA owns it
      CORBA::Object_var ref = poa->id_to_reference(id);
      listener_id = logger->add_listener(LogIdl::LogListener::_narrow(ref));
      listener->mutex_.lock();
    }
    LogIdl::StoredRecordSeq_var records = logger->query(q);
    for (CORBA::ULong i = 0; i < records->length(); ++i) {
      Print(records[i]);
      printed = records[i].serial;
    }
    std::cout.flush();
    if (!follow) return 0;
    listener->mutex_.unlock();
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    int sig = 0;
    sigwait(&set, &sig);
    try {
      logger->remove_listener(listener_id);
    } catch (const CORBA::Exception&) {
    }
    return 0;
  } catch (const LogIdl::InvalidQuery& e) {
    throw UsageError(e.reason.in());
  } catch (const CORBA::Exception& e) {
    throw Failure(Client::Unreachable(entry.path, e));
  }
}

// The registry of actuator kinds, with no session.
int Kinds(Client&, std::vector<std::string>& args) {
  const bool markdown = core::TakeFlag(args, "--markdown");
  for (const auto& a : args)
    if (a.size() > 1 && a[0] == '-') throw UsageError("unknown option '" + a + "'");
  if (args.size() > 1) throw UsageError("expected at most one KIND");
  std::vector<std::string> kinds = actuators::Kinds();
  if (!args.empty()) {
    if (std::find(kinds.begin(), kinds.end(), args[0]) == kinds.end())
      throw Failure("no actuator kind '" + args[0] + "'");
    kinds = {args[0]};
  }
  auto number = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  for (const auto& kind : kinds) {
    const auto& specs = actuators::KindParameters(kind);
    if (markdown) {
      std::cout << "## " << kind << "\n\n| parameter | unit | default | what |\n| --- | --- | --- | --- |\n";
      for (const auto& p : specs)
        std::cout << "| `" << p.name << "` | " << (p.unit.empty() ? "-" : p.unit) << " | "
                  << (p.required ? "required" : number(p.default_value)) << " | " << p.help
                  << " |\n";
      std::cout << "\n";
      continue;
    }
    std::cout << kind << " (" << specs.size() << " parameters)\n";
    for (const auto& p : specs)
      std::cout << "  " << std::left << std::setw(42) << p.name << std::setw(11)
                << (p.unit.empty() ? "-" : p.unit) << std::setw(10)
                << (p.required ? "required" : number(p.default_value)) << " " << p.help << "\n";
  }
  return 0;
}

// Reads a scene file with no session: the ORB is never started.
int Inspect(Client&, std::vector<std::string>& args) {
  std::string out_path;
  const bool export_scene = TakeOption(args, "--export", &out_path);
  for (const auto& a : args)
    if (a.size() > 1 && a[0] == '-') throw UsageError("unknown option '" + a + "'");
  if (args.size() != 1)
    throw UsageError(args.empty() ? "expected a file" : "expected one file, got " +
                                                            std::to_string(args.size()));
  const std::string& path = args[0];
  std::vector<std::string> warnings;
  collada::FileInfo info;
  sgal::Scene scene;
  try {
    scene = model_file::FormatOf(path) == model_file::Format::kUrdf
                ? model_file::Import(path, &warnings)
                : collada::Import(path, &warnings, &info);
  } catch (const collada::ImportError& e) {
    for (const auto& w : warnings) std::cerr << "warning: " << w << "\n";
    throw Failure(std::string("not imported: ") + e.what());
  }
  PrintSceneReport(path, scene, info, warnings, std::cout);
  if (export_scene) {
    try {
      collada::Export(scene, out_path);
    } catch (const collada::ExportError& e) {
      throw Failure(e.what());
    }
    std::cout << "exported to " << out_path << "\n";
  }
  return 0;
}

// The naming service this program uses, once it answers: the address on stdout (for $(...) and
// `export`), where it came from on stderr.
int Address(Client& client, std::vector<std::string>& args) {
  const bool as_export = TakeFlag(args, "--export");
  if (!args.empty()) throw UsageError("address takes no arguments but --export");
  CosNaming::NamingContext_var root = client.Root();  // ConnectionError when nothing answers
  std::cerr << "caliper-ctl: the naming service of " << client.address_source() << "\n";
  if (as_export) {
    // single quotes for the shell, a quote inside written as '\''
    std::string quoted;
    for (const char c : client.address())
      quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    std::cout << "export CALIPER_NAMESERVICE='" << quoted << "'\n";
  } else {
    std::cout << client.address() << "\n";
  }
  return 0;
}

std::map<std::string, Verb> Verbs() {
  std::map<std::string, Verb> verbs;
  verbs["ls"] = {"ls", "list the components in the naming service with their states", List};
  verbs["address"] = {"address [--export]",
                      "print the session's naming service address (and, on stderr, whose it is)",
                      Address};
  verbs["address"].details =
      "  The address every verb would use, once its naming service answers (exit 1 when not).\n"
      "  --export prints `export CALIPER_NAMESERVICE='...'` for your shell:\n"
      "    eval \"$(launch/caliper ctl address --export)\"\n";
  verbs["state"] = {"state NAME", "print a component's lifecycle state (and why, in ERROR)", State};
  for (const std::string v : {"activate", "deactivate", "reset", "exit"}) {
    verbs[v] = {v + " NAME",
                v == "exit" ? "end a component's process cleanly"
                            : v + " a component in its execution context",
                [v](Client& c, std::vector<std::string>& a) { return Transition(c, a, v); }};
  }
  verbs["log"] = {"log [--follow] [--min-priority P] [--category PREFIX] [--component NAME]\n"
                  "          [--grep REGEX] [--limit N] [--service LOGGER]",
                  "print the session log (the newest N records, 50 by default); --follow keeps "
                  "printing new ones until Ctrl-C",
                  Log};
  verbs["log"].takes_interrupt = true;
  verbs["log"].details =
      "  --grep REGEX  a regular expression in RE2 syntax (no backreferences or lookaround), at\n"
      "                most " +
      std::to_string(logging::kMaxPatternBytes) +
      " bytes, searched anywhere in the message\n"
      "  --limit N     the logger returns at most 10000 records per query\n";
  verbs["kinds"] = {"kinds [KIND] [--markdown]",
                    "list the actuator kinds and every parameter each takes, with its unit and "
                    "default (no session needed)",
                    Kinds, "files"};
  verbs["kinds"].details =
      "  The parameters a model file's <param> may give an actuator of that kind (and the\n"
      "  Model's `ACTUATOR.PARAMETER` ids); --markdown prints tables (docs/reference).\n";
  verbs["inspect"] = {"inspect FILE [--export OUT.dae]",
                      "report what a model file (COLLADA .dae, .zae or URDF .urdf) holds, or why "
                      "it does not import (no session needed); --export writes the imported scene "
                      "as COLLADA",
                      Inspect, "files"};
  AddModelVerbs(&verbs);
  AddRendererVerbs(&verbs);
  AddClusterVerbs(&verbs);
  AddRecordingVerbs(&verbs);
  AddBatchVerb(&verbs);
  return verbs;
}

void PrintHelp(const std::map<std::string, Verb>& verbs) {
  std::cout << "Usage: caliper-ctl [--nameservice corbaname::HOST:PORT] [--timeout S] VERB ...\n\n"
            << "Talks to a running Caliper session. The naming service is --nameservice, else\n"
            << "$CALIPER_NAMESERVICE, else the newest session launch/caliper started that still\n"
            << "runs, else the one of `launch/caliper nameserver start`, else\n"
            << "corbaname::127.0.0.1:2809; a $CALIPER_NAMESERVICE naming a local session that has\n"
            << "ended gives way to a running session, with a note on stderr (`address` says\n"
            << "which).\n"
            << "NAME is an instance name (model0), model0@host (as batch summaries print it),\n"
            << "host/model0, or host.host_cxt/model0.rtc.\n"
            << "`inspect` and `kinds` need no session.\n";
  const std::pair<const char*, const char*> groups[] = {
      {"components", "Components"},
      {"model", "Model (model0, or --model NAME on each verb)"},
      {"cluster", "Cluster (a manager per host starts and stops Models)"},
      {"renderer", "Scene Renderer (renderer0, or --renderer NAME)"},
      {"files", "Files"}};
  for (const auto& [group, title] : groups) {
    std::cout << "\n" << title << ":\n";
    for (const auto& [name, verb] : verbs)
      if (verb.group == group)
        std::cout << "  " << std::left << std::setw(12) << name << verb.summary << "\n";
  }
  std::cout << "\n`caliper-ctl VERB --help` describes one verb. Exit status: 0 done, 1 failed, "
               "2 bad usage.\n";
}

int Main(int argc, char** argv) {
  const auto verbs = Verbs();
  client::SessionOptions options;
  options.program = "caliper-ctl";
  // the global options, up to the verb; the verb's own follow it
  core::ArgumentSpec spec;
  spec.valued = {"--nameservice", "--timeout"};
  spec.stop_at_positional = true;
  const core::Arguments global = core::ParseArguments({argv + 1, argv + argc}, spec);
  if (global.help) {
    PrintHelp(verbs);
    return 0;
  }
  if (!global.missing_value.empty()) {
    std::cerr << "caliper-ctl: " << global.missing_value << " needs a value\n";
    return 2;
  }
  if (!global.unknown.empty()) {
    std::cerr << "caliper-ctl: unknown option " << global.unknown << " (see --help)\n";
    return 2;
  }
  options.nameservice = global.Value("--nameservice", options.nameservice);
  if (global.Has("--timeout") &&
      (!core::ParseDouble(global.Value("--timeout"), &options.timeout_s) ||
       !(options.timeout_s > 0))) {
    std::cerr << "caliper-ctl: --timeout wants seconds > 0\n";
    return 2;
  }
  if (global.positional.empty()) {
    PrintHelp(verbs);
    return 2;
  }
  const std::string verb_name = global.positional[0];
  std::vector<std::string> rest(global.positional.begin() + 1, global.positional.end());
  const auto it = verbs.find(verb_name);
  if (it == verbs.end()) {
    std::cerr << "caliper-ctl: unknown verb '" << verb_name << "' (see --help)\n";
    return 2;
  }
  const Verb& verb = it->second;
  if (TakeFlag(rest, "--help") || TakeFlag(rest, "-h")) {
    std::cout << "Usage: caliper-ctl " << verb.usage << "\n  " << verb.summary << "\n"
              << verb.details;
    return 0;
  }
  if (verb.takes_interrupt) {
    // taken with sigwait by the verb: blocked before the ORB starts its threads
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
  }
  try {
    Client client(options);
    return verb.run(client, rest);
  } catch (const UsageError& e) {
    std::cerr << "caliper-ctl " << verb_name << ": " << e.what() << "\nUsage: caliper-ctl "
              << verb.usage << "\n";
    return 2;
  } catch (const Failure& e) {
    std::cerr << "caliper-ctl " << verb_name << ": " << e.what() << "\n";
    return 1;
  } catch (const CORBA::Exception& e) {
    std::cerr << "caliper-ctl " << verb_name << ": " << rtc::Describe(e) << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "caliper-ctl " << verb_name << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace
}  // namespace caliper::ctl

int main(int argc, char** argv) { return caliper::ctl::Main(argc, argv); }
