// The COLLADA importer: every corpus file imports or fails naming the file; units, axes, robots,
// couplings, constraints and materials of chosen corpus files; every error path on a small file
// of its own; the Caliper extension.
#include "caliper/collada/importer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "comma_locale.h"
#include "corpus.h"
#include "scene_compare.h"

namespace caliper::collada {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Data(const std::string& name) {
  return std::string(CALIPER_COLLADA_TEST_DATA) + "/" + name;
}
std::string Corpus(const std::string& relative) {
  return testing::CorpusDir() + "/collada/" + relative;
}

// Every .dae and .zae under the corpus's collada folder, sorted.
std::vector<std::string> CorpusFiles() {
  std::vector<std::string> files;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(testing::CorpusDir() + "/collada")) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".dae" || ext == ".zae"))
      files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The scene of a file that must import (the test fails with the importer's message otherwise).
sgal::Scene Load(const std::string& path, std::vector<std::string>* warnings = nullptr) {
  try {
    return Import(path, warnings);
  } catch (const ImportError& e) {
    ADD_FAILURE() << "import failed: " << e.what();
  }
  return sgal::Scene();
}

// The message of the ImportError a file must raise ("" and a failure when it imports).
std::string ErrorOf(const std::string& path) {
  try {
    Import(path, nullptr);
  } catch (const ImportError& e) {
    return e.what();
  }
  ADD_FAILURE() << path << " imported; an ImportError was expected";
  return "";
}

size_t Count(const sgal::Scene& s, sgal::ConstraintKind kind) {
  return std::count_if(s.constraints.begin(), s.constraints.end(),
                       [&](const sgal::Constraint& c) { return c.kind == kind; });
}

size_t CountLimited(const sgal::Scene& s) {
  return std::count_if(s.constraints.begin(), s.constraints.end(),
                       [](const sgal::Constraint& c) { return c.limits[0].enabled(); });
}

// World-frame bounds of every shape vertex of a scene.
Eigen::AlignedBox3d ShapeBounds(const sgal::Scene& s) {
  Eigen::AlignedBox3d box;
  for (const auto& b : s.bodies)
    for (const auto& shape : b.shapes) {
      const auto* mesh = std::get_if<sgal::TriangleMesh>(&shape.geometry);
      if (mesh == nullptr) continue;
      for (const auto& v : mesh->mesh->vertices)
        box.extend(b.pose.Apply(shape.pose.Apply(v.cast<double>())));
    }
  return box;
}

bool Contains(const std::vector<std::string>& lines, const std::string& part) {
  return std::any_of(lines.begin(), lines.end(),
                     [&](const std::string& l) { return l.find(part) != std::string::npos; });
}

TEST(ColladaImportTest, EveryCorpusFileImportsOrFailsNamingTheFile) {
  CALIPER_REQUIRE_CORPUS();
  const auto files = CorpusFiles();
  EXPECT_EQ(files.size(), 60u);
  std::set<std::string> failed;
  size_t imported = 0;
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    try {
      std::vector<std::string> warnings;
      const sgal::Scene s = Import(f, &warnings);
      EXPECT_TRUE(sgal::Validate(s).empty());
      ++imported;
    } catch (const ImportError& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
      failed.insert(f.substr(testing::CorpusDir().size() + 9));
      std::cout << "fails: " << e.what() << "\n";
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an ImportError: " << e.what();
    }
  }
  std::cout << imported << " of " << files.size() << " corpus files import, " << failed.size()
            << " fail\n";
  EXPECT_EQ(failed.count("collada_dom/1.4_badFile.dae"), 1u);
  EXPECT_EQ(failed.count("khronos_cts_1.5/kinematics_model_link_formula.dae"), 1u);
  EXPECT_EQ(failed.size(), 2u) << "only the two broken files should fail";
}

TEST(ColladaImportTest, BrokenCorpusFilesSayWhatIsWrongAndWhere) {
  CALIPER_REQUIRE_CORPUS();
  // libxml2's own reasons, at the line where it found the problem
  const std::string bad = ErrorOf(Corpus("collada_dom/1.4_badFile.dae"));
  // truncated after </asset>
  EXPECT_NE(bad.find("1.4_badFile.dae:13: malformed XML: Premature end of data in tag COLLADA "
                     "line 7"),
            std::string::npos)
      << bad;
  const std::string formula = ErrorOf(Corpus("khronos_cts_1.5/kinematics_model_link_formula.dae"));
  EXPECT_NE(formula.find("kinematics_model_link_formula.dae:102: malformed XML: Opening and ending "
                         "tag mismatch: instance_formula line 101 and technique_common"),
            std::string::npos)
      << formula;
}

