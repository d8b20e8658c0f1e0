// The Main Window's Open dialog offers URDF beside COLLADA, and a .urdf chosen in it loads in a
// real caliper-model: by path from the Model's read directories, converted to COLLADA and sent by
// content from elsewhere. Widgets on QT_QPA_PLATFORM=offscreen; the dialog's picture is kept in
// the artifacts (main_window_open_dialog.png).
#include <gtest/gtest.h>

#include <QApplication>
#include <QFileDialog>
#include <QStatusBar>
#include <QLineEdit>
#include <QPushButton>
#include <QTimer>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>

#include "caliper/model.hh"
#include "main_window.h"
#include "model_link.h"
#include "support/gui_test.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

namespace fs = std::filesystem;
namespace M = ::Caliper::Simulation;
using main_window::MainWindow;
using main_window::ModelLink;
using std::chrono::seconds;

std::string Source(const std::string& relative) {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(src != nullptr ? src : ".") + "/" + relative;
}

TEST(MainWindowOpen, TheFilterOffersUrdfBesideCollada) {
  const QString filter = MainWindow::ModelFileFilter();
  const QStringList entries = filter.split(";;");
  ASSERT_GE(entries.size(), 2);
  EXPECT_EQ(entries[0], "Model files (*.dae *.zae *.urdf)") << filter.toStdString();
  EXPECT_TRUE(entries.contains("URDF (*.urdf)")) << filter.toStdString();
  EXPECT_TRUE(entries.contains("COLLADA (*.dae *.zae)")) << filter.toStdString();
}

class MainWindowOpenTest : public ModelProcessTest {
 protected:
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(StartModelSession("models/pendulum_tendon.dae"));
    ModelLink::Options options;
    options.nameservice = naming_->address();
    options.reconnect_period_ms = 300;
    window_ = std::make_unique<MainWindow>(std::make_unique<ModelLink>(options), 10.0);
    window_->show();
    // Open is enabled once the window's link has reached the Model (its worker thread): a click
    // before that does nothing, and no dialog would come up
    ASSERT_TRUE(WaitInGui(
        [&] { return window_->findChild<QPushButton*>("open")->isEnabled(); }, seconds(10)))
        << "the Main Window did not connect to the Model";
  }

  /// Clicks Open, and in the dialog that comes up runs `inspect` and chooses `file`.
  /// False when no file dialog came up within 10 s.
  bool OpenThroughDialog(const std::string& file,
                         const std::function<void(QFileDialog&)>& inspect) {
    bool seen = false;
    auto* poll = new QTimer(window_.get());
    int tries = 0;
    QObject::connect(poll, &QTimer::timeout, [&, poll] {
      QFileDialog* dialog = nullptr;
      for (QWidget* w : QApplication::topLevelWidgets())
        if (auto* d = qobject_cast<QFileDialog*>(w); d != nullptr) dialog = d;
      if (dialog == nullptr && ++tries < 200) return;  // 10 s at 50 ms
      poll->stop();
      if (dialog == nullptr) return;
      seen = true;
      inspect(*dialog);
      // typed, as a user would: selectFile() leaves a focused name field as it is
      dialog->findChild<QLineEdit*>("fileNameEdit")->setText(QString::fromStdString(file));
      static_cast<QDialog*>(dialog)->accept();  // QFileDialog::accept, through its public base
    });
    poll->start(50);
    window_->findChild<QPushButton*>("open")->click();  // returns when the dialog closed
    poll->stop();
    poll->deleteLater();
    return seen;
  }

  std::string Scene() {
    M::SimulationStatus_var s = model_->status();
    return s->scene.in();
  }

  TempDir elsewhere_;
  std::unique_ptr<MainWindow> window_;
};

TEST_F(MainWindowOpenTest, AUrdfChosenInTheDialogLoadsByPathOrConverted) {
  const std::string urdf = Source("tests/data/urdf/arm2/arm2.urdf");
  QStringList filters;
  const bool seen = OpenThroughDialog(urdf, [&](QFileDialog& dialog) {
    filters = dialog.nameFilters();
    dialog.setDirectory(QString::fromStdString(fs::path(urdf).parent_path().string()));
    dialog.resize(760, 480);
    QApplication::processEvents();
    EXPECT_TRUE(dialog.grab().save(
        QString::fromStdString(ArtifactPath("main_window_open_dialog.png", dir_.path()))));
  });
  ASSERT_TRUE(seen) << "no file dialog came up";
  EXPECT_TRUE(filters.contains("Model files (*.dae *.zae *.urdf)"))
      << filters.join("|").toStdString();
  EXPECT_TRUE(filters.contains("URDF (*.urdf)")) << filters.join("|").toStdString();
  // tests/data is a read directory of this Model: by path
  EXPECT_TRUE(WaitInGui([&] { return Scene() == urdf; }, seconds(10))) << Scene();

  // from elsewhere: converted here and sent as arm2.dae
  const std::string copy = elsewhere_.path() + "/arm2.urdf";
  fs::create_directories(elsewhere_.path() + "/meshes");
  fs::copy_file(urdf, copy);
  fs::copy_file(Source("tests/data/urdf/arm2/meshes/bar.stl"),
                elsewhere_.path() + "/meshes/bar.stl");
  ASSERT_TRUE(OpenThroughDialog(copy, [](QFileDialog&) {}));
  EXPECT_TRUE(WaitInGui([&] { return Scene() == "arm2.dae (sent by content)"; }, seconds(10)))
      << Scene();

  // a URDF with something to warn about, converted: the warning is said in the status bar (the
  // Model, given COLLADA, has none to log)
  const std::string bare = elsewhere_.path() + "/bare.urdf";
  std::ofstream(bare) << R"(<robot name="bare"><link name="base"/><link name="arm"/>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/></joint></robot>)";
  ASSERT_TRUE(OpenThroughDialog(bare, [](QFileDialog&) {}));
  std::string shown;
  EXPECT_TRUE(WaitInGui(
      [&] {
        shown = window_->statusBar()->currentMessage().toStdString();
        return shown.find("bare.dae (converted from " + bare + "): 1 import warning: ") !=
                   std::string::npos &&
               shown.find("link 'arm': no <inertial> on a moving link") != std::string::npos;
      },
      seconds(10)))
      << shown;
}

}  // namespace
}  // namespace caliper::testing
