// Every operation of every servant called over the IDL with values that try to hurt: a million
// ids, 10 MB strings, NaN and infinities in every double, unknown and empty names, nil and wrong
// references, and sixteen clients at once. Each call must end in a user exception with a reason
// or a bounded answer; the process stays alive, answers afterwards, and its resident memory grows
// by at most what the test measured and a quarter more (and by little over a second round of the
// same calls). An out-of-range enum (the renderer's ShapeKind) ends in MARSHAL from omniORB and
// the renderer answers on. Also omniORB's message limit (corba.max_message_size): a larger
// request is refused with a system exception and the server answers the next call. No call is
// timed: one that hangs ends in the client's 20 s call timeout, a system exception.
//
// The components run as real processes with a private omniNames. The renderer's SceneObserver is
// reached through a stand-in Model bound in the naming service (the renderer registers with it);
// so are the Graph Plotter's DataConsumer (it subscribes to a stand-in Model) and the Log
// Viewer's LogListener (it registers with a stand-in Logger). The renderer needs X with GLX, the
// plotter and the log viewer X: skipped without DISPLAY (CI starts Xvfb).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <ostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "caliper/cluster.hh"
#include "caliper/core/system.h"
#include "caliper/logging.hh"
#include "caliper/model.hh"
#include "caliper/renderer.hh"
#include "caliper/rtc/naming.h"
#include "hostile_twin.hh"  // observer.idl with one ShapeKind more (tests/integration/CMakeLists.txt)
#include "support/corba.h"

namespace caliper::testing {
namespace {

namespace R = ::Caliper::RTC;
namespace L = ::Caliper::Logging;
namespace C = ::Caliper::Cluster;
namespace V = ::Caliper::Viewer;

using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
/// Doubles no operation may take as a physical value.
const std::vector<double> kNonFinite = {kNaN, kInf, -kInf};
constexpr size_t kMillion = 1000000;
const std::string kTenMegabytes(10u << 20, 'a');
/// Growth of a server's resident memory over one test [kB]: about twice the most each test
/// measured on this machine (printed as "[ measure  ]"), at least 32 MiB: under load (a CI run,
/// builds beside it) the allocator keeps more of what a million-element decode took at once
/// (Motors: 26 to 101 MiB between runs), so a bound near the measured figure failed by chance.
/// What it catches is memory kept per hostile input (a million ids or 10 MB strings kept would
/// exceed it many times); a leak shows in the second of two equal rounds (kRoundGrowthKb).
constexpr long MiB = 1024;
/// The servers started here allocate from one malloc arena and map blocks of 128 KiB and more
/// apart, returned at once when freed: with glibc's defaults (an arena per thread, up to 8 per
/// core, and a threshold that rises to 32 MiB as blocks are freed) the memory a million-element
/// decode leaves behind depends on which of omniORB's threads served it and on what came before,
/// and a test's growth varied from 17 to 148 MiB between runs.
const bool kOneArena =
    setenv("MALLOC_ARENA_MAX", "1", 1) == 0 && setenv("MALLOC_MMAP_THRESHOLD_", "131072", 1) == 0;
/// Growth of resident memory over a second round of the same hostile calls [kB] (measured: 0 to
/// 5 MiB alone, up to 36 MiB under load; a round keeping its million ids or 10 MB strings would
/// add far more).
constexpr long kRoundGrowthKb = 64 * 1024;

/// The head of a long text, for failure messages.
std::string Head(const std::string& text) {
  return text.size() <= 300
             ? text
             : text.substr(0, 300) + "... (" + std::to_string(text.size()) + " bytes)";
}

/// VmRSS of a process [kB] (-1 when it is gone).
long RssKb(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

/// Every call gives up after 20 s: a server that hangs shows as TIMEOUT, never as a stuck test.
CORBA::ORB_ptr Orb() { return ServingClientOrb("hostile_corba_test", 20); }

/// Activates a servant in the test's root POA (which then owns it) and returns its reference.
CORBA::Object_ptr Activate(PortableServer::ServantBase* servant) {
  return caliper::testing::Activate(Orb(), servant);
}

// ------------------------------------------------------------------------ outcomes

/// How a call ended: normally, with a user exception (its name and reason) or a system one.
struct Outcome {
  enum Kind { kOk, kUser, kSystem } kind = kOk;
  std::string name;
  std::string reason;
};

std::ostream& operator<<(std::ostream& os, const Outcome& o) {
  if (o.kind == Outcome::kOk) return os << "answered";
  return os << (o.kind == Outcome::kUser ? "user exception " : "system exception ") << o.name
            << ": " << Head(o.reason);
}

template <class F>
Outcome Try(F&& call) {
#define CALIPER_USER_EXCEPTION(type)               \
  catch (const type& e) {                          \
    return {Outcome::kUser, #type, e.reason.in()}; \
  }
  try {
    call();
    return {};
  }
  CALIPER_USER_EXCEPTION(M::NotAvailable)
  CALIPER_USER_EXCEPTION(M::LoadFailed)
  CALIPER_USER_EXCEPTION(M::RunFailed)
  CALIPER_USER_EXCEPTION(M::EditRefused)
  CALIPER_USER_EXCEPTION(D::UnknownId)
  CALIPER_USER_EXCEPTION(D::InvalidParameter)
  CALIPER_USER_EXCEPTION(D::NotAvailable)
  CALIPER_USER_EXCEPTION(D::LimitExceeded)
  CALIPER_USER_EXCEPTION(L::InvalidQuery)
  CALIPER_USER_EXCEPTION(L::NotAvailable)
  CALIPER_USER_EXCEPTION(L::LimitExceeded)
  CALIPER_USER_EXCEPTION(C::CapacityReached)
  CALIPER_USER_EXCEPTION(C::StartFailed)
  CALIPER_USER_EXCEPTION(C::UnknownComponent)
  CALIPER_USER_EXCEPTION(V::NotAvailable)
  catch (const CORBA::UserException& e) {
    return {Outcome::kUser, e._name(), "(a user exception this test does not know)"};
  }
  catch (const CORBA::SystemException& e) {
    return {Outcome::kSystem, rtc::Describe(e), ""};
  }
#undef CALIPER_USER_EXCEPTION
}

/// A refusal: a user exception whose reason is neither empty nor an echo of a 10 MB input.
#define EXPECT_REFUSED(call, part)                                                         \
  do {                                                                                     \
    const Outcome o_ = Try([&] { call; });                                                 \
    EXPECT_EQ(o_.kind, Outcome::kUser) << #call << ": " << o_;                             \
    EXPECT_TRUE(Contains(o_.reason, part)) << #call << ": " << o_ << "\nwanted: " << part; \
    EXPECT_LT(o_.reason.size(), 64u * 1024) << #call << ": " << o_;                        \
  } while (false)

/// Answered or refused with a reason, never a system exception.
#define EXPECT_ANSWERED(call)                                         \
  do {                                                                \
    const Outcome o_ = Try([&] { call; });                            \
    EXPECT_NE(o_.kind, Outcome::kSystem) << #call << ": " << o_;      \
    if (o_.kind == Outcome::kUser) {                                  \
      EXPECT_FALSE(o_.reason.empty()) << #call;                       \
      EXPECT_LT(o_.reason.size(), 64u * 1024) << #call << ": " << o_; \
    }                                                                 \
  } while (false)

S::StringSeq Ids(size_t n, const std::string& id) {
  S::StringSeq seq;
  seq.length(static_cast<CORBA::ULong>(n));
  for (CORBA::ULong i = 0; i < n; ++i) seq[i] = id.c_str();
  return seq;
}

// ------------------------------------------------------------------------ components

/// A component process bound in a private naming service, and its object.
class Component {
 public:
  Component(const std::string& program, const std::string& instance, const NamingService& naming,
            const std::string& dir, std::vector<std::string> options)
      : naming_(naming.address()), instance_(instance) {
    std::vector<std::string> argv = {Bin(program),
                                     "--nameservice",
                                     naming_,
                                     "--instance",
                                     instance.substr(0, instance.size() - 1),
                                     "-o",
                                     "log.service=none",
                                     "-o",
                                     "log.spool_dir=" + dir + "/spool"};
    argv.insert(argv.end(), options.begin(), options.end());
    process_ = std::make_unique<Process>(argv, dir + "/" + instance + ".out");
  }

  /// Waits until the component is bound and answers; false with the reason in `why`.
  bool Up(std::string* why) {
    const bool up = WaitFor(
        [&] {
          try {
            CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming_);
            object_ = rtc::FindComponent(root, instance_).object;
            R::LightweightRTObject_var rt = R::LightweightRTObject::_narrow(object_);
            R::ComponentProfile_var profile = rt->get_component_profile();
            return true;
          } catch (...) {
            return false;
          }
        },
        seconds(20));
    if (!up) *why = instance_ + " did not come up:\n" + process_->Output();
    return up;
  }

  CORBA::Object_ptr object() const { return object_.in(); }
  Process& process() { return *process_; }
  /// Alive, answering get_component_profile, and not grown past `rss_before` + `growth_kb`.
  void ExpectHealthy(long rss_before, long growth_kb) {
    EXPECT_TRUE(kOneArena);
    ASSERT_TRUE(process_->Running()) << process_->Output();
    R::LightweightRTObject_var rt = R::LightweightRTObject::_narrow(object_);
    R::ComponentProfile_var profile;
    EXPECT_NO_THROW(profile = rt->get_component_profile());
    const long rss = RssKb(process_->pid());
    EXPECT_LT(rss - rss_before, growth_kb)
        << instance_ << ": " << rss_before << " kB before, " << rss << " kB after";
    std::printf("[ measure  ] %s resident memory %ld kB before, %ld kB after\n", instance_.c_str(),
                rss_before, rss);
  }

 private:
  std::string naming_;
  std::string instance_;
  std::unique_ptr<Process> process_;
  CORBA::Object_var object_;
};

std::string SourceDir() {
  const char* source = std::getenv("CALIPER_SOURCE_DIR");
  return source != nullptr ? source : ".";
}

std::string Pendulum() { return SourceDir() + "/models/pendulum_tendon.dae"; }

// ------------------------------------------------------------------------ the lifecycle

/// The LightweightRTObject and ExecutionContext operations every component serves, with hostile
/// arguments; leaves the component as it found it (finalize and exit end it by design, and are
/// called only where the test ends the process).
void HammerLifecycle(CORBA::Object_ptr object) {
  R::LightweightRTObject_var rt = R::LightweightRTObject::_narrow(object);
  ASSERT_FALSE(CORBA::is_nil(rt));
  EXPECT_ANSWERED(rt->initialize());  // initialized already: PRECONDITION_NOT_MET, not a throw
  EXPECT_TRUE(rt->is_alive(R::ExecutionContext::_nil()));
  R::ExecutionContextList_var contexts = rt->get_owned_contexts();
  ASSERT_EQ(contexts->length(), 1u);
  R::ExecutionContext_var context = R::ExecutionContext::_duplicate(contexts[0]);
  EXPECT_TRUE(rt->is_alive(context));
  // an object that is no execution context of ours, and one where nothing listens
  R::ExecutionContext_var stranger = R::ExecutionContext::_unchecked_narrow(object);
  EXPECT_FALSE(rt->is_alive(stranger));
  CORBA::Object_var nobody = Orb()->string_to_object(
      ("corbaloc::127.0.0.1:" + std::to_string(FreePort()) + "/gone").c_str());
  R::ExecutionContext_var gone = R::ExecutionContext::_unchecked_narrow(nobody);
  EXPECT_FALSE(rt->is_alive(gone));
  EXPECT_ANSWERED(R::ComponentProfile_var(rt->get_component_profile()));
  EXPECT_ANSWERED(CORBA::String_var(rt->get_last_error()));

  const double rate = context->get_rate();
  for (const double bad : {kNaN, kInf, -kInf, 0.0, -1.0, 1e-300, 4.9e-324, 1e300, 1e7})
    EXPECT_EQ(context->set_rate(bad), R::BAD_PARAMETER) << "set_rate(" << bad << ")";
  EXPECT_EQ(context->get_rate(), rate);
  const R::ContextStatistics before = context->get_statistics();
  std::this_thread::sleep_for(milliseconds(300));
  const R::ContextStatistics after = context->get_statistics();
  if (context->is_running() && context->get_kind() == R::PERIODIC) {
    EXPECT_LT(after.ticks - before.ticks, 10 + static_cast<unsigned long long>(rate))
        << "ticks in 0.3 s at " << rate << " Hz";
  }

  R::LightweightRTObject_var nil = R::LightweightRTObject::_nil();
  R::LightweightRTObject_var other = R::LightweightRTObject::_unchecked_narrow(context);
  R::LightweightRTObject_var unreachable = R::LightweightRTObject::_unchecked_narrow(nobody);
  for (R::LightweightRTObject_ptr comp : {nil.in(), other.in(), unreachable.in()}) {
    EXPECT_EQ(context->activate_component(comp), R::BAD_PARAMETER);
    EXPECT_EQ(context->deactivate_component(comp), R::BAD_PARAMETER);
    EXPECT_EQ(context->reset_component(comp), R::BAD_PARAMETER);
    EXPECT_ANSWERED(context->get_component_state(comp));
  }
  if (context->get_kind() == R::PERIODIC) {
    EXPECT_EQ(context->tick(), R::UNSUPPORTED);
  }
  // started twice, stopped twice, started again: the second of each is refused
  const bool running = context->is_running();
  if (running) {
    EXPECT_EQ(context->start(), R::PRECONDITION_NOT_MET);
    EXPECT_EQ(context->stop(), R::RTC_OK);
    EXPECT_EQ(context->stop(), R::PRECONDITION_NOT_MET);
    EXPECT_EQ(context->start(), R::RTC_OK);
  }
  EXPECT_EQ(context->is_running(), running);
}

// ------------------------------------------------------------------------ a DataConsumer

class NullConsumer : public virtual POA_Caliper::Daq::DataConsumer {
 public:
  void on_samples(const D::SampleBatch&) override {}
};

// ------------------------------------------------------------------------ Model

class HostileModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    naming_ = std::make_unique<NamingService>(dir_.path());
    model_ = std::make_unique<Component>("caliper-model", "model0", *naming_, dir_.path(),
                                         std::vector<std::string>{"-o", "model.scene=" + Pendulum(),
                                                                  "-o", "exec.auto_activate=true"});
    std::string why;
    ASSERT_TRUE(model_->Up(&why)) << why;
    ref_ = M::Model::_narrow(model_->object());
    ASSERT_TRUE(WaitFor(
        [&] { return M::SimulationStatus_var(ref_->status())->state == M::STOPPED; }, seconds(10)));
    rss_before_ = RssKb(model_->process().pid());
  }

