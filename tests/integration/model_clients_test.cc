// The Model against hostile and careless clients, over the IDL only: observers and subscriptions
// capped per client and in all (Daq::LimitExceeded with the limit), a fixed number of threads
// however many calls come, objects that are no observer refused, a slow observer kept and served
// the current state once it answers, and its execution context started and stopped by six clients
// at once. The test's ORB listens on 17 loopback addresses: each address is one "client".
#include <dirent.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <condition_variable>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "support/corba.h"

namespace caliper::testing {
namespace {

namespace R = ::Caliper::RTC;

using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr int kClients = 17;               // loopback addresses the test's ORB listens on
constexpr CORBA::ULongLong kObserversPerClient = 16;
constexpr CORBA::ULongLong kSubscriptionsPerClient = 32;
constexpr CORBA::ULongLong kTotal = 256;   // observers, and subscriptions, over all clients
const char* const kTension = "pendulum_tendon.line.tendon.tension";

/// Threads of a process (entries of /proc/PID/task).
int Threads(pid_t pid) {
  DIR* dir = opendir(("/proc/" + std::to_string(pid) + "/task").c_str());
  if (dir == nullptr) return -1;
  int n = 0;
  while (dirent* e = readdir(dir))
    if (e->d_name[0] != '.') ++n;
  closedir(dir);
  return n;
}

// ------------------------------------------------------------------------ the test's ORB

/// One ORB for the program, listening on 127.0.0.1 .. 127.0.0.17, with objects under readable
/// keys (omniORB's INS POA) so that a reference to any of them through any address is a
/// corbaloc URI.
class Orb {
 public:
  static Orb& Get() {
    static Orb* orb = new Orb;  // lives until the process ends (servants stay active)
    return *orb;
  }
  CORBA::ORB_ptr orb() { return orb_.in(); }

  /// Activates `servant` (the POA owns it) under `key`; returns its reference through the
  /// address of `client` (0 .. kClients - 1).
  CORBA::Object_ptr Activate(PortableServer::Servant servant, const std::string& key, int client) {
    PortableServer::ObjectId_var id = PortableServer::string_to_ObjectId(key.c_str());
    poa_->activate_object_with_id(id, servant);
    servant->_remove_ref();
    return Ref(key, client);
  }
  /// A reference to whatever is (or is not) under `key`, through the address of `client`.
  CORBA::Object_ptr Ref(const std::string& key, int client) {
    return orb_->string_to_object(("corbaloc::" + Address(client) + "/" + key).c_str());
  }
  std::string Address(int client) const {
    return "127.0.0." + std::to_string(client + 1) + ":" + std::to_string(ports_[client]);
  }

 private:
  Orb() {
    std::vector<std::string> args = {"model_clients_test", "-ORBclientCallTimeOutPeriod", "10000",
                                     "-ORBmaxGIOPConnectionPerServer", "16"};
    for (int k = 0; k < kClients; ++k) {
      ports_.push_back(FreePort());
      args.push_back("-ORBendPoint");
      args.push_back("giop:tcp:127.0.0." + std::to_string(k + 1) + ":" +
                     std::to_string(ports_.back()));
    }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    int argc = static_cast<int>(argv.size());
    orb_ = CORBA::ORB_init(argc, argv.data());
    CORBA::Object_var obj = orb_->resolve_initial_references("omniINSPOA");
    poa_ = PortableServer::POA::_narrow(obj);
    poa_->the_POAManager()->activate();
  }

  CORBA::ORB_var orb_;
  PortableServer::POA_var poa_;
  std::vector<int> ports_;
};

class CountingObserver : public virtual POA_Caliper::Scene::SceneObserver {
 public:
  explicit CountingObserver(std::atomic<int>* transforms) : transforms_(transforms) {}
  void on_scene(const S::Description&) override {}
  void on_transforms(CORBA::ULongLong, CORBA::Double, const S::BodyTransformSeq&,
                     const S::TendonStateSeq&) override {
    ++*transforms_;
  }
  void on_scene_cleared() override {}

 private:
  std::atomic<int>* transforms_;
};

class CountingConsumer : public virtual POA_Caliper::Daq::DataConsumer {
 public:
  explicit CountingConsumer(std::atomic<int>* batches) : batches_(batches) {}
  void on_samples(const D::SampleBatch&) override { ++*batches_; }

