// The Tcl controller (examples/controllers/tcl/arm_controller.tcl) against a real caliper-model
// in a private omniNames, through Tcl Combat and the type information the build generates from
// our IDL (idl/backends/tclir.py -> build/idl/caliper/caliper_ir.tcl).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The first executable `name` on $PATH ("" when there is none).
std::string FindOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + name;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

std::string Env(const char* name) {
  const char* value = std::getenv(name);
  return value ? value : "";
}

/// The printed row of one parameter: before and after stepping, and its unit.
struct Row {
  bool found = false;
  std::string before, after, unit;
};

Row ParameterRow(const std::string& output, const std::string& id) {
  std::istringstream lines(output);
  std::string line;
  Row row;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string first;
    if (!(words >> first) || first != id) continue;
    row.found = static_cast<bool>(words >> row.before >> row.after >> row.unit);
    return row;
  }
  return row;
}

class TclController : public ::testing::Test {
 protected:
  void SetUp() override {
    tclsh_ = FindOnPath("tclsh");
    if (tclsh_.empty()) GTEST_SKIP() << "tclsh is not installed (Debian: tcl)";
    const std::string probe = dir_.path() + "/probe.tcl";
    {
      std::ofstream out(probe);
      out << "puts [package require combat]\n";
    }
    const auto combat = RunCommand({tclsh_, probe});
    if (combat.exit_code != 0)
      GTEST_SKIP() << "the Tcl package combat is not installed (Debian: tcl-combat): "
                   << combat.err;

    ir_ = Env("CALIPER_IR");
    ASSERT_FALSE(ir_.empty()) << "CALIPER_IR is not set (run through ctest)";
    struct stat st;
    ASSERT_EQ(stat(ir_.c_str(), &st), 0) << "no generated type information at " << ir_;
    script_ = Env("CALIPER_SOURCE_DIR") + "/examples/controllers/tcl/arm_controller.tcl";
    arm_ = Env("CALIPER_SOURCE_DIR") + "/models/ecce_arm.dae";

    naming_ = std::make_unique<NamingService>(dir_.path());
    model_ = std::make_unique<Process>(
        // Combat has no unix transport: the Model listens on loopback TCP too, as asked
        std::vector<std::string>{Bin("caliper-model"), "--nameservice", naming_->address(), "-o",
                                 "log.service=none", "-o",
                                 "log.spool_dir=" + dir_.path() + "/spool", "-o",
                                 "corba.loopback_tcp=true"},
        dir_.path() + "/model.out");
    ASSERT_TRUE(WaitFor([&] { return Contains(model_->Output(), " is up as "); }, seconds(20)))
        << model_->Output();
    // "... model is up as HOST.host_cxt/model0.rtc in corbaname::..."
    const std::string out = model_->Output();
    const size_t from = out.find(" is up as ") + 10;
    path_ = out.substr(from, out.find(' ', from) - from);
  }

  CommandResult Controller(std::vector<std::string> args) {
    std::vector<std::string> argv = {tclsh_, script_, "--ir", ir_, "--model", arm_};
    argv.insert(argv.end(), args.begin(), args.end());
    return RunCommand(argv, seconds(60));
  }

  TempDir dir_;
  std::string tclsh_, ir_, script_, arm_, path_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> model_;
};

