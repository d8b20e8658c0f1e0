// The Model component with real processes: a private omniNames and caliper-model, driven by
// caliper-ctl's model verbs and, for SceneObservers, over CORBA by servants in this test.
#include "caliper/model.hh"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "caliper/rtc/naming.h"
#include "support/corba.h"

namespace caliper::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr double kDt = 0.001;  // time step of the shipped models [s]
const char* const kPendulum = "models/pendulum_tendon.dae";
const char* const kMass = "pendulum_tendon.pendulum.mass";
const char* const kTension = "pendulum_tendon.line.tendon.tension";
const char* const kPosition = "pendulum_tendon.pendulum.position";

std::string Source(const std::string& relative) {
  const char* dir = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(dir != nullptr ? dir : ".") + "/" + relative;
}

/// The value after `label` on its line of `caliper-ctl status` ("" when missing).
std::string Field(const std::string& status, const std::string& label) {
  std::istringstream in(status);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(label + " ", 0) == 0) {
      const size_t start = line.find_first_not_of(' ', label.size());
      return start == std::string::npos ? "" : line.substr(start);
    }
  return "";
}

/// The number in `caliper-ctl get`'s `id = value unit` line (NaN when missing).
double Scalar(const std::string& get_output, const std::string& id) {
  const std::regex line("(^|\n)" + std::regex_replace(id, std::regex("\\."), "\\.") +
                        " = ([^ \n]+)");
  std::smatch m;
  if (!std::regex_search(get_output, m, line)) return std::nan("");
  return std::strtod(m[2].str().c_str(), nullptr);
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> Split(const std::string& line, char separator) {
  std::vector<std::string> parts;
  std::istringstream in(line);
  for (std::string part; std::getline(in, part, separator);) parts.push_back(part);
  return parts;
}

// ------------------------------------------------------------------------ the test's ORB

/// The test's ORB, serving the observers; calls give up after 10 s.
CORBA::ORB_ptr Orb() {
  return TestOrb({"model_test", "-ORBendPoint", "giop:tcp:127.0.0.1:",
                  "-ORBclientCallTimeOutPeriod", "10000", "-ORBgiopMaxMsgSize", "268435456"});
}

/// A SceneObserver that keeps what it receives; `delay` makes on_transforms slow.
class RecordingObserver : public virtual POA_Caliper::Scene::SceneObserver {
 public:
  struct Update {
    uint64_t update;
    double time;
    std::vector<uint32_t> changed;
    size_t tendons;
  };

  explicit RecordingObserver(milliseconds delay = milliseconds(0)) : delay_(delay) {}

  void on_scene(const S::Description& scene) override {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::pair<std::string, bool>> bodies;
    for (CORBA::ULong i = 0; i < scene.bodies.length(); ++i)
      bodies.emplace_back(scene.bodies[i].name.in(), scene.bodies[i].moving);
    scenes_.push_back(bodies);
  }
  void on_transforms(CORBA::ULongLong update, CORBA::Double sim_time,
                     const S::BodyTransformSeq& changed,
                     const S::TendonStateSeq& tendons) override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      Update u{update, sim_time, {}, tendons.length()};
      for (CORBA::ULong i = 0; i < changed.length(); ++i)
        u.changed.push_back(changed[i].body_index);
      updates_.push_back(u);
    }
    if (delay_.count() > 0) std::this_thread::sleep_for(delay_);
  }
  void on_scene_cleared() override {
    std::lock_guard<std::mutex> lock(mutex_);
    ++cleared_;
  }

  std::vector<std::vector<std::pair<std::string, bool>>> scenes() {
    std::lock_guard<std::mutex> lock(mutex_);
    return scenes_;
  }
  std::vector<Update> updates() {
    std::lock_guard<std::mutex> lock(mutex_);
    return updates_;
  }

 private:
  const milliseconds delay_;
  std::mutex mutex_;
  std::vector<std::vector<std::pair<std::string, bool>>> scenes_;
  std::vector<Update> updates_;
  int cleared_ = 0;
};

/// An observer activated in the test's RootPOA; deactivated (if still active) when destroyed.
class ActiveObserver {
 public:
  explicit ActiveObserver(milliseconds delay = milliseconds(0))
      : servant_(new RecordingObserver(delay)), poa_(RootPoa(Orb())) {
    id_ = poa_->activate_object(servant_);
    CORBA::Object_var obj = poa_->id_to_reference(id_);
    ref_ = S::SceneObserver::_narrow(obj);
  }
  ~ActiveObserver() { Deactivate(); }
  /// Calls to the observer raise OBJECT_NOT_EXIST from now on, as if its process were gone.
  void Deactivate() {
    if (active_) poa_->deactivate_object(id_);
    active_ = false;
  }
  RecordingObserver& observer() { return *servant_; }
  S::SceneObserver_ptr ref() { return ref_.in(); }

 private:
  RecordingObserver* servant_;
  PortableServer::ServantBase_var owner_{servant_};
  PortableServer::POA_var poa_;
  PortableServer::ObjectId_var id_;
  S::SceneObserver_var ref_;
  bool active_ = true;
};

// ------------------------------------------------------------------------ fixture

class ModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    naming_ = std::make_unique<NamingService>(dir_.path());
    // load_scene reads the test data by path (other files go by content: confined_files_test)
    std::vector<std::string> argv{Bin("caliper-model"), "--nameservice", naming_->address(), "-o",
                                  "exec.auto_activate=true", "-o", "log.service=none", "-o",
                                  "log.spool_dir=" + dir_.path() + "/spool", "-o",
                                  "model.read_dirs=" + Source("models") + ":" + Source("tests/data")};
    argv.insert(argv.end(), extra_args_.begin(), extra_args_.end());
    model_ = std::make_unique<Process>(argv, dir_.path() + "/model.out");
    ASSERT_TRUE(WaitFor([&] { return Ctl({"status"}).exit_code == 0; }, seconds(10)))
        << model_->Output();
  }

  CommandResult Ctl(const std::vector<std::string>& args) {
    return caliper::testing::Ctl(naming_->address(), args);
  }

  /// Loads a shipped model through ctl.
  void Load(const std::string& relative) {
    const auto r = Ctl({"load", Source(relative)});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }

  std::string Status() {
    const auto r = Ctl({"status"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.out;
  }
  double SimTime() { return std::strtod(Field(Status(), "simulated time [s]").c_str(), nullptr); }

  double Get(const std::string& id) {
    const auto r = Ctl({"get", id});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return Scalar(r.out, id);
  }

  /// The Model over CORBA, for what ctl does not do (observers).
  M::Model_ptr Model() {
    if (CORBA::is_nil(model_ref_)) {
      CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming_->address());
      const rtc::ComponentEntry entry = rtc::FindComponent(root, "model0");
      model_ref_ = M::Model::_narrow(entry.object);
    }
    return model_ref_.in();
  }

  std::vector<std::string> extra_args_;  // more arguments of caliper-model (set before SetUp)
  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> model_;
  M::Model_var model_ref_;
};

// ------------------------------------------------------------------------ simulation control

TEST_F(ModelTest, CtlLoadsStepsRunsPausesAndStops) {
  // nothing loaded yet: a reason, exit 1
  const auto early = Ctl({"start"});
  EXPECT_EQ(early.exit_code, 1);
  EXPECT_TRUE(Contains(early.err, "no scene is loaded")) << early.err;
  EXPECT_EQ(Field(Status(), "state"), "EMPTY");

  const auto load = Ctl({"load", Source(kPendulum)});
  ASSERT_EQ(load.exit_code, 0) << load.err;
  EXPECT_TRUE(Contains(load.out, "model0: loaded " + Source(kPendulum))) << load.out;
  std::string status = Status();
  EXPECT_EQ(Field(status, "state"), "STOPPED");
  EXPECT_EQ(Field(status, "scene"), Source(kPendulum));
  EXPECT_EQ(Field(status, "time step [s]"), "0.001");
  EXPECT_EQ(Field(status, "steps"), "0");
  EXPECT_EQ(Field(status, "last error"), "-");

  // step N advances the simulated time by N * dt and pauses
  for (const int n : {100, 250}) {
    const double before = SimTime();
    const auto step = Ctl({"step", std::to_string(n)});
    ASSERT_EQ(step.exit_code, 0) << step.err;
    EXPECT_TRUE(Contains(step.out, std::to_string(n) + " steps")) << step.out;
    status = Status();
    EXPECT_EQ(Field(status, "state"), "PAUSED");
    EXPECT_NEAR(std::strtod(Field(status, "simulated time [s]").c_str(), nullptr) - before, n * kDt,
                1e-9);
  }
  EXPECT_EQ(Field(status, "steps"), "350");

  // running: the time advances; paused: it stands still; a step while running is refused
  ASSERT_EQ(Ctl({"start"}).exit_code, 0);
  EXPECT_EQ(Field(Status(), "state"), "RUNNING");
  const double running_from = SimTime();
  EXPECT_TRUE(WaitFor([&] { return SimTime() > running_from + 0.1; }, seconds(5)));
  const auto step_running = Ctl({"step", "10"});
  EXPECT_EQ(step_running.exit_code, 1);
  EXPECT_TRUE(Contains(step_running.err, "running")) << step_running.err;
  const auto pause = Ctl({"pause"});
  ASSERT_EQ(pause.exit_code, 0) << pause.err;
  EXPECT_TRUE(Contains(pause.out, "model0: PAUSED at t = ")) << pause.out;
  const double paused_at = SimTime();
  std::this_thread::sleep_for(milliseconds(200));
  EXPECT_EQ(SimTime(), paused_at);

  // stop rewinds to the loaded state; reset rewinds and keeps running
  ASSERT_EQ(Ctl({"stop"}).exit_code, 0);
  status = Status();
  EXPECT_EQ(Field(status, "state"), "STOPPED");
  EXPECT_EQ(SimTime(), 0.0);
  ASSERT_EQ(Ctl({"start"}).exit_code, 0);
  EXPECT_TRUE(WaitFor([&] { return SimTime() > 0.3; }, seconds(5)));
  ASSERT_EQ(Ctl({"reset"}).exit_code, 0);
  status = Status();
  EXPECT_EQ(Field(status, "state"), "RUNNING");
  EXPECT_LT(std::strtod(Field(status, "simulated time [s]").c_str(), nullptr), 0.2);
}

