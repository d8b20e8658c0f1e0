// Scene editing on ModelCore, without CORBA: every kind of edit on the shipped arm, applied while
// the simulation runs (time, bodies and actuator states carry over), refused edits that change
// nothing, undo and redo, a stop that keeps edits and a load that forgets them, the edited scene's
// export loading again identically, and the pull of the GUI's Ctrl+drag moving a hanging link.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "caliper/collada/importer.h"
#include "caliper/core/scratch_directory.h"
#include "caliper/sgal/edits.h"
#include "caliper/simulation/model_core.h"

namespace caliper::simulation {
namespace {

std::string Model(const std::string& file) {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(src ? src : ".") + "/models/" + file;
}

sgal::PathElement Point(const std::string& body, double x, double y, double z) {
  sgal::PathElement e;
  e.body = body;
  e.position = {x, y, z};
  return e;
}

std::vector<double> Read(ModelCore& core, const std::string& id) {
  return core.Sample({id}).at(0).values;
}

const sgal::Tendon& TendonOf(const sgal::Scene& s, const std::string& name) {
  const sgal::Tendon* t = s.FindTendon(name);
  if (t == nullptr) throw std::runtime_error("no tendon " + name);
  return *t;
}

class ModelEdit : public ::testing::Test {
 protected:
  void SetUp() override { core_.Load(Model("ecce_arm.dae")); }
  std::shared_ptr<const sgal::Scene> scene() { return core_.description(); }
  ModelCore core_;
};

TEST_F(ModelEdit, MovingAViaPointWhileSteppingKeepsTimeBodiesAndActuators) {
  core_.SetCommands({{"elbow_flexor", 6.0}});
  ASSERT_EQ(core_.StepNow(300), 300u);
  const double t = core_.status().sim_time;
  const auto forearm = Read(core_, "ecce_arm.forearm.position");
  const auto velocity = Read(core_, "ecce_arm.forearm.linear_velocity");
  const auto actuator = [&](const std::string& name) {
    for (const auto& a : core_.ActuatorStates())
      if (a.name == name) return a;
    throw std::runtime_error("no actuator " + name);
  };
  const auto motor = actuator("elbow_flexor");
  ASSERT_GT(motor.tension, 1.0);
  const auto old_path = TendonOf(*scene(), "elbow_flexor").path;

  const auto status = core_.Edit([&](const sgal::Scene& s) {
    return sgal::MovePathPoint(s, "elbow_flexor", 0, Point(old_path[0].body, 0.01, -0.02, 0.03));
  });
  EXPECT_EQ(status.revision, 1u);
  EXPECT_NE(status.undo.find("elbow_flexor"), std::string::npos) << status.undo;
  EXPECT_TRUE(status.redo.empty());
  // the edit is in the scene as loaded (what observers and a rewind see)
  const auto& path = TendonOf(*scene(), "elbow_flexor").path;
  EXPECT_EQ(path[0].position, Eigen::Vector3d(0.01, -0.02, 0.03));
  EXPECT_EQ(path.size(), old_path.size());
  // nothing else moved: the same instant, the same bodies, the motor's current and command
  EXPECT_EQ(core_.status().sim_time, t);
  EXPECT_EQ(core_.status().steps, 300u);
  const auto forearm_after = Read(core_, "ecce_arm.forearm.position");
  const auto velocity_after = Read(core_, "ecce_arm.forearm.linear_velocity");
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(forearm_after[k], forearm[k], 1e-12);
    EXPECT_NEAR(velocity_after[k], velocity[k], 1e-9);
  }
  EXPECT_EQ(actuator("elbow_flexor").tension, motor.tension);
  EXPECT_EQ(actuator("elbow_flexor").command, 6.0);
  // and the simulation goes on from there
  EXPECT_EQ(core_.StepNow(10), 10u);
  EXPECT_NEAR(core_.status().sim_time, t + 10 * core_.status().time_step, 1e-9);
}

TEST_F(ModelEdit, EditsWhileRunningApplyBetweenSteps) {
  core_.SetRealTimeFactor(0);
  core_.Start();
  for (int i = 0; i < 20; ++i) {
    core_.Advance(std::chrono::milliseconds(2));
    const double mass = 0.5 + 0.05 * i;
    core_.Edit([&](const sgal::Scene& s) { return sgal::SetMass(s, "forearm", mass); });
    EXPECT_NEAR(Read(core_, "ecce_arm.forearm.mass").at(0), mass, 1e-6);  // Bullet keeps floats
  }
  EXPECT_EQ(core_.status().state, RunState::kRunning);
  EXPECT_GT(core_.status().steps, 0u);
  EXPECT_EQ(core_.edit_status().revision, 20u);
}

TEST_F(ModelEdit, UndoAndRedoWalkTheHistory) {
  const sgal::Scene before = *scene();
  const auto& t = TendonOf(before, "elbow_flexor");
  core_.Edit([&](const sgal::Scene& s) {
    return sgal::InsertPathPoint(s, "elbow_flexor", 1, Point("upper_arm", 0.02, 0, -0.1));
  });
  EXPECT_EQ(TendonOf(*scene(), "elbow_flexor").path.size(), t.path.size() + 1);
  core_.Edit([&](const sgal::Scene& s) { return sgal::SetMass(s, "upper_arm", 2.5); });
  EXPECT_DOUBLE_EQ(scene()->FindBody("upper_arm")->inertia.mass, 2.5);

  auto status = core_.Undo();
  EXPECT_NE(status.redo.find("mass of upper_arm"), std::string::npos) << status.redo;
  EXPECT_NE(status.undo.find("insert"), std::string::npos) << status.undo;
  EXPECT_EQ(scene()->FindBody("upper_arm")->inertia.mass,
            before.FindBody("upper_arm")->inertia.mass);
  EXPECT_EQ(scene()->FindBody("upper_arm")->inertia.tensor,
            before.FindBody("upper_arm")->inertia.tensor);
  status = core_.Undo();
  EXPECT_TRUE(status.undo.empty());
  EXPECT_EQ(TendonOf(*scene(), "elbow_flexor").path.size(), t.path.size());
  EXPECT_THROW(core_.Undo(), sgal::EditError);
  status = core_.Redo();
  EXPECT_EQ(TendonOf(*scene(), "elbow_flexor").path.size(), t.path.size() + 1);
  EXPECT_EQ(TendonOf(*scene(), "elbow_flexor").path[1].position, Eigen::Vector3d(0.02, 0, -0.1));
  // a new edit drops what could have been redone
  core_.Edit([&](const sgal::Scene& s) { return sgal::RemovePathPoint(s, "elbow_flexor", 1); });
  EXPECT_TRUE(core_.edit_status().redo.empty());
  EXPECT_THROW(core_.Redo(), sgal::EditError);
  EXPECT_EQ(core_.edit_status().revision, 6u);  // 3 edits, 2 undos, 1 redo
}

TEST_F(ModelEdit, RefusedEditsSayWhyAndChangeNothing) {
  const sgal::Scene before = *scene();
  const auto expect_refused = [&](const std::function<sgal::SceneEdit(const sgal::Scene&)>& make,
                                  const std::string& reason_part) {
    try {
      core_.Edit(make);
      ADD_FAILURE() << "accepted; expected a refusal with '" << reason_part << "'";
    } catch (const sgal::EditError& e) {
      EXPECT_NE(std::string(e.what()).find(reason_part), std::string::npos) << e.what();
    }
    EXPECT_EQ(core_.edit_status().revision, 0u);
  };
  expect_refused([](const sgal::Scene& s) { return sgal::MovePathPoint(s, "nope", 0, Point("", 0, 0, 0)); },
                 "no tendon 'nope'");
  expect_refused([](const sgal::Scene& s) {
    return sgal::MovePathPoint(s, "elbow_flexor", 0, Point("no_such_body", 0, 0, 0));
  }, "no body 'no_such_body'");
  expect_refused([](const sgal::Scene& s) {
    return sgal::MovePathPoint(s, "elbow_flexor", 0, Point("forearm", NAN, 0, 0));
  }, "not finite");
  expect_refused([](const sgal::Scene& s) { return sgal::RemovePathPoint(s, "girdle_elevator", 1); },
                 "end of the tendon");
  expect_refused([](const sgal::Scene& s) { return sgal::SetMass(s, "forearm", -1); },
                 "mass must be in");
  expect_refused([](const sgal::Scene& s) { return sgal::SetMass(s, "torso", 3); }, "does not move");
  expect_refused([](const sgal::Scene& s) {
    return sgal::RemoveObstacle(s, "elbow_pulley");
  }, "wraps around it");
  expect_refused([](const sgal::Scene& s) { return sgal::SetShapeDims(s, "forearm", 0, {0.1}); },
                 "dimensions");
  // a tendon from the torso to the forearm with a ligament along it
  const auto add_ligament = [](const std::string& tendon, const std::string& parameter) {
    return [tendon, parameter](const sgal::Scene& s) {
      sgal::Tendon t;
      t.name = tendon;
      t.path = {Point("torso", 0, 0, 0), Point("forearm", 0, 0, 0)};
      sgal::Actuator a;
      a.name = "new_actuator";
      a.kind = "ligament";
      a.parameters[parameter] = 1;
      return sgal::AddTendon(s, t, a);
    };
  };
  expect_refused(add_ligament("elbow_flexor", "stiffness"), "exists");
  // an actuator the engine cannot build (a parameter its kind does not know) is the engine's refusal
  expect_refused(add_ligament("new_tendon", "no_such_parameter"), "engine refuses");
  EXPECT_EQ(scene()->tendons.size(), before.tendons.size());
  EXPECT_EQ(TendonOf(*scene(), "elbow_flexor").path[0].position,
            TendonOf(before, "elbow_flexor").path[0].position);
}

TEST_F(ModelEdit, AddedTendonPullsAndRemovingItUndoes) {
  sgal::Tendon t;
  t.name = "extra";
  t.radius = 0.002;
  t.path = {Point("upper_arm", 0.03, 0, -0.05), Point("forearm", 0.03, 0, -0.05)};
  sgal::Actuator a;
  a.name = "extra_ligament";
  a.kind = "ligament";
  a.parameters["stiffness"] = 2000;
  core_.Edit([&](const sgal::Scene& s) { return sgal::AddTendon(s, t, a); });
  ASSERT_NE(scene()->FindTendon("extra"), nullptr);
  EXPECT_EQ(scene()->actuators.back().tendon, "extra");
  const double length = Read(core_, "ecce_arm.extra.tendon.length").at(0);
  EXPECT_GT(length, 0.01);
  // stretched past its rest length by the elbow's bending, it pulls
  core_.SetChannel("ecce_arm.extra_ligament.rest_length", {0.5 * length});
  core_.StepNow(20);
  EXPECT_GT(Read(core_, "ecce_arm.extra.tendon.tension").at(0), 1.0);
  core_.Edit([&](const sgal::Scene& s) { return sgal::RemoveTendon(s, "extra"); });
  EXPECT_EQ(scene()->FindTendon("extra"), nullptr);
  EXPECT_THROW(Read(core_, "ecce_arm.extra.tendon.length"), UnknownId);
  core_.Undo();
  EXPECT_NE(scene()->FindTendon("extra"), nullptr);
  EXPECT_EQ(scene()->actuators.back().name, "extra_ligament");
  // back with its channels and the rest length tuned while it ran
  EXPECT_GT(Read(core_, "ecce_arm.extra.tendon.length").at(0), 0.01);
  EXPECT_EQ(Read(core_, "ecce_arm.extra_ligament.rest_length").at(0), 0.5 * length);
}

TEST_F(ModelEdit, UndoPutsBackTunedValuesActuatorStatesAndCommands) {
  // a mass tuned while running, then edited: the undo gives the tuned mass back
  core_.SetChannel("ecce_arm.forearm.mass", {1.7});
  core_.Edit([&](const sgal::Scene& s) { return sgal::SetMass(s, "forearm", 0.9); });
  EXPECT_NEAR(Read(core_, "ecce_arm.forearm.mass").at(0), 0.9, 1e-6);
  core_.Undo();
  EXPECT_NEAR(Read(core_, "ecce_arm.forearm.mass").at(0), 1.7, 1e-6);
  // the scene as loaded (what a rewind returns to) never had the tuned value
  EXPECT_NE(scene()->FindBody("forearm")->inertia.mass, 1.7);

  // a driven motor with a tuned stiffness, removed and brought back: stiffness, command and the
  // motor's state (its tension) as they were at the removal
  core_.SetChannel("ecce_arm.elbow_flexor.stiffness", {4321});
  core_.SetCommands({{"elbow_flexor", 6.0}});
  core_.StepNow(200);
  const auto tension = [&] {
    for (const auto& x : core_.ActuatorStates())
      if (x.name == "elbow_flexor") return x.tension;
    return -1.0;
  };
  const double at_removal = tension();
  ASSERT_GT(at_removal, 1.0);
  core_.Edit([&](const sgal::Scene& s) { return sgal::RemoveTendon(s, "elbow_flexor"); });
  core_.StepNow(50);
  core_.Undo();
  EXPECT_EQ(Read(core_, "ecce_arm.elbow_flexor.stiffness").at(0), 4321);
  EXPECT_EQ(Read(core_, "ecce_arm.elbow_flexor.command").at(0), 6.0);
  EXPECT_EQ(tension(), at_removal);
}

TEST_F(ModelEdit, RemovingATendonTakesItsChannelsDelaysAlongAndUndoBringsThemBack) {
  // tests/data/collada/measurement_delays.dae: the tendon `line` (ligament `spring`) with its
  // tension delayed 4 ms, the hinge's position 2 ms
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  core_.Load(std::string(src ? src : ".") + "/tests/data/collada/measurement_delays.dae");
  core_.StepNow(10);
  const auto delays = [&] {
    std::vector<std::string> ids;
    for (const auto& d : scene()->measurement_delays) ids.push_back(d.id);
    return ids;
  };
  const std::vector<std::string> before = delays();
  ASSERT_EQ(before, (std::vector<std::string>{"line.tendon.tension", "hinge.position"}));
  const ModelCore::EditStatus removed =
      core_.Edit([&](const sgal::Scene& s) { return sgal::RemoveTendon(s, "line"); });
  EXPECT_NE(removed.undo.find("1 measurement delays"), std::string::npos) << removed.undo;
  EXPECT_EQ(delays(), (std::vector<std::string>{"hinge.position"}));
  core_.StepNow(10);  // the scene without the tendon runs, its other delay too
  EXPECT_EQ(Read(core_, "measurement_delays.hinge.position").size(), 1u);
  core_.Undo();
  EXPECT_EQ(delays(), before);
  EXPECT_EQ(Read(core_, "measurement_delays.line.tendon.tension.undelayed").size(), 1u);
}

TEST_F(ModelEdit, AMeasurementDelaySetLiveLagsItsChannelAndUndoRemovesIt) {
  core_.SetCommands({{"elbow_flexor", 6.0}});
  core_.StepNow(50);
  const std::string id = "ecce_arm.elbow_flexor.current";
  // by the DAQ's id; 3 ms at the arm's 1 ms steps
  const ModelCore::EditStatus set = core_.Edit(
      [&](const sgal::Scene& s) { return sgal::SetMeasurementDelay(s, id, 0.003); });
  EXPECT_EQ(set.last, "delay elbow_flexor.current by 3 ms");
  ASSERT_EQ(scene()->measurement_delays.size(), 1u);
  EXPECT_EQ(scene()->measurement_delays[0].id, "elbow_flexor.current");
  EXPECT_EQ(scene()->measurement_delays[0].delay, 0.003);
  // from the edit on, the channel reads its true value of 3 steps before (at first, the value at
  // the edit: the ring starts full of it)
  std::vector<double> truth;
  for (int i = 0; i < 20; ++i) {
    core_.StepNow(1);
    truth.push_back(Read(core_, id + ".undelayed").at(0));
    if (i >= 3) {
      EXPECT_EQ(Read(core_, id).at(0), truth[i - 3]) << i;
    }
  }
  EXPECT_NE(truth.front(), truth.back());  // the current moved
  // a change of the delay, by the file's id
  core_.Edit([&](const sgal::Scene& s) {
    return sgal::SetMeasurementDelay(s, "elbow_flexor.current", 0.001);
  });
  EXPECT_EQ(scene()->measurement_delays.at(0).delay, 0.001);
  core_.StepNow(2);
  const double before = Read(core_, id + ".undelayed").at(0);
  core_.StepNow(1);
  EXPECT_EQ(Read(core_, id).at(0), before);
  // undo twice: no delay, the channel reads the truth and `.undelayed` is gone
  core_.Undo();
  EXPECT_EQ(scene()->measurement_delays.at(0).delay, 0.003);
  core_.Undo();
  EXPECT_TRUE(scene()->measurement_delays.empty());
  core_.StepNow(1);
  EXPECT_THROW(Read(core_, id + ".undelayed"), UnknownId);
  // refusals name the reason and change nothing
  const auto refused = [&](const std::string& channel, double delay, const std::string& why) {
    try {
      core_.Edit(
          [&](const sgal::Scene& s) { return sgal::SetMeasurementDelay(s, channel, delay); });
      ADD_FAILURE() << channel << " was delayed";
    } catch (const sgal::EditError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
    EXPECT_TRUE(scene()->measurement_delays.empty());
  };
  refused("elbow_flexor.currnt", 0.002, "elbow_flexor.currnt");
  refused("elbow_flexor.command", 0.002, "written from outside");
  refused("elbow_flexor.current", -1, "[0, 10] s");
  refused("elbow_flexor.current", 0, "has no measurement delay");
}

TEST_F(ModelEdit, ADelayByTheDaqsIdInASceneWhoseNameIsNotIdSafe) {
  // the arm renamed "ECCE Arm": its channels start with the id-safe ecce_arm.
  std::ifstream in(Model("ecce_arm.dae"), std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "<visual_scene id=\"visual_scene\" name=\"ecce_arm\">";
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, from.size(), "<visual_scene id=\"visual_scene\" name=\"ECCE Arm\">");
  core::ScratchDirectory dir("model-edit");
  const std::string file = dir.path() + "/renamed.dae";
  std::ofstream(file, std::ios::binary) << text;
  core_.Load(file);
  ASSERT_EQ(scene()->name, "ECCE Arm");
  ASSERT_EQ(core_.model_name(), "ecce_arm");
  const ModelCore::EditStatus set = core_.Edit([&](const sgal::Scene& s) {
    return sgal::SetMeasurementDelay(s, "ecce_arm.elbow.position", 0.002);
  });
  EXPECT_EQ(set.last, "delay elbow.position by 2 ms");
  ASSERT_EQ(scene()->measurement_delays.size(), 1u);
  EXPECT_EQ(scene()->measurement_delays[0].id, "elbow.position");
  EXPECT_EQ(Read(core_, "ecce_arm.elbow.position.undelayed").size(), 1u);
}

TEST_F(ModelEdit, ChangingOrRemovingADelayKeepsTheOthersInTheirOrder) {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  core_.Load(std::string(src ? src : ".") + "/tests/data/collada/measurement_delays.dae");
  const auto delays = [&] {
    std::vector<std::pair<std::string, double>> out;
    for (const auto& d : scene()->measurement_delays) out.emplace_back(d.id, d.delay);
    return out;
  };
  using List = std::vector<std::pair<std::string, double>>;
  const List loaded = delays();
  ASSERT_EQ(loaded, (List{{"line.tendon.tension", 0.004}, {"hinge.position", 0.002}}));
  core_.Edit([&](const sgal::Scene& s) {
    return sgal::SetMeasurementDelay(s, "line.tendon.tension", 0.006);
  });
  EXPECT_EQ(delays(), (List{{"line.tendon.tension", 0.006}, {"hinge.position", 0.002}}));
  const ModelCore::EditStatus removed = core_.Edit(
      [&](const sgal::Scene& s) { return sgal::SetMeasurementDelay(s, "line.tendon.tension", 0); });
  EXPECT_EQ(removed.last, "remove the measurement delay of line.tendon.tension");
  EXPECT_EQ(delays(), (List{{"hinge.position", 0.002}}));
  core_.StepNow(5);
  core_.Undo();
  EXPECT_EQ(delays(), (List{{"line.tendon.tension", 0.006}, {"hinge.position", 0.002}}));
  core_.Undo();
  EXPECT_EQ(delays(), loaded);
  core_.StepNow(5);  // and it runs
  EXPECT_EQ(Read(core_, "measurement_delays.line.tendon.tension.undelayed").size(), 1u);
}

TEST_F(ModelEdit, StopRewindsTimeButKeepsEditsAndLoadForgetsThem) {
  core_.StepNow(50);
  core_.Edit([&](const sgal::Scene& s) { return sgal::SetMass(s, "hand", 0.7); });
  core_.Stop();
  EXPECT_EQ(core_.status().steps, 0u);
  EXPECT_DOUBLE_EQ(scene()->FindBody("hand")->inertia.mass, 0.7);
  EXPECT_FALSE(core_.edit_status().undo.empty());
  core_.Load(Model("ecce_arm.dae"));
  EXPECT_TRUE(core_.edit_status().undo.empty());
  EXPECT_NE(scene()->FindBody("hand")->inertia.mass, 0.7);
}

TEST_F(ModelEdit, TheEditedSceneExportsAndLoadsAgainIdentically) {
  core_.Edit([&](const sgal::Scene& s) {
    return sgal::InsertPathPoint(s, "wrist_flexor", 1, Point("forearm", 0.021, -0.013, -0.2));
  });
  sgal::WrapObstacle o;
  o.name = "new_pulley";
  o.body = "upper_arm";
  o.kind = sgal::ObstacleKind::kSphere;
  o.pose.position = {0.01, 0.02, -0.15};
  o.radius = 0.025;
  core_.Edit([&](const sgal::Scene& s) { return sgal::SetObstacle(s, o); });
  sgal::PathElement wrap;
  wrap.kind = sgal::PathElement::Kind::kWrap;
  wrap.obstacle = "new_pulley";
  core_.Edit([&](const sgal::Scene& s) { return sgal::InsertPathPoint(s, "elbow_extensor", 1, wrap); });
  const sgal::Body forearm = *scene()->FindBody("forearm");  // a copy: edits replace the scene
  std::vector<double> dims = sgal::GeometryDims(forearm.shapes.at(0).geometry);
  ASSERT_FALSE(dims.empty());
  for (double& d : dims) d *= 1.25;
  core_.Edit([&](const sgal::Scene& s) { return sgal::SetShapeDims(s, "forearm", 0, dims); });
  core_.Edit([&](const sgal::Scene& s) { return sgal::SetMass(s, "forearm", 0.9); });
  sgal::Tendon strap;
  strap.name = "strap";
  strap.path = {Point("upper_arm", 0.03, 0, -0.05), Point("forearm", 0.03, 0, -0.05)};
  sgal::Actuator strap_ligament{"strap_ligament", "ligament", "", {{"stiffness", 1234}}, {}};
  core_.Edit([&](const sgal::Scene& s) { return sgal::AddTendon(s, strap, strap_ligament); });
  const sgal::Scene edited = *scene();
  // the visual drawn from the resized shape follows it
  for (const auto& v : edited.FindBody("forearm")->visuals) {
    if (v.geometry.index() == forearm.shapes.at(0).geometry.index()) {
      EXPECT_EQ(sgal::GeometryDims(v.geometry), dims) << v.name;
    }
  }

  core::ScratchDirectory dir("model-edit");
  const std::string file = dir.path() + "/edited.dae";
  {
    std::ofstream out(file, std::ios::binary);
    out << core_.ExportBytes();
  }
  const sgal::Scene again = collada::Import(file, nullptr);
  ASSERT_EQ(again.tendons.size(), edited.tendons.size());
  for (size_t i = 0; i < edited.tendons.size(); ++i) {
    const auto& a = edited.tendons[i];
    const auto& b = *again.FindTendon(a.name);
    ASSERT_EQ(a.path.size(), b.path.size()) << a.name;
    for (size_t k = 0; k < a.path.size(); ++k) {
      EXPECT_EQ(a.path[k].kind, b.path[k].kind) << a.name << " " << k;
      EXPECT_EQ(a.path[k].body, b.path[k].body) << a.name << " " << k;
      EXPECT_EQ(a.path[k].obstacle, b.path[k].obstacle) << a.name << " " << k;
      EXPECT_LT((a.path[k].position - b.path[k].position).norm(), 1e-12) << a.name << " " << k;
    }
  }
  ASSERT_EQ(again.actuators.size(), edited.actuators.size());
  for (size_t i = 0; i < edited.actuators.size(); ++i) {
    EXPECT_EQ(again.actuators[i].name, edited.actuators[i].name);
    EXPECT_EQ(again.actuators[i].tendon, edited.actuators[i].tendon);
    EXPECT_EQ(again.actuators[i].kind, edited.actuators[i].kind);
  }
  EXPECT_NEAR(again.actuators.back().parameters.at("stiffness"), 1234, 1e-9);
  const sgal::WrapObstacle* pulley = again.FindObstacle("new_pulley");
  ASSERT_NE(pulley, nullptr);
  EXPECT_EQ(pulley->kind, sgal::ObstacleKind::kSphere);
  EXPECT_NEAR(pulley->radius, 0.025, 1e-12);
  EXPECT_LT((pulley->pose.position - o.pose.position).norm(), 1e-12);
  const auto& forearm_again = *again.FindBody("forearm");
  EXPECT_NEAR(forearm_again.inertia.mass, 0.9, 1e-12);
  EXPECT_LT((forearm_again.inertia.tensor - edited.FindBody("forearm")->inertia.tensor).norm(), 1e-12);
  const std::vector<double> dims_again = sgal::GeometryDims(forearm_again.shapes.at(0).geometry);
  ASSERT_EQ(dims_again.size(), dims.size());
  for (size_t k = 0; k < dims.size(); ++k) EXPECT_NEAR(dims_again[k], dims[k], 1e-12);
  // and it simulates as the edited scene does: 200 steps from the same start, same bits
  ModelCore other;
  other.Load(file);
  core_.Stop();
  core_.StepNow(200);
  other.StepNow(200);
  EXPECT_EQ(Read(other, "ecce_arm.hand.position"), Read(core_, "ecce_arm.hand.position"));
}

TEST(ModelPull, APullNotRenewedEndsByItself) {
  Limits limits;
  limits.pull_lease = std::chrono::milliseconds(50);
  ModelCore core({}, limits);
  core.Load(Model("ecce_arm.dae"));
  const auto start = Read(core, "ecce_arm.hand.position");
  const Eigen::Vector3d target(start[0] + 0.3, start[1], start[2] + 0.2);
  core.Pull("hand", Eigen::Vector3d::Zero(), target, 0);
  core.StepNow(20);
  EXPECT_GT(Read(core, "ecce_arm.pull.force_x").at(0), 1.0) << "the pull acts while it lasts";
  EXPECT_EQ(Read(core, "ecce_arm.pull.body").at(0), 5.0);  // the hand
  EXPECT_NEAR(Read(core, "ecce_arm.pull.target_z").at(0), target.z(), 1e-12);
  std::this_thread::sleep_for(std::chrono::milliseconds(120));  // its client is gone
  core.StepNow(1);
  EXPECT_EQ(Read(core, "ecce_arm.pull.force_x").at(0), 0.0);
  EXPECT_EQ(Read(core, "ecce_arm.pull.force_z").at(0), 0.0);
  EXPECT_EQ(Read(core, "ecce_arm.pull.body"), std::vector<double>{-1});
}

TEST(ModelPull, HugeOrUnstablePullsAreRefused) {
  ModelCore core;
  core.Load(Model("ecce_arm.dae"));
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  EXPECT_THROW(core.Pull("hand", zero, Eigen::Vector3d(1e300, 0, 0), 0), sgal::EditError);
  EXPECT_THROW(core.Pull("hand", Eigen::Vector3d(0, 0, 1e5), zero, 0), sgal::EditError);
  EXPECT_THROW(core.Pull("hand", zero, zero, 1e12), sgal::EditError);
  EXPECT_THROW(core.Pull("hand", zero, zero, -1), sgal::EditError);
  EXPECT_NO_THROW(core.Pull("hand", zero, zero, 100));
}

TEST_F(ModelEdit, PullMovesAHangingLinkTowardTheTargetAndReleaseEndsIt) {
  core_.StepNow(100);
  const auto start = Read(core_, "ecce_arm.hand.position");
  const Eigen::Vector3d target(start[0] + 0.3, start[1], start[2] + 0.2);
  core_.Pull("hand", Eigen::Vector3d::Zero(), target, 0);
  core_.StepNow(1500);
  const auto pulled = Read(core_, "ecce_arm.hand.position");
  const double before = (Eigen::Vector3d(start[0], start[1], start[2]) - target).norm();
  const double after = (Eigen::Vector3d(pulled[0], pulled[1], pulled[2]) - target).norm();
  EXPECT_LT(after, 0.6 * before) << "the hand went from " << before << " m to " << after
                                 << " m of the target";
  // an unpulled twin stays where the arm hangs
  ModelCore twin;
  twin.Load(Model("ecce_arm.dae"));
  twin.StepNow(1600);
  const auto hanging = Read(twin, "ecce_arm.hand.position");
  EXPECT_GT((Eigen::Vector3d(hanging[0], hanging[1], hanging[2]) - target).norm(), 0.8 * before);
  // the pull survives an edit, and ends on release
  core_.Edit([&](const sgal::Scene& s) { return sgal::SetMass(s, "upper_arm", 1.1); });
  core_.StepNow(200);
  const auto still = Read(core_, "ecce_arm.hand.position");
  EXPECT_LT((Eigen::Vector3d(still[0], still[1], still[2]) - target).norm(), 0.6 * before);
  core_.ReleasePull();
  core_.StepNow(2000);
  const auto released = Read(core_, "ecce_arm.hand.position");
  EXPECT_GT((Eigen::Vector3d(released[0], released[1], released[2]) - target).norm(),
            (Eigen::Vector3d(still[0], still[1], still[2]) - target).norm() + 0.05);
  EXPECT_THROW(core_.Pull("torso", Eigen::Vector3d::Zero(), target, 0), sgal::EditError);
  EXPECT_THROW(core_.Pull("nobody", Eigen::Vector3d::Zero(), target, 0), sgal::EditError);
}

TEST_F(ModelEdit, SelectionIsCheckedAndCounted) {
  core_.Select("body", "forearm", 0);
  auto s = core_.selection();
  EXPECT_EQ(s.kind, "body");
  EXPECT_EQ(s.name, "forearm");
  const uint64_t revision = s.revision;
  core_.Select("path_point", "elbow_flexor", 1);
  EXPECT_EQ(core_.selection().index, 1u);
  EXPECT_EQ(core_.selection().revision, revision + 1);
  EXPECT_THROW(core_.Select("body", "nobody", 0), sgal::EditError);
  EXPECT_THROW(core_.Select("path_point", "elbow_flexor", 99), sgal::EditError);
  EXPECT_THROW(core_.Select("wheel", "x", 0), sgal::EditError);
  core_.Select("", "", 0);
  EXPECT_EQ(core_.selection().kind, "");
  // a via point inserted before the selected element: the selection follows the element; its
  // removal ends the selection
  core_.Select("path_point", "elbow_flexor", 1);
  core_.Edit([&](const sgal::Scene& sc) {
    return sgal::InsertPathPoint(sc, "elbow_flexor", 1, Point("upper_arm", 0.01, 0, -0.1));
  });
  EXPECT_EQ(core_.selection().index, 2u);
  core_.Edit([&](const sgal::Scene& sc) { return sgal::RemovePathPoint(sc, "elbow_flexor", 1); });
  EXPECT_EQ(core_.selection().index, 1u);
  core_.Edit([&](const sgal::Scene& sc) {
    return sgal::InsertPathPoint(sc, "elbow_flexor", 1, Point("upper_arm", 0.01, 0, -0.1));
  });
  core_.Select("path_point", "elbow_flexor", 1);
  core_.Edit([&](const sgal::Scene& sc) { return sgal::RemovePathPoint(sc, "elbow_flexor", 1); });
  EXPECT_EQ(core_.selection().kind, "");
  // removing the selected tendon clears the selection
  core_.Select("tendon", "wrist_flexor", 0);
  core_.Edit([&](const sgal::Scene& sc) { return sgal::RemoveTendon(sc, "wrist_flexor"); });
  EXPECT_EQ(core_.selection().kind, "");
}

}  // namespace
}  // namespace caliper::simulation