  void TearDown() override {
    if (!model_ || !ref_) return;  // SetUp failed and said why
    model_->ExpectHealthy(rss_before_, rss_growth_kb_);
    EXPECT_NO_THROW(M::SimulationStatus_var(ref_->status())) << model_->process().Output();
    model_->process().Signal(SIGTERM);
    EXPECT_EQ(model_->process().Wait(seconds(10)), 0) << model_->process().Output();
  }

  std::string Scene() { return M::SimulationStatus_var(ref_->status())->scene.in(); }

  M::Octets PendulumBytes() {
    const std::string text = ReadFile(Pendulum());
    M::Octets bytes(static_cast<CORBA::ULong>(text.size()));
    bytes.length(static_cast<CORBA::ULong>(text.size()));
    std::copy(text.begin(), text.end(), reinterpret_cast<char*>(bytes.get_buffer()));
    return bytes;
  }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Component> model_;
  M::Model_var ref_;
  long rss_before_ = 0;
  long rss_growth_kb_ = 32 * MiB;  // each test that sends millions sets its own
};

TEST_F(HostileModelTest, SimulationControlRefusesBadScenesAndNonFiniteSettings) {
  rss_growth_kb_ = 64 * MiB;  // measured: 0.9 to 19 MiB (10 MB names and scenes)
  const std::string scene = Scene();
  // loading by path: empty, 10 MB, a directory; the previous scene stays loaded
  EXPECT_REFUSED(ref_->load_scene(""), "");
  EXPECT_EQ(Try([&] { ref_->load_scene(kTenMegabytes.c_str()); }).kind, Outcome::kUser);
  EXPECT_REFUSED(ref_->load_scene("/"), "");
  EXPECT_REFUSED(ref_->load_scene("/nonexistent/scene.dae"), "");
  // loading by content: nothing, 10 MB of garbage, names empty, 10 MB long or of no format
  const M::Octets pendulum = PendulumBytes();
  M::Octets garbage(static_cast<CORBA::ULong>(kTenMegabytes.size()));
  garbage.length(static_cast<CORBA::ULong>(kTenMegabytes.size()));
  std::fill(garbage.get_buffer(), garbage.get_buffer() + garbage.length(), 0xff);
  EXPECT_REFUSED(ref_->load_scene_data("", M::Octets()), "");
  EXPECT_REFUSED(ref_->load_scene_data("x.dae", M::Octets()), "");
  EXPECT_REFUSED(ref_->load_scene_data("x.dae", garbage), "");
  EXPECT_REFUSED(ref_->load_scene_data("x.zae", garbage), "");
  EXPECT_REFUSED(ref_->load_scene_data("", pendulum), "");
  EXPECT_REFUSED(ref_->load_scene_data("scene.txt", pendulum), "");
  EXPECT_REFUSED(ref_->load_scene_data((kTenMegabytes + ".txt").c_str(), pendulum), "");
  EXPECT_ANSWERED(ref_->load_scene_data((kTenMegabytes + ".dae").c_str(), pendulum));
  EXPECT_ANSWERED(ref_->load_scene_data("../../../etc/passwd.dae", pendulum));
  ASSERT_NO_THROW(ref_->load_scene(Pendulum().c_str()));
  EXPECT_EQ(Scene(), scene);

  for (const double bad : {kNaN, kInf, -kInf, 0.0, -0.0, -1.0, 1e300})
    EXPECT_REFUSED(ref_->set_time_step(bad), "time step");
  for (const double bad : kNonFinite) EXPECT_REFUSED(ref_->set_real_time_factor(bad), "factor");
  EXPECT_REFUSED(ref_->set_real_time_factor(-1), "factor");
  EXPECT_ANSWERED(ref_->set_time_step(4.9e-324));  // the smallest positive double is in (0, 0.1]
  EXPECT_ANSWERED(ref_->set_time_step(1e-3));
  EXPECT_ANSWERED(ref_->set_real_time_factor(1e308));
  EXPECT_ANSWERED(ref_->set_real_time_factor(4.9e-324));
  EXPECT_ANSWERED(ref_->set_real_time_factor(1));
  EXPECT_EQ(ref_->step(0), 0u);

  // every order of the run verbs answers
  for (int round = 0; round < 3; ++round)
    for (const char verb : std::string("psrtrtppsr"))
      EXPECT_ANSWERED(verb == 'p'   ? ref_->pause()
                      : verb == 's' ? ref_->stop()
                      : verb == 'r' ? ref_->reset()
                                    : ref_->start());

  // the most steps one call asks for ends when another client pauses it (no bound in time: a
  // pause that did not end it would show as the client's 20 s call timeout, a system exception)
  std::atomic<CORBA::ULong> ran{0};
  std::thread stepper([&] {
    try {
      ran = ref_->step(std::numeric_limits<CORBA::ULong>::max());
    } catch (const CORBA::Exception&) {
      ADD_FAILURE() << "step(4294967295): " << Try([&] { throw; });
    }
  });
  ASSERT_TRUE(
      WaitFor([&] { return M::SimulationStatus_var(ref_->status())->steps > 100; }, seconds(10)));
  ref_->pause();
  stepper.join();
  EXPECT_GT(ran.load(), 100u);
  EXPECT_LT(ran.load(), std::numeric_limits<CORBA::ULong>::max());
  EXPECT_ANSWERED(ref_->stop());
}

TEST_F(HostileModelTest, MotorsAndParametersRefuseUnknownNamesNonFiniteValuesAndMillions) {
  rss_growth_kb_ = 192 * MiB;  // measured: 26 to 101 MiB (a million commands, ids)
  M::ActuatorInfoSeq_var actuators = ref_->actuators();
  ASSERT_GT(actuators->length(), 0u);
  const std::string motor = actuators[0].name.in();
  EXPECT_ANSWERED(M::ActuatorStateSeq_var(ref_->actuator_states()));

  for (const std::string& name : {std::string(), std::string("nosuch"), kTenMegabytes})
    EXPECT_REFUSED(ref_->set_command(name.c_str(), 1), "");
  for (const double bad : kNonFinite) EXPECT_REFUSED(ref_->set_command(motor.c_str(), bad), "");
  M::CommandSeq commands;
  commands.length(kMillion);
  for (CORBA::ULong i = 0; i < kMillion; ++i) {
    commands[i].actuator = motor.c_str();
    commands[i].value = 0;
  }
  EXPECT_REFUSED(ref_->set_commands(commands), "");
  commands.length(3);
  commands[1].value = kNaN;
  EXPECT_REFUSED(ref_->set_commands(commands), "");
  commands[1].value = 0;
  commands[2].actuator = "";
  EXPECT_REFUSED(ref_->set_commands(commands), "");
  // the largest finite command: the step faults or runs, and the Model says which
  EXPECT_ANSWERED(ref_->set_command(motor.c_str(), std::numeric_limits<double>::max()));
  EXPECT_ANSWERED(ref_->step(50));
  EXPECT_ANSWERED(ref_->stop());
  EXPECT_ANSWERED(ref_->set_command(motor.c_str(), 0));

  // listing: patterns empty, of 10 MB, of many wildcards, malformed brackets and escapes
  for (const std::string& pattern :
       {std::string(), kTenMegabytes, std::string(1u << 20, '?'), std::string(64, '*'),
        std::string("["), std::string("[!"), std::string("\\"), std::string("*[*")}) {
    EXPECT_ANSWERED(D::ChannelInfoSeq_var(ref_->list(pattern.c_str())));
    EXPECT_ANSWERED(D::ChannelInfoSeq_var(ref_->channels(pattern.c_str())));
  }
  D::ChannelInfoSeq_var channels = ref_->list("*");
  ASSERT_GT(channels->length(), 0u);
  const std::string first = channels[0].id.in();

  // reading: a million ids, 10 MB and empty ids, and the most one call may take
  EXPECT_REFUSED(D::ValueSeq_var(ref_->get(Ids(kMillion, first))), "");
  EXPECT_REFUSED(D::ValueSeq_var(ref_->sample(Ids(kMillion, first))), "");
  for (const std::string& id : {std::string(), std::string("nosuch"), kTenMegabytes}) {
    EXPECT_REFUSED(D::ValueSeq_var(ref_->get(Ids(1, id))), "");
    EXPECT_REFUSED(D::ValueSeq_var(ref_->sample(Ids(1, id))), "");
  }
  EXPECT_ANSWERED(D::ValueSeq_var(ref_->get(Ids(100000, first))));
  EXPECT_ANSWERED(D::ValueSeq_var(ref_->get(S::StringSeq())));

  // a control cycle refuses what set_commands and get refuse; a refused command steps nothing
  const auto steps = [&] { return M::SimulationStatus_var(ref_->status())->steps; };
  const CORBA::ULongLong before = steps();
  EXPECT_REFUSED(M::CycleResult_var(ref_->control_cycle(commands, 10, Ids(1, first))), "");
  commands.length(kMillion);
  EXPECT_REFUSED(M::CycleResult_var(ref_->control_cycle(commands, 10, Ids(1, first))), "");
  EXPECT_EQ(steps(), before);
  commands.length(1);
  commands[0].actuator = motor.c_str();
  commands[0].value = 0;
  EXPECT_REFUSED(M::CycleResult_var(ref_->control_cycle(commands, 10, Ids(kMillion, first))), "");
  EXPECT_REFUSED(M::CycleResult_var(ref_->control_cycle(commands, 10, Ids(1, "nosuch"))), "");
  EXPECT_EQ(steps(), before);
  M::CycleResult_var cycle = ref_->control_cycle(commands, 10, Ids(2, first));
  EXPECT_EQ(cycle->steps, 10u);
  EXPECT_EQ(cycle->values.length(), 2u);

  // writing: every writable channel with non-finite values, a wrong count, a lying shape and
  // 10 MB of values
  int writable = 0;
  for (CORBA::ULong c = 0; c < channels->length(); ++c) {
    const D::ChannelInfo& info = channels[c];
    if (!info.writable) continue;
    ++writable;
    const CORBA::ULong n = info.rows * info.cols;
    D::Value value;
    value.rows = info.rows;
    value.cols = info.cols;
    value.data.length(n);
    for (const double bad : kNonFinite) {
      for (CORBA::ULong i = 0; i < n; ++i) value.data[i] = bad;
      EXPECT_REFUSED(ref_->set(info.id.in(), value), "");
    }
    for (CORBA::ULong i = 0; i < n; ++i) value.data[i] = 0;
    value.data.length(n + 1);
    EXPECT_REFUSED(ref_->set(info.id.in(), value), "");
    value.data.length(0);
    EXPECT_REFUSED(ref_->set(info.id.in(), value), "");
    value.rows = value.cols = std::numeric_limits<CORBA::ULong>::max();
    value.data.length(10u << 17);  // 10 MB of doubles
    EXPECT_REFUSED(ref_->set(info.id.in(), value), "");
  }
  EXPECT_GT(writable, 0);
  D::Value one;
  one.rows = one.cols = 1;
  one.data.length(1);
  one.data[0] = 1;
  for (const std::string& id : {std::string(), std::string("nosuch"), kTenMegabytes})
    EXPECT_REFUSED(ref_->set(id.c_str(), one), "");
}

TEST_F(HostileModelTest, SceneSubscriptionsObserversAndExperimentsRefuseHostileValues) {
  rss_growth_kb_ = 320 * MiB;  // measured: 103 to 142 MiB (experiments of millions)
  EXPECT_ANSWERED(S::Description_var(ref_->scene_description()));
  EXPECT_ANSWERED(M::Octets_var(ref_->export_scene()));
  EXPECT_REFUSED(ref_->save_scene(""), "");
  EXPECT_REFUSED(ref_->save_scene(kTenMegabytes.c_str()), "");
  EXPECT_REFUSED(ref_->save_scene("/nonexistent/dir/scene.dae"), "");

  // subscriptions: nil, a million ids, unknown ids, no ids, any rate; unknown ids to unsubscribe
  D::DataConsumer_var consumer =
      D::DataConsumer::_narrow(CORBA::Object_var(Activate(new NullConsumer)));
  D::ChannelInfoSeq_var channels = ref_->list("*");
  const std::string first = channels[0].id.in();
  EXPECT_REFUSED(ref_->subscribe(Ids(1, first), 1, D::DataConsumer::_nil()), "nil");
  EXPECT_REFUSED(ref_->subscribe(Ids(kMillion, first), 1, consumer), "");
  EXPECT_REFUSED(ref_->subscribe(Ids(1, kTenMegabytes), 1, consumer), "");
  EXPECT_REFUSED(ref_->subscribe(Ids(1, ""), 1, consumer), "");
  D::DataConsumer_var model_as_consumer = D::DataConsumer::_unchecked_narrow(ref_);
  EXPECT_REFUSED(ref_->subscribe(Ids(1, first), 1, model_as_consumer), "");
  EXPECT_ANSWERED(ref_->subscribe(S::StringSeq(), 1, consumer));
  for (const CORBA::ULong every : {0u, 1u, std::numeric_limits<CORBA::ULong>::max()}) {
    CORBA::ULongLong id = 0;
    EXPECT_ANSWERED(id = ref_->subscribe(Ids(1, first), every, consumer));
    EXPECT_ANSWERED(ref_->unsubscribe(id));
    EXPECT_ANSWERED(ref_->unsubscribe(id));
  }
  for (const CORBA::ULongLong id : std::vector<CORBA::ULongLong>{0, 123456789, ~0ull}) {
    EXPECT_ANSWERED(ref_->unsubscribe(id));
    EXPECT_ANSWERED(ref_->remove_observer(id));
  }
  EXPECT_REFUSED(ref_->add_observer(S::SceneObserver::_nil()), "nil");
  EXPECT_ANSWERED(ref_->step(100));

  // experiments: a valid one, then one hostile field at a time
  M::Experiment valid;
  valid.name = "hostile";
  valid.scene_file_name = "pendulum_tendon.dae";
  valid.scene_data = PendulumBytes();
  valid.record = Ids(1, first);
  valid.every_n_steps = 1;
  valid.duration = 0.01;
  ASSERT_EQ(Try([&] { M::Recording_var(ref_->run_experiment(valid)); }).kind, Outcome::kOk);
  auto with = [&](const std::function<void(M::Experiment&)>& change) {
    M::Experiment e = valid;
    change(e);
    return e;
  };
  std::vector<std::pair<std::string, M::Experiment>> hostile;
  for (const double bad : {kNaN, kInf, -kInf, -1.0, 1e308})
    hostile.emplace_back("duration " + std::to_string(bad),
                         with([&](M::Experiment& e) { e.duration = bad; }));
  hostile.emplace_back("no scene", with([](M::Experiment& e) { e.scene_data.length(0); }));
  hostile.emplace_back("10 MB of garbage", with([&](M::Experiment& e) {
                         e.scene_data.length(static_cast<CORBA::ULong>(kTenMegabytes.size()));
                         std::fill(e.scene_data.get_buffer(),
                                   e.scene_data.get_buffer() + e.scene_data.length(), 0xff);
                       }));
  hostile.emplace_back("file name of 10 MB",
                       with([&](M::Experiment& e) { e.scene_file_name = kTenMegabytes.c_str(); }));
  hostile.emplace_back("a million recorded ids",
                       with([&](M::Experiment& e) { e.record = Ids(kMillion, first); }));
  hostile.emplace_back("an unknown recorded id",
                       with([&](M::Experiment& e) { e.record = Ids(1, "nosuch"); }));
  hostile.emplace_back("every 0 steps", with([](M::Experiment& e) { e.every_n_steps = 0; }));
  for (const double bad : kNonFinite) {
    hostile.emplace_back("command time " + std::to_string(bad), with([&](M::Experiment& e) {
                           e.schedule.length(1);
                           e.schedule[0].time = bad;
                           e.schedule[0].actuator = "motor";
                           e.schedule[0].value = 1;
                         }));
    hostile.emplace_back("command value " + std::to_string(bad), with([&](M::Experiment& e) {
                           e.schedule.length(1);
                           e.schedule[0].time = 0;
                           e.schedule[0].actuator = "motor";
                           e.schedule[0].value = bad;
                         }));
    hostile.emplace_back("override " + std::to_string(bad), with([&](M::Experiment& e) {
                           e.overrides.length(1);
                           e.overrides[0].id = first.c_str();
                           e.overrides[0].value.rows = e.overrides[0].value.cols = 1;
                           e.overrides[0].value.data.length(1);
                           e.overrides[0].value.data[0] = bad;
                         }));
  }
  hostile.emplace_back("a million commands", with([&](M::Experiment& e) {
                         e.schedule.length(kMillion);
                         for (CORBA::ULong i = 0; i < kMillion; ++i) {
                           e.schedule[i].time = 0;
                           e.schedule[i].actuator = "nosuch";
                           e.schedule[i].value = 0;
                         }
                       }));
  hostile.emplace_back("an unknown actuator", with([&](M::Experiment& e) {
                         e.schedule.length(1);
                         e.schedule[0].time = 0;
                         e.schedule[0].actuator = kTenMegabytes.c_str();
                         e.schedule[0].value = 0;
                       }));
  hostile.emplace_back("an unknown override", with([&](M::Experiment& e) {
                         e.overrides.length(1);
                         e.overrides[0].id = "";
                         e.overrides[0].value.data.length(1);
                       }));
  // twice: what the first round leaves in the allocator is reused by the second, a leak is not
  long rss_after_first = 0;
  // (no bound in time per call: one that hung would end in the client's 20 s call timeout, a
  // system exception)
  for (int round = 0; round < 2; ++round) {
    for (auto& [what, experiment] : hostile) {
      const Outcome o = Try([&] { M::Recording_var(ref_->run_experiment(experiment)); });
      // a command from +inf s on never applies: answered like one after the end
      if (what == "command time inf")
        EXPECT_NE(o.kind, Outcome::kSystem) << what << ": " << o;
      else
        EXPECT_EQ(o.kind, Outcome::kUser) << what << ": " << o;
      EXPECT_LT(o.reason.size(), 64u * 1024) << what;
    }
    const long rss = RssKb(model_->process().pid());
    if (round == 0) rss_after_first = rss;
    std::printf(
        "[ measure  ] model0 resident memory %ld kB after round %d of hostile experiments\n", rss,
        round + 1);
  }
  EXPECT_LT(RssKb(model_->process().pid()) - rss_after_first, kRoundGrowthKb);
  ASSERT_EQ(Try([&] { M::Recording_var(ref_->run_experiment(valid)); }).kind, Outcome::kOk);
}

TEST_F(HostileModelTest, SceneEditingRefusesHostileEditsAndTheModelGoesOn) {
  rss_growth_kb_ = 96 * MiB;  // 10 MB names, a million dims
  const double kHuge = std::numeric_limits<double>::max();
  auto point = [](const std::string& body, double x, double y, double z, const std::string& o = "") {
    S::PathPoint p;
    p.body = body.c_str();
    p.x = x;
    p.y = y;
    p.z = z;
    p.obstacle = o.c_str();
    return p;
  };
  auto path_length = [&] {
    S::Description_var d = ref_->scene_description();
    return d->tendons[0].path.length();
  };
  const CORBA::ULong path = path_length();
  // names: empty, unknown, 10 MB; indices at the ends of the range; non-finite and huge positions
  for (const std::string& name : {std::string(), std::string("nosuch"), kTenMegabytes}) {
    EXPECT_REFUSED(M::EditStatus_var(ref_->move_path_point(name.c_str(), 1, point("frame", 0, 0, 0))), "");
    if (!name.empty()) {  // "" is the world for a point and nothing for a selection
      EXPECT_REFUSED(M::EditStatus_var(ref_->move_path_point("line", 1, point(name, 0, 0, 0))), "");
      EXPECT_REFUSED(M::EditStatus_var(ref_->insert_path_point("line", 1, point("", 0, 0, 0, name))), "");
      EXPECT_REFUSED(ref_->select(name.c_str(), "pendulum", 0), "");
    }
    EXPECT_REFUSED(M::EditStatus_var(ref_->remove_tendon(name.c_str())), "");
    EXPECT_REFUSED(M::EditStatus_var(ref_->remove_obstacle(name.c_str())), "");
    EXPECT_REFUSED(M::EditStatus_var(ref_->set_mass(name.c_str(), 1)), "");
    EXPECT_REFUSED(S::VisualSeq_var(ref_->body_shapes(name.c_str())), "");
    EXPECT_REFUSED(ref_->select("body", name.c_str(), 0), "");
    EXPECT_REFUSED(ref_->pull(name.c_str(), {0, 0, 0}, {0, 0, 0}, 0), "");
  }
  for (const CORBA::ULong index : {CORBA::ULong(0xffffffffu), path, CORBA::ULong(1u << 31)}) {
    EXPECT_REFUSED(M::EditStatus_var(ref_->move_path_point("line", index, point("frame", 0, 0, 0))), "");
    EXPECT_REFUSED(M::EditStatus_var(ref_->insert_path_point("line", index, point("frame", 0, 0, 0))), "");
    EXPECT_REFUSED(M::EditStatus_var(ref_->remove_path_point("line", index)), "");
    EXPECT_REFUSED(M::EditStatus_var(ref_->set_shape_dims("pendulum", index, S::DoubleSeq())), "");
  }
  for (const double bad : kNonFinite) {
    EXPECT_REFUSED(M::EditStatus_var(ref_->move_path_point("line", 1, point("frame", bad, 0, 0))), "");
    EXPECT_REFUSED(M::EditStatus_var(ref_->set_mass("pendulum", bad)), "");
    EXPECT_REFUSED(ref_->pull("pendulum", {bad, 0, 0}, {0, 0, 0}, 0), "");
    EXPECT_REFUSED(ref_->pull("pendulum", {0, 0, 0}, {0, 0, 0}, bad), "");
  }
  // huge but finite pulls: refused with the bound, never an infinite force and a fault
  EXPECT_REFUSED(ref_->pull("pendulum", {0, 0, 0}, {kHuge, 0, 0}, 0), "within");
  EXPECT_REFUSED(ref_->pull("pendulum", {0, 0, 0}, {0, 0, 0}, kHuge), "stiffness");
  EXPECT_REFUSED(ref_->pull("frame", {0, 0, 0}, {0, 0, 0}, 0), "does not move");
  EXPECT_REFUSED(M::EditStatus_var(ref_->set_mass("pendulum", -1)), "mass");
  EXPECT_REFUSED(M::EditStatus_var(ref_->set_mass("frame", 1)), "does not move");
  S::DoubleSeq dims;
  dims.length(kMillion);
  EXPECT_REFUSED(M::EditStatus_var(ref_->set_shape_dims("pendulum", 0, dims)), "");
  dims.length(3);
  dims[0] = dims[1] = dims[2] = kHuge;
  EXPECT_REFUSED(M::EditStatus_var(ref_->set_shape_dims("pendulum", 0, dims)), "");
  // obstacles: bad kinds, radii, poses
  S::Obstacle o;
  o.name = "knob";
  o.body = "pendulum";
  o.kind = "cube";
  o.pose = {0, 0, 0, 1, 0, 0, 0};
  o.radius = 0.01;
  o.length = 0.02;
  EXPECT_REFUSED(M::EditStatus_var(ref_->set_obstacle(o)), "sphere or cylinder");
  o.kind = "sphere";
  for (const double bad : {0.0, -1.0, kHuge, kNaN}) {
    o.radius = bad;
    EXPECT_REFUSED(M::EditStatus_var(ref_->set_obstacle(o)), "radius");
  }
  o.radius = 0.01;
  o.pose = {0, 0, 0, 0, 0, 0, 0};  // not a rotation
  EXPECT_REFUSED(M::EditStatus_var(ref_->set_obstacle(o)), "unit quaternion");
  // measurement delays: bad delays, unknown and empty ids, a command
  for (const double bad : {-1.0, kHuge, kNaN})
    EXPECT_REFUSED(M::EditStatus_var(ref_->set_measurement_delay("pivot.position", bad)),
                   "[0, 10] s");
  EXPECT_REFUSED(M::EditStatus_var(ref_->set_measurement_delay("no.such.channel", 0.002)),
                 "no such parameter");
  EXPECT_REFUSED(M::EditStatus_var(ref_->set_measurement_delay("", 0.002)), "channel id");
  EXPECT_REFUSED(M::EditStatus_var(ref_->set_measurement_delay("pivot.position", 0)),
                 "has no measurement delay");
  // tendons: existing names, unknown kinds, huge radii
  EXPECT_REFUSED(M::EditStatus_var(ref_->add_tendon("line", point("frame", 0, 0, 0),
                                                    point("pendulum", 0, 0, 0), 0.001, "m2",
                                                    "dc_motor_tendon")), "exists");
  EXPECT_REFUSED(M::EditStatus_var(ref_->add_tendon("t2", point("frame", 0, 0, 0),
                                                    point("pendulum", 0, 0, 0), 0.001, "m2",
                                                    kTenMegabytes.c_str())), "no actuator kind");
  EXPECT_REFUSED(M::EditStatus_var(ref_->add_tendon("t2", point("frame", 0, 0, 0),
                                                    point("pendulum", 0, 0, 0), kHuge, "m2",
                                                    "dc_motor_tendon")), "radius");
  // history: nothing to undo or redo
  EXPECT_REFUSED(M::EditStatus_var(ref_->undo()), "nothing to undo");
  EXPECT_REFUSED(M::EditStatus_var(ref_->redo()), "nothing to redo");
  M::EditStatus_var status = ref_->edit_status();
  EXPECT_EQ(status->revision, 0u) << "a refused edit counted";
  EXPECT_EQ(path_length(), path);
  EXPECT_ANSWERED(M::ActuatorKindSeq_var(ref_->actuator_kinds()));
  EXPECT_ANSWERED(ref_->release_pull());

  // a thousand sound edits from four clients at once while stepping, all answered; then undos:
  // the history keeps the last 200, and what undo walks back are moves of the via point
  std::vector<std::thread> clients;
  std::atomic<int> answered{0};
  for (int c = 0; c < 4; ++c)
    clients.emplace_back([&, c] {
      for (int i = 0; i < 250; ++i) {
        try {
          if (c == 0 && i % 10 == 0) ref_->step(5);
          M::EditStatus_var s = ref_->move_path_point("line", 1, point("frame", 0.3, 0, 1.0 + 1e-4 * i));
          ++answered;
        } catch (const CORBA::UserException&) {
          ++answered;  // a step from another client running: NotAvailable
        } catch (const CORBA::Exception&) {
        }
      }
    });
  for (auto& t : clients) t.join();
  EXPECT_EQ(answered.load(), 1000);
  int undone = 0;
  for (; undone < 1000; ++undone) {
    try {
      M::EditStatus_var s = ref_->undo();
      EXPECT_EQ(std::string(s->last.in()).rfind("undo move via point 1 of line", 0), 0u) << s->last.in();
    } catch (const M::EditRefused& e) {
      EXPECT_TRUE(Contains(e.reason.in(), "nothing to undo")) << e.reason.in();
      break;
    }
  }
  EXPECT_EQ(undone, 200) << "the history holds the last 200 edits";
  S::Description_var d = ref_->scene_description();
  EXPECT_EQ(d->tendons[0].path.length(), path);
  EXPECT_GE(d->tendons[0].path[1].z, 1.0);  // one of the moves, not the file's point (1.125)
  EXPECT_LT(d->tendons[0].path[1].z, 1.0 + 1e-4 * 250);
  EXPECT_ANSWERED(ref_->step(10));
}

TEST_F(HostileModelTest, RecordingAndReplayRefuseHostilePathsOptionsAndTimes) {
  rss_growth_kb_ = 96 * MiB;  // 10 MB paths, a million ids
  const double kHuge = std::numeric_limits<double>::max();
  M::RecordOptions options;
  options.keyframe_every = 100;
  options.channels_every = 1;
  options.max_bytes = 0;
  // no write directory is configured for this Model: every path is refused, saying why
  for (const std::string& path : {std::string(), std::string("/etc/passwd"), kTenMegabytes,
                                  std::string("../../x.caliper")})
    EXPECT_REFUSED(M::RecordStatus_var(ref_->start_recording(path.c_str(), options)), "");
  options.channels = Ids(kMillion, "x");
  EXPECT_REFUSED(M::RecordStatus_var(ref_->start_recording("r.caliper", options)), "");
  EXPECT_ANSWERED(M::RecordStatus_var(ref_->stop_recording()));
  EXPECT_ANSWERED(M::RecordStatus_var(ref_->recording_status()));
  // replays: paths that are no recording, or lead nowhere
  for (const std::string& path : {std::string(), std::string("/etc/passwd"), kTenMegabytes, Pendulum()})
    EXPECT_REFUSED(M::ReplayStatus_var(ref_->open_replay(path.c_str())), "");
  for (const double t : {kNaN, kHuge, -kHuge, 0.0})
    EXPECT_REFUSED(M::ReplayStatus_var(ref_->seek(t)), "no replay");
  EXPECT_REFUSED(ref_->fork(), "no replay");
  M::ReplayStatus_var replay = ref_->replay_status();
  EXPECT_FALSE(replay->replaying);
  EXPECT_ANSWERED(ref_->step(10));
}

TEST_F(HostileModelTest, LifecycleAndExecutionContextRefuseHostileArguments) {
  HammerLifecycle(ref_);
}

TEST_F(HostileModelTest, SixteenClientsHammeringMixedOperationsAreAllAnswered) {
  rss_growth_kb_ = 64 * MiB;  // measured: 0.7 MiB (16 connections and their threads)
  D::ChannelInfoSeq_var channels = ref_->list("*");
  const std::string first = channels[0].id.in();
  M::ActuatorInfoSeq_var actuators = ref_->actuators();
  const std::string motor = actuators[0].name.in();
  R::ExecutionContextList_var contexts = ref_->get_owned_contexts();
  R::ExecutionContext_var context = R::ExecutionContext::_duplicate(contexts[0]);
  constexpr int kThreads = 16, kCalls = 150;
  std::atomic<int> system_exceptions{0}, calls{0};
  std::mutex mutex;
  std::string first_failure;
  const auto begin = std::chrono::steady_clock::now();
  std::vector<std::thread> clients;
  for (int t = 0; t < kThreads; ++t)
    clients.emplace_back([&, t] {
      for (int i = 0; i < kCalls; ++i) {
        const int op = (t * 7 + i) % 14;
        const Outcome o = Try([&] {
          switch (op) {
            case 0:
              M::SimulationStatus_var(ref_->status());
              break;
            case 1:
              D::ValueSeq_var(ref_->get(Ids(100, first)));
              break;
            case 2:
              ref_->set_command(motor.c_str(), (i % 3 == 0) ? kNaN : 0.5);
              break;
            case 3:
              ref_->step(20);
              break;
            case 4:
              D::ChannelInfoSeq_var(ref_->list("*a*"));
              break;
            case 5:
              ref_->start();
              break;
            case 6:
              ref_->pause();
              break;
            case 7:
              ref_->reset();
              break;
            case 8:
              ref_->set_real_time_factor(i % 2 == 0 ? 0 : kInf);
              break;
            case 9:
              ref_->add_observer(S::SceneObserver::_nil());
              break;
            case 10:
              ref_->unsubscribe(i);
              break;
            case 11:
              context->set_rate(i % 2 == 0 ? 100 : kNaN);
              break;
            case 12:
              M::ActuatorStateSeq_var(ref_->actuator_states());
              break;
            case 13:
              ref_->set_time_step(i % 2 == 0 ? 1e-3 : -kInf);
              break;
          }
        });
        ++calls;
        if (o.kind == Outcome::kSystem) {
          ++system_exceptions;
          std::lock_guard<std::mutex> lock(mutex);
          if (first_failure.empty())
            first_failure = "operation " + std::to_string(op) + ": " + o.name;
        }
      }
    });
  for (auto& c : clients) c.join();
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  std::printf("[ measure  ] %d mixed calls from %d clients in %.2f s\n", calls.load(), kThreads,
              elapsed);
  EXPECT_EQ(calls, kThreads * kCalls);
  EXPECT_EQ(system_exceptions, 0) << first_failure;
  EXPECT_ANSWERED(ref_->stop());
}

// ------------------------------------------------------------------------ message size

TEST(HostileMessageSize, ARequestOverTheLimitIsASystemExceptionAndTheServerGoesOn) {
  TempDir dir;
  NamingService naming(dir.path());
  Component model("caliper-model", "model0", naming, dir.path(),
                  {"-o", "model.scene=" + Pendulum(), "-o", "corba.max_message_size=4"});
  std::string why;
  ASSERT_TRUE(model.Up(&why)) << why;
  M::Model_var ref = M::Model::_narrow(model.object());
  M::Octets big(5u << 20);
  big.length(5u << 20);
  std::fill(big.get_buffer(), big.get_buffer() + big.length(), 'x');
  const Outcome o = Try([&] { ref->load_scene_data("big.dae", big); });
  EXPECT_EQ(o.kind, Outcome::kSystem) << o;
  // over loopback TCP MARSHAL or COMM_FAILURE; over a unix socket (the default) the server's
  // closing the connection mid-request is a TRANSIENT
  EXPECT_TRUE(Contains(o.name, "MARSHAL") || Contains(o.name, "COMM_FAILURE") ||
              Contains(o.name, "TRANSIENT"))
      << o;
  // a million ids (about 30 MB) too
  D::ChannelInfoSeq_var channels = ref->list("*");
  const Outcome ids = Try([&] { D::ValueSeq_var(ref->get(Ids(kMillion, channels[0].id.in()))); });
  EXPECT_EQ(ids.kind, Outcome::kSystem) << ids;
  // the server answers the next calls, and one just under the limit
  EXPECT_TRUE(model.process().Running()) << model.process().Output();
  EXPECT_NO_THROW(M::SimulationStatus_var(ref->status()));
  big.length(3u << 20);
  const Outcome under = Try([&] { ref->load_scene_data("big.dae", big); });
  EXPECT_EQ(under.kind, Outcome::kUser) << under;
  EXPECT_STREQ(M::SimulationStatus_var(ref->status())->scene.in(), Pendulum().c_str());
  std::printf("[ measure  ] 5 MiB request to a 4 MiB server: %s\n", o.name.c_str());
}

// ------------------------------------------------------------------------ Logger

L::Record Record(const std::string& source, CORBA::ULongLong seq, const std::string& message) {
  return TestRecord("hostile0", source, seq, message);
}

L::RecordFilter AllRecords() { return RecordsOf("", ""); }

class NullListener : public virtual POA_Caliper::Logging::LogListener {
 public:
  void on_records(const L::StoredRecordSeq&) override {}
};

TEST(HostileLogger, EveryOperationAnswersHostileRecordsQueriesAndListeners) {
  TempDir dir;
  NamingService naming(dir.path());
  Component logger(
      "caliper-logger", "logger0", naming, dir.path(),
      {"-o", "logger.directory=" + dir.path() + "/logs", "-o", "logger.memory_records=10000"});
  std::string why;
  ASSERT_TRUE(logger.Up(&why)) << why;
  const long rss_before = RssKb(logger.process().pid());
  L::Logger_var ref = L::Logger::_narrow(logger.object());

  // records: every field at its extremes, 10 MB texts, control bytes and invalid UTF-8
  L::RecordSeq odd;
  odd.length(6);
  odd[0] = Record("hostile:1", 1, kTenMegabytes);
  odd[1] = Record(kTenMegabytes, 1, "a 10 MB source");
  odd[2] = Record("", 0, std::string("tab\tnew\nline\r\x01\x7f\xff\xfe", 15));
  odd[2].category = kTenMegabytes.c_str();
  odd[2].instance = "";
  odd[3] = Record("hostile:1", ~0ull, "the last seq");
  odd[3].time_us = std::numeric_limits<CORBA::LongLong>::max();
  odd[3].priority = std::numeric_limits<CORBA::Long>::max();
  odd[3].pid = -1;
  odd[4] = Record("hostile:2", 1, "the first of all times");
  odd[4].time_us = std::numeric_limits<CORBA::LongLong>::min();
  odd[4].priority = std::numeric_limits<CORBA::Long>::min();
  odd[5] = Record("hostile:2", 1, "a duplicate");
  EXPECT_ANSWERED(ref->submit(odd));
  // stored, bounded: the 10 MB message cut, the 10 MB source too
  L::RecordFilter q = AllRecords();
  q.max_priority = std::numeric_limits<CORBA::Long>::max();
  q.category_prefix = "caliper.test";
  q.regex = "^a{1000}|the last seq|a 10 MB source";
  L::StoredRecordSeq_var found = ref->query(q);
  ASSERT_EQ(found->length(), 3u);
  for (CORBA::ULong i = 0; i < found->length(); ++i) {
    EXPECT_LE(std::strlen(found[i].rec.message.in()), 16u * 1024);
    EXPECT_LE(std::strlen(found[i].rec.source.in()), 16u * 1024);
  }
  // a million records (about 60 MB on the wire) in one call, twice: the second round reuses
  // what the allocator kept of the first, a leak would grow it
  L::RecordSeq million;
  million.length(kMillion);
  long rss_after_first = 0;
  for (int round = 0; round < 2; ++round) {
    for (CORBA::ULong i = 0; i < kMillion; ++i)
      million[i] = Record("hostile:" + std::to_string(3 + round), i + 1, "m");
    const auto begin = std::chrono::steady_clock::now();
    EXPECT_ANSWERED(ref->submit(million));
    const long rss = RssKb(logger.process().pid());
    if (round == 0) rss_after_first = rss;
    std::printf(
        "[ measure  ] a million records submitted in %.2f s; logger0 resident memory %ld "
        "kB\n",
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count(), rss);
  }
  EXPECT_LT(RssKb(logger.process().pid()) - rss_after_first, kRoundGrowthKb);
  million.length(0);

  // queries: 10 MB and malformed expressions, every field at its extremes
  q = AllRecords();
  q.regex = kTenMegabytes.c_str();
  EXPECT_REFUSED(ref->query(q), "");
  for (const char* bad : {"(", "[", "a{100000}", "(?<=a)b", "\\1", "*"}) {
    q.regex = bad;
    EXPECT_ANSWERED(L::StoredRecordSeq_var(ref->query(q)));
  }
  q = AllRecords();
  q.category_prefix = kTenMegabytes.c_str();
  q.instance = kTenMegabytes.c_str();
  EXPECT_ANSWERED(L::StoredRecordSeq_var(ref->query(q)));
  q = AllRecords();
  q.max_priority = std::numeric_limits<CORBA::Long>::min();
  q.from_time_us = std::numeric_limits<CORBA::LongLong>::max();
  q.to_time_us = std::numeric_limits<CORBA::LongLong>::min();
  q.after_serial = ~0ull;
  q.limit = std::numeric_limits<CORBA::ULong>::max();
  EXPECT_ANSWERED(L::StoredRecordSeq_var(ref->query(q)));
  q = AllRecords();
  q.max_priority = std::numeric_limits<CORBA::Long>::max();
  q.limit = std::numeric_limits<CORBA::ULong>::max();
  L::StoredRecordSeq_var newest;
  EXPECT_ANSWERED(newest = ref->query(q));
  if (newest.operator->() != nullptr) {
    EXPECT_LE(newest->length(), 10000u) << "the most one query returns";
  }

  // listeners: nil, no listener, nothing there; unknown ids to remove
  EXPECT_REFUSED(ref->add_listener(L::LogListener::_nil()), "nil");
  L::LogListener_var logger_as_listener = L::LogListener::_unchecked_narrow(ref);
  EXPECT_REFUSED(ref->add_listener(logger_as_listener), "");
  CORBA::Object_var nobody = Orb()->string_to_object(
      ("corbaloc::127.0.0.1:" + std::to_string(FreePort()) + "/gone").c_str());
  EXPECT_REFUSED(ref->add_listener(L::LogListener::_unchecked_narrow(nobody)), "");
  L::LogListener_var listener =
      L::LogListener::_narrow(CORBA::Object_var(Activate(new NullListener)));
  CORBA::ULongLong id = 0;
  EXPECT_ANSWERED(id = ref->add_listener(listener));
  for (const CORBA::ULongLong gone : std::vector<CORBA::ULongLong>{id, id, 0, ~0ull})
    EXPECT_ANSWERED(ref->remove_listener(gone));
  EXPECT_ANSWERED(CORBA::String_var(ref->session_file()));
  HammerLifecycle(ref);

  EXPECT_EQ(ref->submit(L::RecordSeq()), 0u);
  logger.ExpectHealthy(rss_before, 768 * MiB);  // measured: 377 MiB (a million records, twice)
}

// ------------------------------------------------------------------------ Manager

TEST(HostileManager, CreateAndDestroyRefuseUnknownTypesHugeConfigurationsAndNames) {
  TempDir dir;
  NamingService naming(dir.path());
  Component manager(
      "caliper-manager", "manager0", naming, dir.path(),
      {"-o", "manager.max_models=1", "-o", "manager.output_dir=" + dir.path() + "/children", "-o",
       "manager.start_timeout=10"});
  std::string why;
  ASSERT_TRUE(manager.Up(&why)) << why;
  const long rss_before = RssKb(manager.process().pid());
  C::Manager_var ref = C::Manager::_narrow(manager.object());

  R::NameValueList none;
  for (const std::string& type : {std::string(), std::string("nosuch"), kTenMegabytes,
                                  std::string("../../bin/sh"), std::string("model ")})
    EXPECT_REFUSED(C::Child_var(ref->create(type.c_str(), none)), "not a type");
  auto config = [](std::vector<std::pair<std::string, std::string>> entries) {
    R::NameValueList list;
    list.length(static_cast<CORBA::ULong>(entries.size()));
    for (CORBA::ULong i = 0; i < entries.size(); ++i) {
      list[i].name = entries[i].first.c_str();
      list[i].value = entries[i].second.c_str();
    }
    return list;
  };
  R::NameValueList many;
  many.length(kMillion);
  for (CORBA::ULong i = 0; i < kMillion; ++i) {
    many[i].name = "model.scene";
    many[i].value = "x";
  }
  EXPECT_REFUSED(C::Child_var(ref->create("model", many)), "more than 256");
  many.length(0);
  EXPECT_REFUSED(C::Child_var(ref->create("model", config({{"", ""}}))), "not one a client");
  EXPECT_REFUSED(C::Child_var(ref->create("model", config({{kTenMegabytes, "1"}}))),
                 "not one a client");
  EXPECT_REFUSED(C::Child_var(ref->create("model", config({{"corba.endpoint", "giop:tcp::"}}))),
                 "set by the manager");
  EXPECT_REFUSED(C::Child_var(ref->create("model", config({{"model.inject_fault", "x"}}))),
                 "not one a client");
  // values the child refuses, or that no command line carries: StartFailed with the reason, and
  // no child left running (a create that waited past the start timeout of 10 s and never ended
  // would show as the client's 20 s call timeout, a system exception)
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"exec.rate", "nan"}, {"exec.rate", "-inf"}, {"model.scene", kTenMegabytes}}) {
    const Outcome o = Try([&] { C::Child_var(ref->create("model", config({{key, value}}))); });
    EXPECT_EQ(o.kind, Outcome::kUser) << key << "=" << Head(value) << ": " << o;
    EXPECT_LT(o.reason.size(), 64u * 1024) << key;
  }
  EXPECT_EQ(ref->running(), 0u);
  for (const std::string& name : {std::string(), std::string("nosuch0"), kTenMegabytes})
    EXPECT_REFUSED(ref->destroy(name.c_str()), "");
  EXPECT_ANSWERED(C::ChildSeq_var(ref->list()));
  EXPECT_EQ(ref->capacity(), 1u);
  HammerLifecycle(ref);
  manager.ExpectHealthy(rss_before, 160 * MiB);  // measured: 61 MiB (a million entries)
}