TEST(ColladaImportTest, ScalesByUnitMeterNotByName) {
  CALIPER_REQUIRE_CORPUS();
  // a quad of +-3.2808 ft (+-39.3701 in) under a 0.75 scale: +-0.75 m either way
  for (const char* f :
       {"khronos_cts_1.4.1/asset_unit_foot.dae", "khronos_cts_1.4.1/asset_unit_inch.dae",
        "khronos_cts_1.5/asset_unit_foot.dae"}) {
    SCOPED_TRACE(f);
    const auto box = ShapeBounds(Load(Corpus(f)));
    EXPECT_NEAR(box.max().x(), 0.75, 1e-4);
    EXPECT_NEAR(box.min().x(), -0.75, 1e-4);
    EXPECT_NEAR(box.max().z(), 0.75, 1e-4);
    // Y_UP: the quad at y = +0.75 ft*... faces up, and lies at -0.75 on Z-up's y
    EXPECT_NEAR(box.min().y(), -0.75, 1e-4);
    EXPECT_NEAR(box.max().y(), -0.75, 1e-4);
  }
  // meter="1" name="centimeter": metres
  const sgal::Scene seymour = Load(Corpus("bullet3/seymourplane_triangulate.dae"));
  EXPECT_GT(ShapeBounds(seymour).sizes().maxCoeff(), 10.0);
}

TEST(ColladaImportTest, ReportsTheFilesVersionUnitAndUpAxis) {
  FileInfo info;
  Import(Data("caliper_arm.dae"), nullptr, &info);
  EXPECT_EQ(info.version, "1.5.0");
  EXPECT_FALSE(info.zipped);
  EXPECT_EQ(info.meter, 1.0);
  EXPECT_EQ(info.unit_name, "meter");
  EXPECT_EQ(info.up_axis, "Z_UP");
  EXPECT_EQ(info.authoring_tool, "hand written");
  // filled as far as it was read when the import fails
  EXPECT_THROW(Import(Data("malformed_negative_mass.dae"), nullptr, &info), ImportError);
  EXPECT_EQ(info.up_axis, "Z_UP");
  CALIPER_REQUIRE_CORPUS();
  Import(Corpus("khronos_cts_1.4.1/asset_unit_foot.dae"), nullptr, &info);
  EXPECT_EQ(info.version, "1.4.1");
  EXPECT_EQ(info.meter, 0.3048);
  EXPECT_EQ(info.unit_name, "foot");
  EXPECT_EQ(info.up_axis, "Y_UP");
  Import(Corpus("collada_robots/willowgarage-pr2.zae"), nullptr, &info);
  EXPECT_TRUE(info.zipped);
}

TEST(ColladaImportTest, TurnsXUpToZUp) {
  CALIPER_REQUIRE_CORPUS();
  // a cone with its apex at x = 150 in and its base at x = -75 in
  const auto box = ShapeBounds(Load(Corpus("khronos_cts_1.4.1/asset_up_axis_x_up.dae")));
  // (mesh vertices are floats)
  EXPECT_NEAR(box.max().z(), 150 * 0.0254, 1e-6);
  EXPECT_NEAR(box.min().z(), -75 * 0.0254, 1e-6);
  EXPECT_NEAR(box.max().y(), 50 * 0.0254, 1e-6);
  EXPECT_NEAR(box.max().x(), 50 * 0.0254, 1e-6);
}

TEST(ColladaImportTest, TurnsYUpGravityInCentimetresToZUpSi) {
  CALIPER_REQUIRE_CORPUS();
  for (const char* f : {"collada_dom/1.4_Seymour.dae", "collada_dom/1.5_Seymour.dae"}) {
    SCOPED_TRACE(f);
    std::vector<std::string> warnings;
    const sgal::Scene s = Load(Corpus(f), &warnings);
    EXPECT_NEAR(s.gravity.x(), 0, 1e-12);
    EXPECT_NEAR(s.gravity.y(), 0, 1e-12);
    EXPECT_NEAR(s.gravity.z(), -9.8, 1e-12);
    EXPECT_DOUBLE_EQ(s.settings.time_step, 0.083);
    // no rigid bodies: static bodies made from the nodes, with a warning
    EXPECT_TRUE(Contains(warnings, "no rigid bodies")) << warnings.size();
    ASSERT_FALSE(s.bodies.empty());
    for (const auto& b : s.bodies) EXPECT_EQ(b.type, sgal::BodyType::kStatic);
  }
}

struct Robot {
  const char* file;
  size_t bodies;
  size_t joints;
  size_t limited;  // joints with limits (the PR2's wheels and rolling joints turn freely)
};

