// The Main Window in the test process against a real caliper-model: Start advances the simulated
// time shown, editing a parameter in the tree changes the Model's value over CORBA, and with no
// Model in reach the window says so and stays responsive. Widgets run on QT_QPA_PLATFORM=offscreen.
#include <gtest/gtest.h>
#include <signal.h>

#include <QApplication>
#include <QElapsedTimer>
#include <QFileInfo>
#include <QSettings>
#include <QLabel>
#include <QLineEdit>
#include <QHeaderView>
#include <QPushButton>
#include <QStatusBar>
#include <QTest>
#include <QTreeWidget>
#include <chrono>
#include <cstdlib>

#include "caliper/model.hh"
#include "caliper/rtc.hh"
#include "caliper/rtc/naming.h"
#include "main_window.h"
#include "model_link.h"
#include "support/gui_test.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;
namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;
using main_window::MainWindow;
using main_window::ModelLink;

constexpr const char* kMassId = "pendulum_tendon.pendulum.mass";

double SimTimeShown(MainWindow& w) {
  const QString text = w.findChild<QLabel*>("sim_time")->text();  // "t = 1.234 s"
  const QStringList parts = text.split(' ');
  return parts.size() >= 3 ? parts[2].toDouble() : -1.0;
}

class MainWindowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    App();
    Orb();
    naming_ = std::make_unique<NamingService>(dir_.path());
    settings_ = dir_.path() + "/caliper-main.ini";
    qputenv("CALIPER_MAIN_SETTINGS", QByteArray::fromStdString(settings_));
  }

  std::unique_ptr<Process> StartModel() {
    const std::string models = std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/models";
    return StartModelProcess(naming_->address(), models + "/pendulum_tendon.dae", dir_.path(),
                             dir_.path() + "/model.out");
  }

  M::Model_var WaitForModel() { return testing::WaitForModel(naming_->address()); }

  std::unique_ptr<MainWindow> Window(const std::string& nameservice) {
    ModelLink::Options options;
    options.nameservice = nameservice;
    options.reconnect_period_ms = 300;
    auto w = std::make_unique<MainWindow>(std::make_unique<ModelLink>(options), 10.0);
    w->show();
    return w;
  }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::string settings_;
};

/// The lifecycle state of `instance` read over CORBA.
std::string StateOverCorba(const std::string& address, const std::string& instance) {
  namespace RTC = ::Caliper::RTC;
  try {
    CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), address);
    RTC::LightweightRTObject_var comp =
        RTC::LightweightRTObject::_narrow(rtc::FindComponent(root, instance).object);
    RTC::ExecutionContextList_var ecs = comp->get_owned_contexts();
    switch (ecs[0]->get_component_state(comp)) {
      case RTC::CREATED_STATE: return "CREATED";
      case RTC::INACTIVE_STATE: return "INACTIVE";
      case RTC::ACTIVE_STATE: return "ACTIVE";
      case RTC::ERROR_STATE: return "ERROR";
    }
  } catch (...) {
  }
  return "?";
}

/// The row of `instance` in the components panel, or nullptr.
QTreeWidgetItem* ComponentRow(MainWindow& w, const QString& instance) {
  auto* tree = w.findChild<QTreeWidget*>("components");
  for (int k = 0; k < tree->topLevelItemCount(); ++k)
    if (tree->topLevelItem(k)->text(0) == instance) return tree->topLevelItem(k);
  return nullptr;
}