// ------------------------------------------------------------------------ Sample component

TEST(HostileSample, TheLifecycleOfAPlainComponentRefusesHostileArguments) {
  TempDir dir;
  NamingService naming(dir.path());
  Component sample("caliper-sample", "sample0", naming, dir.path(), {});
  std::string why;
  ASSERT_TRUE(sample.Up(&why)) << why;
  const long rss_before = RssKb(sample.process().pid());
  HammerLifecycle(sample.object());
  // any client may finalize an inactive component (as in OpenRTM), once; exit then still ends
  // the process cleanly (it was refused, and the finalized process lingered until a signal)
  R::LightweightRTObject_var rt = R::LightweightRTObject::_narrow(sample.object());
  EXPECT_EQ(rt->finalize(), R::RTC_OK);
  EXPECT_EQ(rt->finalize(), R::PRECONDITION_NOT_MET);
  EXPECT_EQ(rt->initialize(), R::PRECONDITION_NOT_MET);
  EXPECT_FALSE(rt->is_alive(R::ExecutionContext::_nil()));
  sample.ExpectHealthy(rss_before, 32 * MiB);  // measured: 0.2 MiB
  EXPECT_EQ(rt->exit(), R::RTC_OK);
  EXPECT_EQ(sample.process().Wait(seconds(10)), 0) << sample.process().Output();
}

