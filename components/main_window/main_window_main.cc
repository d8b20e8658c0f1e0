// caliper-main: the Main Window, a plain Qt client of the Model (no component lifecycle).
//
//   caliper-main [--nameservice corbaname::HOST:PORT] [--model INSTANCE] [--no-tools]
//                [--tools renderer,plotter,log_viewer] [--plot ID,ID,...]... [--arrange]
//                [MODEL_FILE]
//
// The session (window geometry, last model, simulation settings, open tools and their windows) is
// kept in a per-user settings file, or in $CALIPER_MAIN_SETTINGS. --no-tools does not start the
// tools that were open last time; --tools starts the ones named; each --plot is one plot the
// plotter shows when it has no layout of its own; --arrange tiles the windows once the tools are
// up.

#include <QApplication>
#include <QFileInfo>
#include <QTimer>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "caliper/gui_session/tool_window.h"
#include "caliper/rtc/client_orb.h"
#include "main_window.h"
#include "model_link.h"

int main(int argc, char** argv) {
  caliper::main_window::ModelLink::Options options;
  std::string model_file;
  bool restore_tools = true;
  bool arrange = false;
  QStringList tools;
  QStringList plots;  // one entry per plot: comma-separated ids
  // --help needs no display: looked for before Qt starts (which then takes out its own options,
  // -geometry, -platform, ...)
  bool help = false;
  for (int i = 1; i < argc; ++i)
    help |= std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h";
  std::unique_ptr<QApplication> app;
  if (!help) app = std::make_unique<QApplication>(argc, argv);
  QStringList args;
  if (app) {
    args = QApplication::arguments();
  } else {
    args << "caliper-main" << "--help";
  }
  for (int i = 1; i < args.size(); ++i) {
    const std::string a = args[i].toStdString();
    if ((a == "--nameservice" || a == "--model") && i + 1 < args.size()) {
      (a == "--nameservice" ? options.nameservice : options.instance) = args[++i].toStdString();
    } else if (a == "--no-tools") {
      restore_tools = false;
    } else if (a == "--arrange") {
      arrange = true;
    } else if (a == "--tools" && i + 1 < args.size()) {
      tools = args[++i].split(',', Qt::SkipEmptyParts);
    } else if (a == "--plot" && i + 1 < args.size()) {
      plots << args[++i];
    } else if (a == "--help" || a == "-h") {
      std::cout
          << "usage: caliper-main [--nameservice corbaname::HOST:PORT] [--model INSTANCE]\n"
             "                    [--no-tools] [--tools LIST] [--plot IDS]... [--arrange]\n"
             "                    [MODEL_FILE]\n"
             "  The Main Window: simulation control, parameters, components, and the other tools.\n"
             "  --nameservice ADDR  the naming service (default: omniORB's configuration)\n"
             "  --model INSTANCE    the Model's instance name (default model0)\n"
             "  --no-tools          do not reopen the tools that were open last time\n"
             "  --tools LIST        open these tools (comma separated: "
          << caliper::main_window::MainWindow::ToolNames().join(",").toStdString()
          << ")\n"
             "  --plot IDS          one plot of these ids (comma separated) when the plotter has\n"
             "                      no saved layout; give it again for each further plot\n"
             "  --arrange           tile the main window and the tools on the screen\n"
             "  MODEL_FILE          load this model into the Model\n"
             "  The session is kept in $CALIPER_MAIN_SETTINGS, or else in "
          << caliper::main_window::MainWindow::SettingsPath().toStdString() << "\n";
      return 0;
    } else if (!a.empty() && a[0] != '-') {
      model_file = a;
    } else {
      std::cerr << "caliper-main: unknown option '" << a << "'\n";
      return 2;
    }
  }

  CORBA::ORB_var orb = caliper::rtc::ClientOrb("caliper-main");

  int status = 0;
  {
    auto link = std::make_unique<caliper::main_window::ModelLink>(options);
    if (!model_file.empty()) {
      const QString path = QFileInfo(QString::fromStdString(model_file)).absoluteFilePath();
      link->LoadScene(path.toStdString());
    }
    caliper::main_window::MainWindow window(std::move(link), 5.0, nullptr,
                                            /*restore_tools=*/false);
    // SIGTERM/SIGINT (launch/caliper ending the session) close the window, which saves the session
    // and ends the tools: caught before any tool starts
    caliper::gui_session::CloseOnTerminationSignals(&window);
    window.SetDefaultPlots(plots);
    if (arrange) window.setGeometry(window.ArrangedGeometry("main"));
    if (restore_tools) window.ReopenTools();
    for (const QString& tool : tools) window.StartTool(tool);
    window.show();
    // the tools place themselves; arranging again once they are shown also moves restored ones
    if (arrange) QTimer::singleShot(3000, &window, [&window] { window.ArrangeWindows(); });
    status = QApplication::exec();
  }
  orb->destroy();
  return status;
}
