#include "support/gui_test.h"

#include <QElapsedTimer>
#include <QTest>
#include <cstdlib>

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
  static CORBA::ORB_ptr orb = [] {
    int argc = 3;
    const char* args[] = {"caliper_gui_test", "-ORBendPoint", "giop:tcp:127.0.0.1:"};
    return CORBA::ORB_init(argc, const_cast<char**>(args));
  }();
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

std::string ArtifactPath(const std::string& name, const std::string& fallback_dir) {
  const char* dir = std::getenv("CALIPER_ARTIFACT_DIR");
  return (dir != nullptr && *dir != '\0' ? std::string(dir) : fallback_dir) + "/" + name;
}

}  // namespace caliper::testing