TEST_F(ModelTest, AchievedRealTimeFactorStaysPositiveAcrossAResetWhileRunning) {
  Load(kPendulum);
  ASSERT_EQ(Ctl({"start"}).exit_code, 0);
  std::this_thread::sleep_for(milliseconds(1300));
  ASSERT_EQ(Ctl({"reset"}).exit_code, 0);
  // the factor is measured over windows of a second; the first one after the reset spans it
  std::this_thread::sleep_for(milliseconds(1100));
  const std::string status = Status();
  EXPECT_EQ(Field(status, "state"), "RUNNING");
  const std::string line = Field(status, "real-time factor");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(line, m, std::regex("^1 requested, ([-0-9.e]+) achieved")))
      << status;
  EXPECT_NEAR(std::strtod(m[1].str().c_str(), nullptr), 1.0, 0.2) << status;
}

// ------------------------------------------------------------------------ parameters

TEST_F(ModelTest, ParamsListsIdsWithUnitsShapesAndAccess) {
  Load(kPendulum);
  const auto all = Ctl({"params"});
  ASSERT_EQ(all.exit_code, 0) << all.err;
  EXPECT_TRUE(std::regex_search(all.out, std::regex("(^|\n)ID +UNIT +SHAPE +ACCESS +KIND +VALUE")))
      << all.out;
  EXPECT_TRUE(std::regex_search(
      all.out, std::regex("\npendulum_tendon\\.pendulum\\.mass +kg +1x1 +rw +static +0\\.6\n")))
      << all.out;
  EXPECT_TRUE(std::regex_search(
      all.out, std::regex("\npendulum_tendon\\.line\\.tendon\\.tension +N +1x1 +ro +dynamic +0\n")))
      << all.out;
  EXPECT_TRUE(std::regex_search(
      all.out, std::regex("\npendulum_tendon\\.pendulum\\.position +m +3x1 +ro +dynamic *\n")))
      << all.out;
  EXPECT_TRUE(std::regex_search(
      all.out, std::regex("\npendulum_tendon\\.motor\\.command +V +1x1 +rw +dynamic")))
      << all.out;

  // a word matches the ids that contain it; a glob matches as a glob
  const auto tension = Ctl({"params", "tension"});
  ASSERT_EQ(tension.exit_code, 0) << tension.err;
  const auto lines = Lines(tension.out);
  ASSERT_GE(lines.size(), 3u) << tension.out;
  for (size_t i = 1; i < lines.size(); ++i) {
    EXPECT_TRUE(Contains(lines[i], "tension")) << lines[i];
    EXPECT_TRUE(std::regex_search(lines[i], std::regex(" N +1x1 "))) << lines[i];
  }
  EXPECT_TRUE(Contains(tension.out, "\npendulum_tendon.line.tendon.tension ")) << tension.out;
  EXPECT_TRUE(Contains(tension.out, "\npendulum_tendon.motor.tension ")) << tension.out;
  const auto glob = Ctl({"params", "pendulum_tendon.motor.*_inertia"});
  EXPECT_EQ(Lines(glob.out).size(), 3u) << glob.out;
  const auto none = Ctl({"params", "nothing_like_this"});
  EXPECT_EQ(none.exit_code, 0);
  EXPECT_TRUE(Contains(none.out, "no id matches")) << none.out;
}

TEST_F(ModelTest, GetAndSetRoundTripAStaticParameterAndRefuseBadWrites) {
  Load(kPendulum);
  EXPECT_NEAR(Get(kMass), 0.6, 1e-6);
  const auto set = Ctl({"set", kMass, "0.75"});
  ASSERT_EQ(set.exit_code, 0) << set.err;
  EXPECT_EQ(set.out, std::string(kMass) + " = 0.75 kg\n");
  const auto get = Ctl({"get", kMass, kPosition, "pendulum_tendon.pendulum.rotation"});
  ASSERT_EQ(get.exit_code, 0) << get.err;
  EXPECT_TRUE(Contains(get.out, std::string(kMass) + " = 0.75 kg\n")) << get.out;
  // a vector on one line with its unit, a matrix row by row
  EXPECT_TRUE(std::regex_search(get.out, std::regex("\npendulum_tendon\\.pendulum\\.position = "
                                                    "\\[[^,]+, [^,]+, 1\\.1\\] m\n")))
      << get.out;
  EXPECT_TRUE(std::regex_search(
      get.out, std::regex("\npendulum_tendon\\.pendulum\\.rotation \\(3x3\\) =\n( +[-0-9.e]+ +"
                          "[-0-9.e]+ +[-0-9.e]+\n){3}$")))
      << get.out;

  // the new mass takes part in the simulation: stepping still works, and it stays
  ASSERT_EQ(Ctl({"step", "10"}).exit_code, 0);
  EXPECT_NEAR(Get(kMass), 0.75, 1e-6);

  struct Case {
    std::vector<std::string> args;
    std::string reason;
  };
  const std::vector<Case> refused = {
      {{"set", kTension, "3"}, std::string(kTension) + ": read-only"},
      {{"set", kMass, "nan"}, std::string(kMass) + ": value is not finite"},
      {{"set", kMass, "inf"}, "not finite"},
      {{"set", kMass, "-1"}, "mass must be positive"},
      {{"set", kMass, "1", "2"}, "expected 1 values (shape 1x1), got 2"},
  };
  for (const Case& c : refused) {
    const auto r = Ctl(c.args);
    EXPECT_EQ(r.exit_code, 1) << c.args[2];
    EXPECT_TRUE(Contains(r.err, c.reason)) << r.err;
    EXPECT_EQ(r.out, "");
  }
  EXPECT_NEAR(Get(kMass), 0.75, 1e-6) << "refused writes change nothing";

  const auto not_a_number = Ctl({"set", kMass, "heavy"});
  EXPECT_EQ(not_a_number.exit_code, 2);
  EXPECT_TRUE(Contains(not_a_number.err, "'heavy' is not a number")) << not_a_number.err;
}

