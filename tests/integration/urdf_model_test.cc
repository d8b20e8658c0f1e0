// URDF robots through a real caliper-model and caliper-ctl: a .urdf below the Model's read
// directories loads by path (its mesh beside it), steps, and `save` writes COLLADA that inspects
// as the same robot with its tendon; one elsewhere goes by content, converted to COLLADA by
// caliper-ctl; the Model refuses a .urdf sent by content (saying how to send it), and a URDF
// whose mesh lies outside its read directories by path (caliper-ctl then sends it converted); a
// batch runs an experiment whose scene is a .urdf.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "caliper/model.hh"
#include "caliper/rtc/client_orb.h"
#include "support/corba.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

namespace fs = std::filesystem;
namespace M = ::Caliper::Simulation;

using std::chrono::seconds;

std::string Source(const std::string& relative) {
  const char* dir = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(dir != nullptr ? dir : ".") + "/" + relative;
}

// The lines of `inspect` output from the `bodies` header to the `warnings` one, without the
// first lines (file, format, units) that differ between a URDF and its COLLADA.
std::string Robot(const std::string& inspect) {
  const size_t from = inspect.find("bodies (");
  const size_t to = inspect.find("warnings (");
  return from == std::string::npos ? "" : inspect.substr(from, to - from);
}

// root/models (the search path) with arm2.urdf and its mesh, root/session (the write
// directory), root/outside with another copy
class UrdfModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::canonical(tmp_.path()).string();
    for (const char* d : {"models", "session", "outside"}) {
      fs::create_directories(root_ + "/" + d + "/meshes");
      fs::copy_file(Source("tests/data/urdf/arm2/arm2.urdf"), root_ + "/" + d + "/arm2.urdf");
      fs::copy_file(Source("tests/data/urdf/arm2/meshes/bar.stl"),
                    root_ + "/" + d + "/meshes/bar.stl");
    }
    naming_ = std::make_unique<NamingService>(root_);
    model_ = std::make_unique<Process>(
        std::vector<std::string>{Bin("caliper-model"), "--nameservice", naming_->address(), "-o",
                                 "exec.auto_activate=true", "-o", "log.service=none", "-o",
                                 "log.spool_dir=" + root_ + "/spool", "-o",
                                 "model.read_dirs=" + root_ + "/models", "-o",
                                 "model.write_dir=" + root_ + "/session"},
        root_ + "/model.out");
    ref_ =
        WaitForModel(rtc::ClientOrb("urdf_model_test"), naming_->address(), "model0", seconds(20));
    ASSERT_FALSE(CORBA::is_nil(ref_)) << model_->Output();
  }

  CommandResult Ctl(const std::vector<std::string>& args) {
    return caliper::testing::Ctl(naming_->address(), args);
  }

  std::string Scene() { return LoadedScene(ref_); }

  std::string LoadRefusal(const std::string& path) {
    return caliper::testing::LoadRefusal(ref_, path);
  }

  /// Steps `n` and says whether all ran without a fault.
  void StepsFine(int n) {
    const auto step = Ctl({"step", std::to_string(n)});
    EXPECT_EQ(step.exit_code, 0) << step.out << step.err;
    M::SimulationStatus_var s = ref_->status();
    EXPECT_EQ(s->state, M::PAUSED) << s->last_error.in();
    EXPECT_EQ(s->steps, static_cast<CORBA::ULongLong>(n));
  }

  TempDir tmp_;
  std::string root_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> model_;
  M::Model_var ref_;
};

TEST_F(UrdfModelTest, LoadsByPathStepsAndSavesCollada) {
  const std::string urdf = root_ + "/models/arm2.urdf";
  const auto load = Ctl({"load", urdf});
  ASSERT_EQ(load.exit_code, 0) << load.err;
  EXPECT_FALSE(Contains(load.out, "by content")) << load.out;
  EXPECT_EQ(Scene(), urdf);
  const auto motor = Ctl({"motor", "flexor_motor", "6"});
  EXPECT_EQ(motor.exit_code, 0) << motor.err;
  StepsFine(300);

  // saved by the Model into its write directory: COLLADA with the robot and its tendon
  const std::string saved = root_ + "/session/arm2_saved.dae";
  const auto save = Ctl({"save", saved});
  ASSERT_EQ(save.exit_code, 0) << save.err;
  EXPECT_TRUE(Contains(ReadFile(saved), "<COLLADA"));
  EXPECT_TRUE(Contains(ReadFile(saved), "profile=\"CALIPER\""));
  const auto original = Ctl({"inspect", urdf});
  const auto copy = Ctl({"inspect", saved});
  ASSERT_EQ(copy.exit_code, 0) << copy.err;
  EXPECT_TRUE(Contains(copy.out, "format                  COLLADA")) << copy.out;
  EXPECT_TRUE(Contains(copy.out, "bodies (3: 2 dynamic, 1 static)")) << copy.out;
  EXPECT_TRUE(Contains(copy.out, "constraints (2)")) << copy.out;
  EXPECT_TRUE(Contains(copy.out, "  flexor                radius 0.001 m")) << copy.out;
  EXPECT_TRUE(Contains(copy.out, "  flexor_motor          dc_motor_tendon on flexor")) << copy.out;
  EXPECT_EQ(Robot(copy.out), Robot(original.out));
  // and it loads back by path
  EXPECT_EQ(LoadRefusal(saved), "");
  StepsFine(10);
}

