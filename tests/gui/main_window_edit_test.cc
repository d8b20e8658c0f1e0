// Scene editing in the Main Window against a real caliper-model with models/ecce_arm.dae: the
// parameter tree and the Selection panel follow the Model's selection (and a tree row selects on
// the Model), an edit through the panel reaches the Model, Undo and Redo in the Edit menu are
// named after the edit and take it back and forth, a refused edit shows the Model's reason and
// changes nothing, an edit by another client enables Undo in the window, and a sensor delay is set
// on a joint's channel and taken back. Widgets run on QT_QPA_PLATFORM=offscreen.
#include <gtest/gtest.h>
#include <signal.h>

#include <QAction>
#include <QApplication>
#include <QComboBox>
#include <QDialog>
#include <QDoubleSpinBox>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QStatusBar>
#include <QTest>
#include <QTreeWidget>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "caliper/model.hh"
#include "main_window.h"
#include "model_link.h"
#include "support/gui_test.h"
#include "support/main_window_on_model.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;
namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;
using main_window::MainWindow;
using main_window::ModelLink;

class MainWindowEditTest : public ModelProcessTest {
 protected:
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(StartModelSession("models/ecce_arm.dae"));
    window_ = MainWindowOnModel(naming_->address(), 100);
    window_->show();
    ASSERT_TRUE(
        WaitInGui([&] { return window_->GroupOf("ecce_arm.forearm") != nullptr; }, seconds(10)))
        << "the parameter tree is filled from the Model";
  }

  void TearDown() override {
    window_.reset();
    StopModel();
  }

  double Get(const std::string& id) {
    S::StringSeq ids;
    ids.length(1);
    ids[0] = id.c_str();
    D::ValueSeq_var v = model_->get(ids);
    return v[0].data[0];
  }

  QString Status() { return window_->statusBar()->currentMessage(); }
  // whether the Selection panel's mass shows `kg` within 5 s
  bool PanelShowsMass(double kg) {
    return WaitInGui(
        [&] {
          auto* mass = window_->findChild<QDoubleSpinBox*>("selection_mass");
          return mass != nullptr && std::abs(mass->value() - kg) < 1e-9;
        },
        seconds(5));
  }
  template <typename T>
  T* Find(const char* name) {
    T* w = window_->findChild<T*>(name);
    EXPECT_NE(w, nullptr) << "no " << name;
    return w;
  }

  std::unique_ptr<MainWindow> window_;
};

TEST_F(MainWindowEditTest, TheTreeAndThePanelFollowTheModelsSelectionAndATreeRowSelects) {
  auto* tree = Find<QTreeWidget>("parameters");
  // another client (the renderer's pick) selects the forearm
  model_->select("body", "forearm", 0);
  ASSERT_TRUE(WaitInGui([&] { return tree->currentItem() == window_->GroupOf("ecce_arm.forearm"); },
                        seconds(5)))
      << "current row: "
      << (tree->currentItem() ? tree->currentItem()->text(0).toStdString() : "none");
  EXPECT_TRUE(tree->currentItem()->isSelected());
  EXPECT_TRUE(tree->currentItem()->isExpanded());
  EXPECT_TRUE(Status().contains("selected body forearm")) << Status().toStdString();
  EXPECT_EQ(Find<QLabel>("selection_title")->text().toStdString(), "Body forearm");

  // a tendon: its row and its actuator's rows
  model_->select("tendon", "elbow_flexor", 0);
  ASSERT_TRUE(WaitInGui(
      [&] { return tree->currentItem() == window_->GroupOf("ecce_arm.elbow_flexor.tendon"); },
      seconds(5)));
  EXPECT_TRUE(window_->GroupOf("ecce_arm.elbow_flexor")->isSelected()) << "the actuator's row";
  EXPECT_FALSE(window_->GroupOf("ecce_arm.forearm")->isSelected()) << "the last selection went";
  EXPECT_TRUE(Find<QPushButton>("remove_tendon")->isVisible());

  // a via point: its tendon's rows, its position in mm in the panel
  model_->select("path_point", "elbow_flexor", 1);
  ASSERT_TRUE(
      WaitInGui([&] { return Status().contains("via point 1 of elbow_flexor"); }, seconds(5)))
      << Status().toStdString();
  EXPECT_TRUE(Status().contains("(44, -10, -200) mm in upper_arm")) << Status().toStdString();
  auto* z = Find<QDoubleSpinBox>("point_z");
  ASSERT_NE(z, nullptr);
  EXPECT_NEAR(z->value(), -200.0, 1e-9);

  // choosing the hand's row in the tree selects it on the Model
  tree->setCurrentItem(window_->GroupOf("ecce_arm.hand"));
  EXPECT_TRUE(WaitInGui(
      [&] {
        M::Selection_var s = model_->current_selection();
        return std::string(s->kind.in()) == "body" && std::string(s->name.in()) == "hand";
      },
      seconds(5)));
  EXPECT_TRUE(WaitInGui([&] { return Find<QLabel>("selection_title")->text() == "Body hand"; },
                        seconds(5)));
  EXPECT_EQ(tree->currentItem(), window_->GroupOf("ecce_arm.hand")) << "the row chosen stays";
}

