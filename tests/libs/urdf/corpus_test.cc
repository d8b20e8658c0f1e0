// Every URDF robot of the reference corpus imports with the bodies, joints and mass its file
// declares (corpus_robots.h, counted with Python from the files), and hangs or stands for 5 s of
// simulated time in Bullet under gravity without a fault, a NaN or a runaway speed.

#include "corpus.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "../collada/scene_compare.h"
#include "caliper/collada/exporter.h"
#include "caliper/collada/importer.h"
#include "caliper/physics_bullet/bullet_scene.h"
#include "caliper/sgal/kinematics.h"
#include "caliper/urdf/importer.h"
#include "corpus_robots.h"

namespace caliper::testing {
namespace {

std::string UrdfPath(const CorpusRobot& robot) { return CorpusDir() + "/urdf/" + robot.path; }

sgal::Scene ImportRobot(const CorpusRobot& robot, urdf::Options options = {}) {
  // the folder that holds the package example-robot-data (SOURCES.md)
  options.package_path = {CorpusDir() + "/urdf"};
  std::vector<std::string> warnings;
  return urdf::Import(UrdfPath(robot), &warnings, options);
}

double TotalMass(const sgal::Scene& scene) {
  double mass = 0;  // [kg]
  for (const sgal::Body& body : scene.bodies) mass += body.inertia.mass;
  return mass;
}

int Count(const sgal::Scene& scene, sgal::ConstraintKind kind) {
  int n = 0;
  for (const sgal::Constraint& c : scene.constraints) n += c.kind == kind;
  return n;
}

// A root link named "world" is the world itself (importer.h), not a body; the link fixed to it
// is the static base then.
bool RootIsWorld(const CorpusRobot& robot) { return std::string(robot.root) == "world"; }

class CorpusRobotTest : public ::testing::TestWithParam<CorpusRobot> {};

TEST_P(CorpusRobotTest, ImportsTheDeclaredBodiesJointsAndMass) {
  CALIPER_REQUIRE_CORPUS();
  const CorpusRobot& robot = GetParam();
  const sgal::Scene scene = ImportRobot(robot);
  EXPECT_TRUE(sgal::Validate(scene).empty());
  // one body per moving joint and the base, links on fixed joints merged into them
  EXPECT_EQ(static_cast<int>(scene.bodies.size()), robot.merged_bodies());
  EXPECT_EQ(Count(scene, sgal::ConstraintKind::kHinge), robot.revolute + robot.continuous);
  EXPECT_EQ(Count(scene, sgal::ConstraintKind::kSlider), robot.prismatic);
  EXPECT_EQ(static_cast<int>(scene.constraints.size()), robot.moving());
  EXPECT_EQ(static_cast<int>(scene.couplings.size()), robot.mimic);
  EXPECT_NEAR(TotalMass(scene), robot.declared_mass, 1e-9);
  for (const sgal::Body& body : scene.bodies) {
    EXPECT_EQ(body.type,
              body.name == robot.base ? sgal::BodyType::kStatic : sgal::BodyType::kDynamic)
        << body.name;
  }
}

// Unmerged, a link on a fixed joint is a body of its own that moves with its parent: without
// <inertial>, or with a zero mass (a massless frame such as a tool flange), it gets the default
// mass and a warning naming it.
// Import -> COLLADA export -> import gives the same scene: bodies, masses, collision shapes
// (meshes vertex for vertex), visual counts, joints with limits, damping and friction, couplings.
TEST_P(CorpusRobotTest, RoundTripThroughColladaGivesTheSameScene) {
  CALIPER_REQUIRE_CORPUS();
  const CorpusRobot& robot = GetParam();
  const sgal::Scene first = ImportRobot(robot);
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() /
      ("caliper-urdf-" + std::to_string(getpid()) + "-" + robot.name + ".dae");
  collada::Export(first, out.string());
  std::vector<std::string> warnings;
  const sgal::Scene again = collada::Import(out.string(), &warnings);
  std::filesystem::remove(out);
  SceneComparison compare(1e-9);
  EXPECT_EQ(compare.Compare(first, again), 0);
}

TEST_P(CorpusRobotTest, KeepsEveryLinkWhenFixedJointsAreNotMerged) {
  CALIPER_REQUIRE_CORPUS();
  const CorpusRobot& robot = GetParam();
  urdf::Options options;
  options.merge_fixed_joints = false;
  std::vector<std::string> warnings;
  const sgal::Scene scene = urdf::Import(UrdfPath(robot), &warnings, options);
  EXPECT_TRUE(sgal::Validate(scene).empty());
  const int world_link = RootIsWorld(robot) ? 1 : 0;
  EXPECT_EQ(static_cast<int>(scene.bodies.size()), robot.links - world_link);
  // the joint from a "world" link makes the base static instead of a constraint
  EXPECT_EQ(Count(scene, sgal::ConstraintKind::kFixed), robot.fixed - world_link);
  const sgal::Body* base = scene.FindBody(robot.base);
  ASSERT_NE(base, nullptr) << robot.base;
  EXPECT_EQ(base->type, sgal::BodyType::kStatic);
  int static_bodies = 0;
  for (const sgal::Body& body : scene.bodies) static_bodies += body.type == sgal::BodyType::kStatic;
  EXPECT_EQ(static_bodies, 1);
  EXPECT_EQ(static_cast<int>(scene.constraints.size()), robot.joints() - world_link);
  int zero_mass = 0;
  for (const char* link : robot.zero_mass) {
    if (link == nullptr) continue;
    ++zero_mass;
    bool warned = false;
    for (const auto& w : warnings)
      warned |= w.find("link '" + std::string(link) +
                       "': mass 0 kg on a link held by the fixed "
                       "joint") != std::string::npos;
    EXPECT_TRUE(warned) << link;
  }
  const int defaulted = robot.links_without_inertial - world_link + zero_mass;
  EXPECT_NEAR(TotalMass(scene), robot.declared_mass + defaulted * urdf::kDefaultMass, 1e-9);
}

// The scene with every joint whose zero lies outside its limits (Kinova's shoulder, elbow and
// wrist) moved 0.05 rad or m inside the nearest limit, so that the engine's limits do not jerk
// the robot at the start.
sgal::Scene PosedWithinLimits(sgal::Scene scene) {
  std::map<std::string, double> q;
  for (const sgal::Constraint& c : scene.constraints) {
    const sgal::Limit& limit = c.limits[0];
    const bool moves =
        c.kind == sgal::ConstraintKind::kHinge || c.kind == sgal::ConstraintKind::kSlider;
    if (!moves || !limit.enabled() || (limit.lower <= 0 && 0 <= limit.upper)) continue;
    const double margin = std::min(0.05, 0.5 * (limit.upper - limit.lower));
    q[c.name] = limit.lower > 0 ? limit.lower + margin : limit.upper - margin;
  }
  if (q.empty()) return scene;
  const std::vector<sgal::Pose> poses = sgal::ForwardKinematics(scene, q);
  for (size_t b = 0; b < poses.size(); ++b) scene.bodies[b].pose = poses[b];
  return scene;
}

// The body speeds a robot falling from rest under gravity can reach: a point mass dropping twice
// the robot's reach (the farthest body frame from the base) reaches sqrt(2 g 2 reach); light
// links whipped by heavy ones go faster (Panda's fingers reached 1.21 times that with links that
// do not collide with each other), so 1.5 times that. Measured without self-collision: UR5 5.4,
// Panda 7.7, Kinova 0.7, PR2 3.5, iiwa 4.6 m/s against bounds of 8.6, 9.6, 5.5, 10.5, 10.5 m/s.
double SpeedBound(const sgal::Scene& scene, const Eigen::Vector3d& base) {
  double reach = 0;  // [m]
  for (const sgal::Body& body : scene.bodies) {
    reach = std::max(reach, (body.pose.position - base).norm());
  }
  return 1.5 * std::sqrt(2 * 9.81 * 2 * reach);  // [m/s]
}

// The robot as imported (its links do not collide with each other, the default), its base
// static: no fault, no NaN, no body faster than SpeedBound, the base where it was.
TEST_P(CorpusRobotTest, HangsFiveSecondsUnderGravity) {
  CALIPER_REQUIRE_CORPUS();
  const CorpusRobot& robot = GetParam();
  const sgal::Scene scene = PosedWithinLimits(ImportRobot(robot));
  const int base = scene.BodyIndex(robot.base);
  ASSERT_GE(base, 0);
  const Eigen::Vector3d base_start = scene.bodies[base].pose.position;
  const double bound = SpeedBound(scene, base_start);  // [m/s]
  auto physics = physics_bullet::MakeScene(scene);
  const double dt = scene.settings.time_step;  // [s]
  const int steps = static_cast<int>(std::lround(5.0 / dt));
  double fastest = 0;  // [m/s]
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) {
    ASSERT_NO_THROW(physics->Step()) << robot.name << " at t = " << physics->time() << " s";
    if (i % 10 != 9) continue;
    const std::vector<sgal::BodyState> states = physics->BodyStates();
    for (size_t b = 0; b < states.size(); ++b) {
      const sgal::BodyState& s = states[b];
      ASSERT_TRUE(s.pose.position.allFinite() && s.linear_velocity.allFinite() &&
                  s.angular_velocity.allFinite())
          << scene.bodies[b].name << " at t = " << physics->time() << " s";
      fastest = std::max(fastest, s.linear_velocity.norm());
      ASSERT_LT(s.linear_velocity.norm(), bound)
          << scene.bodies[b].name << " at t = " << physics->time() << " s";
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT((physics->BodyStates()[base].pose.position - base_start).norm(), 1e-9);
  std::printf(
      "%s: %d bodies, %d steps of %g s in %.2f s wall, fastest body %.3f m/s (bound %.2f)\n",
      robot.name, static_cast<int>(scene.bodies.size()), steps, dt, seconds, fastest, bound);
}

INSTANTIATE_TEST_SUITE_P(Corpus, CorpusRobotTest, ::testing::ValuesIn(kCorpusRobots),
                         [](const auto& p) { return std::string(p.param.name); });

// The lowest point of a shape placed at `pose` in the world [m] (z up).
double LowestZ(const sgal::Shape& shape, const sgal::Pose& body) {
  const sgal::Pose pose = body * shape.pose;
  const Eigen::Matrix3d r = pose.orientation.toRotationMatrix();
  const double z = pose.position.z();
  return std::visit(
      [&](const auto& g) -> double {
        using G = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<G, sgal::Box>) {
          return z - 0.5 * (r.row(2).cwiseAbs().dot(g.size));
        } else if constexpr (std::is_same_v<G, sgal::Sphere>) {
          return z - g.radius;
        } else if constexpr (std::is_same_v<G, sgal::Cylinder> || std::is_same_v<G, sgal::Cone>) {
          // the rim: half length along the axis, radius across it
          const double axis_z = std::abs(r(2, 2));
          return z - 0.5 * g.length * axis_z - g.radius * std::sqrt(1 - axis_z * axis_z);
        } else if constexpr (std::is_same_v<G, sgal::Capsule>) {
          return z - 0.5 * g.length * std::abs(r(2, 2)) - g.radius;
        } else if constexpr (std::is_same_v<G, sgal::ConvexHull> ||
                             std::is_same_v<G, sgal::TriangleMesh>) {
          double low = std::numeric_limits<double>::infinity();
          for (const Eigen::Vector3f& v : g.mesh->vertices) {
            low = std::min(low, pose.Apply(v.cast<double>()).z());
          }
          return low;
        } else {
          return std::numeric_limits<double>::infinity();  // a plane is not part of a robot
        }
      },
      shape.geometry);
}

// R2D2 with a floating base on a ground plane under its wheels stays upright and where it is.
TEST(CorpusRobot, R2d2WithAFloatingBaseStandsOnTheGround) {
  CALIPER_REQUIRE_CORPUS();
  const CorpusRobot* r2d2 = nullptr;
  for (const CorpusRobot& r : kCorpusRobots) {
    if (std::string(r.name) == "R2D2") r2d2 = &r;
  }
  urdf::Options options;
  options.floating_base = true;
  sgal::Scene scene = ImportRobot(*r2d2, options);
  ASSERT_EQ(static_cast<int>(scene.bodies.size()), r2d2->moving() + 1);
  double ground = std::numeric_limits<double>::infinity();  // [m]
  for (const sgal::Body& body : scene.bodies) {
    for (const sgal::Shape& shape : body.shapes)
      ground = std::min(ground, LowestZ(shape, body.pose));
  }
  ASSERT_TRUE(std::isfinite(ground));
  sgal::Body plane;
  plane.name = "ground";
  plane.type = sgal::BodyType::kStatic;
  plane.inertia.mass = 0;
  sgal::Shape floor;
  floor.name = "ground";
  floor.geometry = sgal::Plane{Eigen::Vector3d::UnitZ(), ground};
  plane.shapes.push_back(floor);
  scene.bodies.push_back(plane);

  const sgal::Body* base = scene.FindBody(r2d2->root);
  ASSERT_NE(base, nullptr);
  EXPECT_EQ(base->type, sgal::BodyType::kDynamic);
  const sgal::Pose start = base->pose;
  auto physics = physics_bullet::MakeScene(scene);
  const int base_index = scene.BodyIndex(r2d2->root);
  const int steps = static_cast<int>(std::lround(5.0 / scene.settings.time_step));
  for (int i = 0; i < steps; ++i) ASSERT_NO_THROW(physics->Step()) << "t = " << physics->time();
  const sgal::BodyState end = physics->BodyStates()[base_index];
  ASSERT_TRUE(end.pose.position.allFinite());
  // upright: the base's z axis within 2 degrees of the world's
  const double tilt =
      std::acos(std::min(1.0, (end.pose.orientation * Eigen::Vector3d::UnitZ()).z()));
  EXPECT_LT(tilt, 2 * M_PI / 180) << "tilt " << tilt << " rad";
  // it settled on its wheels: no more than 1 cm away sideways and in height, at rest
  EXPECT_LT((end.pose.position - start.position).head<2>().norm(), 0.01);
  EXPECT_NEAR(end.pose.position.z(), start.position.z(), 0.01);
  EXPECT_LT(end.linear_velocity.norm(), 0.01);
  std::printf("R2D2 on the ground: tilt %.2e rad, moved %.2e m sideways, %.2e m in height\n", tilt,
              (end.pose.position - start.position).head<2>().norm(),
              end.pose.position.z() - start.position.z());
}

}  // namespace
}  // namespace caliper::testing
