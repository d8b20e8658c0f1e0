#include "cluster_verbs.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "caliper/cluster.hh"

namespace caliper::ctl {
namespace {

namespace C = ::Caliper::Cluster;
namespace RTC = ::Caliper::RTC;

// create waits until the new Model is bound, destroy until it ended (KILL after 5 s) [ms]
constexpr CORBA::ULong kLongCallMs = 300 * 1000;

// A manager as found in the naming service; `manager` is nil when it does not answer.
struct ManagerRef {
  rtc::ComponentEntry entry;
  C::Manager_var manager;
  std::string error;  // why it does not answer
};

// Every manager bound: its profile says type manager, or (when it does not answer) its
// instance name starts with `manager`.
std::vector<ManagerRef> Managers(Client& client) {
  CosNaming::NamingContext_var root = client.Root();
  std::vector<ManagerRef> out;
  for (auto& e : rtc::ListComponents(root)) {
    ManagerRef m;
    try {
      RTC::LightweightRTObject_var comp = RTC::LightweightRTObject::_narrow(e.object);
      if (CORBA::is_nil(comp)) continue;
      RTC::ComponentProfile_var profile = comp->get_component_profile();
      if (std::string(profile->type_name) != "manager") continue;
      m.manager = C::Manager::_narrow(e.object);
    } catch (const CORBA::Exception& ex) {
      if (e.instance.rfind("manager", 0) != 0) continue;
      m.error = Client::Unreachable(e.path, ex);
    }
    m.entry = std::move(e);
    out.push_back(std::move(m));
  }
  return out;
}

// The managers a verb works on: --manager NAME, else all of them.
std::vector<ManagerRef> Targets(Client& client, std::vector<std::string>& args) {
  std::string name;
  if (!TakeOption(args, "--manager", &name)) return Managers(client);
  ManagerRef m;
  m.entry = client.Find(name);
  try {
    m.manager = C::Manager::_narrow(m.entry.object);
  } catch (const CORBA::Exception& e) {
    throw Failure(Client::Unreachable(m.entry.path, e));
  }
  if (CORBA::is_nil(m.manager)) throw Failure(m.entry.path + " is not a manager (caliper-manager)");
  return {m};
}

// Runs calls on a manager: the IDL's reasons and unreachable managers become Failures.
template <class F>
auto Call(const ManagerRef& m, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const C::CapacityReached& e) {
    throw Failure(m.entry.instance + ": " + e.reason.in());
  } catch (const C::StartFailed& e) {
    throw Failure(m.entry.instance + ": " + e.reason.in());
  } catch (const C::UnknownComponent& e) {
    throw Failure(m.entry.instance + ": " + e.reason.in());
  } catch (const CORBA::SystemException& e) {
    throw Failure(Client::Unreachable(m.entry.path, e));
  }
}

std::string Uptime(double seconds) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << seconds << " s";
  return s.str();
}

int ListManagers(Client& client, std::vector<std::string>& args) {
  RejectOptions(args);
  if (!args.empty()) throw UsageError("managers takes no arguments");
  const auto managers = Managers(client);
  for (const auto& m : managers) {
    std::string error = m.error;
    std::ostringstream children;
    std::string load;
    if (error.empty()) {
      try {
        C::ChildSeq_var list = Call(m, [&] { return m.manager->list(); });
        load = std::to_string(Call(m, [&] { return m.manager->running(); })) + "/" +
               std::to_string(Call(m, [&] { return m.manager->capacity(); })) + " running";
        for (CORBA::ULong i = 0; i < list->length(); ++i) {
          const C::Child& c = list[i];
          children << "  " << std::left << std::setw(12)
                   << (std::strlen(c.instance) > 0 ? c.instance.in() : "-") << "pid "
                   << std::setw(9) << c.pid << std::setw(22) << c.state.in()
                   << Uptime(c.uptime) << "\n";
        }
      } catch (const Failure& e) {
        error = e.what();
      }
    }
    std::cout << m.entry.path << "  " << (error.empty() ? load : "unreachable: " + error) << "\n"
              << children.str();
  }
  if (managers.empty())
    std::cout << "(no manager bound in " << client.address()
              << "; start caliper-manager on each host)\n";
  return 0;
}

// A manager create may use: its free slots, or the reason it is full.
struct Slot {
  const ManagerRef* ref;
  long free;
  std::string full;
};

