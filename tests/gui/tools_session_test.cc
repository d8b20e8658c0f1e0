// The Main Window opens the tools (renderer, plotter, log viewer) as their own processes from its
// Tools menu and gives each its place on the screen; the tools write where their windows are into
// the session file; closing the Main Window ends them and remembers them; the next Main Window
// opens them again where they were, and Arrange Windows tiles running tools. Runs on the X display
// (launch/caliper test starts Xvfb): the tools are X clients and the renderer needs GLX.
#include <gtest/gtest.h>
#include <signal.h>

#include <QAction>
#include <QPixmap>
#include <QScreen>
#include <QSettings>
#include <cstdlib>
#include <map>

#include "caliper/gui_session/tool_window.h"
#include "main_window.h"
#include "model_link.h"
#include "support/gui_test.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;
using gui_session::ReadToolWindow;
using gui_session::ToolWindowRecord;
using main_window::MainWindow;
using main_window::ModelLink;

bool Alive(long long pid) { return pid > 0 && ::kill(static_cast<pid_t>(pid), 0) == 0; }

class ToolsSession : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string why = NoDisplay("the tools are X clients"); !why.empty())
      GTEST_SKIP() << why;
    App();
    Orb();
    naming_ = std::make_unique<NamingService>(dir_.path());
    settings_ = QString::fromStdString(dir_.path() + "/caliper-main.ini");
    qputenv("CALIPER_MAIN_SETTINGS", settings_.toLocal8Bit());
    const std::string models = std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/models";
    model_ = StartModelProcess(naming_->address(), models + "/pendulum_tendon.dae", dir_.path(),
                               dir_.path() + "/model.out");
  }

  std::unique_ptr<MainWindow> Window(bool restore_tools) {
    ModelLink::Options options;
    options.nameservice = naming_->address();
    options.reconnect_period_ms = 300;
    auto w = std::make_unique<MainWindow>(std::make_unique<ModelLink>(options), 10.0, nullptr,
                                          restore_tools);
    w->SetToolArguments("renderer", {"-o", "log.service=none", "-o",
                                     QString::fromStdString("log.spool_dir=" + dir_.path() +
                                                            "/spool")});
    w->show();
    return w;
  }

  /// Waits until `tool`, started by `w`, has written its shown window into the session file.
  ToolWindowRecord WaitShown(MainWindow& w, const QString& tool) {
    ToolWindowRecord record;
    WaitInGui(
        [&] {
          record = ReadToolWindow(settings_, tool);
          return w.ToolPid(tool) != 0 && record.pid == w.ToolPid(tool) && record.window_id != 0;
        },
        seconds(30));
    return record;
  }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> model_;
  QString settings_;
};

TEST_F(ToolsSession, ToolsOpenInTheirPlacesAreRememberedRestoredAndArranged) {
  auto w = Window(/*restore_tools=*/false);
  const QStringList tools = MainWindow::ToolNames();
  ASSERT_EQ(tools, QStringList({"renderer", "plotter", "log_viewer"}));

  // Tools menu: each tool starts as its own process and comes up in its own place
  for (const QString& tool : tools) {
    auto* action = w->findChild<QAction*>("tool_" + tool);
    ASSERT_NE(action, nullptr) << tool.toStdString();
    action->trigger();
  }
  std::map<QString, QRect> placed = {{"main", w->geometry()}};
  for (const QString& tool : tools) {
    const ToolWindowRecord record = WaitShown(*w, tool);
    ASSERT_NE(record.window_id, 0u) << tool.toStdString() << " never showed its window";
    EXPECT_EQ(record.geometry, w->ArrangedGeometry(tool)) << tool.toStdString();
    placed[tool] = record.geometry;
  }
  EXPECT_EQ(w->geometry(), w->ArrangedGeometry("main"));
  for (const auto& [a, ra] : placed)
    for (const auto& [b, rb] : placed)
      if (a < b) {
        EXPECT_FALSE(ra.intersects(rb)) << a.toStdString() << " overlaps " << b.toStdString();
      }

  // the renderer is a component: the components panel lists it
  const QString screenshot = QString::fromStdString(ArtifactPath("tools_session.png", dir_.path()));
  WaitInGui([] { return false; }, std::chrono::milliseconds(1500));  // let the tools draw
  ASSERT_TRUE(QGuiApplication::primaryScreen()->grabWindow(0).save(screenshot));

  // closing the Main Window ends the tools and remembers them
  std::map<QString, long long> pids;
  for (const QString& tool : tools) pids[tool] = w->ToolPid(tool);
  EXPECT_TRUE(w->close());
  w.reset();
  for (const QString& tool : tools) EXPECT_FALSE(Alive(pids[tool])) << tool.toStdString();
  QStringList open = QSettings(settings_, QSettings::IniFormat).value("tools/open").toStringList();
  open.sort();
  QStringList expected = tools;
  expected.sort();
  EXPECT_EQ(open, expected);

  // the user had moved the renderer: the next session opens every tool where it was
  const QRect moved(40, 300, 500, 400);
  {
    QSettings st(settings_, QSettings::IniFormat);
    st.setValue("renderer/geometry", gui_session::FormatGeometry(moved));
  }
  w = Window(/*restore_tools=*/true);
  for (const QString& tool : tools) {
    const ToolWindowRecord record = WaitShown(*w, tool);
    ASSERT_NE(record.window_id, 0u) << tool.toStdString() << " was not reopened";
    EXPECT_NE(record.pid, pids[tool]) << "a new process";
    EXPECT_EQ(record.geometry, tool == "renderer" ? moved : placed[tool]) << tool.toStdString();
  }

  // Arrange Windows moves the running renderer back into its place
  w->findChild<QAction*>("arrange_windows")->trigger();
  ToolWindowRecord arranged;
  EXPECT_TRUE(WaitInGui(
      [&] {
        arranged = ReadToolWindow(settings_, "renderer");
        return arranged.geometry == w->ArrangedGeometry("renderer");
      },
      seconds(10)))
      << "renderer still at " << gui_session::FormatGeometry(arranged.geometry).toStdString();
  for (const QString& tool : tools) pids[tool] = w->ToolPid(tool);
  w->close();
  w.reset();
  for (const QString& tool : tools) EXPECT_FALSE(Alive(pids[tool])) << tool.toStdString();
}

}  // namespace
}  // namespace caliper::testing