TEST_F(ModelTest, UnknownIdsAndActuatorsAreNamed) {
  Load(kPendulum);
  const auto get = Ctl({"get", kMass, "pendulum_tendon.no_such.mass"});
  EXPECT_EQ(get.exit_code, 1);
  EXPECT_TRUE(Contains(get.err, "'pendulum_tendon.no_such.mass'")) << get.err;
  EXPECT_EQ(get.out, "") << "nothing printed when one id is unknown";
  const auto set = Ctl({"set", "pendulum_tendon.no_such.mass", "1"});
  EXPECT_EQ(set.exit_code, 1);
  EXPECT_TRUE(Contains(set.err, "'pendulum_tendon.no_such.mass'")) << set.err;
  const auto motor = Ctl({"motor", "no_such_motor", "3"});
  EXPECT_EQ(motor.exit_code, 1);
  EXPECT_TRUE(Contains(motor.err, "no actuator 'no_such_motor'")) << motor.err;
  const auto record = Ctl(
      {"record", "pendulum_tendon.nope", "--duration", "0.1", "--csv", dir_.path() + "/never.csv"});
  EXPECT_EQ(record.exit_code, 1);
  EXPECT_TRUE(Contains(record.err, "'pendulum_tendon.nope'")) << record.err;
  const auto model = Ctl({"status", "--model", "model7"});
  EXPECT_EQ(model.exit_code, 1);
  EXPECT_TRUE(Contains(model.err, "model7")) << model.err;
}

TEST_F(ModelTest, WithoutASceneEveryCallRaisesItsDeclaredNotAvailableWithTheReason) {
  // a client sees the reason, not CORBA::UNKNOWN: each operation declares what it raises
  S::StringSeq ids;
  ids.length(1);
  ids[0] = CORBA::string_dup(kMass);
  const auto expect_daq_unavailable = [](const char* what, const std::function<void()>& call) {
    try {
      call();
      ADD_FAILURE() << what << " succeeded without a scene";
    } catch (const D::NotAvailable& e) {
      EXPECT_TRUE(Contains(e.reason.in(), "no scene is loaded")) << what << ": " << e.reason.in();
    } catch (const CORBA::Exception& e) {
      ADD_FAILURE() << what << " raised " << e._name() << ", not Daq::NotAvailable";
    }
  };
  expect_daq_unavailable("sample", [&] { D::ValueSeq_var v = Model()->sample(ids); });
  expect_daq_unavailable("get", [&] { D::ValueSeq_var v = Model()->get(ids); });
  expect_daq_unavailable("set", [&] {
    D::Value value;
    value.rows = value.cols = 1;
    value.data.length(1);
    value.data[0] = 1.0;
    Model()->set(kMass, value);
  });
  struct Discard : public virtual POA_Caliper::Daq::DataConsumer {
    void on_samples(const D::SampleBatch&) override {}
  };
  auto* consumer = new Discard;
  PortableServer::POA_var poa = RootPoa(Orb());
  PortableServer::ObjectId_var oid = poa->activate_object(consumer);
  consumer->_remove_ref();
  CORBA::Object_var consumer_obj = poa->id_to_reference(oid);
  D::DataConsumer_var consumer_ref = D::DataConsumer::_narrow(consumer_obj);
  expect_daq_unavailable("subscribe", [&] { Model()->subscribe(ids, 1, consumer_ref); });
  poa->deactivate_object(oid);
  // the Simulation interfaces' operations raise Simulation's NotAvailable
  const auto expect_unavailable = [](const char* what, const std::function<void()>& call) {
    try {
      call();
      ADD_FAILURE() << what << " succeeded without a scene";
    } catch (const M::NotAvailable& e) {
      EXPECT_TRUE(Contains(e.reason.in(), "no scene is loaded")) << what << ": " << e.reason.in();
    } catch (const CORBA::Exception& e) {
      ADD_FAILURE() << what << " raised " << e._name() << ", not Simulation::NotAvailable";
    }
  };
  expect_unavailable("start", [&] { Model()->start(); });
  expect_unavailable("set_command", [&] { Model()->set_command("motor", 1.0); });
  expect_unavailable("set_time_step", [&] { Model()->set_time_step(0.002); });
  expect_unavailable("measurement_delays",
                     [&] { S::SensorDelaySeq_var d = Model()->measurement_delays(); });
}

// ------------------------------------------------------------------------ loading

