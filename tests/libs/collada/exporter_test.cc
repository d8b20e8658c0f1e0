// The COLLADA exporter: export -> import gives the same scene for every corpus file that imports
// and for the extension example; exported files pass the OpenCOLLADA schema validator.
#include "caliper/collada/exporter.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "caliper/collada/importer.h"
#include "comma_locale.h"
#include "corpus.h"
#include "scene_compare.h"

namespace caliper::collada {
namespace {

std::string Data(const std::string& name) {
  return std::string(CALIPER_COLLADA_TEST_DATA) + "/" + name;
}
std::string Corpus(const std::string& relative) {
  return testing::CorpusDir() + "/collada/" + relative;
}

// A scratch directory for the files a test writes, removed afterwards.
class ColladaExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() / ("caliper_collada_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Out(const std::string& name) const { return (dir_ / name).string(); }

  // Exports a scene and imports the file again; fails on a difference.
  void ExpectRoundTrip(const sgal::Scene& scene, const std::string& out) {
    ASSERT_NO_THROW(Export(scene, out));
    std::vector<std::string> warnings;
    sgal::Scene again;
    try {
      again = Import(out, &warnings);
    } catch (const ImportError& e) {
      FAIL() << "re-import failed: " << e.what();
    }
    for (const auto& w : warnings) ADD_FAILURE() << "re-import warns: " << w;
    testing::SceneComparison compare(1e-9);
    EXPECT_EQ(compare.Compare(scene, again), 0);
  }

  std::filesystem::path dir_;
};

// Runs opencolladavalidator on a file; "" when it passes, else its output.
std::string Validate(const std::string& file, const std::string& log) {
  const std::string command = "opencolladavalidator '" + file + "' > '" + log + "' 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  // it does not always exit non-zero on a schema error
  if (status == 0 && text.str().find("Schema validation error") == std::string::npos) return "";
  return "exit status " + std::to_string(status) + ": " + text.str().substr(0, 2000);
}

bool HaveValidator() {
  return std::system("command -v opencolladavalidator > /dev/null 2>&1") == 0;
}

TEST_F(ColladaExportTest, RoundTripsEveryCorpusFileThatImports) {
  CALIPER_REQUIRE_CORPUS();
  std::vector<std::string> files;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(testing::CorpusDir() + "/collada")) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".dae" || ext == ".zae"))
      files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  size_t round_tripped = 0;
  for (size_t i = 0; i < files.size(); ++i) {
    sgal::Scene scene;
    try {
      scene = Import(files[i], nullptr);
    } catch (const ImportError&) {
      continue;  // the importer test covers the files that do not import
    }
    SCOPED_TRACE(files[i]);
    ExpectRoundTrip(scene, Out("corpus" + std::to_string(i) + ".dae"));
    ++round_tripped;
  }
  std::cout << round_tripped << " corpus files round-tripped\n";
  EXPECT_EQ(round_tripped, files.size() - 2);
}

TEST_F(ColladaExportTest, RoundTripsTheExtensionExampleAndEveryTestFileThatImports) {
  size_t round_tripped = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CALIPER_COLLADA_TEST_DATA)) {
    sgal::Scene scene;
    try {
      scene = Import(entry.path().string(), nullptr);
    } catch (const ImportError&) {
      continue;  // the malformed_* files
    }
    SCOPED_TRACE(entry.path().string());
    ExpectRoundTrip(scene, Out(entry.path().filename().string()));
    ++round_tripped;
  }
  EXPECT_GE(round_tripped, 5u);  // caliper_arm, minimal, transforms, nonphysical_inertia, ...
}

TEST_F(ColladaExportTest, WritesDecimalPointsUnderACommaDecimalLocale) {
  // a Qt process under LANG=de_DE.UTF-8 exports: the file must read back the same in any locale
  const sgal::Scene scene = Import(Data("caliper_arm.dae"), nullptr);
  const std::string out = Out("german.dae");
  {
    CALIPER_COMMA_DECIMAL_LOCALE(locale);
    ASSERT_NO_THROW(Export(scene, out));
  }
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str().find("1,2"), std::string::npos) << "a decimal comma in the file";
  sgal::Scene again;
  ASSERT_NO_THROW(again = Import(out, nullptr));
  EXPECT_EQ(again.FindBody("forearm")->inertia.mass, 1.2);
  EXPECT_EQ(testing::SceneComparison(1e-9).Compare(scene, again), 0);
}