TEST_F(MainWindowEditTest, ASceneWhoseNameIsNotIdSafeIsFollowedByItsDaqIds) {
  // the arm renamed "ECCE Arm", sent by content: its channels start with the id-safe ecce_arm.
  const char* source = std::getenv("CALIPER_SOURCE_DIR");
  ASSERT_NE(source, nullptr);
  std::string text = ReadFile(std::string(source) + "/models/ecce_arm.dae");
  const std::string from = "<visual_scene id=\"visual_scene\" name=\"ecce_arm\">";
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, from.size(), "<visual_scene id=\"visual_scene\" name=\"ECCE Arm\">");
  M::Octets data(static_cast<CORBA::ULong>(text.size()));
  data.length(static_cast<CORBA::ULong>(text.size()));
  std::copy(text.begin(), text.end(), reinterpret_cast<char*>(data.get_buffer()));
  model_->set_mass("forearm", 1.25);  // the load forgets it: the panel must show the file's 1.0
  model_->load_scene_data("renamed_arm.dae", data);
  ASSERT_STREQ(S::Description_var(model_->scene_description())->name.in(), "ECCE Arm");
  // the tree follows the Model's selection by the DAQ's ids, and the panel reads the mass there
  auto* tree = Find<QTreeWidget>("parameters");
  model_->select("body", "forearm", 0);
  EXPECT_TRUE(WaitInGui(
      [&] {
        return window_->GroupOf("ecce_arm.forearm") != nullptr &&
               tree->currentItem() == window_->GroupOf("ecce_arm.forearm");
      },
      seconds(10)))
      << "current row: "
      << (tree->currentItem() ? tree->currentItem()->text(0).toStdString() : "none");
  EXPECT_TRUE(PanelShowsMass(1.0))
      << "the panel shows the forearm's mass from ecce_arm.forearm.mass";
  // a joint's Sensor delay row offers its channels
  model_->select("constraint", "elbow", 0);
  EXPECT_TRUE(WaitInGui(
      [&] {
        auto* combo = window_->findChild<QComboBox*>("delay_channel");
        return combo != nullptr && combo->findData("ecce_arm.elbow.position") >= 0;
      },
      seconds(5)));
}