TEST_F(ModelTest, MalformedFileFailsWithTheImportersMessageAndThePreviousSceneKeepsRunning) {
  Load(kPendulum);
  ASSERT_EQ(Ctl({"start"}).exit_code, 0);
  struct Case {
    std::string file;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"tests/data/collada/malformed_negative_mass.dae", "a dynamic body needs a positive mass"},
      {"tests/data/collada/malformed_xml.dae", ":40: malformed XML"},
      {"tests/data/collada/malformed_unknown_kind.dae", "unknown actuator kind"},
      {"tests/data/collada/malformed_dangling_tendon_body.dae",
       ":102: attachment: dangling reference: tendon 'line' point on unknown body"},
      {"tests/data/collada/no_such_file.dae", "cannot open"},
  };
  for (const Case& c : cases) {
    const auto r = Ctl({"load", Source(c.file)});
    EXPECT_EQ(r.exit_code, 1) << c.file;
    EXPECT_TRUE(Contains(r.err, Source(c.file))) << r.err;
    EXPECT_TRUE(Contains(r.err, c.message)) << r.err;
    EXPECT_TRUE(Contains(r.err, "model0 keeps " + Source(kPendulum) + ", RUNNING")) << r.err;
    const std::string status = Status();
    EXPECT_EQ(Field(status, "state"), "RUNNING");
    EXPECT_EQ(Field(status, "scene"), Source(kPendulum));
    const double t = SimTime();
    EXPECT_TRUE(WaitFor([&] { return SimTime() > t + 0.05; }, seconds(5))) << "still running";
  }
}

// ------------------------------------------------------------------------ motors