// Starts up to `count` Models through `managers`, the freest first, printing each on `report`;
// returns those that started and puts why the others did not into `*why`. Failure when no
// manager answers.
std::vector<SpawnedModel> SpawnOn(Client& client, const std::vector<ManagerRef>& managers,
                                  unsigned long count, const RTC::NameValueList& config,
                                  std::ostream& report, std::string* why) {
  std::vector<Slot> slots;
  std::string away;
  for (const auto& m : managers) {
    try {
      if (!m.error.empty()) throw Failure(m.error);
      const long capacity = Call(m, [&] { return m.manager->capacity(); });
      const long running = Call(m, [&] { return m.manager->running(); });
      slots.push_back({&m, capacity - running, ""});
      omniORB::setClientCallTimeout(m.manager, kLongCallMs);
    } catch (const Failure& e) {
      away += std::string("\n  ") + e.what();
    }
  }
  if (slots.empty())
    throw Failure("no manager answers in " + client.address() +
                  (away.empty() ? " (none is bound: start caliper-manager on each host)" : away));

  std::vector<SpawnedModel> created;
  while (created.size() < count) {
    // the manager with the most free slots; a full one tells why (its count may be stale)
    const auto next =
        std::max_element(slots.begin(), slots.end(), [](const Slot& a, const Slot& b) {
          return a.full.empty() != b.full.empty() ? !a.full.empty() : a.free < b.free;
        });
    if (!next->full.empty()) break;
    const ManagerRef& m = *next->ref;
    C::Child* created_child = nullptr;
    try {
      created_child = Call(m, [&]() -> C::Child* {
        try {
          return m.manager->create("model", config);
        } catch (const C::CapacityReached& e) {
          next->full = m.entry.instance + ": " + e.reason.in();
          return nullptr;
        }
      });
    } catch (const Failure& e) {
      // a start that failed, or a manager gone: that manager is out, the Models made stay
      report << e.what() << "\n";
      next->full = e.what();
    }
    if (created_child == nullptr) continue;
    C::Child_var child = created_child;
    report << "created " << child->instance.in() << " (pid " << child->pid << ") as "
           << child->naming_path.in() << " on " << m.entry.instance << "\n";
    created.push_back({child->instance.in(), child->naming_path.in(), m.entry.path});
    --next->free;
  }
  why->clear();
  if (created.size() < count) {
    std::string reasons;
    for (const auto& slot : slots)
      if (!slot.full.empty()) reasons += "\n  " + slot.full;
    *why = "every manager is full:" + reasons + away;
  }
  return created;
}

int Create(Client& client, std::vector<std::string>& args) {
  std::string value;
  unsigned long count = 1;
  if (TakeOption(args, "--count", &value)) {
    char* end = nullptr;
    count = std::strtoul(value.c_str(), &end, 10);
    if (value.empty() || *end != '\0' || !std::isdigit(static_cast<unsigned char>(value[0])) ||
        count < 1 || count > 10000)
      throw UsageError("--count: '" + value + "' is not a whole number from 1 to 10000");
  }
  RTC::NameValueList config;
  while (TakeOption(args, "-o", &value)) {
    const size_t eq = value.find('=');
    if (eq == std::string::npos || eq == 0)
      throw UsageError("-o wants KEY=VALUE, got '" + value + "'");
    config.length(config.length() + 1);
    config[config.length() - 1].name = value.substr(0, eq).c_str();
    config[config.length() - 1].value = value.substr(eq + 1).c_str();
  }
  const std::vector<ManagerRef> managers = Targets(client, args);
  RejectOptions(args);
  if (!args.empty()) throw UsageError("unexpected argument '" + args[0] + "'");
  std::string why;
  const auto created = SpawnOn(client, managers, count, config, std::cout, &why);
  if (created.size() == count) return 0;
  throw Failure((created.empty() ? std::string()
                                 : "created " + std::to_string(created.size()) + " of " +
                                       std::to_string(count) + "; ") +
                why);
}