TEST_F(ColladaExportTest, RoundTripsEveryShapeKindConstraintKindAndBodyType) {
  sgal::Scene s;
  s.name = "all kinds";
  s.gravity = Eigen::Vector3d(0.1, -0.2, -9.7);
  s.settings = {2e-3, 37, 4.5};
  s.materials = {{"rubber", 1.1, 0.7}, {"steel", 0.3, 0.2}};
  auto mesh = std::make_shared<sgal::Mesh>();
  mesh->vertices = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}, {0, 0, 0.1f}};
  mesh->triangles = {{{0, 2, 1}}, {{0, 1, 3}}, {{0, 3, 2}}, {{1, 2, 3}}};
  const std::vector<sgal::Geometry> geometries = {sgal::Box{Eigen::Vector3d(0.1, 0.2, 0.3)},
                                                  sgal::Sphere{0.05},
                                                  sgal::Capsule{0.02, 0.1},
                                                  sgal::Cylinder{0.03, 0.2},
                                                  sgal::Cone{0.04, 0.12},
                                                  sgal::Plane{Eigen::Vector3d(0, 0.6, 0.8), -0.5},
                                                  sgal::ConvexHull{mesh},
                                                  sgal::TriangleMesh{mesh}};
  const sgal::BodyType types[3] = {sgal::BodyType::kDynamic, sgal::BodyType::kStatic,
                                   sgal::BodyType::kKinematic};
  for (size_t i = 0; i < geometries.size(); ++i) {
    sgal::Body b;
    b.name = "body " + std::to_string(i);  // not an XML id
    b.type = types[i % 3];
    b.pose.position = Eigen::Vector3d(0.1 * i, -0.2, 1.0 + 0.01 * i);
    b.pose.orientation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d(1, 2, 3).normalized()));
    b.inertia.mass = 0.5 + i;
    b.inertia.com = Eigen::Vector3d(0.01, -0.02, 0.03 * i);
    Eigen::Matrix3d r =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1, 0.2).normalized()).toRotationMatrix();
    b.inertia.tensor =
        r * Eigen::Vector3d(0.02, 0.03, 0.04 + 0.001 * i).asDiagonal() * r.transpose();
    sgal::Shape shape;
    shape.geometry = geometries[i];
    shape.pose.position = Eigen::Vector3d(0.01, 0.02, -0.03);
    shape.pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()));
    shape.material = i % 2 ? "rubber" : "steel";
    if (i == 3) {
      shape.group = 4;
      shape.mask = 5;
      shape.name = "named shape";
    }
    b.shapes.push_back(shape);
    if (i == 0) b.shapes.clear();  // a body without shapes
    sgal::Visual v;
    v.geometry = geometries[i];
    v.color = Eigen::Vector4f(0.1f * i, 0.5f, 0.25f, 1.0f);
    b.visuals.push_back(v);
    b.linear_velocity = Eigen::Vector3d(0.1, 0, -0.1 * i);
    b.angular_velocity = Eigen::Vector3d(0, 0.2 * i, 0);
    s.bodies.push_back(b);
  }
  const sgal::ConstraintKind kinds[5] = {
      sgal::ConstraintKind::kHinge, sgal::ConstraintKind::kSlider, sgal::ConstraintKind::kBall,
      sgal::ConstraintKind::kFixed, sgal::ConstraintKind::kGeneric6Dof};
  for (int i = 0; i < 7; ++i) {
    sgal::Constraint c;
    c.name = "joint " + std::to_string(i);
    c.kind = kinds[i % 5];
    c.body_a = s.bodies[i].name;
    c.body_b = i == 5 ? "" : s.bodies[i + 1].name;
    c.frame_a.position = Eigen::Vector3d(0.01 * i, 0.02, 0.03);
    c.frame_a.orientation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitX()));
    c.frame_b.position = Eigen::Vector3d(-0.01, 0.0, 0.05);
    c.collide_connected = i % 2 == 1;
    c.limits[0] = {-0.5, 0.25 * i};
    c.springs[0] = {10.0 + i, 0.5, 0.1};
    c.friction[0] = 0.05 * (i + 1);  // [N m] or [N]
    if (c.kind == sgal::ConstraintKind::kGeneric6Dof) {
      c.friction[4] = 0.7;
      for (int k = 1; k < 6; ++k)
        c.limits[k] = k % 2 ? sgal::Limit{-0.1 * k, 0.2 * k} : sgal::Limit{};
      c.springs[4] = {3, 0.2, -0.3};
    }
    s.constraints.push_back(c);
  }
  s.couplings.push_back({"joint 0", "joint 5", -0.5, 0.25});
  s.obstacles.push_back(
      {"pulley", "body 2", sgal::ObstacleKind::kCylinder, s.bodies[2].pose, 0.02, 0.04});
  s.obstacles.push_back({"ball", "", sgal::ObstacleKind::kSphere, sgal::Pose(), 0.03, 0.0});
  sgal::Tendon t;
  t.name = "tendon";
  t.radius = 0.002;
  t.collide_with_bodies = false;
  sgal::PathElement p;
  p.body = "body 1";
  p.position = Eigen::Vector3d(0.01, 0.02, 0.03);
  t.path.push_back(p);
  p.body = "";
  p.friction = 0.2;
  t.path.push_back(p);
  sgal::PathElement w;
  w.kind = sgal::PathElement::Kind::kWrap;
  w.obstacle = "pulley";
  w.side = Eigen::Vector3d(0, 0.05, 0);
  t.path.push_back(w);
  p.body = "body 4";
  p.friction = 0;
  t.path.push_back(p);
  s.tendons.push_back(t);
  sgal::Actuator a;
  a.name = "motor";
  a.kind = "dc_motor_tendon";
  a.tendon = "tendon";
  a.parameters = {
      {"resistance", 0.8}, {"spool_radius", 0.006}, {"rotor_inertia", 2e-7}, {"gear_ratio", 53}};
  a.options = {{"elastic", "zener"}};
  s.actuators.push_back(a);
  ASSERT_TRUE(sgal::Validate(s).empty()) << sgal::Validate(s).front();
  ExpectRoundTrip(s, Out("kinds.dae"));
  if (HaveValidator()) {
    EXPECT_EQ(Validate(Out("kinds.dae"), Out("kinds.log")), "");
  }
}

