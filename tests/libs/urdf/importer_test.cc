// The URDF importer's semantics, each on a small file of known numbers (tests/data/urdf): joint
// kinds, limits, dynamics, mimics, inertial frames, defaults, merged fixed joints, meshes in every
// format and how their paths resolve, Caliper's data in the URDF and beside it, the round trip
// through COLLADA, and the errors for bad files.

#include "caliper/collada/importer.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "../collada/scene_compare.h"
#include "caliper/collada/exporter.h"
#include "caliper/urdf/importer.h"
#include "caliper/model_file/model_file.h"

namespace caliper::urdf {
namespace {

namespace fs = std::filesystem;

const std::string kData = CALIPER_URDF_TEST_DATA;
const std::string kPackages = kData + "/meshes";

Options WithPackages() {
  Options o;
  o.package_path = {kPackages};
  return o;
}

const sgal::Body& BodyOf(const sgal::Scene& s, const std::string& name) {
  const sgal::Body* b = s.FindBody(name);
  if (b == nullptr) throw std::runtime_error("no body " + name);
  return *b;
}

const sgal::Constraint& JointOf(const sgal::Scene& s, const std::string& name) {
  for (const auto& c : s.constraints)
    if (c.name == name) return c;
  throw std::runtime_error("no constraint " + name);
}

bool AnyWarning(const std::vector<std::string>& warnings, const std::string& text) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

std::string ImportError(const std::string& file, const Options& options = {}) {
  std::vector<std::string> warnings;
  try {
    Import(file, &warnings, options);
  } catch (const urdf::ImportError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " imported";
  return "";
}

// A small URDF written for one test, removed after it.
class TempUrdf {
 public:
  TempUrdf(const std::string& name, const std::string& text)
      : path_(fs::temp_directory_path() / ("caliper-" + name + "-" + std::to_string(getpid()))) {
    fs::create_directories(path_);
    std::ofstream(file()) << text;
  }
  ~TempUrdf() { fs::remove_all(path_); }
  std::string file() const { return (path_ / "robot.urdf").string(); }
  fs::path dir() const { return path_; }

 private:
  fs::path path_;
};

const char* const kInertial =
    R"(<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>)";

std::string Robot(const std::string& body) { return "<robot name=\"r\">\n" + body + "\n</robot>"; }

// A link `name` of 1 kg with kInertial, on one line.
std::string InertialLink(const std::string& name) {
  return "<link name=\"" + name + "\">" + kInertial + "</link>";
}

// ImportError of `text` written as robot.urdf in a folder of its own named after `name`.
std::string ImportErrorOf(const std::string& name, const std::string& text) {
  TempUrdf urdf(name, text);
  return ImportError(urdf.file());
}

// The warnings of importing `text` written as robot.urdf in a folder of its own named after `name`.
std::vector<std::string> ImportWarningsOf(const std::string& name, const std::string& text) {
  TempUrdf urdf(name, text);
  std::vector<std::string> warnings;
  Import(urdf.file(), &warnings);
  return warnings;
}

// World pose of body_a's joint frame when the joint is at q, from the constraint's frames.
Eigen::Isometry3d ChildAt(const sgal::Scene& s, const sgal::Constraint& c, double q) {
  const Eigen::Isometry3d parent =
      c.body_b.empty() ? Eigen::Isometry3d::Identity() : BodyOf(s, c.body_b).pose.ToIsometry();
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  if (c.kind == sgal::ConstraintKind::kHinge)
    motion.linear() = Eigen::AngleAxisd(q, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  else
    motion.translation() = Eigen::Vector3d(0, 0, q);
  return parent * c.frame_b.ToIsometry() * motion * c.frame_a.ToIsometry().inverse();
}

class KindsTest : public ::testing::Test {
 protected:
  void SetUp() override { scene = Import(kData + "/kinds.urdf", &warnings, WithPackages()); }
  std::vector<std::string> warnings;
  sgal::Scene scene;
};

TEST_F(KindsTest, EveryLinkIsABodyButMergedOnes) {
  std::set<std::string> names;
  for (const auto& b : scene.bodies) names.insert(b.name);
  EXPECT_EQ(names, (std::set<std::string>{"base", "upper", "fore", "carriage", "wheel", "follower",
                                          "puck", "drone", "bare"}));
  EXPECT_EQ(BodyOf(scene, "base").type, sgal::BodyType::kStatic);  // the root, fixed
  EXPECT_EQ(BodyOf(scene, "upper").type, sgal::BodyType::kDynamic);
  EXPECT_EQ(scene.name, "kinds");
}

TEST_F(KindsTest, JointKindsLimitsAndDynamics) {
  EXPECT_EQ(scene.constraints.size(), 7u);  // no fixed (merged), no floating (free)
  const auto& shoulder = JointOf(scene, "shoulder");
  EXPECT_EQ(shoulder.kind, sgal::ConstraintKind::kHinge);
  EXPECT_EQ(shoulder.body_a, "upper");
  EXPECT_EQ(shoulder.body_b, "base");
  EXPECT_DOUBLE_EQ(shoulder.limits[0].lower, -1);
  EXPECT_DOUBLE_EQ(shoulder.limits[0].upper, 1.5);
  EXPECT_DOUBLE_EQ(shoulder.springs[0].damping, 0.1);
  EXPECT_DOUBLE_EQ(shoulder.springs[0].stiffness, 0);
  EXPECT_DOUBLE_EQ(shoulder.friction[0], 0.05);
  EXPECT_FALSE(shoulder.collide_connected);

  const auto& rail = JointOf(scene, "rail");
  EXPECT_EQ(rail.kind, sgal::ConstraintKind::kSlider);
  EXPECT_DOUBLE_EQ(rail.limits[0].lower, -0.1);
  EXPECT_DOUBLE_EQ(rail.limits[0].upper, 0.2);
  EXPECT_DOUBLE_EQ(rail.springs[0].damping, 0.5);
  EXPECT_DOUBLE_EQ(rail.friction[0], 0.2);

  const auto& spin = JointOf(scene, "spin");
  EXPECT_EQ(spin.kind, sgal::ConstraintKind::kHinge);
  EXPECT_FALSE(spin.limits[0].enabled());  // continuous

  const auto& glide = JointOf(scene, "glide");
  EXPECT_EQ(glide.kind, sgal::ConstraintKind::kGeneric6Dof);
  for (int i : {0, 1, 5}) EXPECT_FALSE(glide.limits[i].enabled()) << "dof " << i;
  for (int i : {2, 3, 4}) {
    EXPECT_TRUE(glide.limits[i].enabled()) << "dof " << i;
    EXPECT_EQ(glide.limits[i].lower, 0);
    EXPECT_EQ(glide.limits[i].upper, 0);
  }
  for (const auto& c : scene.constraints) {
    EXPECT_NE(c.name, "free") << "a floating joint is no constraint";
    EXPECT_FALSE(c.collide_connected) << c.name << ": a link collides with its parent";
  }
  EXPECT_EQ(BodyOf(scene, "drone").pose.position, Eigen::Vector3d(0, 0, 1));
}

TEST_F(KindsTest, MimicIsACoupling) {
  ASSERT_EQ(scene.couplings.size(), 1u);
  EXPECT_EQ(scene.couplings[0].leader, "shoulder");
  EXPECT_EQ(scene.couplings[0].follower, "mimic");
  EXPECT_DOUBLE_EQ(scene.couplings[0].ratio, -0.5);
  EXPECT_DOUBLE_EQ(scene.couplings[0].offset, 0.1);
}

// The joint moves the child about (along) the URDF axis in the parent's joint frame: the
// constraint frames reproduce URDF's child pose = parent * origin * rotation(axis, q).
TEST_F(KindsTest, JointFramesFollowTheAxis) {
  const double q = 0.7;
  // elbow: origin xyz 0 0 0.4 rpy 0 0 0.5 on upper (at 0 0 0.1), axis (0 0 2) normalised
  const Eigen::Isometry3d upper = BodyOf(scene, "upper").pose.ToIsometry();
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  origin.translation() = Eigen::Vector3d(0, 0, 0.4);
  origin.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d expected = upper * origin;
  expected.linear() =
      expected.linear() * Eigen::AngleAxisd(q, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Isometry3d got = ChildAt(scene, JointOf(scene, "elbow"), q);
  EXPECT_LT((got.matrix() - expected.matrix()).norm(), 1e-12);
  // at q = 0 the child is where the description puts it
  EXPECT_LT((ChildAt(scene, JointOf(scene, "elbow"), 0).matrix() -
             BodyOf(scene, "fore").pose.ToIsometry().matrix())
                .norm(),
            1e-12);
  // shoulder about y: a positive angle takes +x of upper towards -z (right hand about y)
  const Eigen::Isometry3d s = ChildAt(scene, JointOf(scene, "shoulder"), M_PI / 2);
  EXPECT_LT((s.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
  // rail along x
  const Eigen::Isometry3d r = ChildAt(scene, JointOf(scene, "rail"), 0.15);
  EXPECT_LT((r.translation() - Eigen::Vector3d(0.15, 0.2, 0)).norm(), 1e-12);
}

// I = R I' R^T: the inertial frame turned 90 deg about z swaps ixx and iyy.
TEST_F(KindsTest, InertialFrameRotationTurnsTheTensor) {
  const auto& upper = BodyOf(scene, "upper");
  EXPECT_DOUBLE_EQ(upper.inertia.mass, 1);
  EXPECT_LT((upper.inertia.com - Eigen::Vector3d(0.1, 0, 0)).norm(), 1e-15);
  const Eigen::Matrix3d expected = Eigen::Vector3d(0.002, 0.001, 0.003).asDiagonal();
  EXPECT_LT((upper.inertia.tensor - expected).norm(), 1e-15) << upper.inertia.tensor;
}

// tool (nothing) and sensor (0.5 kg, 1 cm along its own z, which the mount turns to -y) merge
// into fore: masses, centre of mass and the parallel-axis tensor combined; shapes, visuals and
// the tendon's point go with them.
TEST_F(KindsTest, FixedJointsMergeIntoTheParent) {
  const auto& fore = BodyOf(scene, "fore");
  EXPECT_DOUBLE_EQ(fore.inertia.mass, 1.0);
  const Eigen::Vector3d sensor_com(0, -0.01, 0.3);
  EXPECT_LT((fore.inertia.com - sensor_com / 2).norm(), 1e-15);
  const Eigen::Matrix3d own = Eigen::Vector3d(0.002, 0.002, 0.0005).asDiagonal();
  // diag(1, 2, 3) 1e-4 kg m^2 in the sensor's frame, turned 90 deg about x into fore's
  const Eigen::Matrix3d sensor = Eigen::Vector3d(1e-4, 3e-4, 2e-4).asDiagonal();
  auto shift = [](double m, const Eigen::Vector3d& d) -> Eigen::Matrix3d {
    return m * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  };
  const Eigen::Vector3d c = fore.inertia.com;
  const Eigen::Matrix3d expected = own + shift(0.5, -c) + sensor + shift(0.5, sensor_com - c);
  EXPECT_LT((fore.inertia.tensor - expected).norm(), 1e-15);
  // fore's own prism and the sensor's sphere (1 cm below nothing: at the mount, 0.3 m up)
  ASSERT_EQ(fore.shapes.size(), 2u);
  EXPECT_TRUE(std::holds_alternative<sgal::Sphere>(fore.shapes[1].geometry));
  EXPECT_LT((fore.shapes[1].pose.position - Eigen::Vector3d(0, 0, 0.3)).norm(), 1e-15);
  EXPECT_EQ(fore.visuals.size(), 4u);  // 3 own, the tool's plate
  EXPECT_FALSE(AnyWarning(warnings, "'tool'")) << "a merged link without inertial needs none";
  // the tendon point given on the tool is now on fore, 0.3 m further along its z
  const auto& path = scene.tendons[0].path;
  EXPECT_EQ(path[1].body, "fore");
  EXPECT_LT((path[1].position - Eigen::Vector3d(0, 0, 0.35)).norm(), 1e-15);
  EXPECT_EQ(path[0].body, "base");
  EXPECT_LT((path[0].position - Eigen::Vector3d(0, 0.1, 0.05)).norm(), 1e-15);
  // the pulley on the sensor and the side point in the sensor's frame: z along fore's -y
  ASSERT_EQ(scene.obstacles.size(), 1u);
  EXPECT_EQ(scene.obstacles[0].body, "fore");
  EXPECT_LT((scene.obstacles[0].pose.position - Eigen::Vector3d(0, -0.02, 0.3)).norm(), 1e-15);
  EXPECT_LT((scene.obstacles[0].pose.orientation.toRotationMatrix() * Eigen::Vector3d::UnitZ() -
             Eigen::Vector3d(0, -1, 0))
                .norm(),
            1e-15);
  ASSERT_EQ(scene.tendons.size(), 2u);
  const auto& wrap = scene.tendons[1].path[1];
  ASSERT_EQ(wrap.kind, sgal::PathElement::Kind::kWrap);
  ASSERT_TRUE(wrap.side.has_value());
  EXPECT_LT((*wrap.side - Eigen::Vector3d(0, -0.02, 0.31)).norm(), 1e-15) << wrap.side->transpose();
  ASSERT_EQ(scene.actuators.size(), 1u);
  EXPECT_EQ(scene.actuators[0].kind, "ligament");
  EXPECT_DOUBLE_EQ(scene.actuators[0].parameters.at("stiffness"), 2000);  // 2 N/mm
}

TEST(UrdfImport, FixedJointsKeptAsConstraintsOnRequest) {
  Options o = WithPackages();
  o.merge_fixed_joints = false;
  std::vector<std::string> warnings;
  const sgal::Scene s = Import(kData + "/kinds.urdf", &warnings, o);
  const auto& mount = JointOf(s, "tool_mount");
  EXPECT_EQ(mount.kind, sgal::ConstraintKind::kFixed);
  EXPECT_EQ(mount.body_a, "tool");
  EXPECT_EQ(mount.body_b, "fore");
  EXPECT_NE(s.FindBody("sensor"), nullptr);
  // the tool moves now and has no inertial: the default
  EXPECT_DOUBLE_EQ(BodyOf(s, "tool").inertia.mass, kDefaultMass);
  EXPECT_TRUE(AnyWarning(warnings, "link 'tool': no <inertial>"));
  // the tendon stays on the tool
  EXPECT_EQ(s.tendons[0].path[1].body, "tool");
}

TEST_F(KindsTest, WarningsNameFileLineAndLink) {
  // a link without <inertial> moving on its own joint: the documented default
  const auto& bare = BodyOf(scene, "bare");
  EXPECT_DOUBLE_EQ(bare.inertia.mass, kDefaultMass);
  EXPECT_NEAR(bare.inertia.tensor(0, 0), 0.4 * kDefaultMass * kDefaultRadius * kDefaultRadius,
              1e-18);
  EXPECT_TRUE(AnyWarning(warnings, "kinds.urdf:75: link 'bare': no <inertial>"));
  // unknown geometry skipped
  EXPECT_TRUE(AnyWarning(warnings,
                         "kinds.urdf:66: link 'follower': <visual> of unknown geometry <capsule>"));
  EXPECT_TRUE(BodyOf(scene, "follower").visuals.empty());
  // <gazebo> and <transmission> are ignored without a word
  EXPECT_FALSE(AnyWarning(warnings, "gazebo"));
  EXPECT_FALSE(AnyWarning(warnings, "transmission"));
  EXPECT_EQ(warnings.size(), 2u);
}

// ---- meshes

// The smallest and largest vertex coordinates of a mesh geometry (zeros for others).
struct Box {
  Eigen::Vector3f min = Eigen::Vector3f::Zero(), max = Eigen::Vector3f::Zero();
  Eigen::Vector3f sizes() const { return max - min; }
};

Box Bounds(const sgal::Geometry& g) {
  const sgal::Mesh* m = nullptr;
  if (const auto* h = std::get_if<sgal::ConvexHull>(&g)) m = h->mesh.get();
  if (const auto* t = std::get_if<sgal::TriangleMesh>(&g)) m = t->mesh.get();
  Box box;
  if (m == nullptr || m->vertices.empty()) return box;
  box.min = box.max = m->vertices[0];
  for (const auto& v : m->vertices) {
    box.min = box.min.cwiseMin(v);
    box.max = box.max.cwiseMax(v);
  }
  return box;
}

TEST_F(KindsTest, MeshesOfEveryFormatWithTheirScaleAndUnits) {
  // ASCII STL, scale 2: a tetrahedron of 0.1 m edges becomes 0.2 m; collision meshes are hulls
  const auto& upper = BodyOf(scene, "upper");
  ASSERT_EQ(upper.shapes.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<sgal::ConvexHull>(upper.shapes[0].geometry));
  EXPECT_LT((Bounds(upper.shapes[0].geometry).max - Eigen::Vector3f(0.2f, 0.2f, 0.2f)).norm(),
            1e-6);
  const auto& fore = BodyOf(scene, "fore");
  // binary STL by a path relative to the URDF: a 0.2 m cube about the origin
  ASSERT_TRUE(std::holds_alternative<sgal::TriangleMesh>(fore.visuals[0].geometry));
  const auto& cube = *std::get<sgal::TriangleMesh>(fore.visuals[0].geometry).mesh;
  EXPECT_EQ(cube.triangles.size(), 12u);
  EXPECT_LT((Bounds(fore.visuals[0].geometry).sizes() - Eigen::Vector3f(0.2f, 0.2f, 0.2f)).norm(),
            1e-6);
  // OBJ with quads: triangulated, 2 + 3 x 2 triangles, 0.3 m along x
  const auto& prism = *std::get<sgal::ConvexHull>(fore.shapes[0].geometry).mesh;
  EXPECT_EQ(prism.triangles.size(), 8u);
  EXPECT_NEAR(Bounds(fore.shapes[0].geometry).sizes().x(), 0.3f, 1e-6);
  // COLLADA in centimetres with Y up: the unit applies, the up axis does not (as in ROS)
  const auto plate = Bounds(fore.visuals[3].geometry).sizes();
  EXPECT_LT((plate - Eigen::Vector3f(0.1f, 0.2f, 0.0f)).norm(), 1e-6) << plate.transpose();
  EXPECT_LT((fore.visuals[3].pose.position - Eigen::Vector3d(0, 0, 0.3)).norm(), 1e-15);
  // the URDF's material colour
  EXPECT_EQ(BodyOf(scene, "base").visuals[0].color, Eigen::Vector4f(1, 0, 0, 1));
}

TEST_F(KindsTest, EachMeshFileIsReadOncePerScene) {
  // fore shows the same tetrahedron twice: one mesh in memory
  const auto& fore = BodyOf(scene, "fore");
  const auto& a = std::get<sgal::TriangleMesh>(fore.visuals[1].geometry).mesh;
  const auto& b = std::get<sgal::TriangleMesh>(fore.visuals[2].geometry).mesh;
  EXPECT_EQ(a.get(), b.get());
}

TEST(UrdfMeshPaths, PackageFileAndRelativeReferences) {
  const std::string urdf = kData + "/kinds.urdf";
  const std::string tetra = kPackages + "/caliper_test_meshes/meshes/tetra_ascii.stl";
  std::vector<std::string> tried;
  // a package found by the <name> of its package.xml, in a folder of the package path
  EXPECT_TRUE(fs::equivalent(ResolveMesh("package://caliper_test_meshes/meshes/tetra_ascii.stl",
                                         urdf, {kPackages}, &tried),
                             tetra));
  // or by a folder of that name, without a package.xml: the package path's parent holds meshes/
  const fs::path scratch = fs::temp_directory_path() / ("caliper-urdf-" + std::to_string(getpid()));
  fs::create_directories(scratch / "bare_pkg" / "m");
  std::ofstream(scratch / "bare_pkg" / "m" / "x.stl") << "solid x\nendsolid x\n";
  EXPECT_EQ(ResolveMesh("package://bare_pkg/m/x.stl", urdf, {scratch.string()}, &tried),
            (scratch / "bare_pkg" / "m" / "x.stl").string());
  fs::remove_all(scratch);
  // file:// absolute, and relative to the URDF
  EXPECT_EQ(ResolveMesh("file://" + tetra, urdf, {}, &tried), tetra);
  EXPECT_TRUE(fs::equivalent(
      ResolveMesh("meshes/caliper_test_meshes/meshes/tetra_ascii.stl", urdf, {}, &tried), tetra));
  // not found: every place tried is listed
  tried.clear();
  EXPECT_EQ(ResolveMesh("package://caliper_test_meshes/meshes/none.stl", urdf, {kPackages}, &tried),
            "");
  ASSERT_FALSE(tried.empty());
  EXPECT_NE(tried[0].find("caliper_test_meshes/meshes/none.stl"), std::string::npos);
}

TEST(UrdfMeshPaths, EnvironmentPackagePathCaliperFirstThenRos) {
  unsetenv("CALIPER_PACKAGE_PATH");
  setenv("ROS_PACKAGE_PATH", ("/nonexistent:" + kPackages).c_str(), 1);
  EXPECT_EQ(PackagePathFromEnvironment(), (std::vector<std::string>{"/nonexistent", kPackages}));
  // the importer uses it when no path is given
  std::vector<std::string> warnings;
  EXPECT_NO_THROW(Import(kData + "/kinds.urdf", &warnings));
  setenv("CALIPER_PACKAGE_PATH", "/a:/b", 1);
  EXPECT_EQ(PackagePathFromEnvironment(),
            (std::vector<std::string>{"/a", "/b", "/nonexistent", kPackages}));
  unsetenv("CALIPER_PACKAGE_PATH");
  unsetenv("ROS_PACKAGE_PATH");
}

// ---- Caliper's data beside the URDF

TEST(UrdfImport, SideFileAddsTendonsAndActuators) {
  std::vector<std::string> warnings;
  const sgal::Scene s = Import(kData + "/side.urdf", &warnings);
  // the world link is the world: frame is fixed to it, so static
  EXPECT_EQ(s.FindBody("world"), nullptr);
  EXPECT_EQ(BodyOf(s, "frame").type, sgal::BodyType::kStatic);
  EXPECT_LT((BodyOf(s, "frame").pose.position - Eigen::Vector3d(0, 0, 1)).norm(), 1e-15);
  ASSERT_EQ(s.tendons.size(), 1u);
  EXPECT_EQ(s.tendons[0].path[0].body, "frame");
  EXPECT_LT((s.tendons[0].path[1].position - Eigen::Vector3d(0, 0, -0.4)).norm(), 1e-15);  // mm
  ASSERT_EQ(s.actuators.size(), 1u);
  EXPECT_EQ(s.actuators[0].kind, "dc_motor_tendon");
  EXPECT_DOUBLE_EQ(s.actuators[0].parameters.at("spool_radius"), 0.005);
  EXPECT_TRUE(warnings.empty()) << warnings[0];
}

TEST(UrdfImport, SideFileDelaysAMeasurement) {
  const sgal::Scene s = Import(kData + "/side.urdf", nullptr);
  ASSERT_EQ(s.measurement_delays.size(), 1u);
  EXPECT_EQ(s.measurement_delays[0].id, "motor.current");
  EXPECT_DOUBLE_EQ(s.measurement_delays[0].delay, 0.004);  // 4 ms
  // the same element as COLLADA's, with its checks: a malformed one names file, line and element
  TempUrdf urdf("delay", Robot(InertialLink("base")));
  std::ofstream(urdf.dir() / "robot.caliper.xml")
      << "<caliper>\n  <measurement_delay channel=\"base.mass\" delay=\"soon\"/>\n</caliper>\n";
  const std::string message = ImportError(urdf.file());
  EXPECT_NE(message.find("robot.caliper.xml:2: measurement_delay: attribute delay=\"soon\" is "
                         "not a number"),
            std::string::npos)
      << message;
}

// ---- import -> COLLADA export -> import gives the same scene

TEST(UrdfImport, RoundTripThroughCollada) {
  std::vector<std::string> warnings;
  const sgal::Scene first = Import(kData + "/kinds.urdf", &warnings, WithPackages());
  const fs::path out =
      fs::temp_directory_path() / ("caliper-urdf-" + std::to_string(getpid()) + ".dae");
  collada::Export(first, out.string());
  std::vector<std::string> again_warnings;
  const sgal::Scene again = collada::Import(out.string(), &again_warnings);
  fs::remove(out);
  testing::SceneComparison compare(1e-9);
  EXPECT_EQ(compare.Compare(first, again), 0);
  // and through the one entry point for model files
  EXPECT_EQ(model_file::FormatOf("x/ROBOT.URDF"), model_file::Format::kUrdf);
  EXPECT_EQ(model_file::FormatOf("x/robot.zae"), model_file::Format::kCollada);
  EXPECT_EQ(model_file::FormatOf("x/robot.sdf"), model_file::Format::kUnknown);
}

// ---- bad files: an error naming the file, the line and the element

struct BadFile {
  const char* file;
  const char* expected;
};

class BadUrdf : public ::testing::TestWithParam<BadFile> {};

TEST_P(BadUrdf, ClearErrorNamingFileLineAndElement) {
  const std::string message = ImportError(kData + "/bad/" + GetParam().file);
  EXPECT_NE(message.find(GetParam().expected), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    Files, BadUrdf,
    ::testing::Values(
        BadFile{"two_parents.urdf",
                "two_parents.urdf:4: link 'c': has two parents: joint 'ac' (line 6) and joint 'bc' "
                "(line 7)"},
        BadFile{"loop.urdf",
                "loop.urdf:7: link 'x': the joints form a loop: x (joint 'yx', line 10)"},
        BadFile{"missing_mesh.urdf",
                "missing_mesh.urdf:3: link 'arm': visual mesh 'meshes/no_such_mesh.stl' not found; "
                "tried:\n  "},
        BadFile{"broken_package.urdf",
                "broken_package.urdf:2: link 'base': collision mesh "
                "'package://no_such_package/meshes/base.stl' not found; tried:"},
        BadFile{"zero_mass.urdf", "zero_mass.urdf:3: link 'arm': mass 0 kg on a moving link"},
        BadFile{"malformed.urdf", "malformed.urdf:7: malformed XML: "},
        BadFile{"bad_caliper.urdf",
                "bad_caliper.urdf:8: attachment: dangling reference: tendon 't' point on unknown "
                "body 'forearm'"},
        BadFile{"not_urdf.urdf", "not_urdf.urdf:1: the root element is <COLLADA>, not <robot>"},
        BadFile{"no_such_file.urdf", "no_such_file.urdf: no such file"}));

TEST(UrdfImport, MissingMeshListsEveryPlaceTried) {
  const std::string message = ImportError(kData + "/bad/missing_mesh.urdf");
  EXPECT_NE(message.find(kData + "/bad/meshes/no_such_mesh.stl"), std::string::npos) << message;
  Options o;
  o.package_path = {"/nowhere/a", kPackages};
  const std::string package = ImportError(kData + "/bad/broken_package.urdf", o);
  EXPECT_NE(package.find("no folder above"), std::string::npos) << package;
}

TEST(UrdfImport, ImpossibleInertiaIsRaisedWithAWarning) {
  TempUrdf urdf("raised", R"(<robot name="r">
  <link name="base"/>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
</robot>)");
  std::vector<std::string> warnings;
  const sgal::Scene s = Import(urdf.file(), &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find(":3: link 'arm': principal moments of inertia 0.001 0.001 0.01 kg m^2 "
                             "are not those of a rigid body; raised to 0.005 0.005 0.01"),
            std::string::npos)
      << warnings[0];
  const Eigen::Matrix3d expected = Eigen::Vector3d(0.005, 0.005, 0.01).asDiagonal();
  EXPECT_LT((BodyOf(s, "arm").inertia.tensor - expected).norm(), 1e-12);
}

// A robot's links pass through each other by default (their meshes overlap where they join) and
// meet everything else; with self_collision every pair but a link and its parent collides.
TEST_F(KindsTest, LinksDoNotCollideWithEachOtherByDefault) {
  const sgal::Shape& a = BodyOf(scene, "upper").shapes[0];
  const sgal::Shape& b = BodyOf(scene, "base").shapes[0];
  EXPECT_EQ(a.group & b.mask, 0u);
  EXPECT_EQ(b.group & a.mask, 0u);
  const sgal::Shape ground;  // a shape of the default group and mask, e.g. a floor added later
  EXPECT_NE(a.group & ground.mask, 0u);
  EXPECT_NE(ground.group & a.mask, 0u);
  Options o = WithPackages();
  o.self_collision = true;
  std::vector<std::string> w;
  const sgal::Scene s = Import(kData + "/kinds.urdf", &w, o);
  const sgal::Shape& c = BodyOf(s, "upper").shapes[0];
  const sgal::Shape& d = BodyOf(s, "fore").shapes[0];
  EXPECT_NE(c.group & d.mask, 0u);
  EXPECT_NE(d.group & c.mask, 0u);
  EXPECT_FALSE(JointOf(s, "elbow").collide_connected);
}

TEST(UrdfImport, ZeroPositionOutsideTheLimitsWarns) {
  const std::vector<std::string> warnings = ImportWarningsOf("limits", R"(<robot name="r">
  <link name="base"/>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="0.5" upper="2" effort="1" velocity="1"/></joint>
</robot>)");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find(":4: joint 'j': the link's frame is at joint position 0, outside the "
                             "limits 0.5 .. 2 rad"),
            std::string::npos)
      << warnings[0];
}

// I = R I' R^T with R the inertial origin's rotation (rpy: R = Rz(yaw) Ry(pitch) Rx(roll)), on a
// turn about a skewed axis for which the transposed rotation (the classic bug) differs.
TEST(UrdfImport, InertialRotationOnASkewedAxis) {
  TempUrdf urdf("inertia", Robot(R"(<link name="base"/>
  <link name="arm"><inertial><origin rpy="0.3 -0.4 0.5"/><mass value="1"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.003"/></inertial></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/></joint>)"));
  std::vector<std::string> warnings;
  const sgal::Scene s = Import(urdf.file(), &warnings);
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Matrix3d d = Eigen::Vector3d(0.001, 0.002, 0.003).asDiagonal();
  const Eigen::Matrix3d expected = r * d * r.transpose();
  const Eigen::Matrix3d& got = BodyOf(s, "arm").inertia.tensor;
  EXPECT_LT((got - expected).norm(), 1e-15) << got;
  ASSERT_GT((r.transpose() * d * r - expected).norm(), 1e-4) << "the test would not see R^T I R";
  EXPECT_GT(std::abs(got(0, 1)), 1e-5);
}

TEST(UrdfImport, KeptFixedJointToTheWorldMakesAStaticBody) {
  Options o;
  o.merge_fixed_joints = false;
  std::vector<std::string> warnings;
  const sgal::Scene s = Import(kData + "/side.urdf", &warnings, o);
  EXPECT_EQ(BodyOf(s, "frame").type, sgal::BodyType::kStatic);
  EXPECT_EQ(BodyOf(s, "rod").type, sgal::BodyType::kDynamic);
}

TEST(UrdfImport, SizesNoBodyHasAreErrors) {
  for (const std::string geometry :
       {R"(<box size="-1 1 1"/>)", R"(<sphere radius="0"/>)",
        R"(<cylinder radius="0.1" length="-1"/>)", R"(<mesh filename="x.stl" scale="0 1 1"/>)",
        R"(<mesh filename="x.stl" scale="1e40 1 1"/>)"}) {
    const std::string message =
        ImportErrorOf("sizes", Robot(std::string(R"(<link name="base"><visual><geometry>)") +
                                     geometry + "</geometry></visual></link>"));
    EXPECT_NE(message.find("robot.urdf:2: link 'base': <visual> "), std::string::npos) << message;
    EXPECT_NE(message.find("sizes must be positive numbers"), std::string::npos) << message;
  }
}

TEST(UrdfImport, NegativeInertiaIsAnError) {
  const std::string message = ImportErrorOf("negative", Robot(R"(<link name="base"/>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="-0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/></joint>)"));
  EXPECT_NE(message.find(":3: link 'arm': inertia with a negative principal moment"),
            std::string::npos)
      << message;
}

TEST(UrdfImport, MimicCycleIsAnError) {
  const std::string message = ImportErrorOf("mimic", Robot(R"(<link name="base"/>
  )" + InertialLink("a") + R"(
  )" + InertialLink("b") + R"(
  <joint name="ja" type="continuous"><parent link="base"/><child link="a"/><mimic joint="jb"/></joint>
  <joint name="jb" type="continuous"><parent link="base"/><child link="b"/><mimic joint="ja"/></joint>)"));
  EXPECT_NE(message.find("the mimics form a cycle: "), std::string::npos) << message;
  EXPECT_NE(message.find("(line 5)"), std::string::npos) << message;
}

TEST(UrdfImport, WorldIsOnlyTheRoot) {
  const std::string message = ImportErrorOf("world", Robot(R"(<link name="base"/>
  )" + InertialLink("world") + R"(
  <joint name="j" type="continuous"><parent link="base"/><child link="world"/></joint>)"));
  EXPECT_NE(message.find(":3: link 'world': is the child of joint 'j'"), std::string::npos)
      << message;
  // what a world root carries is not loaded, and the warning says so
  const std::vector<std::string> warnings = ImportWarningsOf(
      "worldroot",
      Robot(
          R"(<link name="world"><collision><geometry><box size="10 10 0.1"/></geometry></collision></link>
  <link name="base"/>
  <joint name="j" type="fixed"><parent link="world"/><child link="base"/></joint>)"));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find(":2: link 'world': the root link 'world' is the world itself: its 0 "
                             "visual(s) and 1 collision(s) are not loaded"),
            std::string::npos)
      << warnings[0];
}

TEST(UrdfImport, UrdfdomErrorsGetTheElementsLine) {
  // a revolute joint without <limit>: urdfdom refuses it, naming the joint
  const std::string message = ImportErrorOf("nolimit", Robot(R"(<link name="base"/>
  )" + InertialLink("arm") + R"(
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/></joint>)"));
  EXPECT_NE(message.find("robot.urdf:4: joint 'hinge': liburdfdom cannot read it: "),
            std::string::npos)
      << message;
}

// Packages are found below a folder of the package path, as ROS finds them in a workspace
// (src/REPO/PKG/package.xml); a package not found names every folder searched.
TEST(UrdfMeshPaths, PackagesBelowTheFoldersOfThePathAndWhereItLooked) {
  TempUrdf ws(
      "ws",
      Robot(
          R"(<link name="base"><visual><geometry><mesh filename="package://deep_pkg/m/x.stl"/></geometry></visual></link>)"));
  const fs::path pkg = ws.dir() / "src" / "repo" / "deep_pkg";
  fs::create_directories(pkg / "m");
  std::ofstream(pkg / "package.xml") << "<package><name>deep_pkg</name></package>";
  fs::copy_file(kPackages + "/caliper_test_meshes/meshes/tetra_ascii.stl", pkg / "m" / "x.stl");
  Options o;
  o.package_path = {(ws.dir() / "src").string()};
  std::vector<std::string> warnings;
  const sgal::Scene s = Import(ws.file(), &warnings, o);
  EXPECT_EQ(BodyOf(s, "base").visuals.size(), 1u);
  o.package_path = {kPackages};
  const std::string message = ImportError(ws.file(), o);
  EXPECT_NE(message.find("(no package 'deep_pkg' in or below " + kPackages + ")"),
            std::string::npos)
      << message;
}

TEST(UrdfImport, SideFileChoosesHowTheUrdfIsRead) {
  TempUrdf urdf("sideopts", Robot(InertialLink("base") + "\n  " + InertialLink("cap") + R"(
  <joint name="j" type="fixed"><parent link="base"/><child link="cap"/></joint>)"));
  std::ofstream(urdf.dir() / "robot.caliper.xml")
      << R"(<caliper base="floating" fixed_joints="keep"/>)";
  std::vector<std::string> warnings;
  const sgal::Scene s = Import(urdf.file(), &warnings);
  EXPECT_EQ(BodyOf(s, "base").type, sgal::BodyType::kDynamic);
  EXPECT_EQ(JointOf(s, "j").kind, sgal::ConstraintKind::kFixed);
  std::ofstream(urdf.dir() / "robot.caliper.xml") << R"(<caliper fixed_joints="bogus"/>)";
  EXPECT_NE(ImportError(urdf.file()).find("robot.caliper.xml:1: <caliper>: fixed_joints=\"bogus\""),
            std::string::npos);
}

TEST(UrdfImport, FloatingBaseFromOptionsAndFromTheFile) {
  Options o = WithPackages();
  o.floating_base = true;
  std::vector<std::string> warnings;
  EXPECT_EQ(BodyOf(Import(kData + "/kinds.urdf", &warnings, o), "base").type,
            sgal::BodyType::kDynamic);
  // <caliper base="floating" fixed_joints="keep"> in the file says the same
  TempUrdf urdf("base", R"(<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="cap"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j" type="fixed"><parent link="base"/><child link="cap"/></joint>
  <caliper base="floating" fixed_joints="keep"/>
</robot>)");
  const sgal::Scene s = Import(urdf.file(), &warnings);
  EXPECT_EQ(BodyOf(s, "base").type, sgal::BodyType::kDynamic);
  EXPECT_EQ(JointOf(s, "j").kind, sgal::ConstraintKind::kFixed);
}

}  // namespace
}  // namespace caliper::urdf