TEST(ColladaImportTest, ReadsTheRobotsBodiesAndJoints) {
  CALIPER_REQUIRE_CORPUS();
  const Robot robots[] = {{"collada_robots/unimation-pumaarm.dae", 7, 6, 6},
                          {"collada_robots/unimation-pumaarm.zae", 7, 6, 6},
                          {"collada_robots/barrett-wam.dae", 8, 7, 7},
                          {"collada_robots/kuka-kr5-r650.dae", 7, 6, 6},
                          {"collada_robots/romela-darwin-op.dae", 21, 20, 20},
                          {"collada_robots/barrett-hand.zae", 9, 8, 8},
                          {"collada_robots/shadow-hand.zae", 23, 22, 22},
                          {"collada_robots/willowgarage-pr2.zae", 88, 87, 68}};
  for (const Robot& r : robots) {
    SCOPED_TRACE(r.file);
    const sgal::Scene s = Load(Corpus(r.file));
    EXPECT_EQ(s.bodies.size(), r.bodies);
    EXPECT_EQ(s.constraints.size(), r.joints);
    EXPECT_EQ(Count(s, sgal::ConstraintKind::kHinge) + Count(s, sgal::ConstraintKind::kSlider),
              r.joints);
    EXPECT_EQ(CountLimited(s), r.limited);
    size_t drawn = 0;
    for (const auto& b : s.bodies) drawn += !b.shapes.empty() && !b.visuals.empty();
    // the PR2 has frames without geometry (cameras, projectors)
    if (r.bodies < 88) {
      EXPECT_EQ(drawn, r.bodies);
    }
  }
  const sgal::Scene puma = Load(Corpus("collada_robots/unimation-pumaarm.dae"));
  EXPECT_EQ(Count(puma, sgal::ConstraintKind::kHinge), 6u);
  EXPECT_EQ(CountLimited(puma), 6u);
  // J1 turns from -223 to 43 degrees
  const auto j1 = std::find_if(puma.constraints.begin(), puma.constraints.end(),
                               [](const auto& c) { return c.name == "J1"; });
  ASSERT_NE(j1, puma.constraints.end());
  EXPECT_NEAR(j1->limits[0].lower, -223 * kPi / 180, 1e-12);
  EXPECT_NEAR(j1->limits[0].upper, 43 * kPi / 180, 1e-12);
  EXPECT_EQ(j1->body_a, "Puma1");
  EXPECT_EQ(j1->body_b, "Puma2");
  // the frames of both sides coincide in the world at the initial pose
  const auto* a = puma.FindBody(j1->body_a);
  const auto* b = puma.FindBody(j1->body_b);
  EXPECT_LT(((a->pose * j1->frame_a).position - (b->pose * j1->frame_b).position).norm(), 1e-9);
  EXPECT_LT(
      (a->pose * j1->frame_a).orientation.angularDistance((b->pose * j1->frame_b).orientation),
      1e-9);
  // OpenRAVE gives shapes and mass frames in the robot's base frame: in the body frame here
  const auto* puma1 = puma.FindBody("Puma1");
  EXPECT_LT(puma1->shapes[0].pose.position.norm(), 1e-9);
  EXPECT_NEAR(puma1->inertia.com.y(), 0.05, 1e-12);
  EXPECT_NEAR(puma1->inertia.mass, 17.4, 1e-12);
}

TEST(ColladaImportTest, CouplesTheShadowHandsJointsByItsFormulas) {
  CALIPER_REQUIRE_CORPUS();
  const sgal::Scene s = Load(Corpus("collada_robots/shadow-hand.zae"));
  EXPECT_EQ(s.bodies.size(), 23u);
  EXPECT_EQ(s.couplings.size(), 9u);
  for (const auto& c : s.couplings) {
    EXPECT_DOUBLE_EQ(c.ratio, 1.0) << c.follower;
    EXPECT_DOUBLE_EQ(c.offset, 0.0) << c.follower;
    EXPECT_NE(c.leader, c.follower);
  }
  const sgal::Scene barrett = Load(Corpus("collada_robots/barrett-hand.zae"));
  EXPECT_EQ(barrett.bodies.size(), 9u);
  ASSERT_EQ(barrett.couplings.size(), 4u);
  EXPECT_NEAR(barrett.couplings[0].ratio, 0.333333, 1e-12);
  EXPECT_NEAR(barrett.couplings[0].offset, 0.8727, 1e-12);
}

TEST(ColladaImportTest, ReadsHavokConstraintsToTheWorld) {
  CALIPER_REQUIRE_CORPUS();
  std::vector<std::string> warnings;
  const sgal::Scene s = Load(Corpus("bullet3/Havok5.5toColladaPhysics.dae"), &warnings);
  EXPECT_EQ(s.bodies.size(), 7u);
  ASSERT_EQ(s.constraints.size(), 2u);
  // two constraints share a sid; names stay unique
  EXPECT_NE(s.constraints[0].name, s.constraints[1].name);
  for (const auto& c : s.constraints) {
    // x rotates freely (min 1 > max -1), everything else is locked: a free hinge to the world
    EXPECT_EQ(c.kind, sgal::ConstraintKind::kHinge) << c.name;
    EXPECT_TRUE(c.body_b.empty()) << c.name;
    EXPECT_FALSE(c.limits[0].enabled());
    EXPECT_FALSE(c.collide_connected);
    const auto* body = s.FindBody(c.body_a);
    ASSERT_NE(body, nullptr);
    EXPECT_LT(((body->pose * c.frame_a).position - c.frame_b.position).norm(), 1e-9);
  }
  // gravity 0 -10 0 in a Y-up file
  EXPECT_NEAR(s.gravity.z(), -10, 1e-12);
  EXPECT_EQ(s.materials.size(), 7u);
}

