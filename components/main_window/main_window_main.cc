// caliper-main: the Main Window, a plain Qt client of the Model (no component lifecycle).
//
//   caliper-main [--nameservice corbaname::HOST:PORT] [--model INSTANCE] [--no-tools] [MODEL_FILE]
//
// The session (window geometry, last model, simulation settings, open tools) is kept in a
// per-user settings file, or in $CALIPER_MAIN_SETTINGS. --no-tools does not start the tools that
// were open last time (launch/caliper starts them itself).
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <QApplication>
#include <QSocketNotifier>
#include <QFileInfo>
#include <iostream>
#include <string>
#include <vector>

#include "caliper/rtc.hh"
#include "main_window.h"
#include "model_link.h"

namespace {
int signal_pipe[2] = {-1, -1};
void OnSignal(int) {
  const char c = 1;
  [[maybe_unused]] const auto n = ::write(signal_pipe[0], &c, 1);
}
}  // namespace

int main(int argc, char** argv) {
  QApplication app(argc, argv);
  caliper::main_window::ModelLink::Options options;
  std::string model_file;
  bool restore_tools = true;
  const QStringList args = QApplication::arguments();
  for (int i = 1; i < args.size(); ++i) {
    const std::string a = args[i].toStdString();
    if ((a == "--nameservice" || a == "--model") && i + 1 < args.size()) {
      (a == "--nameservice" ? options.nameservice : options.instance) = args[++i].toStdString();
    } else if (a == "--no-tools") {
      restore_tools = false;
    } else if (a == "--help" || a == "-h") {
      std::cout << "usage: caliper-main [--nameservice corbaname::HOST:PORT] [--model INSTANCE] "
                   "[--no-tools] [MODEL_FILE]\n";
      return 0;
    } else if (!a.empty() && a[0] != '-') {
      model_file = a;
    } else {
      std::cerr << "caliper-main: unknown option '" << a << "'\n";
      return 2;
    }
  }

  std::vector<std::string> orb_args = {"caliper-main", "-ORBendPoint", "giop:tcp:127.0.0.1:"};
  std::vector<char*> orb_argv;
  for (auto& a : orb_args) orb_argv.push_back(a.data());
  int orb_argc = static_cast<int>(orb_argv.size());
  CORBA::ORB_var orb = CORBA::ORB_init(orb_argc, orb_argv.data());

  int status = 0;
  {
    auto link = std::make_unique<caliper::main_window::ModelLink>(options);
    if (!model_file.empty()) {
      const QString path = QFileInfo(QString::fromStdString(model_file)).absoluteFilePath();
      link->LoadScene(path.toStdString());
    }
    caliper::main_window::MainWindow window(std::move(link), 5.0, nullptr, restore_tools);
    window.show();
    // SIGTERM/SIGINT (launch/caliper ending the session) close the window, which saves the session
    QSocketNotifier* notifier = nullptr;
    if (::socketpair(AF_UNIX, SOCK_STREAM, 0, signal_pipe) == 0) {
      notifier = new QSocketNotifier(signal_pipe[1], QSocketNotifier::Read, &window);
      QObject::connect(notifier, &QSocketNotifier::activated, &window, [&window] {
        char c;
        [[maybe_unused]] const auto n = ::read(signal_pipe[1], &c, 1);
        window.close();
        QApplication::quit();
      });
      struct sigaction sa = {};
      sa.sa_handler = OnSignal;
      sigemptyset(&sa.sa_mask);
      sa.sa_flags = SA_RESTART;
      sigaction(SIGTERM, &sa, nullptr);
      sigaction(SIGINT, &sa, nullptr);
    }
    status = QApplication::exec();
  }
  orb->destroy();
  return status;
}