TEST_F(MainWindowEditTest, MassEditUndoRedoAndARefusedEdit) {
  auto* undo = Find<QAction>("undo");
  auto* redo = Find<QAction>("redo");
  ASSERT_TRUE(undo && redo);
  EXPECT_FALSE(undo->isEnabled()) << "nothing to undo in a fresh scene";
  EXPECT_FALSE(redo->isEnabled());
  EXPECT_NEAR(Get("ecce_arm.forearm.mass"), 1.0, 1e-6);

  model_->select("body", "forearm", 0);
  ASSERT_TRUE(PanelShowsMass(1.0)) << "the panel shows the forearm's mass";

  // an edit through the panel
  Find<QDoubleSpinBox>("selection_mass")->setValue(1.3);
  QTest::mouseClick(Find<QPushButton>("apply_mass"), Qt::LeftButton);
  ASSERT_TRUE(
      WaitInGui([&] { return std::abs(Get("ecce_arm.forearm.mass") - 1.3) < 1e-6; }, seconds(5)))
      << Get("ecce_arm.forearm.mass");
  ASSERT_TRUE(WaitInGui([&] { return undo->isEnabled(); }, seconds(5)));
  EXPECT_EQ(undo->text().toStdString(), "&Undo set the mass of forearm to 1.3 kg");
  EXPECT_FALSE(redo->isEnabled());

  // Undo from the Edit menu: the mass is back; Redo: again
  undo->trigger();
  ASSERT_TRUE(
      WaitInGui([&] { return std::abs(Get("ecce_arm.forearm.mass") - 1.0) < 1e-6; }, seconds(5)));
  ASSERT_TRUE(WaitInGui([&] { return redo->isEnabled(); }, seconds(5)));
  EXPECT_EQ(redo->text().toStdString(), "&Redo set the mass of forearm to 1.3 kg");
  EXPECT_FALSE(undo->isEnabled());
  EXPECT_TRUE(PanelShowsMass(1.0)) << "the panel shows the Model's mass again";
  redo->trigger();
  ASSERT_TRUE(
      WaitInGui([&] { return std::abs(Get("ecce_arm.forearm.mass") - 1.3) < 1e-6; }, seconds(5)));
  ASSERT_TRUE(WaitInGui([&] { return undo->isEnabled() && !redo->isEnabled(); }, seconds(5)));

  // a negative mass: the Model's reason in the status bar, nothing changed
  const auto revision = M::EditStatus_var(model_->edit_status())->revision;
  Find<QDoubleSpinBox>("selection_mass")->setValue(-2);
  QTest::mouseClick(Find<QPushButton>("apply_mass"), Qt::LeftButton);
  std::string reason;
  try {
    model_->set_mass("forearm", -2);
  } catch (const M::EditRefused& e) {
    reason = e.reason.in();
  }
  ASSERT_FALSE(reason.empty()) << "the Model refuses a negative mass";
  EXPECT_TRUE(
      WaitInGui([&] { return Status().contains(QString::fromStdString(reason)); }, seconds(5)))
      << "status bar: " << Status().toStdString() << "; reason: " << reason;
  EXPECT_EQ(M::EditStatus_var(model_->edit_status())->revision, revision);
  EXPECT_NEAR(Get("ecce_arm.forearm.mass"), 1.3, 1e-6);
  EXPECT_EQ(undo->text().toStdString(), "&Undo set the mass of forearm to 1.3 kg");

  // a refused undo (nothing left) says why too
  undo->trigger();
  ASSERT_TRUE(
      WaitInGui([&] { return std::abs(Get("ecce_arm.forearm.mass") - 1.0) < 1e-6; }, seconds(5)));
  ASSERT_TRUE(WaitInGui([&] { return !undo->isEnabled(); }, seconds(5)));
  window_->link().Undo();  // as a shortcut pressed before the menu caught up would
  EXPECT_TRUE(WaitInGui([&] { return Status().contains("undo: nothing to undo"); }, seconds(5)))
      << Status().toStdString();
}

