// The Model's core with URDF robots, without CORBA: a .urdf loads by path (meshes relative to it)
// and steps, a .urdf sent by content is refused with how to send it instead, its COLLADA
// conversion (model_file::ContentToSend) loads by content as the same robot; and the confined
// read directories hold for a URDF's meshes and side file too (ModelFiles::ResolveScene).
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "caliper/collada/importer.h"
#include "caliper/model_file/model_file.h"
#include "caliper/simulation/model_core.h"
#include "caliper/simulation/model_files.h"

namespace caliper::simulation {
namespace {

namespace fs = std::filesystem;

std::string Source(const std::string& relative) {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(src ? src : ".") + "/" + relative;
}

std::string Arm2() { return Source("tests/data/urdf/arm2/arm2.urdf"); }

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void Write(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// The one elbow angle the Model reports [rad], after checking it is a number.
double Elbow(const ModelCore& core) {
  const auto readings = core.Sample({"arm2.elbow.position"});
  EXPECT_EQ(readings.size(), 1u);
  if (readings.size() != 1 || readings[0].values.size() != 1) return NAN;
  return readings[0].values[0];
}

TEST(ModelUrdf, LoadsAUrdfByPathWithItsMeshAndTendonAndSteps) {
  ModelCore core;
  core.Load(Arm2());
  const auto scene = core.description();
  ASSERT_NE(scene, nullptr);
  EXPECT_EQ(scene->bodies.size(), 3u);
  EXPECT_EQ(scene->constraints.size(), 2u);
  ASSERT_EQ(scene->tendons.size(), 1u);
  EXPECT_EQ(scene->tendons[0].name, "flexor");
  EXPECT_EQ(core.status().scene, Arm2());
  EXPECT_EQ(core.model_name(), "arm2");
  // the motor pulls the flexor: the elbow bends, nothing explodes
  core.SetCommands({{"flexor_motor", 6.0}});
  EXPECT_EQ(core.StepNow(500), 500u);
  EXPECT_EQ(core.status().state, RunState::kPaused) << core.status().last_error;
  const double elbow = Elbow(core);
  EXPECT_TRUE(std::isfinite(elbow));
  EXPECT_GT(elbow, 0.01) << "the flexor did not bend the elbow";
}

TEST(ModelUrdf, AUrdfSentByContentIsRefusedSayingHowToSendIt) {
  ModelCore core;
  core.Load(Source("models/pendulum_tendon.dae"));
  try {
    core.LoadData("arm2.urdf", ReadAll(Arm2()));
    ADD_FAILURE() << "a URDF by content was loaded";
  } catch (const LoadError& e) {
    const std::string why = e.what();
    EXPECT_TRUE(Contains(why, "arm2.urdf: a URDF cannot be sent by content")) << why;
    EXPECT_TRUE(Contains(why, "send it by path")) << why;
    EXPECT_TRUE(Contains(why, "`caliper-ctl inspect arm2.urdf --export arm2.dae`")) << why;
  }
  // the scene before stays
  EXPECT_EQ(core.status().scene, Source("models/pendulum_tendon.dae"));
}

TEST(ModelUrdf, ItsColladaConversionLoadsByContentAsTheSameRobot) {
  std::vector<std::string> warnings;
  const model_file::Content content = model_file::ContentToSend(Arm2(), &warnings);
  EXPECT_EQ(content.file_name, "arm2.dae");
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  EXPECT_TRUE(Contains(content.bytes, "<COLLADA")) << content.bytes.substr(0, 200);
  EXPECT_TRUE(Contains(content.bytes, "profile=\"CALIPER\""));

  ModelCore by_path, by_content;
  by_path.Load(Arm2());
  by_content.LoadData(content.file_name, content.bytes);
  EXPECT_EQ(by_content.status().scene, "arm2.dae (sent by content)");
  const auto a = by_path.description(), b = by_content.description();
  ASSERT_EQ(a->bodies.size(), b->bodies.size());
  for (size_t i = 0; i < a->bodies.size(); ++i) {
    EXPECT_EQ(a->bodies[i].name, b->bodies[i].name);
    EXPECT_NEAR(a->bodies[i].inertia.mass, b->bodies[i].inertia.mass, 1e-12) << a->bodies[i].name;
    EXPECT_EQ(a->bodies[i].shapes.size(), b->bodies[i].shapes.size()) << a->bodies[i].name;
  }
  EXPECT_EQ(a->constraints.size(), b->constraints.size());
  ASSERT_EQ(b->tendons.size(), 1u);
  EXPECT_EQ(b->tendons[0].name, "flexor");
  ASSERT_EQ(b->actuators.size(), 1u);
  EXPECT_EQ(b->actuators[0].name, "flexor_motor");
  // the same commands give the same motion (the mesh made it across)
  for (ModelCore* core : {&by_path, &by_content}) {
    core->SetCommands({{"flexor_motor", 6.0}});
    core->StepNow(300);
  }
  EXPECT_NEAR(Elbow(by_path), Elbow(by_content), 1e-9);
}

TEST(ModelUrdf, ContentToSendKeepsColladaAsItIsAndRefusesOtherEndings) {
  const std::string dae = Source("models/pendulum_tendon.dae");
  const model_file::Content content = model_file::ContentToSend(dae, nullptr);
  EXPECT_EQ(content.file_name, "pendulum_tendon.dae");
  EXPECT_EQ(content.bytes, ReadAll(dae));
  try {
    model_file::ContentToSend(Source("README.md"), nullptr);
    ADD_FAILURE() << "README.md was sent";
  } catch (const collada::ImportError& e) {
    EXPECT_TRUE(Contains(e.what(),
                         "README.md: not a model file: Caliper loads *.dae, *.zae or "
                         "*.urdf"))
        << e.what();
  }
  try {
    model_file::ContentToSend("/nonexistent/arm.dae", nullptr);
    ADD_FAILURE() << "a missing file was sent";
  } catch (const collada::ImportError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/arm.dae cannot be read: no such file");
  }
}

// root/models (the read directory) and root/outside, with arm2.urdf in models/ whose mesh is
// found where each test puts it
class ConfinedUrdfTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/caliper-model-urdf-XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    root_ = fs::canonical(pattern).string();
    fs::create_directories(root_ + "/models/meshes");
    fs::create_directories(root_ + "/outside");
    urdf_ = ReadAll(Arm2());
    for (const char* d : {"/models/meshes/bar.stl", "/outside/bar.stl"})
      fs::copy_file(Source("tests/data/urdf/arm2/meshes/bar.stl"), root_ + d);
  }
  void TearDown() override { fs::remove_all(root_); }