TEST_F(MainWindowTest, ComponentsPanelShowsAndChangesLifecycleStatesAndTheSessionIsRestored) {
  auto process = StartModel();
  M::Model_var model = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(model)) << process->Output();
  auto w = Window(naming_->address());

  // the panel lists model0, ACTIVE
  ASSERT_TRUE(WaitInGui(
      [&] {
        QTreeWidgetItem* row = ComponentRow(*w, "model0");
        return row != nullptr && row->text(1) == "ACTIVE";
      },
      seconds(10)));

  // Deactivate: INACTIVE over CORBA and in the panel; Activate brings it back
  auto* tree = w->findChild<QTreeWidget*>("components");
  tree->setCurrentItem(ComponentRow(*w, "model0"));
  QTest::mouseClick(w->findChild<QPushButton*>("component_deactivate"), Qt::LeftButton);
  EXPECT_TRUE(WaitInGui([&] { return StateOverCorba(naming_->address(), "model0") == "INACTIVE"; },
                        seconds(5)));
  EXPECT_TRUE(WaitInGui([&] { return ComponentRow(*w, "model0")->text(1) == "INACTIVE"; },
                        seconds(5)));
  EXPECT_EQ(tree->currentItem(), ComponentRow(*w, "model0")) << "the selection stays";
  QTest::mouseClick(w->findChild<QPushButton*>("component_activate"), Qt::LeftButton);
  EXPECT_TRUE(WaitInGui([&] { return StateOverCorba(naming_->address(), "model0") == "ACTIVE"; },
                        seconds(5)));
  EXPECT_TRUE(WaitInGui([&] { return ComponentRow(*w, "model0")->text(1) == "ACTIVE"; },
                        seconds(5)));

  // the session file: geometry and the last model survive closing the window
  const QString scene =
      QString::fromStdString(std::string(std::getenv("CALIPER_SOURCE_DIR")) +
                             "/models/pendulum_tendon.dae");
  ASSERT_TRUE(WaitInGui([&] { return !w->last_model().isEmpty(); }, seconds(5)));
  EXPECT_EQ(QFileInfo(w->last_model()).canonicalFilePath(), QFileInfo(scene).canonicalFilePath());
  const QRect rect(40, 50, 1250, 720);
  w->setGeometry(rect);
  WaitInGui([] { return false; }, std::chrono::milliseconds(200));
  const QRect before = w->geometry();
  EXPECT_TRUE(w->close());
  w.reset();
  ASSERT_TRUE(QFileInfo::exists(QString::fromStdString(settings_)));

  auto restored = Window(naming_->address());
  WaitInGui([] { return false; }, std::chrono::milliseconds(200));
  EXPECT_EQ(restored->geometry(), before);
  EXPECT_EQ(restored->geometry().size(), rect.size());
  EXPECT_EQ(QFileInfo(restored->last_model()).canonicalFilePath(),
            QFileInfo(scene).canonicalFilePath());
  restored.reset();
  process->Signal(SIGTERM);
  EXPECT_EQ(process->Wait(seconds(10)), 0) << process->Output();
}

TEST_F(MainWindowTest, StartAModelStartsTheLastModelWhenNoneIsInReach) {
  const std::string models = std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/models";
  {
    QSettings st(QString::fromStdString(settings_), QSettings::IniFormat);
    st.setValue("model/last", QString::fromStdString(models + "/pendulum_tendon.dae"));
  }
  auto w = Window(naming_->address());
  auto* button = w->findChild<QPushButton*>("start_model");
  ASSERT_TRUE(WaitInGui([&] { return button->isVisible(); }, seconds(5)));
  QTest::mouseClick(button, Qt::LeftButton);
  ASSERT_TRUE(WaitInGui([&] { return w->ItemOf(kMassId) != nullptr; }, seconds(20)))
      << "the Model started by the window is found";
  EXPECT_FALSE(w->findChild<QLabel*>("no_model")->isVisible());
  EXPECT_FALSE(button->isVisible());
  w.reset();  // ends the Model it started
  EXPECT_TRUE(WaitFor(
      [&] {
        try {
          CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming_->address());
          return rtc::ListComponents(root).empty();
        } catch (...) {
          return false;
        }
      },
      seconds(10)))
      << "no stale model0 in the naming service";
}