TEST_F(UrdfModelTest, ElsewhereItGoesByContentConvertedToCollada) {
  const std::string urdf = root_ + "/outside/arm2.urdf";
  const auto load = Ctl({"load", urdf});
  ASSERT_EQ(load.exit_code, 0) << load.err;
  EXPECT_TRUE(Contains(load.out, "loaded " + urdf + " (sent by content)")) << load.out;
  EXPECT_EQ(Scene(), "arm2.dae (sent by content)");
  StepsFine(100);
  // --send converts one the Model could read itself, too
  const auto sent = Ctl({"load", root_ + "/models/arm2.urdf", "--send"});
  ASSERT_EQ(sent.exit_code, 0) << sent.err;
  EXPECT_EQ(Scene(), "arm2.dae (sent by content)");
  // fetched by content after a load by content: still the robot
  const auto save = Ctl({"save", root_ + "/outside/fetched.dae"});
  ASSERT_EQ(save.exit_code, 0) << save.err;
  const auto copy = Ctl({"inspect", root_ + "/outside/fetched.dae"});
  EXPECT_TRUE(Contains(copy.out, "tendons (1;")) << copy.out;
  // a URDF that cannot be imported is reported here, before anything is sent
  std::ofstream(root_ + "/outside/broken.urdf") << "<robot name='x'><link name='a'></robot>\n";
  const auto broken = Ctl({"load", root_ + "/outside/broken.urdf"});
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_TRUE(Contains(broken.err, root_ + "/outside/broken.urdf")) << broken.err;
  EXPECT_EQ(Scene(), "arm2.dae (sent by content)");
}

TEST_F(UrdfModelTest, TheModelRefusesAUrdfSentByContent) {
  ASSERT_EQ(LoadRefusal(root_ + "/models/arm2.urdf"), "");
  const std::string bytes = ReadFile(root_ + "/models/arm2.urdf");
  M::Octets data(static_cast<CORBA::ULong>(bytes.size()));
  data.length(static_cast<CORBA::ULong>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char*>(data.get_buffer()));
  try {
    ref_->load_scene_data("arm2.urdf", data);
    ADD_FAILURE() << "a URDF by content was loaded";
  } catch (const M::LoadFailed& e) {
    const std::string why = e.reason.in();
    EXPECT_TRUE(Contains(why, "arm2.urdf: a URDF cannot be sent by content")) << why;
    EXPECT_TRUE(Contains(why, "send it by path")) << why;
    EXPECT_TRUE(Contains(why, "`caliper-ctl inspect arm2.urdf --export arm2.dae`")) << why;
  }
  EXPECT_EQ(Scene(), root_ + "/models/arm2.urdf") << "the scene before stays";
}

TEST_F(UrdfModelTest, AMeshOutsideTheReadDirectoriesIsRefusedByPath) {
  std::string text = ReadFile(root_ + "/models/arm2.urdf");
  const std::string outside = "../outside/meshes/bar.stl";
  for (size_t at = text.find("meshes/bar.stl"); at != std::string::npos;
       at = text.find("meshes/bar.stl", at + outside.size()))
    text.replace(at, 14, outside);
  const std::string escape = root_ + "/models/escape.urdf";
  std::ofstream(escape) << text;
  const std::string why = LoadRefusal(escape);
  EXPECT_TRUE(Contains(why, "load_scene: " + escape + " reads another file, which is refused: '" +
                                root_ +
                                "/outside/meshes/bar.stl' is outside the "
                                "directories where the Model reads scenes"))
      << why;
  EXPECT_TRUE(Contains(model_->Output(), "load_scene refused: " + escape)) << model_->Output();
  EXPECT_NE(Scene(), escape);
  // caliper-ctl sees the same and sends it converted, which reads the mesh here
  const auto load = Ctl({"load", escape});
  ASSERT_EQ(load.exit_code, 0) << load.err;
  EXPECT_TRUE(Contains(load.out, "(sent by content)")) << load.out;
  EXPECT_EQ(Scene(), "escape.dae (sent by content)");
  StepsFine(50);
  // malformed XML by path is the file's error, not a refusal
  std::ofstream(root_ + "/models/broken.urdf") << "<robot name='x'><link name='a'></robot>\n";
  const std::string broken = LoadRefusal(root_ + "/models/broken.urdf");
  EXPECT_TRUE(Contains(broken, root_ + "/models/broken.urdf:2: malformed XML")) << broken;
  EXPECT_FALSE(Contains(broken, "load_scene:")) << broken;
}

TEST_F(UrdfModelTest, ABatchRunsAUrdfScene) {
  const std::string runs = root_ + "/outside/runs.json";
  std::ofstream(runs) << R"({
  "scene": "arm2.urdf",
  "duration_s": 0.2,
  "every_n_steps": 50,
  "record": ["arm2.elbow.position"],
  "commands": [[0.0, "flexor_motor", 6.0]],
  "experiments": [{"name": "flex"}, {"name": "still", "commands": []}]
})";
  const auto batch = RunCommand({Bin("caliper-ctl"), "--nameservice", naming_->address(), "batch",
                                 runs, "--out", root_ + "/batch"},
                                seconds(60));
  ASSERT_EQ(batch.exit_code, 0) << batch.out << batch.err;
  for (const char* name : {"flex", "still"}) {
    std::istringstream csv(ReadFile(root_ + "/batch/runs/" + name + ".csv"));
    std::string header, line;
    std::getline(csv, header);
    EXPECT_EQ(header, "time [s],arm2.elbow.position [rad]") << name;
    int rows = 0;
    double last = 0;
    while (std::getline(csv, line)) {
      ++rows;
      last = std::stod(line.substr(line.find(',') + 1));
    }
    EXPECT_EQ(rows, 5) << name << ": t = 0 and every 50 ms";
    if (std::string(name) == "flex") {
      EXPECT_GT(last, 0.01) << "the flexor bent the elbow";
    } else {
      EXPECT_LT(last, 0.01) << "nothing bent it";
    }
  }
}

}  // namespace
}  // namespace caliper::testing
