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
#include "caliper/rtc/transport_security.h"
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
    "                      $CALIPER_NAMESERVICE, else the newest running session,\n"
    "                      else corbaname::127.0.0.1:2809)\n"
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
  caliper::gui_session::ToolArguments args = caliper::gui_session::SplitToolArguments(
      argc, argv, {"--nameservice", "--logger", "--geometry", "--session"}, {"--live"});
  if (args.help) {
    std::cout << kUsage;
    return 0;
  }
  if (!args.error.empty()) return UsageError(args.error);
  if (args.positional.size() > 1)
    return UsageError("unexpected argument '" + args.positional[1] + "'");
  LogViewerWindow::Options options;
  options.link.nameservice = args.Value("--nameservice", options.link.nameservice);
  options.link.instance = args.Value("--logger", options.link.instance);
  const std::string geometry = args.Value("--geometry");
  if (!geometry.empty() &&
      !caliper::gui_session::ParseGeometry(QString::fromStdString(geometry), &options.geometry))
    return UsageError("--geometry needs WIDTHxHEIGHT+X+Y, not '" + geometry + "'");
  options.session_file = QString::fromLocal8Bit(args.Value("--session").c_str());
  const QString log_file =
      args.positional.empty() ? QString() : QString::fromLocal8Bit(args.positional[0].c_str());
  const bool live = args.flags.count("--live") != 0;
  int qt_argc = args.qt_argc();
  QApplication app(qt_argc, args.qt_argv.data());
  const QStringList rest = QApplication::arguments();
  if (rest.size() > 1) return UsageError("unexpected argument '" + rest[1].toStdString() + "'");

  CORBA::ORB_var orb;
  try {
    orb = caliper::rtc::ClientOrb("caliper-logviewer", 0, options.link.nameservice);
  } catch (const caliper::rtc::SecurityError& e) {  // network mode without usable certificates
    std::cerr << "caliper-logviewer: error: " << e.what() << "\n";
    return 2;
  }

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