 private:
  std::atomic<int>* batches_;
};

/// An observer whose calls wait while it is closed, as those of a stopped process do.
class GatedObserver : public virtual POA_Caliper::Scene::SceneObserver {
 public:
  void Close() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = false;
  }
  void Open() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      open_ = true;
    }
    opened_.notify_all();
  }
  /// The latest simulated time received in a transform call [s] (-1 before any).
  double latest_time() {
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_time_;
  }
  int scenes() {
    std::lock_guard<std::mutex> lock(mutex_);
    return scenes_;
  }

  void on_scene(const S::Description&) override {
    std::unique_lock<std::mutex> lock(mutex_);
    ++scenes_;
  }
  void on_transforms(CORBA::ULongLong, CORBA::Double sim_time, const S::BodyTransformSeq&,
                     const S::TendonStateSeq&) override {
    std::unique_lock<std::mutex> lock(mutex_);
    opened_.wait(lock, [&] { return open_; });
    latest_time_ = std::max(latest_time_, static_cast<double>(sim_time));
  }
  void on_scene_cleared() override {}

 private:
  std::mutex mutex_;
  std::condition_variable opened_;
  bool open_ = true;
  double latest_time_ = -1;
  int scenes_ = 0;
};

// ------------------------------------------------------------------------ fixture

class ModelClientsTest : public ModelProcessTest {
 protected:
  ModelClientsTest() : ModelProcessTest([] { return Orb::Get().orb(); }) {}

  /// A fresh observer counting into `transforms`, reached through `client`'s address.
  S::SceneObserver_ptr NewObserver(const std::string& key, int client,
                                   std::atomic<int>* transforms) {
    CORBA::Object_var obj = Orb::Get().Activate(new CountingObserver(transforms), key, client);
    return S::SceneObserver::_unchecked_narrow(obj);
  }
  D::DataConsumer_ptr NewConsumer(const std::string& key, int client, std::atomic<int>* batches) {
    CORBA::Object_var obj = Orb::Get().Activate(new CountingConsumer(batches), key, client);
    return D::DataConsumer::_unchecked_narrow(obj);
  }
};

// ------------------------------------------------------------------------ observers

TEST_F(ModelClientsTest, TenThousandAddObserverCallsStopAtTheCapAndTheThreadsStayFew) {
  const int threads_before = Threads(model_->pid());
  // the counters are static: the Model pushes to the observers until TearDown stops it
  static std::atomic<int> transforms{0};
  std::vector<CORBA::ULongLong> ids;
  std::vector<S::SceneObserver_var> refs;
  int limited = 0;
  for (int i = 0; i < 10000; ++i) {
    S::SceneObserver_var observer = NewObserver("hostile" + std::to_string(i), 0, &transforms);
    try {
      ids.push_back(model()->add_observer(observer));
      refs.push_back(observer);
    } catch (const D::LimitExceeded& e) {
      if (limited++ == 0) {
        EXPECT_EQ(e.limit, kObserversPerClient);
        EXPECT_TRUE(Contains(e.reason.in(), "client " + Orb::Get().Address(0) + " has 16 "
                                            "observers, the most one client may have"))
            << e.reason.in();
      }
      ASSERT_EQ(e.limit, kObserversPerClient) << "call " << i;
    }
  }
  EXPECT_EQ(ids.size(), kObserversPerClient);
  EXPECT_EQ(limited, 10000 - static_cast<int>(kObserversPerClient));
  EXPECT_EQ(std::set<CORBA::ULongLong>(ids.begin(), ids.end()).size(), ids.size());

  const int threads_after = Threads(model_->pid());
  EXPECT_LT(threads_after, 64) << threads_before << " threads before";
  M::SimulationStatus_var status = model()->status();
  EXPECT_EQ(status->state, M::STOPPED);

  // the registered ones are served: each gets the current state, then what steps change
  EXPECT_TRUE(WaitFor([&] { return transforms >= static_cast<int>(kObserversPerClient); },
                      seconds(10)))
      << transforms;
  model()->set_command("motor", 6);
  const int before_steps = transforms;
  EXPECT_EQ(model()->step(200), 200u);
  EXPECT_TRUE(WaitFor([&] { return transforms > before_steps; }, seconds(10)));

  // registering again keeps the id and takes no place; leaving frees one
  EXPECT_EQ(model()->add_observer(refs[3]), ids[3]);
  model()->remove_observer(ids[0]);
  S::SceneObserver_var another = NewObserver("hostile-after-remove", 0, &transforms);
  const CORBA::ULongLong fresh = model()->add_observer(another);
  EXPECT_EQ(std::count(ids.begin(), ids.end(), fresh), 0);
  S::SceneObserver_var one_more = NewObserver("hostile-one-more", 0, &transforms);
  EXPECT_THROW(model()->add_observer(one_more), D::LimitExceeded);
  EXPECT_TRUE(model_->Running());
}