TEST_F(MainWindowEditTest, AnEditByAnotherClientEnablesUndoAndUndoPutsTheViaPointBack) {
  auto path_point = [&](const char* tendon, CORBA::ULong index) {
    S::Description_var d = model_->scene_description();
    for (CORBA::ULong k = 0; k < d->tendons.length(); ++k)
      if (std::string(d->tendons[k].name.in()) == tendon)
        return S::PathPoint(d->tendons[k].path[index]);
    ADD_FAILURE() << "no tendon " << tendon;
    return S::PathPoint();
  };
  const S::PathPoint before = path_point("elbow_flexor", 1);
  ASSERT_STREQ(before.body.in(), "upper_arm");

  S::PathPoint moved = before;
  moved.x = 0.05;
  moved.z = -0.18;
  M::EditStatus_var edited = model_->move_path_point("elbow_flexor", 1, moved);
  const std::string label = edited->undo.in();
  EXPECT_NE(label.find("via point 1 of elbow_flexor"), std::string::npos) << label;

  auto* undo = Find<QAction>("undo");
  ASSERT_TRUE(WaitInGui([&] { return undo->isEnabled(); }, seconds(5)))
      << "the window learns the edit from its status poll";
  EXPECT_EQ(undo->text().toStdString(), "&Undo " + label);
  EXPECT_NEAR(path_point("elbow_flexor", 1).x, 0.05, 1e-12);

  // the panel shows the moved point once it is selected
  model_->select("path_point", "elbow_flexor", 1);
  ASSERT_TRUE(WaitInGui(
      [&] {
        auto* x = window_->findChild<QDoubleSpinBox*>("point_x");
        return x != nullptr && std::abs(x->value() - 50.0) < 1e-9;
      },
      seconds(5)));

  undo->trigger();
  ASSERT_TRUE(WaitInGui([&] { return !undo->isEnabled(); }, seconds(5)));
  const S::PathPoint after = path_point("elbow_flexor", 1);
  EXPECT_STREQ(after.body.in(), before.body.in());
  EXPECT_EQ(after.x, before.x);
  EXPECT_EQ(after.y, before.y);
  EXPECT_EQ(after.z, before.z);
  EXPECT_TRUE(WaitInGui(
      [&] {
        return std::abs(window_->findChild<QDoubleSpinBox*>("point_x")->value() - 44.0) < 1e-9;
      },
      seconds(5)))
      << "the panel shows the point back in place";

  // moving it through the panel: the Model's path takes the typed millimetres
  window_->findChild<QDoubleSpinBox*>("point_y")->setValue(-12);
  QTest::mouseClick(Find<QPushButton>("apply_point"), Qt::LeftButton);
  EXPECT_TRUE(WaitInGui([&] { return std::abs(path_point("elbow_flexor", 1).y + 0.012) < 1e-12; },
                        seconds(5)));
}

// an edit that takes longer than a short call (a big scene's rebuild; here a Model stopped for
// 0.8 s) is waited for with the long timeout, not reported failed although the Model applied it
TEST_F(MainWindowEditTest, AnEditSlowerThanAShortCallIsWaitedFor) {
  ModelLink::Options options;
  options.nameservice = naming_->address();
  options.call_timeout_ms = 300;
  options.poll_period_ms = 60000;        // no poll while the Model is stopped: only the edit
  options.components_period_ms = 60000;  // waits on it
  ModelLink link(options);
  ASSERT_TRUE(WaitInGui([&] { return link.snapshot().connected; }, seconds(10)));
  const CORBA::ULongLong revision = M::EditStatus_var(model_->edit_status())->revision;
  const main_window::Snapshot before = link.snapshot();
  link.SetMass("forearm", 1.25);
  process_->Signal(SIGSTOP);
  QTest::qWait(800);
  process_->Signal(SIGCONT);
  ASSERT_TRUE(
      WaitInGui([&] { return link.snapshot().commands_done > before.commands_done; }, seconds(10)));
  EXPECT_EQ(link.snapshot().error_serial, before.error_serial) << link.snapshot().last_error;
  EXPECT_EQ(M::EditStatus_var(model_->edit_status())->revision, revision + 1);
}