TEST(ColladaImportTest, ReadsPhysicsMaterials) {
  CALIPER_REQUIRE_CORPUS();
  const sgal::Scene s = Load(Corpus("bullet3/friction.dae"));
  ASSERT_EQ(s.materials.size(), 2u);
  for (const auto& m : s.materials) {
    EXPECT_DOUBLE_EQ(m.friction, 0.2) << m.name;
    EXPECT_DOUBLE_EQ(m.restitution, 0.6) << m.name;
  }
  ASSERT_EQ(s.bodies.size(), 2u);
  EXPECT_EQ(s.bodies[0].type, sgal::BodyType::kDynamic);
  EXPECT_EQ(s.bodies[1].type, sgal::BodyType::kStatic);
  for (const auto& b : s.bodies) {
    ASSERT_FALSE(b.shapes.empty());
    EXPECT_FALSE(b.shapes[0].material.empty());
  }
  // gravity 0 -9.81 0 in centimetres per second squared
  EXPECT_NEAR(s.gravity.z(), -0.0981, 1e-12);
}

TEST(ColladaImportTest, TriangulatesConcavePolygonsAndStrips) {
  CALIPER_REQUIRE_CORPUS();
  for (const char* f :
       {"khronos_cts_1.4.1/concave_polygons.dae", "debian_pkgs/ConcavePolygon.dae",
        "debian_pkgs/cube_tristrips.dae", "khronos_cts_1.4.1/polygons_polylist_triangles.dae"}) {
    SCOPED_TRACE(f);
    std::vector<std::string> warnings;
    const sgal::Scene s = Load(Corpus(f), &warnings);
    size_t triangles = 0;
    for (const auto& b : s.bodies)
      for (const auto& v : b.visuals)
        if (const auto* m = std::get_if<sgal::TriangleMesh>(&v.geometry))
          triangles += m->mesh->triangles.size();
    EXPECT_GT(triangles, 0u);
    EXPECT_FALSE(Contains(warnings, "could not be ear-clipped"));
  }
  // a cube as strips: 12 triangles
  const sgal::Scene cube = Load(Corpus("debian_pkgs/cube_tristrips.dae"));
  size_t triangles = 0;
  for (const auto& b : cube.bodies)
    for (const auto& shape : b.shapes)
      if (const auto* m = std::get_if<sgal::TriangleMesh>(&shape.geometry))
        triangles += m->mesh->triangles.size();
  EXPECT_EQ(triangles, 12u);
}

TEST(ColladaImportTest, InstancesANodeOnceForEachInstanceNode) {
  CALIPER_REQUIRE_CORPUS();
  const sgal::Scene s = Load(Corpus("khronos_cts_1.4.1/instances_of_same_node.dae"));
  std::set<std::string> names;
  for (const auto& b : s.bodies) names.insert(b.name);
  EXPECT_EQ(names.size(), s.bodies.size());
  EXPECT_GE(s.bodies.size(), 4u);
}

TEST(ColladaImportTest, BindsKinematicsJointsToVisualNodes) {
  CALIPER_REQUIRE_CORPUS();
  const sgal::Scene s = Load(Corpus("khronos_cts_1.5/instance_kinematics_scene.dae"));
  // a prismatic joint and two revolute ones, limits in millimetres and degrees
  EXPECT_EQ(Count(s, sgal::ConstraintKind::kSlider), 1u);
  EXPECT_EQ(Count(s, sgal::ConstraintKind::kHinge), 2u);
  for (const auto& c : s.constraints) {
    ASSERT_TRUE(c.limits[0].enabled()) << c.name;
    const double range = c.limits[0].upper - c.limits[0].lower;
    EXPECT_NEAR(range, c.kind == sgal::ConstraintKind::kSlider ? 0.5 : 30 * kPi / 180, 1e-12)
        << c.name;
  }
}