TEST_F(ModelClientsTest, ObserversOfManyClientsStopAtTheModelsTotal) {
  static std::atomic<int> transforms{0};
  CORBA::ULongLong added = 0;
  int total_refusals = 0;
  for (int client = 0; client < kClients; ++client)
    for (CORBA::ULongLong i = 0; i < kObserversPerClient; ++i) {
      S::SceneObserver_var observer = NewObserver(
          "many" + std::to_string(client) + "_" + std::to_string(i), client, &transforms);
      try {
        model()->add_observer(observer);
        ++added;
      } catch (const D::LimitExceeded& e) {
        ++total_refusals;
        EXPECT_EQ(e.limit, kTotal);
        EXPECT_TRUE(Contains(e.reason.in(), "the Model serves 256 observers, the most it takes"))
            << e.reason.in();
      }
    }
  EXPECT_EQ(added, kTotal);
  EXPECT_EQ(total_refusals, kClients * static_cast<int>(kObserversPerClient) - 256);
  EXPECT_LT(Threads(model_->pid()), 64);
  EXPECT_EQ(M::SimulationStatus_var(model()->status())->state, M::STOPPED);
  EXPECT_TRUE(WaitFor([&] { return transforms >= 256; }, seconds(20))) << transforms;
}

TEST_F(ModelClientsTest, AnObjectThatIsNoObserverOrDoesNotAnswerIsRefusedWithTheReason) {
  auto refused = [&](CORBA::Object_ptr obj) -> std::string {
    S::SceneObserver_var observer = S::SceneObserver::_unchecked_narrow(obj);
    try {
      model()->add_observer(observer);
    } catch (const M::NotAvailable& e) {
      return e.reason.in();
    }
    return "(accepted)";
  };
  // the Model itself
  EXPECT_TRUE(Contains(refused(model()), "the object is not a SceneObserver")) << refused(model());
  // an address of the test's ORB with nothing under the key
  CORBA::Object_var nothing = Orb::Get().Ref("no-such-object", 0);
  EXPECT_TRUE(Contains(refused(nothing), "the SceneObserver does not exist") ||
              Contains(refused(nothing), "OBJECT_NOT_EXIST"))
      << refused(nothing);
  // an address where nothing listens
  CORBA::Object_var nobody = Orb::Get().orb()->string_to_object(
      ("corbaloc::127.0.0.1:" + std::to_string(FreePort()) + "/gone").c_str());
  EXPECT_TRUE(Contains(refused(nobody), "the SceneObserver does not answer: TRANSIENT"))
      << refused(nobody);
  EXPECT_LT(Threads(model_->pid()), 64);
}

TEST_F(ModelClientsTest, ASlowObserverIsKeptAndGetsTheCurrentStateOnceItAnswers) {
  auto* gated = new GatedObserver;
  gated->_add_ref();  // kept for the test, beyond the POA's reference
  PortableServer::ServantBase_var keep(gated);
  CORBA::Object_var gated_obj = Orb::Get().Activate(gated, "slow", 1);
  static std::atomic<int> others{0};
  S::SceneObserver_var other = NewObserver("other-client", 2, &others);
  model()->set_command("motor", 6);
  model()->add_observer(S::SceneObserver::_unchecked_narrow(gated_obj));
  model()->add_observer(other);
  model()->start();
  ASSERT_TRUE(WaitFor([&] { return gated->latest_time() > 0.1; }, seconds(10)));

  // it stops answering for four seconds: every push meets the deadline
  gated->Close();
  const int others_before = others;
  std::this_thread::sleep_for(seconds(4));
  EXPECT_GT(others - others_before, 10) << "another client is served meanwhile";
  EXPECT_TRUE(Contains(model_->Output(), "is slow or unreachable: TIMEOUT")) << model_->Output();

  // it answers again: within a second it has a state at least as new as the Model's now
  const double now = M::SimulationStatus_var(model()->status())->sim_time;
  gated->Open();
  EXPECT_TRUE(WaitFor([&] { return gated->latest_time() >= now; }, milliseconds(1000)))
      << gated->latest_time() << " s received, the Model was at " << now << " s";
  EXPECT_TRUE(WaitFor([&] { return Contains(model_->Output(), "answers again after"); },
                      seconds(5)))
      << model_->Output();
  EXPECT_FALSE(Contains(model_->Output(), "dropping an observer")) << model_->Output();
  EXPECT_EQ(gated->scenes(), 1) << "kept, not registered anew";
  EXPECT_EQ(M::SimulationStatus_var(model()->status())->state, M::RUNNING);
}