// ------------------------------------------------------------------------ Renderer

/// A stand-in Model for the renderer: it hands the SceneObserver the renderer registers to the
/// test and serves nothing else. Dynamic (DSI), so that it does not follow every change of the
/// Model's IDL: it is a Model to _is_a and answers add_observer and remove_observer.
class StandInModel : public PortableServer::DynamicImplementation {
 public:
  S::SceneObserver_ptr observer() {
    std::lock_guard<std::mutex> lock(mutex_);
    return S::SceneObserver::_duplicate(observer_);
  }

  void invoke(CORBA::ServerRequest_ptr request) override {
    const std::string operation = request->operation();
    CORBA::NVList_ptr args = CORBA::NVList::_nil();  // the request owns it once it has it
    CORBA::Any arg;
    if (operation == "add_observer" || operation == "remove_observer") Orb()->create_list(0, args);
    if (operation == "add_observer") {
      arg.replace(S::_tc_SceneObserver, nullptr);
      args->add_value("observer", arg, CORBA::ARG_IN);
      request->arguments(args);
      S::SceneObserver_ptr observer = S::SceneObserver::_nil();
      *(args->item(0)->value()) >>= observer;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        observer_ = S::SceneObserver::_duplicate(observer);
      }
      CORBA::Any result;
      result <<= static_cast<CORBA::ULongLong>(1);
      request->set_result(result);
    } else if (operation == "remove_observer") {
      arg.replace(CORBA::_tc_ulonglong, nullptr);
      args->add_value("id", arg, CORBA::ARG_IN);
      request->arguments(args);
    } else {
      throw CORBA::NO_IMPLEMENT(0, CORBA::COMPLETED_NO);
    }
  }
  char* _primary_interface(const PortableServer::ObjectId&, PortableServer::POA_ptr) override {
    return CORBA::string_dup(M::Model::_PD_repoId);
  }

 private:
  std::mutex mutex_;
  S::SceneObserver_var observer_;
};