TEST_F(MainWindowTest, StartAdvancesTheSimulatedTimeAndEditingAParameterReachesTheModel) {
  auto process = StartModel();
  M::Model_var model = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(model)) << process->Output();

  auto w = Window(naming_->address());
  ASSERT_TRUE(WaitInGui([&] { return w->ItemOf(kMassId) != nullptr; }, seconds(10)))
      << "the parameter tree is filled from the Model";
  EXPECT_FALSE(w->findChild<QLabel*>("no_model")->isVisible());
  const double t0 = SimTimeShown(*w);
  EXPECT_GE(t0, 0.0);

  // Start: the simulated time shown advances
  QTest::mouseClick(w->findChild<QPushButton*>("start"), Qt::LeftButton);
  ASSERT_TRUE(WaitInGui([&] { return SimTimeShown(*w) > t0 + 0.2; }, seconds(10)))
      << "shown: " << w->findChild<QLabel*>("sim_time")->text().toStdString();
  EXPECT_EQ(w->findChild<QLabel*>("state")->text().toStdString(), "RUNNING");

  // edit the pendulum's mass in place: double-click its value, type, Enter
  // (the Model keeps single-precision values: compare to 1e-6)
  auto* tree = w->findChild<QTreeWidget*>("parameters");
  QTreeWidgetItem* mass = w->ItemOf(kMassId);
  tree->scrollToItem(mass);
  QApplication::processEvents();
  const QRect cell = tree->visualItemRect(mass).intersected(
      QRect(tree->header()->sectionPosition(1), 0, tree->header()->sectionSize(1), 100000));
  QTest::mouseClick(tree->viewport(), Qt::LeftButton, Qt::NoModifier, cell.center());
  QTest::mouseDClick(tree->viewport(), Qt::LeftButton, Qt::NoModifier, cell.center());
  auto* editor = tree->viewport()->findChild<QLineEdit*>();
  ASSERT_NE(editor, nullptr) << "double-clicking a writable value opens an editor";
  editor->selectAll();
  QTest::keyClicks(editor, "0.9");
  QTest::keyClick(editor, Qt::Key_Return);

  auto mass_in_model = [&] {
    S::StringSeq ids;
    ids.length(1);
    ids[0] = kMassId;
    D::ValueSeq_var v = model->get(ids);
    return v[0].data[0];
  };
  ASSERT_TRUE(WaitInGui([&] { return std::abs(mass_in_model() - 0.9) < 1e-6; }, seconds(5)))
      << "the Model's mass is " << mass_in_model();
  EXPECT_TRUE(WaitInGui([&] { return mass->text(1) == "0.9"; }, seconds(3)))
      << "the tree shows " << mass->text(1).toStdString();


  WaitInGui([] { return false; }, std::chrono::milliseconds(600));
  const std::string png = ArtifactPath("main_window.png", dir_.path());
  EXPECT_TRUE(w->grab().save(QString::fromStdString(png))) << png;

  QTest::mouseClick(w->findChild<QPushButton*>("pause"), Qt::LeftButton);
  EXPECT_TRUE(WaitInGui(
      [&] {
        return M::SimulationStatus_var(model->status())->state == M::PAUSED;
      },
      seconds(5)));
  w.reset();
  process->Signal(SIGTERM);
  EXPECT_EQ(process->Wait(seconds(10)), 0) << process->Output();
}

TEST_F(MainWindowTest, SaysSoAndStaysResponsiveWithNoModelInReach) {
  // a naming service without a Model, then an address where nothing listens
  for (const std::string& address :
       {naming_->address(), "corbaname::127.0.0.1:" + std::to_string(FreePort())}) {
    SCOPED_TRACE(address);
    auto w = Window(address);
    auto* label = w->findChild<QLabel*>("no_model");
    ASSERT_TRUE(WaitInGui([&] { return label->isVisible() && label->text().contains("no Model"); },
                          seconds(5)))
        << label->text().toStdString();
    EXPECT_FALSE(w->findChild<QPushButton*>("start")->isEnabled());

    // the event loop keeps turning: no event waits long for several seconds of lookups
    const qint64 longest = LongestEventLoopStall(std::chrono::milliseconds(3000));
    EXPECT_LT(longest, 300) << "the GUI thread was blocked for " << longest << " ms";
    EXPECT_EQ(w->findChild<QLabel*>("state")->text().toStdString(), "no Model");
    QElapsedTimer closing;
    closing.start();
    w.reset();
    EXPECT_LT(closing.elapsed(), 3000) << "closing does not hang on the dead peer";
  }
}

TEST_F(MainWindowTest, AToolThatFailsIsReportedNotLostSilently) {
  auto w = Window(naming_->address());
  // a tool that refuses its arguments ends at once with exit code 2: the status bar says so
  w->SetToolArguments("plotter", {"--no-such-option"});
  ASSERT_TRUE(w->StartTool("plotter"));
  EXPECT_TRUE(WaitInGui(
      [&] { return w->statusBar()->currentMessage().contains("plotter ended with exit code 2"); },
      seconds(10)))
      << w->statusBar()->currentMessage().toStdString();
  EXPECT_TRUE(WaitInGui([&] { return w->OpenTools().isEmpty(); }, seconds(5)));
  EXPECT_FALSE(w->StartTool("no_such_tool"));
  EXPECT_TRUE(w->statusBar()->currentMessage().contains("unknown tool 'no_such_tool'"));
}

}  // namespace
}  // namespace caliper::testing
