#include "support/corba.h"

#include <csignal>
#include <cstdlib>

#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;

bool& TestOrbCreated() {
  static bool created = false;
  return created;
}

/// Destroys the ORB TestOrb made after the last test.
class TestOrbEnvironment : public ::testing::Environment {
 public:
  void TearDown() override {
    if (TestOrbCreated()) TestOrb({})->destroy();
  }
};

const auto* const kTestOrbEnvironment = ::testing::AddGlobalTestEnvironment(new TestOrbEnvironment);

void ActivateRootPoa(CORBA::ORB_ptr orb) {
  PortableServer::POA_var poa = RootPoa(orb);
  PortableServer::POAManager_var manager = poa->the_POAManager();
  manager->activate();
}

}  // namespace

CORBA::ORB_ptr TestOrb(const std::vector<std::string>& args) {
  static CORBA::ORB_var orb = [&] {
    std::vector<std::string> copy = args;
    std::vector<char*> argv;
    for (auto& a : copy) argv.push_back(a.data());
    int argc = static_cast<int>(argv.size());
    CORBA::ORB_var o = CORBA::ORB_init(argc, argv.data());
    ActivateRootPoa(o);
    TestOrbCreated() = true;
    return o;
  }();
  return orb.in();
}

CORBA::ORB_ptr ServingClientOrb(const char* program, double call_timeout_s) {
  static CORBA::ORB_ptr orb = [&] {
    CORBA::ORB_ptr o = rtc::ClientOrb(program, call_timeout_s);
    ActivateRootPoa(o);
    return o;
  }();
  return orb;
}

PortableServer::POA_ptr RootPoa(CORBA::ORB_ptr orb) {
  CORBA::Object_var obj = orb->resolve_initial_references("RootPOA");
  return PortableServer::POA::_narrow(obj);
}

CORBA::Object_ptr Activate(CORBA::ORB_ptr orb, PortableServer::ServantBase* servant) {
  PortableServer::POA_var poa = RootPoa(orb);
  PortableServer::ObjectId_var id = poa->activate_object(servant);
  servant->_remove_ref();
  return poa->id_to_reference(id);
}

::Caliper::Logging::Record TestRecord(const std::string& instance, const std::string& source,
                                      CORBA::ULongLong seq, const std::string& message) {
  ::Caliper::Logging::Record r;
  r.time_us = 1700000000000000;
  r.priority = 600;
  r.category = "caliper.test.hostile";
  r.instance = instance.c_str();
  r.host = "localhost";
  r.pid = 1;
  r.source = source.c_str();
  r.seq = seq;
  r.message = message.c_str();
  return r;
}

::Caliper::Logging::RecordFilter RecordsOf(const std::string& instance, const std::string& regex) {
  ::Caliper::Logging::RecordFilter q;
  q.max_priority = 700;
  q.category_prefix = "";
  q.instance = instance.c_str();
  q.regex = regex.c_str();
  q.from_time_us = 0;
  q.to_time_us = 0;
  q.after_serial = 0;
  q.limit = 0;
  return q;
}

M::Model_ptr WaitForModel(CORBA::ORB_ptr orb, const std::string& naming_address,
                          const std::string& name, std::chrono::milliseconds timeout) {
  M::Model_var model;
  const bool answered = WaitFor(
      [&] {
        try {
          CosNaming::NamingContext_var root = rtc::ResolveRoot(orb, naming_address);
          model = M::Model::_narrow(rtc::FindComponent(root, name).object);
          return !CORBA::is_nil(model) && !model->_non_existent();
        } catch (...) {
          return false;
        }
      },
      timeout);
  return answered ? model._retn() : M::Model::_nil();
}

std::string LoadRefusal(M::Model_ptr model, const std::string& path) {
  try {
    model->load_scene(path.c_str());
    return "";
  } catch (const M::LoadFailed& e) {
    return e.reason.in();
  }
}

std::string LoadedScene(M::Model_ptr model) {
  M::SimulationStatus_var s = model->status();
  return s->scene.in();
}

void ModelProcessTest::SetUp() {
  orb_();
  naming_ = std::make_unique<NamingService>(dir_.path());
  const char* source = std::getenv("CALIPER_SOURCE_DIR");
  // the shipped model.conf: an execution context at 200 Hz, real time
  model_ = std::make_unique<Process>(
      std::vector<std::string>{Bin("caliper-model"), "--nameservice", naming_->address(), "-o",
                               "model.scene=" + std::string(source != nullptr ? source : ".") +
                                   "/models/pendulum_tendon.dae",
                               "-o", "exec.auto_activate=true", "-o", "log.service=none", "-o",
                               "log.spool_dir=" + dir_.path() + "/spool"},
      dir_.path() + "/model.out");
  ASSERT_TRUE(WaitFor(
      [&] {
        try {
          CosNaming::NamingContext_var root = rtc::ResolveRoot(orb_(), naming_->address());
          model_ref_ = M::Model::_narrow(rtc::FindComponent(root, "model0").object);
          return !CORBA::is_nil(model_ref_) &&
                 M::SimulationStatus_var(model_ref_->status())->state == M::STOPPED;
        } catch (...) {
          return false;
        }
      },
      seconds(20)))
      << model_->Output();
}

void ModelProcessTest::TearDown() {
  if (!model_) return;  // SetUp failed before starting it (and said why)
  model_->Signal(SIGTERM);
  EXPECT_EQ(model_->Wait(seconds(10)), 0) << model_->Output();
}

}  // namespace caliper::testing
