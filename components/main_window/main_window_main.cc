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
#include "caliper/rtc/transport_security.h"
#include "main_window.h"
#include "model_link.h"

int main(int argc, char** argv) {
  // our options come out before Qt starts: --help needs no display; Qt takes its own (-geometry,
  // -platform, ...)
  caliper::gui_session::ToolArguments args = caliper::gui_session::SplitToolArguments(
      argc, argv, {"--nameservice", "--model", "--tools", "--plot"}, {"--no-tools", "--arrange"});
  if (args.help) {
    std::cout
        << "usage: caliper-main [--nameservice corbaname::HOST:PORT] [--model INSTANCE]\n"
           "                    [--no-tools] [--tools LIST] [--plot IDS]... [--arrange]\n"
           "                    [MODEL_FILE]\n"
           "  The Main Window: simulation control, parameters, components, and the other tools.\n"
           "  --nameservice ADDR  the naming service, corbaname::HOST:PORT (default:\n"
           "                      $CALIPER_NAMESERVICE, else the newest running session,\n"
           "                      else corbaname::127.0.0.1:2809)\n"
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
  }
  if (args.error.empty() && args.positional.size() > 1)
    args.error = "unexpected argument '" + args.positional[1] + "'";
  if (!args.error.empty()) {
    std::cerr << "caliper-main: " << args.error << " (--help lists the options)\n";
    return 2;
  }
  caliper::main_window::ModelLink::Options options;
  options.nameservice = args.Value("--nameservice", options.nameservice);
  options.instance = args.Value("--model", options.instance);
  const std::string model_file = args.positional.empty() ? "" : args.positional[0];
  const bool restore_tools = args.flags.count("--no-tools") == 0;
  const bool arrange = args.flags.count("--arrange") != 0;
  const QStringList tools =
      QString::fromStdString(args.Value("--tools")).split(',', Qt::SkipEmptyParts);
  QStringList plots;  // one entry per plot: comma-separated ids
  for (const std::string& plot : args.values["--plot"]) plots << QString::fromStdString(plot);
  int qt_argc = args.qt_argc();
  QApplication app(qt_argc, args.qt_argv.data());
  if (QApplication::arguments().size() > 1) {
    std::cerr << "caliper-main: unknown option '" << QApplication::arguments().at(1).toStdString()
              << "' (--help lists the options)\n";
    return 2;
  }

  CORBA::ORB_var orb;
  try {
    orb = caliper::rtc::ClientOrb("caliper-main", 0, options.nameservice);
  } catch (const caliper::rtc::SecurityError& e) {  // network mode without usable certificates
    std::cerr << "caliper-main: error: " << e.what() << "\n";
    return 2;
  }

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
