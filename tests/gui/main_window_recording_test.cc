// Record and replay in the Main Window against a real caliper-model with models/ecce_arm.dae: the
// Record button records into the Model's write directory and stops, the status bar names the file;
// File > Open recording shows the timeline over the recording's times; dragging the slider seeks
// the Model (the last position always reaches it); Start plays to the end with the slider
// following; Fork hides the timeline and the Model takes commands again. The file dialogs are
// replaced by a chooser the test sets. Widgets run on QT_QPA_PLATFORM=offscreen.
#include <gtest/gtest.h>

#include <QAction>
#include <QApplication>
#include <QDoubleSpinBox>
#include <QFileInfo>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QStatusBar>
#include <QTest>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <set>
#include <string>

#include "caliper/model.hh"
#include "main_window.h"
#include "support/gui_test.h"
#include "support/main_window_on_model.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;
namespace M = ::Caliper::Simulation;
using main_window::MainWindow;

class MainWindowRecordingTest : public ModelProcessTest {
 protected:
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(StartModelSession("models/ecce_arm.dae"));
    window_ = MainWindowOnModel(naming_->address(), 50);
    window_->SetFileChooser([this](bool save, const QString&, const QString& suggested) {
      (save ? saves_ : opens_) << suggested;
      return save ? record_to_ : open_;
    });
    window_->show();
    record_ = window_->findChild<QPushButton*>("record");
    ASSERT_NE(record_, nullptr);
    ASSERT_TRUE(WaitInGui([&] { return record_->isEnabled(); }, seconds(10)))
        << "the Record button is enabled once the Model answers recording_status()";
  }

  void TearDown() override {
    window_.reset();
    StopModel();
  }

  QString Status() { return window_->statusBar()->currentMessage(); }
  QString RecordingLabel() { return window_->findChild<QLabel*>("recording")->text(); }
  template <typename T>
  T* Find(const char* name) {
    T* w = window_->findChild<T*>(name);
    EXPECT_NE(w, nullptr) << "no " << name;
    return w;
  }
  M::ReplayStatus Replay() { return M::ReplayStatus_var(model_->replay_status()).in(); }

  std::unique_ptr<MainWindow> window_;
  QPushButton* record_ = nullptr;
  QString record_to_;  // what the chooser answers
  QString open_;
  QStringList saves_;  // what the window suggested
  QStringList opens_;
};

