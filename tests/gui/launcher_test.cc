// `launch/caliper session MODEL` on a desktop: the naming service, the logger, the Model and the
// Main Window, which opens the renderer, the plotter and the log viewer in their places; Ctrl-C in
// the launcher's terminal ends every process of the session, the naming service included.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <QSettings>
#include <QStringList>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "caliper/gui_session/tool_window.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;

bool Alive(long long pid) { return pid > 0 && ::kill(static_cast<pid_t>(pid), 0) == 0; }

// the launcher's state, sessions and GUI session under `dir`; the programs of this build
void LauncherEnvironment(const std::string& dir) {
  const std::string run = dir + "/run";
  ASSERT_EQ(::mkdir(run.c_str(), 0700), 0);
  ASSERT_NE(std::getenv("CALIPER_BIN_DIR"), nullptr);
  ::setenv("XDG_RUNTIME_DIR", run.c_str(), 1);
  ::setenv("CALIPER_SESSIONS_DIR", (dir + "/sessions").c_str(), 1);
  ::setenv("CALIPER_MAIN_SETTINGS", (dir + "/caliper-main.ini").c_str(), 1);
  ::setenv("CALIPER_BUILD_DIR", (std::string(std::getenv("CALIPER_BIN_DIR")) + "/..").c_str(), 1);
  ::setenv("CALIPER_NO_BUILD", "1", 1);
}

std::string SourceDir() {
  const char* dir = std::getenv("CALIPER_SOURCE_DIR");
  return dir != nullptr ? dir : "";
}

std::vector<std::string> Lines(const std::string& path) {
  std::vector<std::string> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(LauncherSession, OpensTheToolsInTheirPlacesAndCtrlCEndsEveryProcess) {
  if (const std::string why = NoDisplay("the session's windows need X"); !why.empty())
    GTEST_SKIP() << why;
  TempDir dir;
  const std::string run = dir.path() + "/run";
  const QString settings = QString::fromStdString(dir.path() + "/caliper-main.ini");
  LauncherEnvironment(dir.path());
  const std::string source = SourceDir();
  ASSERT_FALSE(source.empty()) << "CALIPER_SOURCE_DIR is not set";
  Process launcher({source + "/launch/caliper", "session", source + "/models/pendulum_tendon.dae"},
                   dir.path() + "/launcher.out");

  // every tool shows its window, and they do not overlap
  const QStringList tools = {"renderer", "plotter", "log_viewer"};
  std::vector<gui_session::ToolWindowRecord> records;
  const bool shown = WaitFor(
      [&] {
        records.clear();
        for (const QString& tool : tools) {
          records.push_back(gui_session::ReadToolWindow(settings, tool));
          if (records.back().window_id == 0 || !Alive(records.back().pid)) return false;
        }
        return true;
      },
      seconds(90));
  ASSERT_TRUE(shown) << launcher.Output();
  for (size_t a = 0; a < records.size(); ++a)
    for (size_t b = a + 1; b < records.size(); ++b)
      EXPECT_FALSE(records[a].geometry.intersects(records[b].geometry))
          << tools[a].toStdString() << " overlaps " << tools[b].toStdString();

  // the session's components are in its naming service
  const std::vector<std::string> latest =
      Lines(run + "/caliper-" + std::to_string(::getuid()) + "/latest-session");
  ASSERT_GE(latest.size(), 2u) << launcher.Output();
  const std::string address = latest[0];
  const long long naming_pid = std::atoll(latest[1].c_str());
  CommandResult ls;
  EXPECT_TRUE(WaitFor(
      [&] {
        ls = Ctl(address, {"ls"});
        for (const char* name : {"logger0", "model0", "renderer0"})
          if (ls.out.find(name) == std::string::npos) return false;
        return true;
      },
      seconds(20)))
      << "not all of logger0, model0, renderer0 listed:\n" << ls.out;
  std::smatch m;
  const std::string output = launcher.Output();
  ASSERT_TRUE(std::regex_search(output, m, std::regex(R"(main window \(pid (\d+)\))"))) << output;
  const long long main_pid = std::atoll(m[1].str().c_str());
  EXPECT_TRUE(Alive(main_pid));

  // Ctrl-C: every process of the session ends, the main window saved the open tools
  launcher.Signal(SIGINT);
  const int code = launcher.Wait(seconds(40));
  EXPECT_EQ(code, 130) << launcher.Output();
  EXPECT_EQ(launcher.Output().find("had to kill"), std::string::npos) << launcher.Output();
  EXPECT_TRUE(WaitFor(
      [&] {
        bool any = Alive(main_pid) || Alive(naming_pid);
        for (const auto& r : records) any = any || Alive(r.pid);
        return !any;
      },
      seconds(10)))
      << "a process of the session outlived it";
  QStringList open = QSettings(settings, QSettings::IniFormat).value("tools/open").toStringList();
  open.sort();
  EXPECT_EQ(open, QStringList({"log_viewer", "plotter", "renderer"}));
}

TEST(LauncherSession, HeadlessSessionEndsAtOnceOnSigterm) {
  // a process manager stops a server's session with SIGTERM: it must not wait for a sleep to end
  TempDir dir;
  const std::string run = dir.path() + "/run";
  LauncherEnvironment(dir.path());
  const std::string source = SourceDir();
  ASSERT_FALSE(source.empty()) << "CALIPER_SOURCE_DIR is not set";
  Process launcher({source + "/launch/caliper", "session", "--headless",
                    source + "/models/pendulum_tendon.dae"},
                   dir.path() + "/launcher.out");
  const std::string latest = run + "/caliper-" + std::to_string(::getuid()) + "/latest-session";
  std::string address;
  ASSERT_TRUE(WaitFor(
      [&] {
        const std::vector<std::string> lines = Lines(latest);
        if (lines.empty()) return false;
        address = lines[0];
        return Ctl(address, {"status"}).exit_code == 0 &&
               launcher.Output().find("session running") != std::string::npos;
      },
      seconds(60)))
      << launcher.Output();
  const long long naming_pid = std::atoll(Lines(latest)[1].c_str());
  launcher.Signal(SIGTERM);
  const int code = launcher.Wait(seconds(20));
  EXPECT_EQ(code, 143) << (code == -1 ? "still running 20 s after SIGTERM\n" : "")
                       << launcher.Output();
  EXPECT_NE(launcher.Output().find("shutting the session down"), std::string::npos)
      << launcher.Output();
  EXPECT_TRUE(WaitFor([&] { return !Alive(naming_pid); }, seconds(10)));
  EXPECT_NE(Ctl(address, {"status"}).exit_code, 0) << "the session's Model still answers";
}

}  // namespace
}  // namespace caliper::testing