S::Frame Pose(double v) {
  S::Frame f;
  f.px = f.py = f.pz = v;
  f.qw = f.qx = f.qy = f.qz = v;
  return f;
}

/// A scene of `bodies` bodies of eight visuals whose every number is `v`, with too few
/// dimensions, mesh numbers and triangle indices that point nowhere, unknown names and kinds.
S::Description HostileScene(double v, CORBA::ULong bodies) {
  S::Description d;
  d.name = "hostile";
  d.source = "";
  d.time_step = v;
  d.bodies.length(bodies);
  const S::ShapeKind kinds[] = {S::BOX,  S::SPHERE, S::CAPSULE,     S::CYLINDER,
                                S::CONE, S::PLANE,  S::CONVEX_HULL, S::TRIANGLE_MESH};
  for (CORBA::ULong b = 0; b < bodies; ++b) {
    S::Body& body = d.bodies[b];
    body.name = ("b" + std::to_string(b)).c_str();
    body.pose = Pose(v);
    body.moving = true;
    body.visuals.length(8);
    for (CORBA::ULong k = 0; k < 8; ++k) {
      S::Visual& visual = body.visuals[k];
      visual.name = "";
      visual.geometry.kind = kinds[k];
      visual.geometry.dims.length(k % 3);  // too few dimensions for most kinds
      for (CORBA::ULong i = 0; i < visual.geometry.dims.length(); ++i) visual.geometry.dims[i] = v;
      visual.geometry.mesh = k == 6 ? static_cast<CORBA::Long>(b % 2)
                             : k == 7
                                 ? (b % 3 == 2 ? 1000000 : static_cast<CORBA::Long>((b + 1) % 2))
                                 : -7;
      visual.pose = Pose(v);
      visual.r = visual.g = visual.b = visual.a = static_cast<float>(v);
    }
  }
  // meshes whose triangles use vertices that do not exist (past the end, past 2^31)
  d.meshes.length(2);
  for (CORBA::ULong m = 0; m < 2; ++m) {
    d.meshes[m].vertices.length(4);  // not a multiple of three
    for (CORBA::ULong i = 0; i < 4; ++i) d.meshes[m].vertices[i] = static_cast<float>(v);
    d.meshes[m].triangles.length(6);
    for (CORBA::ULong i = 0; i < 6; ++i)
      d.meshes[m].triangles[i] = m == 0 ? 4000000000u - i : 1000 + i;
    d.meshes[m].normals.length(2);
  }
  d.constraints.length(2);
  for (CORBA::ULong c = 0; c < 2; ++c) {
    d.constraints[c].name = "";
    d.constraints[c].kind = c == 0 ? "hinge" : "nosuch";
    d.constraints[c].body_a = c == 0 ? "b0" : "nobody";
    d.constraints[c].body_b = kTenMegabytes.substr(0, 1000).c_str();
    d.constraints[c].frame_a = Pose(v);
    d.constraints[c].frame_b = Pose(v);
  }
  d.obstacles.length(1);
  d.obstacles[0].name = "";
  d.obstacles[0].body = "nobody";
  d.obstacles[0].kind = "nosuch";
  d.obstacles[0].pose = Pose(v);
  d.obstacles[0].radius = v;
  d.obstacles[0].length = -v;
  d.tendons.length(2);
  d.tendons[0].name = "";
  d.tendons[0].radius = v;
  d.tendons[1].name = "t";
  d.tendons[1].radius = -v;
  d.tendons[1].obstacles.length(1);
  d.tendons[1].obstacles[0] = "nosuch";
  return d;
}

