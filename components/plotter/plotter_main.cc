// caliper-plotter: the Graph Plotter, a Qt client of the Model's data acquisition.
//
//   caliper-plotter [--nameservice corbaname::HOST:PORT] [--model INSTANCE] [--layout FILE]
//                   [--ids ID,ID,...]... [--geometry WxH+X+Y] [--session FILE]
//
// SIGINT and SIGTERM close the window cleanly (the subscription ends, the session is written).
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <QApplication>
#include <QSocketNotifier>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "caliper/gui_session/tool_window.h"
#include "caliper/rtc.hh"
#include "daq_link.h"
#include "plot_layout.h"
#include "plotter_window.h"

namespace {

int signal_pipe[2] = {-1, -1};
void OnSignal(int) {
  const char c = 1;
  [[maybe_unused]] const auto n = ::write(signal_pipe[0], &c, 1);
}

constexpr const char* kUsage = R"(usage: caliper-plotter [OPTIONS]

Plots quantities of a Caliper Model live: pick ids from the Model's data acquisition list, put
several curves in each plot and stack plots on one time axis; pause, zoom (drag), pan
(Shift + drag), export the plot (PNG, SVG, PDF) or the data (CSV), print, save layouts.

options:
  --nameservice corbaname::HOST:PORT   the naming service (default: $CALIPER_NAMESERVICE,
                                       else corbaname::127.0.0.1:2809)
  --model INSTANCE      the Model to plot from (default model0)
  --layout FILE         open a saved layout (File > Save layout writes one)
  --ids ID,ID,...       a plot with these ids (a vector element is ID[i], a matrix element
                        ID[r][c]); give --ids again for each further plot
  --geometry WxH+X+Y    where the window goes, e.g. 1200x800+40+40
  --session FILE        the GUI session file shared with the Main Window (INI): the window's
                        geometry (plotter/geometry, unless --geometry) and the last layout
                        (plotter/layout, unless --layout or --ids) are restored from it and
                        written back when the window moves, is resized or closes
  -h, --help            this text

The time window is 10 s and the buffer keeps 1,000,000 samples per curve (CSV export writes all
of them) unless a layout says otherwise; the Model samples every step and sends batches.
SIGINT and SIGTERM close the window cleanly.
)";

}  // namespace

int main(int argc, char** argv) {
  using caliper::plotter::Layout;
  // our options come out of argv before Qt sees it: QGuiApplication takes --session (X11 session
  // management) for itself, and --help must work without a display
  caliper::plotter::DaqLink::Options options;
  std::string layout_file;
  std::vector<std::string> id_lists;
  QRect geometry;
  QString session;
  std::vector<char*> qt_argv = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    }
    const bool ours = a == "--nameservice" || a == "--model" || a == "--layout" || a == "--ids" ||
                      a == "--geometry" || a == "--session";
    if (!ours) {
      if (a.rfind("--", 0) == 0 || a.rfind("-", 0) != 0) {
        std::cerr << "caliper-plotter: unknown option '" << a << "' (--help lists them)\n";
        return 2;
      }
      qt_argv.push_back(argv[i]);  // -platform, -style, ... are Qt's
      continue;
    }
    if (i + 1 >= argc) {
      std::cerr << "caliper-plotter: " << a << " needs a value (--help)\n";
      return 2;
    }
    const std::string value = argv[++i];
    if (a == "--nameservice") {
      options.nameservice = value;
    } else if (a == "--model") {
      options.instance = value;
    } else if (a == "--layout") {
      layout_file = value;
    } else if (a == "--ids") {
      id_lists.push_back(value);
    } else if (a == "--geometry") {
      if (!caliper::gui_session::ParseGeometry(QString::fromStdString(value), &geometry)) {
        std::cerr << "caliper-plotter: --geometry needs WIDTHxHEIGHT+X+Y, not '" << value << "'\n";
        return 2;
      }
    } else {
      session = QString::fromStdString(value);
    }
  }

  // the layout: --layout and --ids, else the session's
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
  if (!have_layout && !session.isEmpty()) {
    QString error;
    have_layout = caliper::plotter::PlotterWindow::SessionLayout(session, &layout, &error);
    if (!error.isEmpty())
      std::cerr << "caliper-plotter: ignoring the session's layout: " << error.toStdString()
                << "\n";
  }

  int qt_argc = static_cast<int>(qt_argv.size());
  qt_argv.push_back(nullptr);
  QApplication app(qt_argc, qt_argv.data());
  if (QApplication::arguments().size() > 1) {
    std::cerr << "caliper-plotter: unknown option '"
              << QApplication::arguments().at(1).toStdString() << "' (--help lists them)\n";
    return 2;
  }

  std::vector<std::string> orb_args = {"caliper-plotter", "-ORBendPoint", "giop:tcp:127.0.0.1:"};
  std::vector<char*> orb_argv;
  for (auto& a : orb_args) orb_argv.push_back(a.data());
  int orb_argc = static_cast<int>(orb_argv.size());
  CORBA::ORB_var orb = CORBA::ORB_init(orb_argc, orb_argv.data());

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
    if (have_layout) window.ApplyLayout(layout);
    window.SetSessionFile(session);
    auto* tool = new caliper::gui_session::ToolWindow(&window, "plotter", session);
    tool->Restore(geometry);
    window.show();
    // SIGTERM/SIGINT close the window: the session is written, the subscription ends
    if (::socketpair(AF_UNIX, SOCK_STREAM, 0, signal_pipe) == 0) {
      auto* notifier = new QSocketNotifier(signal_pipe[1], QSocketNotifier::Read, &window);
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