TEST_F(MainWindowRecordingTest, RecordOpenSeekPlayAndFork) {
  const std::string file = dir_.path() + "/session-20261125-073808-elbow-flexor-steps.caliper";
  record_to_ = QString::fromStdString(file);
  model_->pause();
  model_->set_command("elbow_flexor", 6.0);

  // Record: the chooser is offered a session-*.caliper in the Model's write directory
  QTest::mouseClick(record_, Qt::LeftButton);
  ASSERT_EQ(saves_.size(), 1);
  const QFileInfo suggested(saves_.front());
  EXPECT_EQ(suggested.absolutePath().toStdString(),
            QFileInfo(QString::fromStdString(dir_.path())).absoluteFilePath().toStdString());
  EXPECT_TRUE(suggested.fileName().startsWith("session-") &&
              suggested.fileName().endsWith(".caliper"))
      << suggested.fileName().toStdString();
  ASSERT_TRUE(WaitInGui(
      [&] {
        M::RecordStatus_var r = model_->recording_status();
        return r->recording &&
               std::string(r->path.in())
                       .find("session-20261125-073808-elbow-flexor-steps.caliper") !=
                   std::string::npos;
      },
      seconds(5)))
      << Status().toStdString();
  ASSERT_TRUE(WaitInGui([&] { return record_->isChecked(); }, seconds(5)));
  EXPECT_TRUE(WaitInGui(
      [&] {
        return RecordingLabel().startsWith(
            "recording session-20261125-073808-elbow-flexor-steps.caliper (");
      },
      seconds(5)))
      << RecordingLabel().toStdString();

  // 500 steps with the command changed half way
  model_->step(250);
  model_->set_command("elbow_flexor", 2.0);
  model_->step(250);
  EXPECT_TRUE(WaitInGui([&] { return RecordingLabel().contains(", 0.5 s)"); }, seconds(5)))
      << RecordingLabel().toStdString();

  // pressing again stops it
  QTest::mouseClick(record_, Qt::LeftButton);
  ASSERT_TRUE(WaitInGui([&] { return !M::RecordStatus_var(model_->recording_status())->recording; },
                        seconds(5)));
  EXPECT_TRUE(
      WaitInGui([&] { return !record_->isChecked() && RecordingLabel().isEmpty(); }, seconds(5)))
      << RecordingLabel().toStdString();
  EXPECT_EQ(saves_.size(), 1) << "stopping asks for no file";
  ASSERT_TRUE(QFileInfo::exists(QString::fromStdString(file)));

  // File > Open recording: the timeline over the recording
  open_ = QString::fromStdString(file);
  auto* timeline = Find<QWidget>("timeline");
  auto* slider = Find<QSlider>("timeline_slider");
  auto* label = Find<QLabel>("timeline_time");
  ASSERT_TRUE(timeline && slider && label);
  EXPECT_FALSE(timeline->isVisible());
  Find<QAction>("open_recording")->trigger();
  ASSERT_TRUE(WaitInGui([&] { return timeline->isVisible(); }, seconds(10)))
      << Status().toStdString();
  const M::ReplayStatus opened = Replay();
  ASSERT_TRUE(opened.replaying);
  // the 500 steps recorded (no channels) replay to the step the recording stopped at
  const int span = static_cast<int>(opened.last_step - opened.first_step);
  EXPECT_EQ(span, 500);
  EXPECT_EQ(slider->minimum(), 0);
  EXPECT_EQ(slider->maximum(), span);
  EXPECT_EQ(slider->value(), 0);
  EXPECT_TRUE(label->text().endsWith(QString(" / %1 s").arg(opened.end_time, 0, 'f', 3)))
      << label->text().toStdString() << " end " << opened.end_time;
  EXPECT_TRUE(window_->windowTitle().contains(
      "replaying session-20261125-073808-elbow-flexor-steps.caliper"))
      << window_->windowTitle().toStdString();
  EXPECT_FALSE(record_->isEnabled()) << "no recording while replaying";
  EXPECT_FALSE(Find<QDoubleSpinBox>("time_step")->isEnabled()) << "a replay keeps its step";
  // the row fits a window as narrow as the arranged one (about 640 px on a 1600 px screen),
  // where a long file name once pushed Fork out of view
  EXPECT_LE(timeline->minimumSizeHint().width(), 640);
  // commands are refused until the fork
  EXPECT_THROW(model_->set_command("elbow_flexor", 1.0), M::NotAvailable);

  const double dt = (opened.end_time - opened.start_time) / span;
  // moving the slider to the middle seeks there
  slider->setValue(span / 2);
  const double middle = window_->TimelineTime(span / 2);
  EXPECT_NEAR(middle, opened.start_time + (span / 2) * dt, 1e-9);
  ASSERT_TRUE(WaitInGui([&] { return std::abs(Replay().time - middle) <= dt * 1.001; }, seconds(5)))
      << "Model at " << Replay().time << " s, slider at " << middle << " s";
  EXPECT_EQ(slider->value(), span / 2) << "the slider stays where it was put";

  // a fast drag: many positions within a few ms, the last one reaches the Model
  for (int v = span / 2; v <= span; v += 2) slider->setValue(v);
  slider->setValue(123);
  const double last = window_->TimelineTime(123);
  ASSERT_TRUE(WaitInGui([&] { return std::abs(Replay().time - last) <= dt * 1.001; }, seconds(5)))
      << "Model at " << Replay().time << " s, last slider position " << last << " s";
  EXPECT_TRUE(WaitInGui([&] { return slider->value() == 123; }, seconds(2)));

  // Start at half speed (the real-time factor box): plays to the end, the slider follows
  auto* rtf = Find<QDoubleSpinBox>("real_time_factor");
  rtf->setValue(0.5);
  emit rtf->editingFinished();
  ASSERT_TRUE(WaitInGui([&] { return std::abs(model_->status()->real_time_factor - 0.5) < 1e-9; },
                        seconds(5)));
  QTest::mouseClick(Find<QPushButton>("start"), Qt::LeftButton);
  std::set<int> seen;
  ASSERT_TRUE(WaitInGui(
      [&] {
        seen.insert(slider->value());
        return slider->value() == span;
      },
      seconds(10)))
      << "slider at " << slider->value() << ", Model at step " << Replay().step;
  EXPECT_EQ(Replay().step, opened.last_step) << "the replay pauses at its end";
  EXPECT_GE(seen.size(), 3u) << "the slider moved with the replay, not in one jump";
  EXPECT_TRUE(label->text().startsWith(QString("%1 / ").arg(opened.end_time, 0, 'f', 3)))
      << label->text().toStdString();

  // Fork: the timeline goes, the Model takes commands again
  QTest::mouseClick(Find<QPushButton>("fork"), Qt::LeftButton);
  ASSERT_TRUE(WaitInGui([&] { return !timeline->isVisible(); }, seconds(5)));
  EXPECT_FALSE(Replay().replaying);
  EXPECT_NO_THROW(model_->set_command("elbow_flexor", 1.0));
  EXPECT_TRUE(WaitInGui([&] { return record_->isEnabled(); }, seconds(5)));
  EXPECT_EQ(window_->windowTitle().toStdString(), "Caliper");
  EXPECT_TRUE(Find<QDoubleSpinBox>("time_step")->isEnabled());
}

TEST_F(MainWindowRecordingTest, ARefusedFileShowsTheModelsReasonAndACancelRecordsNothing) {
  // cancelled: nothing recorded, the button stays up
  record_to_.clear();
  QTest::mouseClick(record_, Qt::LeftButton);
  EXPECT_FALSE(record_->isChecked());
  EXPECT_FALSE(M::RecordStatus_var(model_->recording_status())->recording);

  // outside the Model's write directory: refused with the Model's reason
  record_to_ = "/proc/not-here.caliper";
  QTest::mouseClick(record_, Qt::LeftButton);
  ASSERT_TRUE(WaitInGui([&] { return Status().startsWith("record to /proc/not-here.caliper: "); },
                        seconds(5)))
      << Status().toStdString();
  EXPECT_FALSE(record_->isChecked());
  EXPECT_FALSE(M::RecordStatus_var(model_->recording_status())->recording);
  EXPECT_TRUE(RecordingLabel().isEmpty()) << RecordingLabel().toStdString();

  // not a recording: open refused with the Model's reason, no timeline
  open_ = QString::fromStdString(std::string(std::getenv("CALIPER_SOURCE_DIR")) +
                                 "/models/ecce_arm.dae");
  Find<QAction>("open_recording")->trigger();
  ASSERT_TRUE(WaitInGui([&] { return Status().startsWith("open recording "); }, seconds(10)))
      << Status().toStdString();
  EXPECT_FALSE(Find<QWidget>("timeline")->isVisible());
  EXPECT_FALSE(Replay().replaying);
}

}  // namespace
}  // namespace caliper::testing