TEST_F(ModelTest, MotorChangesTheCommandAndTheTendonTension) {
  Load(kPendulum);
  ASSERT_EQ(Ctl({"step", "300"}).exit_code, 0);
  const double slack = Get(kTension);
  const auto motor = Ctl({"motor", "motor", "6"});
  ASSERT_EQ(motor.exit_code, 0) << motor.err;
  EXPECT_EQ(motor.out, "motor command = 6 V\n");
  const auto list = Ctl({"motor"});
  ASSERT_EQ(list.exit_code, 0) << list.err;
  EXPECT_TRUE(std::regex_search(list.out, std::regex("\nmotor +dc_motor_tendon +line +6 V ")))
      << list.out;
  EXPECT_EQ(Get("pendulum_tendon.motor.command"), 6.0);
  ASSERT_EQ(Ctl({"step", "1000"}).exit_code, 0);
  const double pulled = Get(kTension);
  EXPECT_GT(pulled, slack + 0.5) << "the motor winds the line in";
  EXPECT_EQ(Get("pendulum_tendon.motor.tension"), pulled);
  EXPECT_GT(Get("pendulum_tendon.pivot.position"), 0.01) << "and lifts the pendulum";

  // a command written as a parameter is the actuator's command too
  ASSERT_EQ(Ctl({"set", "pendulum_tendon.motor.command", "3"}).exit_code, 0);
  const auto three = Ctl({"motor"});
  EXPECT_TRUE(std::regex_search(three.out, std::regex("\nmotor +dc_motor_tendon +line +3 V ")))
      << three.out;

  const auto bad = Ctl({"motor", "motor", "nan"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(Contains(bad.err, "not finite")) << bad.err;
  EXPECT_EQ(Ctl({"motor", "motor"}).exit_code, 2);
}

// ------------------------------------------------------------------------ record and save

TEST_F(ModelTest, RecordWritesACsvWithUnitsForTheSimulatedDuration) {
  Load(kPendulum);
  ASSERT_EQ(Ctl({"motor", "motor", "6"}).exit_code, 0);
  ASSERT_EQ(Ctl({"start"}).exit_code, 0);
  const std::string csv = dir_.path() + "/record.csv";
  constexpr int kEvery = 10;
  constexpr double kDuration = 0.6;
  const auto r = Ctl({"record", kPosition, kTension, "--every", std::to_string(kEvery),
                      "--duration", "0.6", "--csv", csv});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Contains(r.err, "100% (t = ")) << r.err;
  EXPECT_TRUE(Contains(r.out, "no gaps")) << r.out;

  const auto lines = Lines(ReadFile(csv));
  ASSERT_GE(lines.size(), 2u);
  EXPECT_EQ(lines[0],
            "time [s],pendulum_tendon.pendulum.position[0] [m],"
            "pendulum_tendon.pendulum.position[1] [m],pendulum_tendon.pendulum.position[2] [m],"
            "pendulum_tendon.line.tendon.tension [N]");
  const double expected = kDuration / (kEvery * kDt);
  const double rows = static_cast<double>(lines.size() - 1);
  EXPECT_NEAR(rows, expected, 1.0) << ReadFile(csv);
  EXPECT_TRUE(Contains(r.out, "wrote " + std::to_string(lines.size() - 1) + " samples")) << r.out;
  double previous = -1;
  for (size_t i = 1; i < lines.size(); ++i) {
    const auto fields = Split(lines[i], ',');
    ASSERT_EQ(fields.size(), 5u) << lines[i];
    const double t = std::strtod(fields[0].c_str(), nullptr);
    if (i > 1) {
      EXPECT_GT(t, previous) << "line " << i;
      EXPECT_NEAR(t - previous, kEvery * kDt, 1e-9) << "line " << i;
    }
    previous = t;
    for (const auto& f : fields) EXPECT_TRUE(std::isfinite(std::strtod(f.c_str(), nullptr)));
  }
  const double first = std::strtod(Split(lines[1], ',')[0].c_str(), nullptr);
  EXPECT_LE(previous - first, kDuration + 1e-9);
}

TEST_F(ModelTest, RecordUsageErrors) {
  const auto no_csv = Ctl({"record", kTension, "--duration", "1"});
  EXPECT_EQ(no_csv.exit_code, 2);
  EXPECT_TRUE(Contains(no_csv.err, "--csv FILE is required")) << no_csv.err;
  const auto every = Ctl({"record", kTension, "--every", "0", "--csv", "x.csv"});
  EXPECT_EQ(every.exit_code, 2);
  const auto duration = Ctl({"record", kTension, "--duration", "-1", "--csv", "x.csv"});
  EXPECT_EQ(duration.exit_code, 2);
  EXPECT_TRUE(Contains(duration.err, "--duration")) << duration.err;
  const auto no_ids = Ctl({"record", "--csv", "x.csv"});
  EXPECT_EQ(no_ids.exit_code, 2);
  const auto option = Ctl({"record", kTension, "--evry", "2", "--csv", "x.csv"});
  EXPECT_EQ(option.exit_code, 2);
  EXPECT_TRUE(Contains(option.err, "unknown option '--evry'")) << option.err;
}

TEST_F(ModelTest, SaveWritesAFileThatInspectAccepts) {
  Load(kPendulum);
  ASSERT_EQ(Ctl({"set", kMass, "0.75"}).exit_code, 0);
  const std::string out = dir_.path() + "/saved.dae";
  const auto save = Ctl({"save", out});
  ASSERT_EQ(save.exit_code, 0) << save.err;
  EXPECT_TRUE(Contains(save.out, out)) << save.out;
  const auto inspect = Ctl({"inspect", out});
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  EXPECT_TRUE(Contains(inspect.out, "bodies (2: 1 dynamic, 1 static)")) << inspect.out;
  EXPECT_TRUE(std::regex_search(inspect.out, std::regex("\n  pendulum +dynamic, 0\\.75 kg")))
      << inspect.out;
  EXPECT_TRUE(Contains(inspect.out, "actuators (1: 1 dc_motor_tendon)")) << inspect.out;
  // the saved file loads back into the Model
  const auto load = Ctl({"load", out});
  EXPECT_EQ(load.exit_code, 0) << load.err;
  EXPECT_NEAR(Get(kMass), 0.75, 1e-6);

  const auto bad = Ctl({"save", "/nonexistent-dir/saved.dae"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(Contains(bad.err, "/nonexistent-dir/saved.dae")) << bad.err;
}

// ------------------------------------------------------------------------ observers

TEST_F(ModelTest, ObserverReceivesTheSceneThenOnlyTheBodiesThatMoved) {
  Load(kPendulum);
  M::Model_ptr model = Model();
  model->set_command("motor", 6);  // the pendulum swings up; the frame is static
  ActiveObserver active;
  RecordingObserver& observer = active.observer();
  const CORBA::ULongLong id = model->add_observer(active.ref());
  ASSERT_TRUE(WaitFor([&] { return observer.updates().size() >= 1; }, seconds(5)));
  model->step(500);
  ASSERT_TRUE(WaitFor(
      [&] {
        const auto u = observer.updates();
        return !u.empty() && std::abs(u.back().time - 0.5) < 1e-9;
      },
      seconds(5)));
  model->remove_observer(id);

  const auto scenes = observer.scenes();
  ASSERT_EQ(scenes.size(), 1u);
  const std::vector<std::pair<std::string, bool>> bodies = {{"frame", false}, {"pendulum", true}};
  EXPECT_EQ(scenes[0], bodies);

  const auto updates = observer.updates();
  ASSERT_GE(updates.size(), 2u);
  EXPECT_EQ(updates[0].update, 1u);
  EXPECT_EQ(updates[0].changed, (std::vector<uint32_t>{0, 1})) << "the first call has every body";
  bool pendulum_moved = false;
  for (size_t i = 1; i < updates.size(); ++i) {
    EXPECT_EQ(updates[i].update, updates[i - 1].update + 1);
    EXPECT_GE(updates[i].time, updates[i - 1].time);
    EXPECT_EQ(std::count(updates[i].changed.begin(), updates[i].changed.end(), 0u), 0)
        << "the static frame in update " << updates[i].update;
    pendulum_moved |= updates[i].changed == std::vector<uint32_t>{1};
    EXPECT_EQ(updates[i].tendons, 1u);
  }
  EXPECT_TRUE(pendulum_moved);
}

TEST_F(ModelTest, ASlowObserverDoesNotSlowTheSimulation) {
  Load(kPendulum);
  M::Model_ptr model = Model();
  model->set_command("motor", 6);
  model->set_real_time_factor(1.0);
  ActiveObserver slow(milliseconds(100));
  model->add_observer(slow.ref());
  const auto wall_start = std::chrono::steady_clock::now();
  model->start();
  std::this_thread::sleep_for(milliseconds(2300));
  M::SimulationStatus_var status = model->status();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  EXPECT_EQ(status->state, M::RUNNING);
  EXPECT_NEAR(status->achieved_real_time_factor, 1.0, 0.1);
  EXPECT_NEAR(status->sim_time / wall, 1.0, 0.1);

  // the observer got coalesced updates, numbered without a break
  const auto updates = slow.observer().updates();
  EXPECT_LE(updates.size(), static_cast<size_t>(wall / 0.1) + 2);
  EXPECT_GE(updates.size(), 5u);
  for (size_t i = 1; i < updates.size(); ++i) {
    EXPECT_EQ(updates[i].update, updates[i - 1].update + 1);
    if (i > 1) {
      EXPECT_GT(updates[i].time - updates[i - 1].time, 0.05) << "coalesced";
    }
  }
}

TEST_F(ModelTest, AnObserverThatIsGoneIsDroppedAndTheModelKeepsRunning) {
  Load(kPendulum);
  M::Model_ptr model = Model();
  model->set_command("motor", 6);
  ActiveObserver gone;
  model->add_observer(gone.ref());
  model->start();
  ASSERT_TRUE(WaitFor([&] { return gone.observer().updates().size() >= 3; }, seconds(5)));
  gone.Deactivate();  // its calls raise OBJECT_NOT_EXIST, as for a process that ended
  ASSERT_TRUE(
      WaitFor([&] { return Contains(model_->Output(), "dropping an observer"); }, seconds(5)))
      << model_->Output();
  EXPECT_TRUE(Contains(model_->Output(), "OBJECT_NOT_EXIST")) << model_->Output();

  // the simulation runs on, and other observers are served
  const double t = M::SimulationStatus_var(model->status())->sim_time;
  EXPECT_TRUE(WaitFor([&] { return M::SimulationStatus_var(model->status())->sim_time > t + 0.2; },
                      seconds(5)));
  EXPECT_EQ(M::SimulationStatus_var(model->status())->state, M::RUNNING);
  ActiveObserver next;
  model->add_observer(next.ref());
  EXPECT_TRUE(WaitFor([&] { return next.observer().updates().size() >= 3; }, seconds(5)));
  EXPECT_EQ(next.observer().scenes().size(), 1u);
}

// ------------------------------------------------------------------------ usage

TEST(ModelVerbs, EveryVerbHasHelpAndBadUsageExits2WithoutASession) {
  const std::string none = "corbaname::127.0.0.1:1";
  for (const std::string verb : {"load", "start", "pause", "stop", "reset", "step", "status",
                                 "params", "get", "set", "motor", "record", "save"}) {
    const auto r = caliper::testing::Ctl(none, {verb, "--help"});
    EXPECT_EQ(r.exit_code, 0) << verb;
    EXPECT_TRUE(Contains(r.out, "Usage: caliper-ctl " + verb)) << r.out;
    EXPECT_TRUE(Contains(r.out, "--model NAME")) << r.out;
  }
  const auto help = caliper::testing::Ctl(none, {"--help"});
  for (const std::string verb : {"load", "step", "params", "record", "save", "inspect", "log"})
    EXPECT_TRUE(std::regex_search(help.out, std::regex("\n  " + verb + " +[a-z]"))) << help.out;
  EXPECT_TRUE(Contains(help.out, "--model NAME")) << help.out;

  const std::vector<std::vector<std::string>> usage = {{"step"},
                                                       {"step", "ten"},
                                                       {"step", "-3"},
                                                       {"load"},
                                                       {"load", "a", "b"},
                                                       {"get"},
                                                       {"set", "x"},
                                                       {"status", "extra"},
                                                       {"params", "a", "b"},
                                                       {"save"},
                                                       {"start", "--frob"},
                                                       {"step", "1", "--model"},
                                                       {"reset", "sample0", "--model", "model0"}};
  for (const auto& args : usage) {
    const auto r = caliper::testing::Ctl(none, args);
    EXPECT_EQ(r.exit_code, 2) << args[0] << " " << (args.size() > 1 ? args[1] : "") << ": "
                              << r.err;
    EXPECT_TRUE(Contains(r.err, "Usage: caliper-ctl " + args[0])) << r.err;
  }
}

// ------------------------------------------------------------------------ hostile clients

// step(4000000000) from one connection: status, get and a second step from another are
// answered at once, and stop ends the request, which replies with the steps that ran.
TEST_F(ModelTest, AHugeStepLeavesTheModelAnsweringAndStopEndsIt) {
  Load(kPendulum);
  M::Model_var stepper = M::Model::_duplicate(Model());
  omniORB::setClientCallTimeout(stepper, 60000);
  std::promise<CORBA::ULong> ran;
  std::thread request([&] {
    try {
      ran.set_value(stepper->step(4000000000u));
    } catch (...) {
      ran.set_exception(std::current_exception());
    }
  });
  auto result = ran.get_future();
  // a second client: its own ORB connection through caliper-ctl
  ASSERT_TRUE(WaitFor([&] { return Field(Status(), "state") == "RUNNING"; }, seconds(10)))
      << Status();
  const double during = SimTime();
  EXPECT_GT(Get(kPosition + std::string()), -1e9);  // answered (not NaN from a failed call)
  const auto second = Ctl({"step", "10"});
  EXPECT_EQ(second.exit_code, 1);
  EXPECT_TRUE(Contains(second.err, "4000000000")) << second.err;
  EXPECT_TRUE(WaitFor([&] { return SimTime() > during; }, seconds(10)));
  const auto stop = Ctl({"stop"});
  EXPECT_EQ(stop.exit_code, 0) << stop.err;
  ASSERT_EQ(result.wait_for(seconds(20)), std::future_status::ready) << "stop did not end it";
  request.join();
  const CORBA::ULong steps = result.get();
  EXPECT_GT(steps, 0u);
  EXPECT_LT(steps, 4000000000u);
  EXPECT_EQ(Field(Status(), "state"), "STOPPED");
  // pause ends one too, and ctl says it ended early
  CommandResult paused_step;
  std::thread again([&] { paused_step = Ctl({"step", "4000000000"}); });
  ASSERT_TRUE(WaitFor([&] { return SimTime() > 0.05; }, seconds(10)));
  EXPECT_EQ(Ctl({"pause"}).exit_code, 0);
  again.join();
  EXPECT_EQ(paused_step.exit_code, 0) << paused_step.err;
  EXPECT_TRUE(Contains(paused_step.out, "ended early by a stop or pause")) << paused_step.out;
  EXPECT_TRUE(Contains(paused_step.out, "of 4000000000 steps")) << paused_step.out;
  EXPECT_EQ(Field(Status(), "state"), "PAUSED");
}

TEST_F(ModelTest, CallsAskingTooMuchRaiseLimitExceededWithTheBound) {
  Load(kPendulum);
  S::StringSeq ids;
  ids.length(1000001);
  for (CORBA::ULong i = 0; i < ids.length(); ++i) ids[i] = "x";
  try {
    D::ValueSeq_var values = Model()->get(ids);
    ADD_FAILURE() << "a million ids were read in one call";
  } catch (const D::LimitExceeded& e) {
    EXPECT_GT(e.limit, 0u);
    EXPECT_LT(e.limit, 1000001u);
    EXPECT_TRUE(Contains(e.reason.in(), "1000001 ids")) << e.reason.in();
  }
  try {
    D::ChannelInfoSeq_var list = Model()->list(std::string(5000, '*').c_str());
    ADD_FAILURE() << "a 5000-character pattern was accepted";
  } catch (const D::LimitExceeded& e) {
    EXPECT_TRUE(Contains(e.reason.in(), "5000 characters")) << e.reason.in();
  }
  // the Model is fine afterwards
  EXPECT_EQ(Field(Status(), "state"), "STOPPED");
}

// A Model whose fifth step throws std::bad_alloc (model.inject_fault, a fail point): over the
// IDL, the step request returns the four steps that ran, the state is FAULTED with the reason,
// the component stays ACTIVE (its execution context goes on), and reset brings it back. The
// same while running: the periodic execution context meets the exception.
class FaultingModelTest : public ModelTest {
 protected:
  FaultingModelTest() { extra_args_ = {"-o", "model.inject_fault=bad_alloc@5"}; }
};

TEST_F(FaultingModelTest, AnExceptionInAStepIsAFaultedStateNotACrash) {
  Load(kPendulum);
  EXPECT_EQ(Model()->step(10), 4u);
  M::SimulationStatus_var s = Model()->status();
  EXPECT_EQ(s->state, M::FAULTED);
  EXPECT_EQ(s->steps, 4u);
  EXPECT_TRUE(Contains(s->last_error.in(), "bad_alloc")) << s->last_error.in();
  EXPECT_THROW(Model()->step(1), M::NotAvailable);
  EXPECT_THROW(Model()->start(), M::NotAvailable);
  const auto state = Ctl({"state", "model0"});
  EXPECT_TRUE(Contains(state.out, "ACTIVE")) << state.out << state.err;
  EXPECT_FALSE(Contains(state.out, "ERROR")) << state.out;
  Model()->reset();
  EXPECT_EQ(M::SimulationStatus_var(Model()->status())->state, M::STOPPED);
  EXPECT_EQ(Model()->step(10), 10u);
  EXPECT_TRUE(model_->Running());
}

class FaultingRunningModelTest : public ModelTest {
 protected:
  FaultingRunningModelTest() { extra_args_ = {"-o", "model.inject_fault=runtime_error@200"}; }
};

TEST_F(FaultingRunningModelTest, TheExecutionContextMeetsTheExceptionAndTheModelSaysFaulted) {
  Load(kPendulum);
  ASSERT_EQ(Ctl({"start"}).exit_code, 0);
  ASSERT_TRUE(WaitFor([&] { return Field(Status(), "state") == "FAULTED"; }, seconds(10)))
      << Status();
  EXPECT_TRUE(Contains(Field(Status(), "last error"), "solver did not converge")) << Status();
  EXPECT_EQ(Field(Status(), "steps"), "199");
  const auto state = Ctl({"state", "model0"});
  EXPECT_TRUE(Contains(state.out, "ACTIVE")) << state.out << state.err;
  ASSERT_EQ(Ctl({"stop"}).exit_code, 0);
  ASSERT_EQ(Ctl({"start"}).exit_code, 0);
  const double from = SimTime();
  EXPECT_TRUE(WaitFor([&] { return SimTime() > from + 0.3; }, seconds(10))) << Status();
}

}  // namespace
}  // namespace caliper::testing
