#include "support/gui_test.h"

#include <signal.h>

#include <QElapsedTimer>
#include <algorithm>
#include <QTest>
#include <cstdlib>

#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"

namespace caliper::testing {

QApplication& App() {
  static int argc = 1;
  static char name[] = "caliper_gui_test";
  static char* argv[] = {name, nullptr};
  if (std::getenv("QT_QPA_PLATFORM") == nullptr) qputenv("QT_QPA_PLATFORM", "offscreen");
  // never destroyed: Qwt's widgets outlive a function-local static QApplication's destructor
  // at exit (it would run after Qt's thread storage is gone)
  static QApplication* app = new QApplication(argc, argv);
  return *app;
}

CORBA::ORB_ptr Orb() {
  static CORBA::ORB_ptr orb = rtc::ClientOrb("caliper_gui_test");  // as the GUI programs have it
  return orb;
}

bool WaitInGui(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
  QElapsedTimer t;
  t.start();
  while (t.elapsed() < timeout.count()) {
    QApplication::processEvents(QEventLoop::AllEvents, 50);
    if (condition()) return true;
    QTest::qWait(50);
  }
  return condition();
}

qint64 LongestEventLoopStall(std::chrono::milliseconds duration) {
  QElapsedTimer t;
  t.start();
  qint64 longest = 0;
  while (t.elapsed() < duration.count()) {
    QElapsedTimer one;
    one.start();
    QApplication::processEvents(QEventLoop::AllEvents, 20);
    longest = std::max(longest, one.elapsed());
    QTest::qWait(20);
  }
  return longest;
}

std::string ArtifactPath(const std::string& name, const std::string& fallback_dir) {
  return ArtifactDir(fallback_dir) + "/" + name;
}

std::string ArtifactDir(const std::string& fallback_dir) {
  const char* dir = std::getenv("CALIPER_ARTIFACT_DIR");
  return dir != nullptr && *dir != '\0' ? std::string(dir) : fallback_dir;
}

std::unique_ptr<Process> StartModelProcess(const std::string& address, const std::string& scene,
                                           const std::string& dir, const std::string& output) {
  // load_scene reads the shipped models, the test data and the test's own files
  const char* source = std::getenv("CALIPER_SOURCE_DIR");
  const std::string root = source != nullptr ? source : ".";
  return std::make_unique<Process>(
      std::vector<std::string>{Bin("caliper-model"), "-o", "model.scene=" + scene, "-o",
                               "exec.auto_activate=true", "--nameservice", address, "-o",
                               "log.service=none", "-o", "log.spool_dir=" + dir + "/spool", "-o",
                               "model.read_dirs=" + root + "/models:" + root + "/tests/data", "-o",
                               "model.write_dir=" + dir},
      output);
}

::Caliper::Simulation::Model_ptr WaitForModel(const std::string& address,
                                              const std::string& instance) {
  namespace M = ::Caliper::Simulation;
  M::Model_var model;
  WaitFor(
      [&] {
        try {
          CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), address);
          model = M::Model::_narrow(rtc::FindComponent(root, instance).object);
          return !CORBA::is_nil(model) && !model->_non_existent();
        } catch (...) {
          return false;
        }
      },
      std::chrono::seconds(20));
  return model._retn();
}

void ModelProcessTest::StartModelSession(const std::string& scene) {
  App();
  Orb();
  naming_ = std::make_unique<NamingService>(dir_.path());
  qputenv("CALIPER_MAIN_SETTINGS", QByteArray::fromStdString(dir_.path() + "/caliper-main.ini"));
  const char* source = std::getenv("CALIPER_SOURCE_DIR");
  process_ = StartModelProcess(naming_->address(),
                               std::string(source != nullptr ? source : ".") + "/" + scene,
                               dir_.path(), dir_.path() + "/model.out");
  model_ = WaitForModel(naming_->address());
  ASSERT_FALSE(CORBA::is_nil(model_)) << process_->Output();
}

void ModelProcessTest::StopModel() {
  if (!process_) return;
  process_->Signal(SIGTERM);
  EXPECT_EQ(process_->Wait(std::chrono::seconds(10)), 0) << process_->Output();
}

}  // namespace caliper::testing