TEST_F(MainWindowEditTest, AddTendonAndRemoveItThroughThePanel) {
  model_->select("body", "upper_arm", 0);
  ASSERT_TRUE(WaitInGui([&] { return Find<QLabel>("selection_title")->text() == "Body upper_arm"; },
                        seconds(5)));
  QTest::mouseClick(Find<QPushButton>("add_tendon"), Qt::LeftButton);
  auto* dialog = window_->findChild<QDialog*>("add_tendon_dialog");
  ASSERT_NE(dialog, nullptr);
  EXPECT_EQ(dialog->findChild<QComboBox*>("from_body")->currentText().toStdString(), "upper_arm")
      << "the selected body is the first end";
  auto* kind = dialog->findChild<QComboBox*>("actuator_kind");
  const int ligament = kind->findText("ligament");
  ASSERT_GE(ligament, 0) << "the Model's kinds are offered";
  kind->setCurrentIndex(ligament);
  dialog->findChild<QLineEdit*>("tendon_name")->setText("test_strap");
  dialog->findChild<QLineEdit*>("actuator_name")->setText("test_strap");
  dialog->findChild<QComboBox*>("to_body")->setCurrentText("forearm");
  dialog->findChild<QDoubleSpinBox*>("from_z")->setValue(-250);
  dialog->findChild<QDoubleSpinBox*>("to_z")->setValue(-40);
  dialog->accept();

  auto has_tendon = [&](const char* name) {
    S::Description_var d = model_->scene_description();
    for (CORBA::ULong k = 0; k < d->tendons.length(); ++k)
      if (std::string(d->tendons[k].name.in()) == name) return true;
    return false;
  };
  ASSERT_TRUE(WaitInGui([&] { return has_tendon("test_strap"); }, seconds(5)))
      << Status().toStdString();
  EXPECT_TRUE(
      WaitInGui([&] { return window_->GroupOf("ecce_arm.test_strap") != nullptr; }, seconds(5)))
      << "the new actuator's parameters appear in the tree";

  model_->select("tendon", "test_strap", 0);
  ASSERT_TRUE(WaitInGui(
      [&] { return window_->findChild<QPushButton*>("remove_tendon") != nullptr; }, seconds(5)));
  QTest::mouseClick(Find<QPushButton>("remove_tendon"), Qt::LeftButton);
  EXPECT_TRUE(WaitInGui([&] { return !has_tendon("test_strap"); }, seconds(5)));
}