// ------------------------------------------------------------------------ subscriptions

TEST_F(ModelClientsTest, TenThousandSubscribeCallsStopAtTheCapsAndTheThreadsStayFew) {
  S::StringSeq ids;
  ids.length(1);
  ids[0] = kTension;
  static std::atomic<int> batches{0};
  int subscribed = 0, limited = 0;
  for (int i = 0; i < 10000; ++i) {
    D::DataConsumer_var consumer = NewConsumer("consumer" + std::to_string(i), 0, &batches);
    try {
      model()->subscribe(ids, 1, consumer);
      ++subscribed;
    } catch (const D::LimitExceeded& e) {
      if (limited++ == 0) {
        EXPECT_TRUE(Contains(e.reason.in(), "client " + Orb::Get().Address(0) +
                                                " has 32 subscriptions"))
            << e.reason.in();
      }
      ASSERT_EQ(e.limit, kSubscriptionsPerClient) << "call " << i;
    }
  }
  EXPECT_EQ(subscribed, static_cast<int>(kSubscriptionsPerClient));
  EXPECT_EQ(limited, 10000 - static_cast<int>(kSubscriptionsPerClient));
  EXPECT_LT(Threads(model_->pid()), 64);
  EXPECT_EQ(model()->step(500), 500u);
  EXPECT_TRUE(WaitFor([&] { return batches >= subscribed; }, seconds(10))) << batches;

  // other clients fill the Model up to its total
  int total_refusals = 0;
  for (int client = 1; client < kClients && subscribed < 300; ++client)
    for (CORBA::ULongLong i = 0; i < kSubscriptionsPerClient; ++i) {
      D::DataConsumer_var consumer = NewConsumer(
          "consumer" + std::to_string(client) + "_" + std::to_string(i), client, &batches);
      try {
        model()->subscribe(ids, 1, consumer);
        ++subscribed;
      } catch (const D::LimitExceeded& e) {
        ++total_refusals;
        ASSERT_EQ(e.limit, kTotal) << e.reason.in();
        EXPECT_TRUE(Contains(e.reason.in(), "the Model serves 256 subscriptions")) << e.reason.in();
      }
    }
  EXPECT_EQ(subscribed, static_cast<int>(kTotal));
  EXPECT_GT(total_refusals, 0);
  EXPECT_LT(Threads(model_->pid()), 64);
  EXPECT_EQ(M::SimulationStatus_var(model()->status())->state, M::PAUSED);
}

// ------------------------------------------------------------------------ execution context

TEST_F(ModelClientsTest, SixClientsStartingAndStoppingTheExecutionContextAtOnce) {
  R::ExecutionContextList_var contexts = model()->get_owned_contexts();
  ASSERT_EQ(contexts->length(), 1u);
  R::ExecutionContext_var context = R::ExecutionContext::_duplicate(contexts[0]);
  std::atomic<int> ok{0}, refused{0}, other{0};
  std::vector<std::thread> clients;
  for (int t = 0; t < 6; ++t)
    clients.emplace_back([&] {
      for (int i = 0; i < 300; ++i)
        for (const bool start : {true, false}) {
          try {
            const R::ReturnCode rc = start ? context->start() : context->stop();
            ++(rc == R::RTC_OK ? ok : rc == R::PRECONDITION_NOT_MET ? refused : other);
          } catch (const CORBA::Exception&) {
            ++other;
          }
        }
    });
  for (auto& c : clients) c.join();
  EXPECT_EQ(other.load(), 0);
  EXPECT_EQ(ok + refused, 3600);
  ASSERT_TRUE(model_->Running()) << model_->Output();

  // the Model runs on: its context starts once more and ticks the simulation
  if (!context->is_running()) {
    EXPECT_EQ(context->start(), R::RTC_OK);
  }
  R::ComponentProfile_var profile = model()->get_component_profile();
  EXPECT_STREQ(profile->instance_name.in(), "model0");
  model()->start();
  EXPECT_TRUE(WaitFor(
      [&] { return M::SimulationStatus_var(model()->status())->sim_time > 0.2; }, seconds(10)))
      << model_->Output();
}

}  // namespace
}  // namespace caliper::testing