TEST(ColladaImportTest, AppliesEveryNodeTransform) {
  std::vector<std::string> warnings;
  const sgal::Scene s = Load(Data("transforms.dae"), &warnings);
  // the world positions of the triangle (0 0 0, 1 0 0, 0 1 0) under each node's transform
  const std::map<std::string, std::array<Eigen::Vector3d, 3>> expected = {
      {"moved", {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 3, 3), Eigen::Vector3d(0, 2, 3)}},
      {"matrix", {Eigen::Vector3d(4, 5, 6), Eigen::Vector3d(4, 6, 6), Eigen::Vector3d(3, 5, 6)}},
      {"looking",
       {Eigen::Vector3d(0, -5, 0), Eigen::Vector3d(1, -5, 0), Eigen::Vector3d(0, -5, 1)}},
      {"skewed", {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(0, 1, 0)}},
      {"scaled", {Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(2, 0, -1), Eigen::Vector3d(0, 3, -1)}},
      {"shared",
       {Eigen::Vector3d(-10, 0, 0), Eigen::Vector3d(-9, 0, 0), Eigen::Vector3d(-10, 1, 0)}},
      {"shared_2",
       {Eigen::Vector3d(10, 0, 0), Eigen::Vector3d(11, 0, 0), Eigen::Vector3d(10, 1, 0)}}};
  ASSERT_EQ(s.bodies.size(), expected.size());
  for (const auto& [name, points] : expected) {
    SCOPED_TRACE(name);
    const sgal::Body* b = s.FindBody(name);
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->type, sgal::BodyType::kStatic);
    ASSERT_EQ(b->shapes.size(), 1u);
    ASSERT_EQ(b->visuals.size(), 1u);
    const auto& mesh = std::get<sgal::TriangleMesh>(b->shapes[0].geometry).mesh;
    ASSERT_EQ(mesh->vertices.size(), 3u);
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d world =
          b->pose.Apply(b->shapes[0].pose.Apply(mesh->vertices[i].cast<double>()));
      EXPECT_LT((world - points[i]).norm(), 1e-6) << i << ": " << world.transpose();
    }
  }
}

