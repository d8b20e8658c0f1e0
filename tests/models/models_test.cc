// The shipped models (models/*.dae): each imports without warnings, is the scene its generator
// builds, passes sgal::Validate, builds a Bullet scene, simulates 10 s stably unpowered and under
// a command pattern (its motors visibly move it), wraps its obstacles, and exports -> reimports
// to the same scene.
#include "models.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "caliper/collada/exporter.h"
#include "caliper/collada/importer.h"
#include "caliper/physics_bullet/bullet_scene.h"
#include "scene_compare.h"

namespace caliper::models {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180;
constexpr double kDuration = 10;  // simulated [s]
constexpr double kMaxSpeed = 5;   // bounded body speeds [m/s]
constexpr double kMaxSpin = 40;   // [rad/s]

// $CALIPER_SOURCE_DIR/models (ctest sets it), else the source tree this test was built from
std::string ModelsDir() {
  const char* source = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(source != nullptr && *source != '\0' ? source : CALIPER_SOURCE_DIR_DEFAULT) +
         "/models";
}

/// Commands [V or excitation] by actuator name at a time [s].
using Pattern = std::function<std::map<std::string, double>(double time)>;

/// What one model is checked for.
struct Case {
  std::string file;
  Pattern pattern;                               // a representative command pattern
  std::map<std::string, double> min_motion_deg;  // joint -> least range it must sweep under it
  double max_rest_drift_deg;                     // unpowered: no joint strays further
};

// ±volts on antagonists, swapping every half period: flexors first
std::map<std::string, double> Alternate(double time, double period, double volts,
                                        const std::vector<std::string>& first,
                                        const std::vector<std::string>& second) {
  const bool first_half = std::fmod(time, period) < period / 2;
  std::map<std::string, double> c;
  for (const auto& a : first) c[a] = first_half ? volts : -volts;
  for (const auto& a : second) c[a] = first_half ? -volts : volts;
  return c;
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.file; }

std::vector<Case> Cases() {
  return {
      {"ecce_arm.dae",
       [](double t) {
         auto c = Alternate(t, 5.0, 4.0,
                            {"girdle_elevator", "shoulder_flexor", "shoulder_abductor",
                             "elbow_flexor", "wrist_flexor"},
                            {"girdle_depressor", "shoulder_extensor", "shoulder_adductor",
                             "elbow_extensor", "wrist_extensor"});
         c["biceps"] = std::fmod(t, 5.0) < 2.5 ? 0.3 : 0.0;  // excitation
         return c;
       },
       {{"girdle_elevation", 5},
        {"shoulder_abduction", 5},
        {"shoulder_flexion", 10},
        {"elbow", 20},
        {"wrist", 10}},
       2.0},
      {"pendulum_tendon.dae",
       [](double t) {
         return std::map<std::string, double>{{"motor", std::fmod(t, 5.0) < 3.0 ? 6.0 : -6.0}};
       },
       {{"pivot", 8}},
       0.5},
      {"two_link_antagonistic.dae",
       [](double t) {
         auto c = Alternate(t, 4.0, 3.0, {"shoulder_flexor"}, {"shoulder_extensor"});
         for (const auto& [k, v] :
              Alternate(t + 1.0, 4.0, 3.0, {"elbow_flexor"}, {"elbow_extensor"}))
           c[k] = v;
         return c;
       },
       {{"shoulder", 15}, {"elbow", 15}},
       0.5},
  };
}

class ShippedModel : public ::testing::TestWithParam<Case> {
 protected:
  std::string Path() const { return ModelsDir() + "/" + GetParam().file; }

  sgal::Scene Load() {
    std::vector<std::string> warnings;
    sgal::Scene scene;
    try {
      scene = collada::Import(Path(), &warnings);
    } catch (const collada::ImportError& e) {
      ADD_FAILURE() << e.what();
    }
    for (const auto& w : warnings) ADD_FAILURE() << "warning: " << w;
    return scene;
  }