/// A scene of one box, through the twin of observer.idl whose ShapeKind has one kind more
/// (NOT_A_SHAPE, 8): the same bytes on the wire as the real Description, any kind in its place.
HostileTwin::Scene::Description TwinScene(HostileTwin::Scene::ShapeKind kind) {
  namespace T = HostileTwin::Scene;
  T::Description d;
  d.name = "twin";
  d.source = "";
  d.time_step = 1e-3;
  d.bodies.length(1);
  T::Body& body = d.bodies[0];
  body.name = "b0";
  body.pose.px = body.pose.py = body.pose.pz = 0;
  body.pose.qw = 1;
  body.pose.qx = body.pose.qy = body.pose.qz = 0;
  body.moving = true;
  body.visuals.length(1);
  T::Visual& visual = body.visuals[0];
  visual.name = "box";
  visual.geometry.kind = kind;
  visual.geometry.dims.length(3);
  for (CORBA::ULong i = 0; i < 3; ++i) visual.geometry.dims[i] = 0.1;
  visual.geometry.mesh = -1;
  visual.pose = body.pose;
  visual.r = visual.g = visual.b = visual.a = 1;
  return d;
}

TEST(HostileRenderer, RendererAndItsObserverAnswerHostileScenesCamerasAndScreenshots) {
  if (const std::string why = NoDisplay("the renderer needs X with GLX"); !why.empty())
    GTEST_SKIP() << why;
  TempDir dir;
  NamingService naming(dir.path());
  // the stand-in Model, bound where the renderer looks for "standin0"
  auto* stand_in = new StandInModel;
  stand_in->_add_ref();  // kept for the test, beyond the POA's reference
  PortableServer::ServantBase_var keep(stand_in);
  CORBA::Object_var stand_in_ref = Activate(stand_in);
  {
    CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming.address());
    CosNaming::Name host;
    host.length(1);
    host[0].id = (core::HostName()).c_str();
    host[0].kind = "host_cxt";
    try {
      CosNaming::NamingContext_var created = root->bind_new_context(host);
    } catch (const CosNaming::NamingContext::AlreadyBound&) {
    }
    root->rebind(rtc::ComponentName(core::HostName(), "standin0"), stand_in_ref);
  }
  Component renderer("caliper-renderer", "renderer0", naming, dir.path(),
                     {"-o", "renderer.model=standin0", "-o", "renderer.check_interval=0.2", "-o",
                      "exec.auto_activate=true"});
  std::string why;
  ASSERT_TRUE(renderer.Up(&why)) << why;
  ASSERT_TRUE(WaitFor(
      [&] {
        S::SceneObserver_var registered = stand_in->observer();
        return !CORBA::is_nil(registered);
      },
      seconds(10)))
      << renderer.process().Output();
  const long rss_before = RssKb(renderer.process().pid());
  S::SceneObserver_var observer = stand_in->observer();
  V::Renderer_var ref = V::Renderer::_narrow(renderer.object());

  // the renderer's own interface
  EXPECT_ANSWERED(ref->view_all());
  EXPECT_ANSWERED(ref->show_constraint_axes(true));
  for (const double bad : {kNaN, kInf, -kInf}) {
    EXPECT_REFUSED(ref->set_camera(Pose(bad), 0.8), "");
    S::Frame finite = Pose(0);
    finite.qw = 1;
    EXPECT_REFUSED(ref->set_camera(finite, bad), "");
  }
  EXPECT_REFUSED(ref->set_camera(Pose(0), 0.8), "quaternion");
  EXPECT_REFUSED(ref->set_camera(Pose(1e308), 0.8), "");
  for (const auto& [w, h] : std::vector<std::pair<CORBA::ULong, CORBA::ULong>>{
           {0, 0}, {1, 1}, {100000, 100000}, {~0u, ~0u}, {8193, 16}})
    EXPECT_REFUSED(ref->screenshot((dir.path() + "/shot.png").c_str(), w, h), "");
  EXPECT_REFUSED(ref->screenshot("", 64, 64), "");

  // its observer: scenes whose every number is NaN, infinite or huge, with indices that point
  // nowhere, then transforms and tendon states of bodies and tendons that do not exist
  for (const double v : {kNaN, kInf, -kInf, 1e308, 0.0}) {
    EXPECT_ANSWERED(observer->on_scene(HostileScene(v, 50)));
    S::BodyTransformSeq moved;
    moved.length(3);
    for (CORBA::ULong i = 0; i < 3; ++i) {
      moved[i].body_index = i == 0 ? 0 : i == 1 ? 49 : 4000000000u;
      moved[i].pose = Pose(v);
    }
    S::TendonStateSeq tendons;
    tendons.length(3);
    for (CORBA::ULong i = 0; i < 3; ++i) {
      tendons[i].tendon_index = i == 2 ? 4000000000u : i;
      tendons[i].points.length(i == 0 ? 7 : 3000);  // not a multiple of three; many points
      for (CORBA::ULong k = 0; k < tendons[i].points.length(); ++k) tendons[i].points[k] = v;
      tendons[i].length = v;
      tendons[i].tension = v;
    }
    static CORBA::ULongLong update = 0;
    for (const CORBA::ULongLong u : std::vector<CORBA::ULongLong>{++update, 0, ~0ull - 1, ~0ull})
      EXPECT_ANSWERED(observer->on_transforms(u, v, moved, tendons));
    update = 0;
    EXPECT_ANSWERED(ref->view_all());
    EXPECT_ANSWERED(ref->screenshot((dir.path() + "/hostile.png").c_str(), 64, 64));
  }
  // a million bodies moved of a scene of fifty, and a scene of 20000 bodies
  S::BodyTransformSeq million;
  million.length(kMillion);
  for (CORBA::ULong i = 0; i < kMillion; ++i) {
    million[i].body_index = i;
    million[i].pose = Pose(0);
  }
  EXPECT_ANSWERED(observer->on_scene(HostileScene(0, 50)));
  EXPECT_ANSWERED(observer->on_transforms(1, 0, million, S::TendonStateSeq()));
  million.length(0);
  EXPECT_ANSWERED(observer->on_scene(HostileScene(1, 500)));
  EXPECT_ANSWERED(ref->screenshot((dir.path() + "/large.png").c_str(), 64, 64));
  // more visuals than the renderer draws (Coin took 1.2 GB for these 160,000): not shown
  EXPECT_ANSWERED(observer->on_scene(HostileScene(1, 20000)));
  EXPECT_TRUE(
      WaitFor([&] { return Contains(renderer.process().Output(), "not shown"); }, seconds(10)))
      << renderer.process().Output();
  // an out-of-range ShapeKind: omniORB checks enums as it unmarshals a request, so the renderer
  // never sees it: the client gets MARSHAL (nothing done), and the renderer answers on. (The
  // SceneObserver's scene is the one enum a client sends to a server; the other enums of our IDL
  // are only answers.) First the twin with a real kind, to show that it is understood.
  {
    CORBA::String_var ior = Orb()->object_to_string(observer);
    CORBA::Object_var object = Orb()->string_to_object(ior);
    HostileTwin::Scene::SceneObserver_var twin = HostileTwin::Scene::SceneObserver::_narrow(object);
    ASSERT_FALSE(CORBA::is_nil(twin));
    const Outcome box = Try([&] { twin->on_scene(TwinScene(HostileTwin::Scene::BOX)); });
    EXPECT_EQ(box.kind, Outcome::kOk) << "a valid scene through the twin: " << box;
    const Outcome bad = Try([&] { twin->on_scene(TwinScene(HostileTwin::Scene::NOT_A_SHAPE)); });
    EXPECT_EQ(bad.kind, Outcome::kSystem) << "ShapeKind 8: " << bad;
    EXPECT_TRUE(Contains(bad.name, "MARSHAL")) << "ShapeKind 8: " << bad;
    std::printf("[ measure  ] on_scene with ShapeKind 8: %s\n", bad.name.c_str());
    EXPECT_TRUE(renderer.process().Running()) << renderer.process().Output();
    EXPECT_ANSWERED(observer->on_scene(HostileScene(1, 5)));
    EXPECT_ANSWERED(ref->screenshot((dir.path() + "/after_enum.png").c_str(), 64, 64));
  }
  EXPECT_ANSWERED(observer->on_scene_cleared());
  EXPECT_ANSWERED(observer->on_scene_cleared());
  EXPECT_ANSWERED(ref->screenshot((dir.path() + "/cleared.png").c_str(), 64, 64));
  HammerLifecycle(ref);
  // the window's thread drew all of it: the renderer still renders
  EXPECT_ANSWERED(ref->view_all());
  renderer.ExpectHealthy(rss_before, 384 * MiB);  // measured: 166 to 193 MiB (20,000 bodies)
}