TEST_F(ColladaExportTest, ExportedFilesPassTheSchemaValidator) {
  if (!HaveValidator())
    GTEST_SKIP() << "opencolladavalidator not found (Debian package opencollada-tools)";
  std::vector<std::string> sources = {Data("caliper_arm.dae")};
  if (!testing::CorpusDir().empty()) {
    for (const char* f :
         {"collada_robots/unimation-pumaarm.dae", "bullet3/Havok5.5toColladaPhysics.dae",
          "bullet3/friction.dae", "khronos_cts_1.5/instance_kinematics_scene.dae",
          "khronos_cts_1.4.1/concave_polygons.dae"})
      sources.push_back(Corpus(f));
  }
  for (size_t i = 0; i < sources.size(); ++i) {
    SCOPED_TRACE(sources[i]);
    const std::string out = Out("valid" + std::to_string(i) + ".dae");
    Export(Import(sources[i], nullptr), out);
    EXPECT_EQ(Validate(out, Out("valid.log")), "");
  }
  // the example itself is valid COLLADA too
  EXPECT_EQ(Validate(Data("caliper_arm.dae"), Out("example.log")), "");
}

TEST_F(ColladaExportTest, KeepsMeasurementDelaysThroughImportExportImport) {
  const sgal::Scene first = Import(Data("measurement_delays.dae"), nullptr);
  ASSERT_EQ(first.measurement_delays.size(), 2u);
  ExpectRoundTrip(first, Out("delays.dae"));
  const sgal::Scene again = Import(Out("delays.dae"), nullptr);
  ASSERT_EQ(again.measurement_delays.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(again.measurement_delays[i].id, first.measurement_delays[i].id);
    // written in seconds with a shortest round-trip form: the same double
    EXPECT_EQ(again.measurement_delays[i].delay, first.measurement_delays[i].delay);
  }
  std::ifstream in(Out("delays.dae"));
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("<measurement_delay channel=\"line.tendon.tension\" delay=\"0.004\" "
                            "unit=\"s\"/>"),
            std::string::npos)
      << text.str().substr(text.str().rfind("<technique profile=\"CALIPER\">"));
}

TEST_F(ColladaExportTest, RejectsAnUnknownActuatorKind) {
  sgal::Scene s = Import(Data("minimal.dae"), nullptr);
  s.actuators[0].kind = "steam_engine";
  try {
    Export(s, Out("bad.dae"));
    FAIL() << "exported an unknown kind";
  } catch (const ExportError& e) {
    EXPECT_NE(std::string(e.what()).find("steam_engine"), std::string::npos) << e.what();
  }
}

TEST_F(ColladaExportTest, FailsNamingTheFileItCannotWrite) {
  const sgal::Scene s = Import(Data("minimal.dae"), nullptr);
  try {
    Export(s, "/nonexistent/dir/out.dae");
    FAIL() << "wrote into a missing directory";
  } catch (const ExportError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/out.dae"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace caliper::collada