int Destroy(Client& client, std::vector<std::string>& args) {
  const std::vector<ManagerRef> managers = Targets(client, args);
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("expected one INSTANCE");
  const std::string& wanted = args[0];
  struct Match {
    const ManagerRef* ref;
    std::string instance;
    bool running;
    long pid;
  };
  std::vector<Match> matches;
  std::string runs;
  for (const auto& m : managers) {
    C::ChildSeq_var list;
    try {
      if (!m.error.empty()) throw Failure(m.error);
      list = Call(m, [&] { return m.manager->list(); });
    } catch (const Failure&) {
      runs += "; " + m.entry.instance + " does not answer";
      continue;
    }
    std::string names;
    for (CORBA::ULong i = 0; i < list->length(); ++i) {
      const C::Child& c = list[i];
      if (std::strlen(c.instance) > 0)
        names += (names.empty() ? "" : ", ") + std::string(c.instance);
      if (wanted == c.instance.in() || wanted == c.naming_path.in())
        matches.push_back({&m, c.instance.in(), std::string(c.state) == "running", c.pid});
    }
    runs += "; " + m.entry.instance + " runs " + (names.empty() ? "none" : names);
  }
  // a running child before an ended one of the same name
  std::stable_partition(matches.begin(), matches.end(), [](const Match& a) { return a.running; });
  if (matches.empty())
    throw Failure("no manager runs '" + wanted + "'" +
                  (runs.empty() ? " (no manager answers)" : " (" + runs.substr(2) + ")"));
  if (matches.size() > 1 && matches[1].running)
    throw UsageError("'" + wanted + "' runs under several managers (" +
                     matches[0].ref->entry.instance + ", " + matches[1].ref->entry.instance +
                     "): give its naming path or --manager NAME");
  const Match& match = matches[0];
  omniORB::setClientCallTimeout(match.ref->manager, kLongCallMs);
  Call(*match.ref, [&] { match.ref->manager->destroy(match.instance.c_str()); });
  std::cout << (match.running ? "destroyed " : "forgot the ended ") << match.instance << " (pid "
            << match.pid << ") on " << match.ref->entry.instance << "\n";
  return 0;
}

}  // namespace

std::vector<SpawnedModel> SpawnModels(Client& client, unsigned long count, std::ostream& report,
                                      std::string* why) {
  return SpawnOn(client, Managers(client), count, RTC::NameValueList(), report, why);
}

void StopModels(Client& client, const std::vector<SpawnedModel>& models, std::ostream& report) {
  for (const auto& model : models) {
    try {
      ManagerRef m;
      m.entry = client.Find(model.manager_path);
      m.manager = C::Manager::_narrow(m.entry.object);
      omniORB::setClientCallTimeout(m.manager, kLongCallMs);
      Call(m, [&] { m.manager->destroy(model.instance.c_str()); });
      report << "destroyed " << model.path << "\n";
    } catch (const std::exception& e) {
      report << "could not stop " << model.path << ": " << e.what() << "\n";
    } catch (const CORBA::Exception& e) {
      report << "could not stop " << model.path << ": " << rtc::Describe(e) << "\n";
    }
  }
}

void AddClusterVerbs(std::map<std::string, Verb>* verbs) {
  (*verbs)["managers"] = {
      "managers", "list the managers (one per host) with their load and children", ListManagers,
      "cluster",
      "  One line per manager: its naming path and RUNNING/CAPACITY, then each child it started:\n"
      "  instance, pid, state (starting, running, exited with code N, killed by signal N) and\n"
      "  uptime (until it ended). Ended children stay listed (the last 50) so that one sees what\n"
      "  died. A manager that does not answer is listed as unreachable with the reason.\n"};
  (*verbs)["create"] = {
      "create [--manager NAME] [--count N] [-o KEY=VALUE ...]",
      "start N Models (1) through the managers, the one with the most free slots first", Create,
      "cluster",
      "  Each Model goes to the manager with the most free slots (or to --manager NAME) and is\n"
      "  printed with its instance, pid and naming path once it is bound. -o sets a key of the\n"
      "  new Models (repeatable; e.g. -o model.scene=FILE, a path on the manager's host).\n"
      "  When every manager is full, prints their reasons and exits 1 (after the Models that\n"
      "  could start); a Model that fails to start prints the end of its output.\n"};
  (*verbs)["destroy"] = {
      "destroy INSTANCE [--manager NAME]",
      "stop a Model a manager started (TERM, KILL after 5 s)", Destroy, "cluster",
      "  INSTANCE is an instance name (model3) or a naming path; the manager that runs it is\n"
      "  found by asking each manager (or only --manager NAME). A child that ended already is\n"
      "  removed from its manager's list.\n"};
}

}  // namespace caliper::ctl
