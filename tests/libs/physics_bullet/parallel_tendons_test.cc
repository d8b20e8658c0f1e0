// Options::threads: the tendons' end-of-step work (paths, contact with the bodies, actuators) on
// several threads gives the same bits as on one, and a fault in one tendon is reported and put
// back as the serial step does. The scene is the benchmark's tree (bench/tree_model.h): 40 bodies
// falling onto a floor and onto each other, 80 tendons with DC motors, many pressing on bodies.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/physics_bullet/bullet_scene.h"
#include "test_kinds.h"
#include "tree_model.h"

namespace caliper::physics_bullet {
namespace {

sgal::Scene Tree(bool spanning, int start) {
  bench::TreeOptions o;
  o.spanning_tendons = spanning;
  o.start = start;
  return bench::MakeTree(o);
}

// threads > 1: every step on the threads (Options::choose_threads off), so that each step tests
// them, unless `choose` (the engine's choice by the steps' times)
std::unique_ptr<sgal::PhysicsScene> Make(const sgal::Scene& scene, int threads,
                                         bool search_ahead = true, bool choose = false) {
  Options options;
  options.threads = threads;
  options.search_contacts_ahead = search_ahead;
  options.choose_threads = choose;
  auto made = MakeScene(scene, options);
  // the motors pull unevenly, so that the tendons' work and contacts differ from one to the next
  for (size_t i = 0; i < scene.actuators.size(); ++i)
    made->SetCommand(scene.actuators[i].name, 0.02 * static_cast<double>(i % 7));  // [V]
  return made;
}

// every value of the exact dynamic state (bodies, tendons, actuators), and every tendon's points
std::vector<double> Bits(const sgal::PhysicsScene& scene) {
  const sgal::DynamicState s = scene.SaveDynamicState();
  std::vector<double> all = s.engine;
  for (const auto& a : s.actuators) all.insert(all.end(), a.begin(), a.end());
  for (const auto& t : scene.TendonStates()) {
    all.push_back(t.length);
    all.push_back(t.speed);
    all.push_back(t.tension);
    all.push_back(t.contacts);
    for (const auto& p : t.points) all.insert(all.end(), {p.x(), p.y(), p.z()});
  }
  return all;
}

void ExpectSameBits(const std::vector<double>& expected, const std::vector<double>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  int differences = 0;
  for (size_t i = 0; i < expected.size(); ++i)
    if (std::memcmp(&expected[i], &actual[i], sizeof(double)) != 0 && ++differences <= 5)
      ADD_FAILURE() << "value " << i << ": " << expected[i] << " != " << actual[i];
  EXPECT_EQ(differences, 0);
}

int Contacts(const sgal::PhysicsScene& scene) {
  int contacts = 0;
  for (const auto& t : scene.TendonStates()) contacts += t.contacts;
  return contacts;
}

// On several threads Bullet's contact search for the next step runs beside the tendons
// (AheadWorld): the same bits as the search inside the next step on one thread, also where bodies
// touch. The tree lands on the floor and on itself after about 1 s.
TEST(ParallelTendons, TheTreeStepsToTheSameBitsOnAnyThreadCount) {
  for (const bool spanning : {false, true}) {
    SCOPED_TRACE(spanning ? "tendons spanning two joints" : "tendons over one joint");
    const sgal::Scene scene = Tree(spanning, 3);
    auto serial = Make(scene, 1);
    std::vector<std::unique_ptr<sgal::PhysicsScene>> parallel;
    parallel.push_back(Make(scene, 2, false));  // the tendons alone on two threads
    for (const int threads : {2, 3}) parallel.push_back(Make(scene, threads));
    parallel.push_back(Make(scene, 2, true, true));  // one way or the other, as timed
    // the same tree without floor and self contact: how far the contacts moved it
    bench::TreeOptions o;
    o.spanning_tendons = spanning;
    o.start = 3;
    o.floor = o.self_contact = false;
    auto untouched = Make(bench::MakeTree(o), 1);
    int most_contacts = 0;
    sgal::DynamicState back;
    for (int step = 1; step <= 1500; ++step) {
      serial->Step();
      if (step <= 1100) untouched->Step();  // compared at the state restored
      for (auto& p : parallel) p->Step();
      most_contacts = std::max(most_contacts, Contacts(*serial));
      // between steps, a live edit of the time step (the search made ahead swept the bodies for
      // the old one), a state restored from 200 steps before (the search was for other poses)
      // and new caches
      std::vector<sgal::PhysicsScene*> all = {serial.get()};
      for (auto& p : parallel) all.push_back(p.get());
      if (step == 1100) back = serial->SaveDynamicState();
      if (step == 1200)
        for (auto* edited : all) edited->SetParameter("simulation.time_step", 5e-4);
      if (step == 1300)
        for (auto* restored : all) restored->RestoreDynamicState(back);
      if (step == 1400)  // new contact caches (a fresh broadphase): the search made ahead is gone
        for (auto* reset : all) reset->ResetCaches();
      if (step % 250 == 0)
        for (auto& p : parallel) ExpectSameBits(Bits(*serial), Bits(*p));
    }
    // what the threads shared was real work: tendons bent around bodies, motors that ran, bodies
    // that touched
    EXPECT_GT(most_contacts, 50);
    double current = 0;
    for (const auto& a : scene.actuators)
      current = std::max(current, std::abs(serial->GetParameter(a.name + ".current")));
    EXPECT_GT(current, 2e-4) << "the largest motor current [A]";
    double moved = 0;
    const auto free = untouched->BodyStates();
    for (size_t b = 0; b < free.size(); ++b)
      moved = std::max(moved, (back.bodies[b].pose.position - free[b].pose.position).norm());
    EXPECT_GT(moved, 0.01) << "how far floor and self contact moved a body [m]";
  }
}

// At 20 ms, before the tree touches anything: Bullet's contact cache is not rolled back by a
// failing step (bullet_scene.h), so only there does the scene go on as one that never faulted.
TEST(ParallelTendons, AFaultInOneTendonIsReportedAndPutBackAsOnOneThread) {
  testing::RegisterTestKinds();
  sgal::Scene scene = Tree(false, 0);
  // two faulty motors: the first in tendon order is the one reported, on any thread count
  for (const size_t k : {size_t{17}, size_t{53}}) {
    sgal::Actuator& a = scene.actuators[k];
    a.kind = "test_faulty_motor";
    a.name = "faulty_" + std::to_string(k);
  }
  std::string serial_message;
  for (const int threads : {1, 2}) {
    SCOPED_TRACE("threads = " + std::to_string(threads));
    auto faulting = Make(scene, threads), reference = Make(scene, threads);
    for (int i = 0; i < 20; ++i) {
      faulting->Step();
      reference->Step();
    }
    const std::vector<double> before = Bits(*faulting);
    faulting->SetParameter("faulty_17.fail", 1);
    faulting->SetParameter("faulty_53.fail", 2);
    std::string message;
    try {
      faulting->Step();
      ADD_FAILURE() << "the step must fail";
    } catch (const sgal::SimulationFault& fault) {
      message = fault.what();
      EXPECT_EQ(fault.element(), "faulty_17");
    }
    EXPECT_EQ(message.rfind("actuator 'faulty_17' (test_faulty_motor) failed at t = 0.021000 s: "
                            "std::runtime_error: injected fault",
                            0),
              0u)
        << message;
    if (threads == 1)
      serial_message = message;
    else
      EXPECT_EQ(message, serial_message);
    EXPECT_EQ(faulting->steps(), 20u);
    ExpectSameBits(before, Bits(*faulting));
    // disarmed, it goes on as the scene that never faulted
    faulting->SetParameter("faulty_17.fail", 0);
    faulting->SetParameter("faulty_53.fail", 0);
    for (int i = 0; i < 20; ++i) {
      faulting->Step();
      reference->Step();
    }
    ExpectSameBits(Bits(*reference), Bits(*faulting));
  }
}

TEST(ParallelTendons, RefusesANegativeThreadCount) {
  Options options;
  options.threads = -1;
  try {
    MakeScene(Tree(false, 0), options);
    ADD_FAILURE() << "a negative thread count must be refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("threads must be >= 0 (0: automatic), got -1"),
              std::string::npos)
        << e.what();
  }
  options.threads = 0;  // every processor this process may run on
  auto automatic = MakeScene(Tree(false, 0), options);
  auto serial = MakeScene(Tree(false, 0));
  for (int i = 0; i < 50; ++i) {
    automatic->Step();
    serial->Step();
  }
  ExpectSameBits(Bits(*serial), Bits(*automatic));
}

}  // namespace
}  // namespace caliper::physics_bullet