  // Runs kDuration seconds under `pattern` (null: unpowered); fails on a SimulationFault or an
  // unbounded speed. Returns the range [rad] each hinge swept and the largest distance [rad]
  // from its starting angle.
  struct Run {
    std::map<std::string, double> range;
    std::map<std::string, double> drift;
    std::map<std::string, size_t> most_points;  // per tendon, over the run
    double wall_s = 0;
  };
  Run Simulate(const sgal::Scene& description, const Pattern& pattern) {
    Run run;
    std::unique_ptr<sgal::PhysicsScene> scene;
    try {
      scene = physics_bullet::MakeScene(description);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "MakeScene: " << e.what();
      return run;
    }
    std::map<std::string, double> start, low, high;
    for (const auto& c : description.constraints) {
      if (c.kind != sgal::ConstraintKind::kHinge) continue;
      start[c.name] = low[c.name] = high[c.name] = scene->GetParameter(c.name + ".position");
    }
    const auto begin = std::chrono::steady_clock::now();
    const int steps = static_cast<int>(std::lround(kDuration / description.settings.time_step));
    double fastest = 0, spin = 0;
    for (int i = 0; i < steps; ++i) {
      if (pattern)
        for (const auto& [actuator, value] : pattern(scene->time()))
          scene->SetCommand(actuator, value);
      try {
        scene->Step();
      } catch (const sgal::SimulationFault& e) {
        ADD_FAILURE() << e.what();
        return run;
      }
      for (const auto& s : scene->BodyStates()) {
        fastest = std::max(fastest, s.linear_velocity.norm());
        spin = std::max(spin, s.angular_velocity.norm());
      }
      for (auto& [name, q0] : start) {
        const double q = scene->GetParameter(name + ".position");
        low[name] = std::min(low[name], q);
        high[name] = std::max(high[name], q);
        run.drift[name] = std::max(run.drift[name], std::abs(q - q0));
      }
      const auto tendons = scene->TendonStates();
      for (size_t t = 0; t < tendons.size(); ++t) {
        size_t& most = run.most_points[description.tendons[t].name];
        most = std::max(most, tendons[t].points.size());
      }
    }
    run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    for (const auto& [name, q0] : start) run.range[name] = high[name] - low[name];
    EXPECT_LT(fastest, kMaxSpeed) << "fastest body [m/s]";
    EXPECT_LT(spin, kMaxSpin) << "fastest spin [rad/s]";
    return run;
  }
};

TEST_P(ShippedModel, ImportsWithoutWarningsAndValidates) {
  const sgal::Scene scene = Load();
  EXPECT_FALSE(scene.bodies.empty());
  for (const auto& p : sgal::Validate(scene)) ADD_FAILURE() << p;
  for (const auto& b : scene.bodies) EXPECT_FALSE(b.visuals.empty()) << b.name << " is not drawn";
}

TEST_P(ShippedModel, IsTheSceneItsGeneratorBuilds) {
  const sgal::Scene scene = Load();
  for (const Model& m : AllModels()) {
    if (m.file != GetParam().file) continue;
    testing::SceneComparison compare(1e-9);
    EXPECT_EQ(compare.Compare(m.scene, scene), 0)
        << GetParam().file << " is stale: run build/bin/make_models";
    return;
  }
  FAIL() << "no generator for " << GetParam().file;
}

TEST_P(ShippedModel, PassesTheSchemaValidator) {
  if (std::system("command -v opencolladavalidator > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "opencolladavalidator not installed";
  const std::string log = (std::filesystem::temp_directory_path() /
                           ("caliper_models_" + std::to_string(::getpid()) + ".log"))
                              .string();
  const int status =
      std::system(("opencolladavalidator '" + Path() + "' > '" + log + "' 2>&1").c_str());
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(log);
  EXPECT_EQ(status, 0) << text;
  EXPECT_EQ(text.find("Schema validation error"), std::string::npos) << text;
}

TEST_P(ShippedModel, ExportsAndReimportsToTheSameScene) {
  const sgal::Scene scene = Load();
  const auto out = std::filesystem::temp_directory_path() /
                   ("caliper_models_" + std::to_string(::getpid()) + "_" + GetParam().file);
  ASSERT_NO_THROW(collada::Export(scene, out.string()));
  std::vector<std::string> warnings;
  sgal::Scene again;
  try {
    again = collada::Import(out.string(), &warnings);
  } catch (const collada::ImportError& e) {
    FAIL() << "re-import: " << e.what();
  }
  std::filesystem::remove(out);
  for (const auto& w : warnings) ADD_FAILURE() << "re-import warns: " << w;
  testing::SceneComparison compare(1e-9);
  EXPECT_EQ(compare.Compare(scene, again), 0);
}

TEST_P(ShippedModel, StaysAtRestUnpoweredFor10Seconds) {
  const sgal::Scene scene = Load();
  const Run run = Simulate(scene, nullptr);
  for (const auto& [joint, drift] : run.drift)
    EXPECT_LT(drift, GetParam().max_rest_drift_deg * kDegree) << joint << " drifts [rad]";
  std::cout << GetParam().file << ": 10 s unpowered in " << run.wall_s << " s wall time\n";
}

TEST_P(ShippedModel, MotorsMoveItStablyUnderACommandPattern) {
  const sgal::Scene scene = Load();
  const Run run = Simulate(scene, GetParam().pattern);
  for (const auto& [joint, degrees] : GetParam().min_motion_deg) {
    ASSERT_TRUE(run.range.count(joint)) << "no hinge " << joint;
    EXPECT_GT(run.range.at(joint), degrees * kDegree) << joint << " swept [rad]";
  }
  std::cout << GetParam().file << ": 10 s commanded in " << run.wall_s << " s wall time; swept";
  for (const auto& [joint, range] : run.range) std::cout << " " << joint << " " << range / kDegree;
  std::cout << " deg\n";
}

// Every wrapping tendon of every shipped model wraps at rest, and some model has one (a model
// without one has nothing to check here: it is not a skip).
TEST(ShippedModels, TendonsWrapTheirObstacles) {
  int wrapping = 0;
  for (const Case& c : Cases()) {
    std::vector<std::string> warnings;
    const sgal::Scene description = collada::Import(ModelsDir() + "/" + c.file, &warnings);
    std::unique_ptr<sgal::PhysicsScene> scene = physics_bullet::MakeScene(description);
    scene->Step();
    const auto at_rest = scene->TendonStates();
    ASSERT_EQ(at_rest.size(), description.tendons.size()) << c.file;
    for (size_t i = 0; i < description.tendons.size(); ++i) {
      const sgal::Tendon& t = description.tendons[i];
      size_t points = 0;
      bool wraps = false;
      for (const auto& e : t.path) {
        points += e.kind == sgal::PathElement::Kind::kPoint ? 1 : 0;
        wraps = wraps || e.kind == sgal::PathElement::Kind::kWrap;
      }
      if (!wraps) continue;
      ++wrapping;
      EXPECT_GT(at_rest[i].points.size(), points)
          << c.file << ": tendon '" << t.name << "' does not wrap at rest";
      EXPECT_GT(at_rest[i].points.size(), 2u) << c.file << ": " << t.name;
    }
  }
  EXPECT_GT(wrapping, 0) << "no shipped model has a wrapping tendon";
}

INSTANTIATE_TEST_SUITE_P(Models, ShippedModel, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<Case>& model) {
                           return model.param.file.substr(0, model.param.file.find('.'));
                         });

TEST(ShippedModels, TheEcceArmHasItsParts) {
  const sgal::Scene arm = MakeEcceArm();
  int motors = 0, ligaments = 0, muscles = 0;
  for (const auto& a : arm.actuators) {
    motors += a.kind == "dc_motor_tendon" ? 1 : 0;
    ligaments += a.kind == "ligament" ? 1 : 0;
    muscles += a.kind == "hill_muscle" ? 1 : 0;
  }
  EXPECT_EQ(motors, 10);
  EXPECT_GE(ligaments, 2);
  EXPECT_GE(muscles, 1);
  EXPECT_EQ(arm.bodies.size(), 6u);  // torso, girdle, shoulder housing, upper arm, forearm, hand
  EXPECT_EQ(arm.constraints.size(), 5u);
  EXPECT_EQ(arm.FindBody("torso")->type, sgal::BodyType::kStatic);
}

}  // namespace
}  // namespace caliper::models