// ------------------------------------------------------------------------ GUI tools' servants

/// A stand-in for a component a GUI tool connects to: a Dynamic (DSI) servant of `repo_id` whose
/// operations `answer` serves (it reads the request's arguments and sets its result, and returns
/// false for an operation it does not know: NO_IMPLEMENT). Serves nothing else, so that it does
/// not follow every change of the IDL. It is also each of `bases` to _is_a (a client that narrows
/// to a base interface asks: DSI knows only the primary one).
class StandIn : public PortableServer::DynamicImplementation {
 public:
  using Answer = std::function<bool(const std::string&, CORBA::ServerRequest_ptr)>;
  StandIn(const char* repo_id, std::vector<std::string> bases, Answer answer)
      : repo_id_(repo_id), bases_(std::move(bases)), answer_(std::move(answer)) {}

  CORBA::Boolean _is_a(const char* id) override {
    return std::find(bases_.begin(), bases_.end(), id) != bases_.end() ||
           PortableServer::DynamicImplementation::_is_a(id);
  }

  void invoke(CORBA::ServerRequest_ptr request) override {
    if (!answer_(request->operation(), request)) throw CORBA::NO_IMPLEMENT(0, CORBA::COMPLETED_NO);
  }
  char* _primary_interface(const PortableServer::ObjectId&, PortableServer::POA_ptr) override {
    return CORBA::string_dup(repo_id_);
  }

 private:
  const char* repo_id_;
  std::vector<std::string> bases_;
  Answer answer_;
};

/// Reads a DSI request's in arguments of the types `types`; the list stays the request's.
CORBA::NVList_ptr Arguments(CORBA::ServerRequest_ptr request,
                            const std::vector<CORBA::TypeCode_ptr>& types) {
  CORBA::NVList_ptr args = CORBA::NVList::_nil();
  Orb()->create_list(0, args);
  for (CORBA::TypeCode_ptr type : types) {
    CORBA::Any arg;
    arg.replace(type, nullptr);
    args->add_value("", arg, CORBA::ARG_IN);
  }
  request->arguments(args);
  return args;
}

/// Activates `stand_in` and binds it as `instance` in the naming service at `naming`.
void BindStandIn(StandIn* stand_in, const NamingService& naming, const std::string& instance) {
  CORBA::Object_var ref = Activate(stand_in);
  CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming.address());
  CosNaming::Name host;
  host.length(1);
  host[0].id = core::HostName().c_str();
  host[0].kind = "host_cxt";
  try {
    CosNaming::NamingContext_var created = root->bind_new_context(host);
  } catch (const CosNaming::NamingContext::AlreadyBound&) {
  }
  root->rebind(rtc::ComponentName(core::HostName(), instance), ref);
}

/// The highest VmRSS of a process [kB] while it lives, sampled every 20 ms.
class PeakRss {
 public:
  explicit PeakRss(pid_t pid)
      : thread_([this, pid] {
          while (!stop_) {
            peak_ = std::max(peak_.load(), RssKb(pid));
            std::this_thread::sleep_for(milliseconds(20));
          }
        }) {}
  ~PeakRss() {
    stop_ = true;
    thread_.join();
  }
  long kb() const { return peak_; }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<long> peak_{0};
  std::thread thread_;
};

/// A GUI tool that served hostile calls: alive, `normal` (a call of the same operation with
/// plain values) answered, and its resident memory, once its GUI thread has taken in what came
/// (RSS level over half a second, at most 10 s), not grown past `rss_before` + `growth_kb`, nor
/// its highest (`peak`) past `rss_before` + `peak_growth_kb`.
void ExpectToolHealthy(Process& tool, const std::string& name, long rss_before, long growth_kb,
                       const PeakRss& peak, long peak_growth_kb,
                       const std::function<void()>& normal) {
  EXPECT_TRUE(kOneArena);
  ASSERT_TRUE(tool.Running()) << tool.Output();
  const Outcome o = Try(normal);
  EXPECT_EQ(o.kind, Outcome::kOk) << name << ", a plain call after the hostile ones: " << o;
  long rss = RssKb(tool.pid());
  for (int k = 0; k < 20; ++k) {
    std::this_thread::sleep_for(milliseconds(500));
    const long now = RssKb(tool.pid());
    if (std::labs(now - rss) < 1024) break;
    rss = now;
  }
  EXPECT_TRUE(tool.Running()) << tool.Output();
  rss = RssKb(tool.pid());
  EXPECT_LT(rss - rss_before, growth_kb)
      << name << ": " << rss_before << " kB before, " << rss << " kB after";
  EXPECT_LT(peak.kb() - rss_before, peak_growth_kb)
      << name << ": " << rss_before << " kB before, at most " << peak.kb() << " kB";
  std::printf("[ measure  ] %s resident memory %ld kB before, %ld kB after, at most %ld kB\n",
              name.c_str(), rss_before, rss, peak.kb());
}

/// A batch of `samples` samples of subscription `sub` whose times and values are all `v`.
D::SampleBatch Batch(CORBA::ULongLong sub, CORBA::ULongLong number, size_t samples, double v,
                     CORBA::ULong values_per_sample = 1, size_t values = ~size_t{0}) {
  D::SampleBatch b;
  b.subscription = sub;
  b.batch = number;
  b.first_step = number;
  b.times.length(static_cast<CORBA::ULong>(samples));
  for (CORBA::ULong i = 0; i < samples; ++i)
    b.times[i] = std::isnan(v) || std::isinf(v) ? v : v + i;
  b.values_per_sample = values_per_sample;
  if (values == ~size_t{0}) values = samples * values_per_sample;
  b.data.length(static_cast<CORBA::ULong>(values));
  for (CORBA::ULong i = 0; i < values; ++i) b.data[i] = v;
  b.layout = 1;
  return b;
}

