#pragma once
// Helpers for tests that talk to Caliper processes over CORBA: the test program's own ORB, the
// servants it serves, and a fixture running caliper-model.

#include <gtest/gtest.h>
#include <omniORB4/CORBA.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "caliper/logging.hh"
#include "caliper/model.hh"
#include "support/process.h"

namespace caliper::testing {

namespace M = ::Caliper::Simulation;
namespace S = ::Caliper::Scene;
namespace D = ::Caliper::Daq;

/// The test program's ORB (omniORB has one a process) with its RootPOA active, for the servants
/// the test serves: made by the first call from `args` (the program's name, then -ORB options;
/// later calls' are ignored) and destroyed after the last test.
CORBA::ORB_ptr TestOrb(const std::vector<std::string>& args);

/// rtc::ClientOrb(program, call_timeout_s), the ORB of Caliper's clients, with its RootPOA active
/// (never destroyed, as ClientOrb's).
CORBA::ORB_ptr ServingClientOrb(const char* program, double call_timeout_s);

/// The RootPOA of `orb`.
PortableServer::POA_ptr RootPoa(CORBA::ORB_ptr orb);

/// Activates `servant` in the RootPOA of `orb` (which then owns it); returns its reference.
CORBA::Object_ptr Activate(CORBA::ORB_ptr orb, PortableServer::ServantBase* servant);

/// A log record of `instance` (priority 600, category caliper.test.hostile, host localhost, pid
/// 1, a fixed time) from `source` with sequence number `seq`.
::Caliper::Logging::Record TestRecord(const std::string& instance, const std::string& source,
                                      CORBA::ULongLong seq, const std::string& message);

/// A query of every record up to priority 700 of `instance` ("" = any) whose message matches
/// `regex` ("" = any), at any time, unlimited.
::Caliper::Logging::RecordFilter RecordsOf(const std::string& instance, const std::string& regex);

/// The Model bound as `name` in the naming service at `naming_address`, reached through `orb`,
/// as soon as it answers (not _non_existent); nil when it is not bound or does not answer within
/// `timeout` (the naming service and the Model start on their own time, so every failure until
/// then counts as "not yet").
M::Model_ptr WaitForModel(CORBA::ORB_ptr orb, const std::string& naming_address,
                          const std::string& name, std::chrono::milliseconds timeout);

/// The reason of the LoadFailed `model`->load_scene(`path`) raises; "" when it loads.
std::string LoadRefusal(M::Model_ptr model, const std::string& path);

/// The scene `model` has loaded, as its status says ("" when none).
std::string LoadedScene(M::Model_ptr model);

/// A fixture running caliper-model with the shipped pendulum_tendon.dae (its execution context
/// active: 200 Hz, real time; no log service) bound as model0 in a private naming service, reached
/// through the ORB `orb()` returns. SetUp waits up to 20 s for it to be STOPPED; TearDown ends it
/// with SIGTERM and expects exit 0 within 10 s.
class ModelProcessTest : public ::testing::Test {
 protected:
  explicit ModelProcessTest(CORBA::ORB_ptr (*orb)()) : orb_(orb) {}
  void SetUp() override;
  void TearDown() override;

  M::Model_ptr model() { return model_ref_.in(); }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> model_;
  M::Model_var model_ref_;

 private:
  CORBA::ORB_ptr (*orb_)();
};

}  // namespace caliper::testing