TEST(ColladaImportTest, RejectsMalformedFilesNamingFileLineElementAndProblem) {
  struct Case {
    const char* file;
    std::vector<const char*> parts;
  };
  const std::vector<Case> cases = {
      {"malformed_xml.dae", {"malformed_xml.dae:40:", "malformed XML", "translate"}},
      {"malformed_version.dae", {"malformed_version.dae", "1.3.0", "not supported"}},
      {"malformed_dangling_geometry.dae",
       {"malformed_dangling_geometry.dae:37:", "instance_geometry", "#no_such_geometry"}},
      {"malformed_dangling_rigid_body.dae",
       {"malformed_dangling_rigid_body.dae:", "instance_rigid_body",
        "no rigid body 'no_such_body'"}},
      {"malformed_dangling_constraint.dae",
       {"malformed_dangling_constraint.dae:", "attachment", "no_such_body"}},
      {"malformed_zero_mass.dae",
       {"malformed_zero_mass.dae:56:", "rigid_body 'link'", "mass 0", "positive mass"}},
      {"malformed_negative_mass.dae",
       {"malformed_negative_mass.dae:56:", "rigid_body 'link'", "mass -2.5"}},
      {"malformed_negative_inertia.dae",
       {"malformed_negative_inertia.dae:56:", "rigid_body 'link'", "not positive definite"}},
      {"malformed_tendon_one_point.dae",
       {"malformed_tendon_one_point.dae:", "tendon 'line'", "at least two points"}},
      {"malformed_unknown_kind.dae",
       {"malformed_unknown_kind.dae:", "actuator 'spring'",
        "unknown actuator kind 'pneumatic_muscle'"}},
      {"malformed_missing_parameter.dae",
       {"malformed_missing_parameter.dae:", "actuator 'spring'",
        "missing required parameter 'stiffness'"}},
      {"malformed_unknown_unit.dae",
       {"malformed_unknown_unit.dae:", "param 'stiffness'", "unknown unit 'lbf/furlong'"}},
      {"malformed_wrong_unit.dae",
       {"malformed_wrong_unit.dae:", "unit 'mm' does not fit parameter 'stiffness'"}},
      {"malformed_unknown_parameter.dae",
       {"malformed_unknown_parameter.dae:", "unknown parameter 'stifness'"}},
      {"malformed_dangling_tendon_body.dae",
       {"malformed_dangling_tendon_body.dae:", "unknown body 'no_such_body'"}},
      {"malformed_negative_friction.dae",
       {"malformed_negative_friction.dae:86:", "friction", "-0.5",
        "(N or N m) must be finite and not negative"}},
      {"malformed_measurement_delay.dae",
       {"malformed_measurement_delay.dae:107:", "measurement_delay", "channel 'hinge.position'",
        "delay=\"-2\" must be finite and not negative"}},
      {"malformed_measurement_delay_unit.dae",
       {"malformed_measurement_delay_unit.dae:107:", "measurement_delay",
        "unit 'mm' is not a time"}},
      {"no_such_file.dae", {"no_such_file.dae", "cannot open"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string message = ErrorOf(Data(c.file));
    for (const char* part : c.parts)
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  }
}

TEST(ColladaImportTest, RejectsAWordThatIsNotANumberInANumericList) {
  // Collada-DOM read `0.1 abc 0` as three numbers, one of them made up, and said nothing
  const std::string floats = ErrorOf(Data("malformed_float_array_word.dae"));
  EXPECT_NE(floats.find("malformed_float_array_word.dae:14: float_array 'tri-positions-array': "
                        "'abc' is not a number (value 5 of the list)"),
            std::string::npos)
      << floats;
  const std::string indices = ErrorOf(Data("malformed_p_word.dae"));
  EXPECT_NE(indices.find("malformed_p_word.dae:28: p: 'two' is not an integer (value 3 of the "
                         "list)"),
            std::string::npos)
      << indices;
  const std::string fraction = ErrorOf(Data("malformed_p_fraction.dae"));
  EXPECT_NE(fraction.find("malformed_p_fraction.dae:28: p: '1.5' is not an integer"),
            std::string::npos)
      << fraction;
}

TEST(ColladaImportTest, RejectsAnElementInsideOneOfItsOwnNameBeforeTheDomCrashes) {
  // Collada-DOM dereferenced a null pointer on <p><p/></p> (found by fuzzing)
  const std::string message = ErrorOf(Data("malformed_p_inside_p.dae"));
  EXPECT_NE(message.find("malformed_p_inside_p.dae:28: <p> inside <p>: COLLADA does not nest "
                         "this element in itself"),
            std::string::npos)
      << message;
}

TEST(ColladaImportTest, ReadsAFileAgainAfterItChanged) {
  // the DOM's DAE is kept between imports (one per schema version): each import must read the
  // file as it is now, not the document the DAE read before from the same path
  const std::string path = std::filesystem::temp_directory_path().string() + "/changing.dae";
  std::filesystem::copy_file(Data("minimal.dae"), path,
                             std::filesystem::copy_options::overwrite_existing);
  EXPECT_EQ(Load(path).bodies.size(), 2u);
  std::filesystem::copy_file(Data("malformed_negative_mass.dae"), path,
                             std::filesystem::copy_options::overwrite_existing);
  EXPECT_NE(ErrorOf(path).find("mass -2.5"), std::string::npos);
  std::filesystem::copy_file(Data("minimal.dae"), path,
                             std::filesystem::copy_options::overwrite_existing);
  EXPECT_EQ(Load(path).bodies.size(), 2u);
  std::remove(path.c_str());
}

TEST(ColladaImportTest, NamesLinesBeyondSixteenBits) {
  // libxml2's nodes keep 16-bit lines: a long file (a large mesh before the physics) still
  // names the right one, for the elements and for malformed XML
  std::ifstream in(Data("malformed_zero_mass.dae"));
  std::stringstream text;
  text << in.rdbuf();
  std::string file = text.str();
  file.insert(file.find('\n') + 1, std::string(70000, '\n'));
  const std::string dir = std::filesystem::temp_directory_path().string();
  const std::string long_file = dir + "/zero_mass_long.dae";
  std::ofstream(long_file) << file;
  const std::string zero_mass = ErrorOf(long_file);
  EXPECT_NE(zero_mass.find("zero_mass_long.dae:70056: rigid_body 'link'"), std::string::npos)
      << zero_mass;
  const std::string broken_file = dir + "/broken_long.dae";
  std::ofstream(broken_file) << file.substr(0, file.rfind("</COLLADA>"));
  const std::string broken = ErrorOf(broken_file);
  EXPECT_NE(broken.find("broken_long.dae:"), std::string::npos) << broken;
  EXPECT_NE(broken.find(": malformed XML: Premature end of data in tag COLLADA line 70003"),
            std::string::npos)
      << broken;
  std::remove(long_file.c_str());
  std::remove(broken_file.c_str());
}

TEST(ColladaImportTest, AFindingAboutAHugeNameIsReportedNotACrash) {
  // the finding "tendon 'NAME' ..." is matched to its element; with std::regex a name of 200 KB
  // overflowed the stack (libstdc++ recurses per character)
  std::ifstream in(Data("malformed_tendon_one_point.dae"));
  std::stringstream text;
  text << in.rdbuf();
  std::string file = text.str();
  const std::string name(200000, 'n');
  for (size_t at = file.find("\"line\""); at != std::string::npos;
       at = file.find("\"line\"", at + name.size()))
    file.replace(at, 6, "\"" + name + "\"");
  const std::string path = std::filesystem::temp_directory_path().string() + "/huge_name.dae";
  std::ofstream(path) << file;
  const std::string message = ErrorOf(path);
  EXPECT_NE(message.find("at least two points"), std::string::npos) << message.substr(0, 300);
  EXPECT_NE(message.find("huge_name.dae:100:"), std::string::npos) << message.substr(0, 300);
  std::remove(path.c_str());
}

TEST(ColladaImportTest, ImportsTheMinimalSceneTheMalformedFilesBreak) {
  std::vector<std::string> warnings;
  const sgal::Scene s = Load(Data("minimal.dae"), &warnings);
  ASSERT_EQ(s.bodies.size(), 2u);
  ASSERT_EQ(s.constraints.size(), 1u);
  EXPECT_EQ(s.constraints[0].kind, sgal::ConstraintKind::kHinge);
  EXPECT_NEAR(s.constraints[0].limits[0].upper, kPi / 4, 1e-12);
  ASSERT_EQ(s.actuators.size(), 1u);
  EXPECT_DOUBLE_EQ(s.actuators[0].parameters.at("stiffness"), 1000);  // 1 N/mm
  EXPECT_TRUE(warnings.empty()) << warnings.front();
}

TEST(ColladaImportTest, RaisesMomentsThatViolateTheTriangleInequalityWithAWarning) {
  std::vector<std::string> warnings;
  const sgal::Scene s = Load(Data("nonphysical_inertia.dae"), &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("nonphysical_inertia.dae:60: inertia"), std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[0].find("triangle inequality"), std::string::npos) << warnings[0];
  // 0.01 0.01 0.05: the two small moments grow to 0.025 each
  const auto* link = s.FindBody("link");
  ASSERT_NE(link, nullptr);
  EXPECT_NEAR(link->inertia.tensor(0, 0), 0.025, 1e-15);
  EXPECT_NEAR(link->inertia.tensor(1, 1), 0.025, 1e-15);
  EXPECT_NEAR(link->inertia.tensor(2, 2), 0.05, 1e-15);
}

TEST(ColladaImportTest, WarnsAboutAnUnknownElementOfTheTechniqueWithItsLine) {
  std::vector<std::string> warnings;
  Load(Data("extension_unknown_element.dae"), &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("extension_unknown_element.dae:107:"), std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[0].find("<muscle_synergy>"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("line 107"), std::string::npos) << warnings[0];
}

TEST(ColladaImportTest, WarnsAboutALengthWithoutUnitInAMillimetreFile) {
  // <unit meter="0.001">, and `rest_length 5` without a unit: read as 5 m, said with its line
  std::vector<std::string> warnings;
  const sgal::Scene s = Load(Data("unitless_length_in_mm_file.dae"), &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("unitless_length_in_mm_file.dae:106:"), std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[0].find("actuator 'spring': length parameter 'rest_length' has no unit "
                             "(line 106) and is read as 5 m"),
            std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[0].find("<unit meter=\"0.001\">"), std::string::npos) << warnings[0];
  ASSERT_EQ(s.actuators.size(), 1u);
  EXPECT_EQ(s.actuators[0].parameters.at("rest_length"), 5.0);
  // the same parameter with a unit, or in a metre file, is not warned about
  warnings.clear();
  Load(Data("extension_unknown_element.dae"), &warnings);
  for (const auto& w : warnings) EXPECT_EQ(w.find("has no unit"), std::string::npos) << w;
}

TEST(ColladaImportTest, ReadsNumbersTheSameUnderACommaDecimalLocale) {
  // the Main Window and the tools are Qt processes: under LANG=de_DE.UTF-8 their C locale reads
  // "1.2" as 1 (strtod, and Collada-DOM's own sscanf for float_array)
  const sgal::Scene plain = Load(Data("caliper_arm.dae"));
  CALIPER_COMMA_DECIMAL_LOCALE(locale);
  const sgal::Scene german = Load(Data("caliper_arm.dae"));
  ASSERT_EQ(german.bodies.size(), 4u);
  EXPECT_EQ(german.FindBody("forearm")->inertia.mass, 1.2);
  EXPECT_EQ(german.FindBody("upper_arm")->inertia.com.z(), 0.01);
  ASSERT_EQ(german.actuators.size(), 5u);
  EXPECT_EQ(german.actuators[0].parameters.at("resistance"), 0.516);
  EXPECT_EQ(testing::SceneComparison(0).Compare(plain, german), 0);
}

TEST(ColladaImportTest, ImportsTheExtensionExample) {
  std::vector<std::string> warnings;
  const sgal::Scene s = Load(Data("caliper_arm.dae"), &warnings);
  for (const auto& w : warnings) ADD_FAILURE() << "unexpected warning: " << w;
  ASSERT_EQ(s.bodies.size(), 4u);
  EXPECT_EQ(s.bodies[0].type, sgal::BodyType::kStatic);
  EXPECT_EQ(s.constraints.size(), 3u);
  EXPECT_EQ(Count(s, sgal::ConstraintKind::kHinge), 3u);
  // settings: the technique's time step wins over the physics scene's
  EXPECT_DOUBLE_EQ(s.settings.time_step, 0.5e-3);
  EXPECT_EQ(s.settings.solver_iterations, 20);
  EXPECT_DOUBLE_EQ(s.settings.world_scale, 10);
  // the elbow: about y, 0 to 150 degrees, with a spring given per degree
  const auto& elbow = s.constraints[1];
  EXPECT_EQ(elbow.name, "elbow");
  EXPECT_NEAR(elbow.limits[0].upper, 150 * kPi / 180, 1e-12);
  const Eigen::Vector3d axis =
      (s.FindBody("upper_arm")->pose * elbow.frame_a).orientation * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(std::abs(axis.y()), 1.0, 1e-12);
  EXPECT_NEAR(elbow.springs[0].stiffness, 0.01 * 180 / kPi, 1e-12);
  EXPECT_NEAR(elbow.springs[0].rest, 20 * kPi / 180, 1e-12);
  // obstacles and tendons in millimetres where they say so
  ASSERT_EQ(s.obstacles.size(), 2u);
  EXPECT_DOUBLE_EQ(s.obstacles[0].radius, 0.025);
  EXPECT_NEAR(s.obstacles[0].pose.position.z(), -0.15, 1e-15);
  ASSERT_EQ(s.tendons.size(), 5u);
  const auto& triceps = s.tendons[1];
  EXPECT_DOUBLE_EQ(triceps.radius, 0.0015);
  ASSERT_EQ(triceps.path.size(), 4u);
  EXPECT_EQ(triceps.path[2].kind, sgal::PathElement::Kind::kWrap);
  ASSERT_TRUE(triceps.path[2].side.has_value());
  EXPECT_NEAR(triceps.path[2].side->x(), -0.06, 1e-15);
  EXPECT_NEAR(triceps.path[3].position.z(), 0.12, 1e-15);
  EXPECT_DOUBLE_EQ(s.tendons[0].path[1].friction, 0.05);
  EXPECT_FALSE(s.tendons[2].collide_with_bodies);
  // actuators of three kinds, parameters in SI
  ASSERT_EQ(s.actuators.size(), 5u);
  const auto& biceps = s.actuators[0];
  EXPECT_EQ(biceps.kind, "dc_motor_tendon");
  EXPECT_NEAR(biceps.parameters.at("inductance"), 5.73e-5, 1e-18);
  EXPECT_NEAR(biceps.parameters.at("torque_constant"), 11.5e-3, 1e-15);
  EXPECT_NEAR(biceps.parameters.at("rotor_inertia"), 14.5e-7, 1e-18);
  EXPECT_NEAR(biceps.parameters.at("spool_radius"), 4.5e-3, 1e-15);
  EXPECT_NEAR(biceps.parameters.at("stiffness"), 2000, 1e-9);
  EXPECT_NEAR(biceps.parameters.at("rest_length"), 0.32, 1e-15);
  EXPECT_EQ(biceps.options.at("elastic"), "linear");
  EXPECT_NEAR(s.actuators[1].parameters.at("zener_E0"), 0.694e6, 1e-6);
  EXPECT_EQ(s.actuators[3].kind, "ligament");
  const auto& brachialis = s.actuators[4];
  EXPECT_EQ(brachialis.kind, "hill_muscle");
  EXPECT_NEAR(brachialis.parameters.at("pennation_angle"), 5 * kPi / 180, 1e-15);
  EXPECT_NEAR(brachialis.parameters.at("activation_time_constant"), 0.015, 1e-15);
  ASSERT_EQ(s.couplings.size(), 1u);
  EXPECT_EQ(s.couplings[0].leader, "elbow");
  EXPECT_EQ(s.couplings[0].follower, "wrist");
  EXPECT_DOUBLE_EQ(s.couplings[0].ratio, 0.3);
  // materials and colours
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_DOUBLE_EQ(s.materials[0].friction, 0.8);
  EXPECT_EQ(s.bodies[1].shapes[0].material, "skin");
  ASSERT_EQ(s.bodies[1].visuals.size(), 1u);
  EXPECT_NEAR(s.bodies[1].visuals[0].color.x(), 0.9, 1e-6);
  // the capsule stands along z after the shape's rotate
  EXPECT_TRUE(std::holds_alternative<sgal::Capsule>(s.bodies[1].shapes[0].geometry));
  EXPECT_NEAR((s.bodies[1].shapes[0].pose.orientation * Eigen::Vector3d::UnitZ()).z(), 1.0, 1e-12);
  EXPECT_NEAR(s.bodies[1].inertia.com.z(), 0.01, 1e-15);
}

TEST(ColladaImportTest, ReadsMeasurementDelaysInTheirUnits) {
  std::vector<std::string> warnings;
  const sgal::Scene s = Load(Data("measurement_delays.dae"), &warnings);
  for (const auto& w : warnings) ADD_FAILURE() << "unexpected warning: " << w;
  ASSERT_EQ(s.measurement_delays.size(), 2u);
  EXPECT_EQ(s.measurement_delays[0].id, "line.tendon.tension");
  EXPECT_DOUBLE_EQ(s.measurement_delays[0].delay, 0.004);  // 4 ms
  EXPECT_EQ(s.measurement_delays[1].id, "hinge.position");
  EXPECT_DOUBLE_EQ(s.measurement_delays[1].delay, 0.002);  // seconds without a unit
}

TEST(ColladaImportTest, TheDocumentedExampleIsTheTestedFile) {
  auto read = [](const std::string& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  };
  const std::string doc = read(CALIPER_COLLADA_DOC);
  const std::string example = read(Data("caliper_arm.dae"));
  ASSERT_FALSE(example.empty());
  const size_t begin = doc.rfind("```xml\n");
  ASSERT_NE(begin, std::string::npos);
  const size_t end = doc.find("```", begin + 7);
  ASSERT_NE(end, std::string::npos);
  EXPECT_EQ(doc.substr(begin + 7, end - begin - 7), example)
      << "docs/collada-extension.md shows another example than tests/data/collada/caliper_arm.dae";
}

}  // namespace
}  // namespace caliper::collada