TEST(HostilePlotter, ThePlottersDataConsumerTakesHostileBatches) {
  if (const std::string why = NoDisplay("the plotter is a Qt window"); !why.empty())
    GTEST_SKIP() << why;
  TempDir dir;
  NamingService naming(dir.path());
  // the stand-in Model: one scalar channel x, STOPPED; subscribe hands the consumer to the test
  std::mutex mutex;
  D::DataConsumer_var consumer;
  std::atomic<int> unsubscribed{0};
  constexpr CORBA::ULongLong kSubscription = 7;
  auto* stand_in = new StandIn(
      M::Model::_PD_repoId, {}, [&](const std::string& op, CORBA::ServerRequest_ptr request) {
        CORBA::Any result;
        if (op == "status") {
          Arguments(request, {});
          M::SimulationStatus s;
          s.state = M::STOPPED;
          s.scene = "standin.dae";
          s.sim_time = 0;
          s.steps = 0;
          s.time_step = 1e-3;
          s.real_time_factor = s.achieved_real_time_factor = 1;
          s.last_error = "";
          result <<= s;
        } else if (op == "channels") {
          Arguments(request, {CORBA::_tc_string});
          D::ChannelInfoSeq infos;
          infos.length(1);
          infos[0].id = "x";
          infos[0].unit = "m";
          infos[0].rows = infos[0].cols = 1;
          infos[0].writable = false;
          infos[0].is_static = false;
          infos[0].description = "a stand-in's channel";
          result <<= infos;
        } else if (op == "subscribe") {
          CORBA::NVList_ptr args =
              Arguments(request, {S::_tc_StringSeq, CORBA::_tc_ulong, D::_tc_DataConsumer});
          D::DataConsumer_ptr c = D::DataConsumer::_nil();
          *(args->item(2)->value()) >>= c;
          std::lock_guard<std::mutex> lock(mutex);
          consumer = D::DataConsumer::_duplicate(c);
          result <<= kSubscription;
        } else if (op == "unsubscribe") {
          Arguments(request, {CORBA::_tc_ulonglong});
          ++unsubscribed;
          return true;
        } else {
          return false;
        }
        request->set_result(result);
        return true;
      });
  PortableServer::ServantBase_var keep(stand_in);
  stand_in->_add_ref();  // kept for the test, beyond the POA's reference
  BindStandIn(stand_in, naming, "standin0");
  Process plotter({Bin("caliper-plotter"), "--nameservice", naming.address(), "--model", "standin0",
                   "--ids", "x", "--geometry", "640x480+0+0"},
                  dir.path() + "/plotter.out");
  auto captured = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return D::DataConsumer::_duplicate(consumer);
  };
  ASSERT_TRUE(WaitFor([&] { return !CORBA::is_nil(D::DataConsumer_var(captured())); }, seconds(15)))
      << plotter.Output();
  D::DataConsumer_var ref = captured();
  CORBA::ULongLong number = 0;
  EXPECT_ANSWERED(ref->on_samples(Batch(kSubscription, ++number, 10, 0.0)));
  std::this_thread::sleep_for(milliseconds(300));
  const long rss_before = RssKb(plotter.pid());
  const PeakRss peak(plotter.pid());

  // a million samples, then a million whose every time and value is NaN, infinite or huge (a
  // time axis of 10 s at 1e308 sent Qwt's tick loop on until std::bad_alloc when drawn)
  EXPECT_ANSWERED(ref->on_samples(Batch(kSubscription, ++number, kMillion, 1.0)));
  for (const double v : {kNaN, kInf, -kInf, 1e308, -1e308, 0.0})
    EXPECT_ANSWERED(ref->on_samples(Batch(kSubscription, ++number, kMillion, v)));
  // layouts that do not fit: too few values, none a sample, more than the plot's one, and every
  // unsigned one (a product with the sample count past 2^64); a million samples of no values
  for (const auto& [per, values] : std::vector<std::pair<CORBA::ULong, size_t>>{
           {1, 0}, {1, 10}, {0, kMillion}, {1000, kMillion}, {~0u, 3}, {1u << 31, 2}, {2, 1}})
    EXPECT_ANSWERED(ref->on_samples(Batch(kSubscription, ++number, kMillion, 5.0, per, values)));
  EXPECT_ANSWERED(ref->on_samples(Batch(kSubscription, ++number, 0, 0.0, 1, kMillion)));
  // batch numbers and Model layouts that jump, go back or wrap
  for (const CORBA::ULongLong n : std::vector<CORBA::ULongLong>{0, ~0ull, ~0ull - 1, 1}) {
    D::SampleBatch b = Batch(kSubscription, n, 100, 2.0);
    for (const CORBA::ULongLong layout : std::vector<CORBA::ULongLong>{0, ~0ull, 2}) {
      b.layout = layout;
      EXPECT_ANSWERED(ref->on_samples(b));
    }
  }
  // a million stale ids, and one of 10 MB
  {
    D::SampleBatch b = Batch(kSubscription, ++number, 10, 3.0);
    b.stale_ids = Ids(kMillion, "x");
    EXPECT_ANSWERED(ref->on_samples(b));
    b.stale_ids = Ids(1, kTenMegabytes);
    EXPECT_ANSWERED(ref->on_samples(b));
  }
  // subscriptions that are not the plotter's (it ends them at the stand-in: a bounded number)
  for (const CORBA::ULongLong sub : std::vector<CORBA::ULongLong>{0, 8, ~0ull})
    EXPECT_ANSWERED(ref->on_samples(Batch(sub, 1, kMillion, 1.0)));
  for (CORBA::ULongLong sub = 100; sub < 1100; ++sub)
    EXPECT_ANSWERED(ref->on_samples(Batch(sub, 1, 1, 1.0)));
  // the same million-sample batch again and again: the inbox holds batches, the store samples
  const D::SampleBatch big = Batch(kSubscription, 0, kMillion, 10.0);
  for (int k = 0; k < 8; ++k) {
    D::SampleBatch b = big;
    b.batch = ++number;
    EXPECT_ANSWERED(ref->on_samples(b));
  }
  ExpectToolHealthy(plotter, "caliper-plotter", rss_before, 256 * MiB, peak, 512 * MiB,
                    [&] { ref->on_samples(Batch(kSubscription, ++number, 10, 2e7)); });
  std::printf("[ measure  ] the plotter ended %d foreign subscriptions at the stand-in\n",
              unsubscribed.load());
  EXPECT_LE(unsubscribed.load(), 1100 + 10);
}

/// A log record whose every field may be hostile.
L::StoredRecord Stored(CORBA::ULongLong serial, const std::string& message,
                       const std::string& name = "standin") {
  L::StoredRecord r;
  r.serial = serial;
  r.rec = TestRecord("standin0", name, serial, message);
  r.rec.category = ("caliper." + name).c_str();
  return r;
}

TEST(HostileLogViewer, TheLogViewersListenerTakesHostileRecords) {
  if (const std::string why = NoDisplay("the log viewer is a Qt window"); !why.empty())
    GTEST_SKIP() << why;
  TempDir dir;
  NamingService naming(dir.path());
  // the stand-in Logger: a session file, no stored records; add_listener hands the listener over
  std::mutex mutex;
  L::LogListener_var listener;
  auto* stand_in = new StandIn(L::Logger::_PD_repoId, {L::LogService::_PD_repoId},
                               [&](const std::string& op, CORBA::ServerRequest_ptr request) {
                                 CORBA::Any result;
                                 if (op == "session_file") {
                                   Arguments(request, {});
                                   result <<= "/nonexistent/caliper-standin.log";
                                 } else if (op == "query") {
                                   Arguments(request, {L::_tc_RecordFilter});
                                   result <<= L::StoredRecordSeq();
                                 } else if (op == "add_listener") {
                                   CORBA::NVList_ptr args =
                                       Arguments(request, {L::_tc_LogListener});
                                   L::LogListener_ptr l = L::LogListener::_nil();
                                   *(args->item(0)->value()) >>= l;
                                   std::lock_guard<std::mutex> lock(mutex);
                                   listener = L::LogListener::_duplicate(l);
                                   result <<= CORBA::ULongLong{1};
                                 } else if (op == "remove_listener") {
                                   Arguments(request, {CORBA::_tc_ulonglong});
                                   return true;
                                 } else {
                                   return false;
                                 }
                                 request->set_result(result);
                                 return true;
                               });
  PortableServer::ServantBase_var keep(stand_in);
  stand_in->_add_ref();  // kept for the test, beyond the POA's reference
  BindStandIn(stand_in, naming, "standin0");
  Process viewer({Bin("caliper-logviewer"), "--nameservice", naming.address(), "--logger",
                  "standin0", "--geometry", "640x480+0+0"},
                 dir.path() + "/logviewer.out");
  auto captured = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return L::LogListener::_duplicate(listener);
  };
  ASSERT_TRUE(WaitFor([&] { return !CORBA::is_nil(L::LogListener_var(captured())); }, seconds(15)))
      << viewer.Output();
  L::LogListener_var ref = captured();
  CORBA::ULongLong serial = 0;
  auto records = [&](size_t n, const std::string& message, const std::string& name = "standin") {
    L::StoredRecordSeq seq;
    seq.length(static_cast<CORBA::ULong>(n));
    for (CORBA::ULong i = 0; i < n; ++i) seq[i] = Stored(++serial, message, name);
    return seq;
  };
  EXPECT_ANSWERED(ref->on_records(records(3, "plain")));
  std::this_thread::sleep_for(milliseconds(300));
  const long rss_before = RssKb(viewer.pid());
  const PeakRss peak(viewer.pid());

  // a million records; records of 10 MB messages and names
  EXPECT_ANSWERED(ref->on_records(records(kMillion, "a million")));
  EXPECT_ANSWERED(ref->on_records(records(3, kTenMegabytes)));
  {
    L::StoredRecordSeq seq = records(4, "ten megabytes of names");
    seq[0].rec.category = kTenMegabytes.c_str();
    seq[1].rec.instance = kTenMegabytes.c_str();
    seq[2].rec.host = kTenMegabytes.c_str();
    seq[3].rec.source = kTenMegabytes.c_str();
    EXPECT_ANSWERED(ref->on_records(seq));
  }
  // times, priorities, pids and sequence numbers at their extremes; empty names
  {
    L::StoredRecordSeq seq = records(8, "extremes");
    const CORBA::LongLong times[] = {std::numeric_limits<CORBA::LongLong>::min(),
                                     std::numeric_limits<CORBA::LongLong>::max(), -1, 0};
    const CORBA::Long numbers[] = {std::numeric_limits<CORBA::Long>::min(),
                                   std::numeric_limits<CORBA::Long>::max(), -1, 0};
    for (CORBA::ULong i = 0; i < 8; ++i) {
      seq[i].rec.time_us = times[i % 4];
      seq[i].rec.priority = numbers[i % 4];
      seq[i].rec.pid = numbers[(i + 1) % 4];
      seq[i].rec.seq = i % 2 == 0 ? 0 : ~0ull;
      seq[i].rec.source = "extremes";  // its seq of 2^64-1 makes the rest of it duplicates
      if (i >= 4) seq[i].rec.category = seq[i].rec.instance = seq[i].rec.source = "";
    }
    EXPECT_ANSWERED(ref->on_records(seq));
  }
  // ten thousand distinct categories and components (each a node of the viewer's source tree)
  {
    L::StoredRecordSeq seq = records(10000, "names");
    for (CORBA::ULong i = 0; i < 10000; ++i) {
      const std::string name = "n" + std::to_string(i);
      seq[i].rec.category = ("caliper." + name + ".x").c_str();
      seq[i].rec.instance = name.c_str();
    }
    EXPECT_ANSWERED(ref->on_records(seq));
  }
  // serials repeated, going back, 0, and a gap (the viewer asks the stand-in, which has none)
  {
    L::StoredRecordSeq seq = records(4, "serials");
    seq[0].serial = 0;
    seq[1].serial = 1;
    seq[2].serial = seq[3].serial;
    EXPECT_ANSWERED(ref->on_records(seq));
    serial += 1000;
    EXPECT_ANSWERED(ref->on_records(records(10, "after a gap")));
  }
  EXPECT_ANSWERED(ref->on_records(L::StoredRecordSeq()));
  // the viewer keeps a million records (LogModel::max_records): measured 744 MiB for them
  ExpectToolHealthy(viewer, "caliper-logviewer", rss_before, 1024 * MiB, peak, 1280 * MiB,
                    [&] { ref->on_records(records(3, "plain again")); });
  EXPECT_TRUE(Contains(viewer.Output(), "following standin0")) << viewer.Output();
}

}  // namespace
}  // namespace caliper::testing