TEST_F(MainWindowEditTest, ASensorDelayOnAJointThroughThePanelAndUndo) {
  auto has_channel = [&](const char* id) {
    D::ChannelInfoSeq_var list = model_->list(id);
    return list->length() == 1;
  };
  auto combo = [&] { return window_->findChild<QComboBox*>("delay_channel"); };
  model_->select("constraint", "elbow", 0);
  ASSERT_TRUE(WaitInGui([&] { return combo() != nullptr && combo()->count() > 0; }, seconds(5)))
      << "a joint's panel offers its sensors";
  const int position = combo()->findData("ecce_arm.elbow.position");
  ASSERT_GE(position, 0) << combo()->itemText(0).toStdString();
  EXPECT_EQ(combo()->itemText(position).toStdString(), "ecce_arm.elbow.position [rad]");
  for (int k = 0; k < combo()->count(); ++k)  // its states only: no parameter, no command
    EXPECT_TRUE(combo()->itemData(k).toString().startsWith("ecce_arm.elbow."))
        << combo()->itemData(k).toString().toStdString();
  combo()->setCurrentIndex(position);
  Find<QDoubleSpinBox>("delay_ms")->setValue(20);
  QTest::mouseClick(Find<QPushButton>("apply_delay"), Qt::LeftButton);
  ASSERT_TRUE(
      WaitInGui([&] { return has_channel("ecce_arm.elbow.position.undelayed"); }, seconds(5)))
      << Status().toStdString();
  auto* undo = Find<QAction>("undo");
  ASSERT_TRUE(WaitInGui([&] { return undo->isEnabled(); }, seconds(5)));
  EXPECT_EQ(undo->text().toStdString(), "&Undo delay elbow.position by 20 ms");
  // the scene description carries the delay, with the channel as the DAQ lists it
  {
    S::Description_var d = model_->scene_description();
    ASSERT_EQ(d->sensor_delays.length(), 1u);
    EXPECT_STREQ(d->sensor_delays[0].id.in(), "ecce_arm.elbow.position");
    EXPECT_DOUBLE_EQ(d->sensor_delays[0].delay, 0.02);
    // and so does the call that lists the delays alone
    S::SensorDelaySeq_var delays = model_->measurement_delays();
    ASSERT_EQ(delays->length(), 1u);
    EXPECT_STREQ(delays[0].id.in(), "ecce_arm.elbow.position");
    EXPECT_DOUBLE_EQ(delays[0].delay, 0.02);
  }
  // the panel, rebuilt with the new channels, marks the delayed one with its delay and does not
  // offer its undelayed twin
  const QString delayed_text = "ecce_arm.elbow.position [rad] (20 ms late)";
  EXPECT_TRUE(WaitInGui([&] { return combo() != nullptr && combo()->findText(delayed_text) >= 0; },
                        seconds(5)));
  EXPECT_LT(combo()->findData("ecce_arm.elbow.position.undelayed"), 0);
  // the spin box shows the chosen channel's delay: 20 ms, then 0 for an undelayed one
  combo()->setCurrentIndex(combo()->findData("ecce_arm.elbow.position"));
  EXPECT_DOUBLE_EQ(Find<QDoubleSpinBox>("delay_ms")->value(), 20);
  const int other = combo()->findData("ecce_arm.elbow.velocity");
  ASSERT_GE(other, 0);
  combo()->setCurrentIndex(other);
  EXPECT_DOUBLE_EQ(Find<QDoubleSpinBox>("delay_ms")->value(), 0);

  // too long (beyond 1000 steps): the Model's reason in the status bar, nothing changed
  const auto revision = M::EditStatus_var(model_->edit_status())->revision;
  combo()->setCurrentIndex(combo()->findData("ecce_arm.elbow.position"));
  Find<QDoubleSpinBox>("delay_ms")->setValue(20000);
  QTest::mouseClick(Find<QPushButton>("apply_delay"), Qt::LeftButton);
  EXPECT_TRUE(WaitInGui(
      [&] { return Status().contains("elbow.position': delay must be in [0, 10] s, not 20"); },
      seconds(5)))
      << Status().toStdString();
  EXPECT_FALSE(Status().contains("20.0")) << "the value as typed: " << Status().toStdString();
  EXPECT_EQ(M::EditStatus_var(model_->edit_status())->revision, revision);

  undo->trigger();
  EXPECT_TRUE(
      WaitInGui([&] { return !has_channel("ecce_arm.elbow.position.undelayed"); }, seconds(5)));
  EXPECT_EQ(S::Description_var(model_->scene_description())->sensor_delays.length(), 0u);
  EXPECT_EQ(S::SensorDelaySeq_var(model_->measurement_delays())->length(), 0u);
  EXPECT_TRUE(WaitInGui(
      [&] {
        return combo() != nullptr && combo()->findText(delayed_text) < 0 &&
               combo()->findText("ecce_arm.elbow.position [rad]") >= 0;
      },
      seconds(5)))
      << "the mark goes with the delay";

  // a tendon's panel offers its actuator's sensors too
  model_->select("tendon", "elbow_flexor", 0);
  EXPECT_TRUE(WaitInGui(
      [&] { return combo() != nullptr && combo()->findData("ecce_arm.elbow_flexor.current") >= 0; },
      seconds(5)));
}

}  // namespace
}  // namespace caliper::testing
