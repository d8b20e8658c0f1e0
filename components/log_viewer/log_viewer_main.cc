// caliper-logviewer: the Log Viewer, a plain Qt client of the Logging component (no component
// lifecycle of its own). See kUsage.

#include <QApplication>
#include <QTimer>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "caliper/gui_session/tool_window.h"
#include "caliper/rtc/client_orb.h"
#include "log_viewer_window.h"

namespace {

constexpr const char* kUsage =
    "usage: caliper-logviewer [--nameservice corbaname::HOST:PORT] [--logger INSTANCE]\n"
    "                         [--geometry WxH+X+Y] [--session FILE] [--live] [LOG_FILE]\n"
    "\n"
    "Browses and filters Caliper log records: follows the Logging component live, or shows a\n"
    "past session's log file.\n"
    "\n"
    "  LOG_FILE            a session log (caliper-YYYYmmdd-HHMMSS-SESSION.log) to open; the live\n"
    "                      service is then not followed unless --live is given\n"
    "  --nameservice ADDR  the naming service, corbaname::HOST:PORT (default:\n"
    "                      $CALIPER_NAMESERVICE, else corbaname::127.0.0.1:2809)\n"
    "  --logger INSTANCE   the Logging component's instance name (default: logger0)\n"
    "  --live              with LOG_FILE: also follow the live service, adding its records to the\n"
    "                      file's (records in both are shown once)\n"
    "  --geometry WxH+X+Y  window size and position (wins over the session file's)\n"
    "  --session FILE      settings file shared with the Main Window (INI): the window geometry\n"
    "                      and the filters are restored from its [log_viewer] group and written\n"
    "                      back on close\n"
    "  -h, --help          this help\n"
    "\n"
    "Ctrl+C copies the selected rows (tab-separated); File > Export writes them as a session log.\n"
    "SIGINT and SIGTERM close the window cleanly (the live listener is unregistered).\n";


int UsageError(const std::string& message) {
  std::cerr << "caliper-logviewer: error: " << message << "\n"
            << "Try 'caliper-logviewer --help'.\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using caliper::log_viewer::LinkStatus;
  using caliper::log_viewer::LogViewerWindow;
  // our options come out before QApplication sees argv: Qt itself takes `--session VALUE` (X11
  // session management) and would swallow the shared session file
  LogViewerWindow::Options options;
  QString log_file;
  bool live = false;
  std::vector<char*> qt_argv = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    } else if (a == "--nameservice" || a == "--logger" || a == "--geometry" || a == "--session") {
      if (i + 1 >= argc) return UsageError("option " + a + " needs a value");
      const std::string value = argv[++i];
      if (a == "--nameservice") {
        options.link.nameservice = value;
      } else if (a == "--logger") {
        options.link.instance = value;
      } else if (a == "--geometry") {
        if (!caliper::gui_session::ParseGeometry(QString::fromStdString(value), &options.geometry))
          return UsageError("--geometry needs WIDTHxHEIGHT+X+Y, not '" + value + "'");
      } else {
        options.session_file = QString::fromLocal8Bit(value.c_str());
      }
    } else if (a == "--live") {
      live = true;
    } else if (!a.empty() && a[0] != '-' && log_file.isEmpty()) {
      log_file = QString::fromLocal8Bit(a.c_str());
    } else if (a.size() > 1 && a[0] == '-' && a[1] != '-') {
      // Qt's own (-platform offscreen, -style fusion ...); what Qt does not take is refused below
      qt_argv.push_back(argv[i]);
      if (caliper::gui_session::IsQtOptionWithValue(a) && i + 1 < argc)
        qt_argv.push_back(argv[++i]);
    } else {
      return UsageError("unexpected argument '" + a + "'");
    }
  }
  int qt_argc = static_cast<int>(qt_argv.size());
  qt_argv.push_back(nullptr);
  QApplication app(qt_argc, qt_argv.data());
  const QStringList rest = QApplication::arguments();
  if (rest.size() > 1) return UsageError("unexpected argument '" + rest[1].toStdString() + "'");

  CORBA::ORB_var orb = caliper::rtc::ClientOrb("caliper-logviewer");

  int status = 0;
  {
    LogViewerWindow window(options);
    // SIGTERM/SIGINT close the window, which saves the session and unregisters the listener:
    // caught from now on (a file may take a while to open), acted upon once the event loop runs
    caliper::gui_session::CloseOnTerminationSignals(&window);
    if (!log_file.isEmpty()) {
      QString error;
      if (!window.OpenFile(log_file, &error)) {
        std::cerr << "caliper-logviewer: error: " << error.toStdString() << "\n";
        status = 1;
      }
      for (const QString& problem : window.problems())
        std::cerr << "caliper-logviewer: warning: " << problem.toStdString() << "\n";
    }
    if (status == 0) {
      if (log_file.isEmpty() || live) window.FollowLive(/*keep=*/!log_file.isEmpty());
      window.show();
      // connection changes on stderr too, for the launcher's session log
      auto* watch = new QTimer(&window);
      QObject::connect(watch, &QTimer::timeout, &window, [&window, shown = LinkStatus{}]() mutable {
        const LinkStatus s = window.link_status();
        if (s.connected == shown.connected && s.registrations == shown.registrations) return;
        if (s.connected)
          std::cerr << "caliper-logviewer: " << s.message << "; session log " << s.session_file
                    << "\n";
        else if (shown.connected)
          std::cerr << "caliper-logviewer: " << s.message << "\n";
        shown = s;
      });
      if (window.live()) watch->start(200);
      status = QApplication::exec();
    }
  }
  orb->destroy();
  return status;
}
