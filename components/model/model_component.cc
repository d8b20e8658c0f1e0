#include "model_component.h"

#include <cstdlib>
#include <log4cpp/Priority.hh>
#include <string>

#include "caliper/logging.hh"
#include "caliper/logging/log.h"
#include "caliper/rtc/naming.h"
#include "caliper/simulation/fault_injection.h"
#include "caliper/simulation/model_files.h"

namespace caliper::model {

using namespace simulation;

namespace {

// the session log's records, into the Model's recording (if one runs)
class SessionLogListener : public virtual POA_Caliper::Logging::LogListener {
 public:
  explicit SessionLogListener(ModelCore& core) : core_(core) {}
  void on_records(const Caliper::Logging::StoredRecordSeq& records) override {
    for (CORBA::ULong i = 0; i < records.length(); ++i) {
      const Caliper::Logging::Record& r = records[i].rec;
      recording::LogRecord out;
      out.time = 1e-6 * static_cast<double>(r.time_us);
      out.priority = log4cpp::Priority::getPriorityName(static_cast<int>(r.priority));
      out.category = r.category.in();
      out.component = r.instance.in();
      out.message = r.message.in();
      core_.AddSessionLog(out);
    }
  }

 private:
  ModelCore& core_;
};

}  // namespace

std::vector<core::ConfigKey> ModelComponent::ConfigKeys() {
  using Type = core::ConfigKey::Type;
  std::vector<core::ConfigKey> keys = {
      {"model.scene", Type::kString, "", "COLLADA scene loaded at start ('' = none)"},
      {"model.real_time_factor", Type::kDouble, "1", "1 = real time, 0 = as fast as possible", 0,
       1e6},
      {"model.autostart", Type::kBool, "false", "start simulating once loaded and active"},
      {"model.tendon_contact", Type::kBool, "true",
       "bend tendons around bodies they would cut through"},
      {"model.physics_threads", Type::kInt, "1",
       "threads that advance the tendons and search contacts at the end of each step (1 = one, "
       "0 = every processor this process may run on); the same results on any count",
       0, 8},
      {"model.inject_fault", Type::kString, "",
       "for tests of the fault path: KIND@STEP makes step STEP of the first scene built throw "
       "(KIND: simulation_fault, bad_alloc, out_of_range, runtime_error, unknown); '' = never"},
  };
  for (const core::ConfigKey& key : ModelFiles::ConfigKeys()) keys.push_back(key);
  return keys;
}

ModelComponent::ModelComponent(rtc::Runtime& runtime)
    : runtime_(runtime), autostart_(runtime.config().GetBool("model.autostart")) {
  physics_bullet::Options options;
  options.tendon_body_contact = runtime.config().GetBool("model.tendon_contact");
  options.threads = static_cast<int>(runtime.config().GetInt("model.physics_threads"));
  if (options.threads != 1) {
    // what BoundThreadSpin set in model_main, or the user's own choice
    const char* spin = std::getenv("GOMP_SPINCOUNT");
    const char* policy = std::getenv("OMP_WAIT_POLICY");
    const std::string waiting =
        spin     ? std::string("spins ") + spin + " turns (GOMP_SPINCOUNT) before it sleeps"
        : policy ? std::string("waits as OMP_WAIT_POLICY=") + policy + " says"
                 : "spins libgomp's default 300000 turns before it sleeps";
    logging::Get("model").info(
        "model.physics_threads = %d: the tendons and the contact search on %d threads at the end "
        "of each step; a thread waiting for work %s",
        options.threads, physics_bullet::ThreadCount(options.threads), waiting.c_str());
  }
  const InjectedFault fault = ParseInjectedFault(runtime.config().GetString("model.inject_fault"));
  if (fault.kind != InjectedFault::Kind::kNone)
    logging::Get("model").warn("model.inject_fault: step %llu of the first scene will throw",
                               static_cast<unsigned long long>(fault.at_step));
  core_ = std::make_unique<ModelCore>(
      options, Limits{},
      fault.kind == InjectedFault::Kind::kNone ? nullptr : FailFirstScene(fault, options));
  core_->SetRealTimeFactor(runtime.config().GetDouble("model.real_time_factor"));
}

rtc::ReturnCode ModelComponent::OnInitialize() {
  const ModelFiles files = ModelFiles::FromConfig(runtime_.config());
  logging::Get("model").info("scene paths from clients: read below %s; written below %s",
                             files.read.Describe().c_str(), files.write.Describe().c_str());
  std::string scene = runtime_.config().GetString("model.scene");
  // a scene a client chose (through a manager) is confined like load_scene's
  if (!scene.empty() && runtime_.config().GetBool("model.confine_scene"))
    scene = files.ResolveScene(scene);
  if (!scene.empty()) core_->Load(scene);  // a bad file fails initialisation with its message
  log_watch_ = std::thread([this] {
    std::unique_lock<std::mutex> lock(log_watch_mutex_);
    while (!log_watch_stop_) {
      lock.unlock();
      const bool done = ListenToSessionLog();
      lock.lock();
      if (done) break;
      log_watch_wake_.wait_for(lock, std::chrono::seconds(2), [this] { return log_watch_stop_; });
    }
  });
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode ModelComponent::OnActivated() {
  if (autostart_ && core_->status().state == RunState::kStopped) core_->Start();
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode ModelComponent::OnDeactivated() {
  try {
    if (core_->status().state == RunState::kRunning) core_->Pause();
  } catch (const NotAvailable&) {
    // an experiment owns the simulation: it is no periodic run to pause
  }
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode ModelComponent::OnFinalize() {
  StopLogWatch();  // before the ORB goes
  core_->CancelExperiment();  // the ORB's shutdown waits for calls in progress
  return rtc::ReturnCode::kOk;
}

bool ModelComponent::ListenToSessionLog() {
  const std::string name = runtime_.config().GetString("log.service");
  if (name.empty() || name == "none") return true;  // nothing to look for
  try {
    CosNaming::NamingContext_var root =
        rtc::ResolveRoot(runtime_.orb(), runtime_.naming_address());
    Caliper::Logging::LogService_var logger =
        Caliper::Logging::LogService::_narrow(rtc::FindComponent(root, name).object);
    if (CORBA::is_nil(logger)) return false;
    CORBA::Object_var ref = runtime_.Activate(new SessionLogListener(*core_));
    logger->add_listener(Caliper::Logging::LogListener::_narrow(ref));
    core_->UseSessionLog(true);
    logging::Get("model").info("recordings take the session log of '%s'", name.c_str());
    return true;
  } catch (const std::exception&) {
    // no Logging component (yet): the Model's own records go into recordings
  } catch (const CORBA::Exception&) {
  }
  return false;
}

void ModelComponent::StopLogWatch() {
  {
    std::lock_guard<std::mutex> lock(log_watch_mutex_);
    log_watch_stop_ = true;
  }
  log_watch_wake_.notify_all();
  if (log_watch_.joinable()) log_watch_.join();
}

ModelComponent::~ModelComponent() { StopLogWatch(); }

rtc::ReturnCode ModelComponent::OnExecute() {
  if (runtime_.context().kind() == rtc::ContextKind::kExternal) {
    core_->Tick();
  } else {
    // leave a fifth of each period to CORBA calls
    const double period = 1.0 / runtime_.context().rate();
    core_->Advance(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(0.8 * period)));
  }
  return rtc::ReturnCode::kOk;
}

}  // namespace caliper::model