  /// A URDF in models/ whose mesh reference is `mesh`.
  std::string UrdfWithMesh(const std::string& name, const std::string& mesh) {
    std::string text = urdf_;
    for (size_t at = text.find("meshes/bar.stl"); at != std::string::npos;
         at = text.find("meshes/bar.stl", at + mesh.size()))
      text.replace(at, 14, mesh);
    const std::string path = root_ + "/models/" + name;
    Write(path, text);
    return path;
  }

  ModelFiles Files() const {
    return ModelFiles{
        core::ConfinedPaths({root_ + "/models"}, "model.read_dirs", "the Model reads scenes", true),
        core::ConfinedPaths({}, "model.write_dir", "the Model writes scenes", true)};
  }

  /// PathRefused's message for ResolveScene(path), "" when accepted.
  std::string Refusal(const std::string& path) {
    try {
      Files().ResolveScene(path);
      return "";
    } catch (const core::PathRefused& e) {
      return e.what();
    }
  }

  std::string root_, urdf_;
};

TEST_F(ConfinedUrdfTest, FilesReadListsTheMeshesAndTheSideFile) {
  const std::string urdf = UrdfWithMesh("arm2.urdf", "meshes/bar.stl");
  EXPECT_EQ(model_file::FilesRead(urdf),
            std::vector<std::string>{root_ + "/models/meshes/bar.stl"});
  Write(root_ + "/models/arm2.caliper.xml", "<caliper/>");
  EXPECT_EQ(model_file::FilesRead(urdf),
            (std::vector<std::string>{root_ + "/models/meshes/bar.stl",
                                      root_ + "/models/arm2.caliper.xml"}));
  EXPECT_TRUE(model_file::FilesRead(Source("models/pendulum_tendon.dae")).empty());
  // a mesh that is nowhere is the importer's to report, with every place tried
  EXPECT_TRUE(model_file::FilesRead(UrdfWithMesh("gone.urdf", "meshes/gone.stl")).empty());
  Write(root_ + "/models/broken.urdf", "<robot name='x'><link name='a'></robot>");
  try {
    model_file::FilesRead(root_ + "/models/broken.urdf");
    ADD_FAILURE() << "malformed XML was read";
  } catch (const collada::ImportError& e) {
    EXPECT_TRUE(Contains(e.what(), root_ + "/models/broken.urdf:1: malformed XML")) << e.what();
  }
}

TEST_F(ConfinedUrdfTest, AUrdfWhoseMeshesLieInsideIsAccepted) {
  EXPECT_EQ(Refusal(UrdfWithMesh("arm2.urdf", "meshes/bar.stl")), "");
  EXPECT_EQ(Refusal(UrdfWithMesh("by_uri.urdf", "file://" + root_ + "/models/meshes/bar.stl")), "");
  EXPECT_EQ(Files().ResolveScene("arm2.urdf"), root_ + "/models/arm2.urdf");
  // and the core loads what was accepted
  ModelCore core;
  core.Load(Files().ResolveScene("arm2.urdf"));
  EXPECT_EQ(core.description()->bodies.size(), 3u);
}

TEST_F(ConfinedUrdfTest, AUrdfWithAMeshOutsideIsRefusedNamingTheMesh) {
  const std::string outside = root_ + "/outside/bar.stl";
  fs::create_symlink(outside, root_ + "/models/meshes/link.stl");
  fs::create_directory_symlink(root_ + "/outside", root_ + "/models/out");
  for (const std::string& mesh : {std::string("../outside/bar.stl"), outside, "file://" + outside,
                                  std::string("meshes/link.stl"), std::string("out/bar.stl")}) {
    const std::string urdf = UrdfWithMesh("escape.urdf", mesh);
    const std::string why = Refusal(urdf);
    EXPECT_TRUE(Contains(why, urdf + " reads another file, which is refused: '"))
        << mesh << ": " << why;
    EXPECT_TRUE(Contains(why, "is outside the directories where the Model reads scenes (" + root_ +
                                  "/models; set by model.read_dirs)"))
        << mesh << ": " << why;
  }
  // a side file leading out
  UrdfWithMesh("arm2.urdf", "meshes/bar.stl");
  Write(root_ + "/outside/secret.xml", "<caliper/>");
  fs::create_symlink(root_ + "/outside/secret.xml", root_ + "/models/arm2.caliper.xml");
  EXPECT_TRUE(Contains(Refusal(root_ + "/models/arm2.urdf"), "arm2.caliper.xml"));
}

}  // namespace
}  // namespace caliper::simulation