TEST_F(TclController, LoadsTheArmDrivesAnActuatorAndReadsParametersWithUnits) {
  const auto r = Controller({"--nameservice", naming_->address(), "--actuator", "elbow_flexor",
                             "--command", "6", "--steps", "300", "--pattern", "*.elbow_flexor.*",
                             "--pattern", "*.elbow.position", "--bench"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(Contains(r.out, "model: " + path_ + " via " + naming_->address())) << r.out;
  EXPECT_TRUE(Contains(r.out, "loaded: " + arm_ + " (state STOPPED")) << r.out;

  // the actuator list, with kinds and command units
  EXPECT_TRUE(Contains(r.out, "actuators (14):")) << r.out;
  for (const char* name : {"elbow_flexor", "elbow_extensor", "shoulder_flexor", "wrist_flexor"})
    EXPECT_TRUE(Contains(r.out, std::string("  ") + name)) << name << "\n" << r.out;
  EXPECT_TRUE(Contains(r.out, "dc_motor_tendon")) << r.out;
  EXPECT_TRUE(Contains(r.out, "command [V]")) << r.out;

  EXPECT_TRUE(Contains(r.out, "set_command elbow_flexor 6 V")) << r.out;
  EXPECT_TRUE(Contains(r.out, "stepped 300: sim_time 0.3 s, 300 steps, state PAUSED")) << r.out;

  // the driven motor pulls: its command, current and tension rise, the elbow turns
  const Row command = ParameterRow(r.out, "ecce_arm.elbow_flexor.command");
  ASSERT_TRUE(command.found) << r.out;
  EXPECT_EQ(command.before, "0");
  EXPECT_EQ(command.after, "6");
  EXPECT_EQ(command.unit, "V");
  const Row tension = ParameterRow(r.out, "ecce_arm.elbow_flexor.tendon.tension");
  ASSERT_TRUE(tension.found) << r.out;
  EXPECT_EQ(tension.unit, "N");
  EXPECT_GT(std::stod(tension.after), std::stod(tension.before) + 1.0) << r.out;
  const Row current = ParameterRow(r.out, "ecce_arm.elbow_flexor.current");
  ASSERT_TRUE(current.found) << r.out;
  EXPECT_EQ(current.unit, "A");
  EXPECT_GT(std::stod(current.after), 0.0) << r.out;
  const Row elbow = ParameterRow(r.out, "ecce_arm.elbow.position");
  ASSERT_TRUE(elbow.found) << r.out;
  EXPECT_EQ(elbow.unit, "rad");
  EXPECT_NE(elbow.before, elbow.after) << r.out;
  // static parameters are read too and stay as they are
  const Row stiffness = ParameterRow(r.out, "ecce_arm.elbow_flexor.stiffness");
  ASSERT_TRUE(stiffness.found) << r.out;
  EXPECT_EQ(stiffness.unit, "N/m");
  EXPECT_EQ(stiffness.before, stiffness.after);

  // the cost of one call from Tcl
  const size_t bench = r.out.find("BENCH status: 1000 calls, ");
  ASSERT_NE(bench, std::string::npos) << r.out;
  std::cout << r.out.substr(bench);
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(TclController, AcceptsTheModelsFullCorbanameUrl) {
  const std::string url = naming_->address() + "#" + path_;
  const auto r = Controller({"--nameservice", url, "--steps", "10"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(Contains(r.out, "model: " + path_ + " via " + url)) << r.out;
  EXPECT_TRUE(Contains(r.out, "stepped 10: sim_time 0.01 s, 10 steps")) << r.out;
}

TEST_F(TclController, TakesTheNamingServiceFromTheEnvironment) {
  setenv("CALIPER_NAMESERVICE", naming_->address().c_str(), 1);
  const auto r = Controller({"--steps", "5"});
  unsetenv("CALIPER_NAMESERVICE");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(Contains(r.out, "model: " + path_ + " via " + naming_->address())) << r.out;
}

TEST_F(TclController, ExitsOneWithAMessageWhenTheModelCannotBeReached) {
  const std::string nowhere = "corbaname::127.0.0.1:" + std::to_string(FreePort());
  const auto unreachable = Controller({"--nameservice", nowhere});
  EXPECT_EQ(unreachable.exit_code, 1) << unreachable.out << unreachable.err;
  EXPECT_TRUE(Contains(unreachable.err, "arm_controller: cannot reach the naming service at " +
                                            nowhere + ": CORBA::"))
      << unreachable.err;
  EXPECT_TRUE(unreachable.out.empty()) << unreachable.out;

  // a naming service without that model: every host context tried is named
  const auto missing = Controller({"--nameservice", naming_->address(), "--instance", "model7"});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_TRUE(Contains(missing.err, "no live model at " + naming_->address())) << missing.err;
  const std::string host = path_.substr(0, path_.find('/'));
  EXPECT_TRUE(Contains(missing.err, host + "/model7.rtc: CosNaming::NamingContext::NotFound"))
      << missing.err;

  // a scene the model cannot load: the importer's message
  const auto bad = Controller({"--nameservice", naming_->address(), "--model",
                               dir_.path() + "/missing.dae"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(Contains(bad.err, "Caliper::Simulation::LoadFailed")) << bad.err;

  // the model stays up through all of it
  EXPECT_TRUE(model_->Running()) << model_->Output();
}

}  // namespace
}  // namespace caliper::testing
