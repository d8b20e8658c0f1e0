// caliper-plotter: the Graph Plotter, a Qt client of the Model's data acquisition.
//
//   caliper-plotter [--nameservice corbaname::HOST:PORT] [--model INSTANCE] [--layout FILE]
//                   [--ids ID,ID,...]... [--geometry WxH+X+Y] [--session FILE]
//
// SIGINT and SIGTERM close the window cleanly (the subscription ends, the session is written).

#include <QApplication>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "caliper/gui_session/tool_window.h"
#include "caliper/logging/log.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/transport_security.h"
#include "daq_link.h"
#include "plot_layout.h"
#include "plotter_window.h"

namespace {

constexpr const char* kUsage = R"(usage: caliper-plotter [OPTIONS]

Plots quantities of a Caliper Model live: pick ids from the Model's data acquisition list, put
several curves in each plot and stack plots on one time axis; pause, zoom (drag), pan
(Shift + drag), export the plot (PNG, SVG, PDF) or the data (CSV), print, save layouts.

options:
  --nameservice corbaname::HOST:PORT   the naming service (default: $CALIPER_NAMESERVICE,
                                       else the newest running session, else
                                       corbaname::127.0.0.1:2809)
  --model INSTANCE      the Model to plot from (default model0)
  --layout FILE         open a saved layout (File > Save layout writes one)
  --ids ID,ID,...       a plot with these ids (a vector element is ID[i], a matrix element
                        ID[r][c]); give --ids again for each further plot
  --geometry WxH+X+Y    where the window goes, e.g. 1200x800+40+40
  --session FILE        the GUI session file shared with the Main Window (INI): the window's
                        geometry (plotter/geometry, unless --geometry) and the last layout
                        (plotter/layout, unless --layout or --ids) are restored from it and
                        written back when the window moves, is resized or closes (the layout
                        also as soon as it is applied and whenever it changes); a layout
                        there that does not parse is kept as plotter/layout.rejected
  -h, --help            this text
  -platform NAME, -style NAME, ...  Qt's own options

The time window is 10 s and the buffer keeps 1,000,000 samples per curve (CSV export writes all
of them) unless a layout says otherwise; the Model samples every step and sends batches.
SIGINT and SIGTERM close the window cleanly.
)";


}  // namespace

int main(int argc, char** argv) {
  using caliper::plotter::Layout;
  // our options come out of argv before Qt sees it: QGuiApplication takes --session (X11 session
  // management) for itself, and --help must work without a display
  caliper::gui_session::ToolArguments args = caliper::gui_session::SplitToolArguments(
      argc, argv, {"--nameservice", "--model", "--layout", "--ids", "--geometry", "--session"}, {});
  if (args.help) {
    std::cout << kUsage;
    return 0;
  }
  if (args.error.empty() && !args.positional.empty())
    args.error = "unexpected argument '" + args.positional[0] + "'";
  if (!args.error.empty()) {
    std::cerr << "caliper-plotter: " << args.error << " (--help lists the options)\n";
    return 2;
  }
  caliper::plotter::DaqLink::Options options;
  options.nameservice = args.Value("--nameservice", options.nameservice);
  options.instance = args.Value("--model", options.instance);
  const std::string layout_file = args.Value("--layout");
  const std::vector<std::string> id_lists = args.values["--ids"];
  QRect geometry;
  const std::string geometry_text = args.Value("--geometry");
  if (!geometry_text.empty() &&
      !caliper::gui_session::ParseGeometry(QString::fromStdString(geometry_text), &geometry)) {
    std::cerr << "caliper-plotter: --geometry needs WIDTHxHEIGHT+X+Y, not '" << geometry_text
              << "'\n";
    return 2;
  }
  const QString session = QString::fromStdString(args.Value("--session"));

  // the layout of --layout and --ids
  Layout layout;
  bool have_layout = false;
  if (!layout_file.empty()) {
    try {
      layout = caliper::plotter::LoadLayout(layout_file);
      have_layout = true;
    } catch (const caliper::plotter::LayoutError& e) {
      std::cerr << "caliper-plotter: " << e.what() << "\n";
      return 2;
    }
  }
  for (const auto& list : id_lists) {
    const auto ids = caliper::plotter::SplitIds(list);
    if (ids.empty()) {
      std::cerr << "caliper-plotter: --ids '" << list << "' names no id\n";
      return 2;
    }
    caliper::plotter::AddPlot(&layout, ids);
    have_layout = true;
  }

  int qt_argc = args.qt_argc();
  QApplication app(qt_argc, args.qt_argv.data());
  if (QApplication::arguments().size() > 1) {
    std::cerr << "caliper-plotter: unknown option '"
              << QApplication::arguments().at(1).toStdString() << "' (--help lists them)\n";
    return 2;
  }

  // what the data consumer logs goes to stderr (the launcher's session log)
  caliper::logging::Initialize("plotter", caliper::logging::kWarn);
  CORBA::ORB_var orb;
  try {
    orb = caliper::rtc::ClientOrb("caliper-plotter", 0, options.nameservice);
  } catch (const caliper::rtc::SecurityError& e) {  // network mode without usable certificates
    std::cerr << "caliper-plotter: error: " << e.what() << "\n";
    return 2;
  }
  // no call of this process waits longer than the link's call timeout (the naming service's
  // included; the link bounds its calls to the Model itself)
  omniORB::setClientCallTimeout(static_cast<CORBA::ULong>(options.call_timeout_ms));

  int status = 0;
  {
    std::unique_ptr<caliper::plotter::DaqLink> link;
    try {
      link = std::make_unique<caliper::plotter::DaqLink>(options);
    } catch (const CORBA::Exception& e) {
      std::cerr << "caliper-plotter: cannot serve the data consumer: " << e._name() << "\n";
      orb->destroy();
      return 1;
    }
    caliper::plotter::PlotterWindow window(std::move(link));
    // the session file first: the layout applied below goes into it at once, so that a plotter
    // that never closes (killed, its X server gone) does not leave an earlier session's layout
    window.SetSessionFile(session);
    // the layout: --layout and --ids, else the session's (kept aside when it does not parse,
    // before anything writes the session)
    if (have_layout) {
      window.ApplyLayout(layout);
    } else if (!session.isEmpty()) {
      QString error;
      if (!window.RestoreSessionLayout(session, &error) && !error.isEmpty())
        std::cerr << "caliper-plotter: " << error.toStdString() << "\n";
    }
    auto* tool = new caliper::gui_session::ToolWindow(&window, "plotter", session);
    tool->Restore(geometry);
    window.show();
    // SIGTERM/SIGINT close the window: the session is written, the subscription ends
    caliper::gui_session::CloseOnTerminationSignals(&window);
    status = QApplication::exec();
  }
  orb->destroy();
  caliper::logging::Shutdown();
  return status;
}
