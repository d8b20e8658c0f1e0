// caliper-renderer: the Scene Renderer. The GUI (Qt, Coin) runs on the main thread; the component
// runtime (CORBA, lifecycle) on a second one; they meet in the SceneMailbox.
//
//   caliper-renderer [component options]                    an examiner viewer window
//   caliper-renderer --screenshot FILE [--after SECONDS]    a PNG after SECONDS of wall time, exit
#include <signal.h>
#include <unistd.h>

#include <QApplication>
#include <QTimer>
#include <atomic>
#include <cstdlib>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "caliper/logging/log.h"
#include "caliper/render_coin/offscreen_renderer.h"
#include "caliper/render_coin/scene_graph.h"
#include "caliper/render_coin/viewer.h"
#include "caliper/rtc/rtobject_servant.h"
#include "renderer_component.h"

namespace {

using namespace caliper;

struct Options {
  std::string screenshot;  // PNG path; empty for the interactive viewer
  double after = 3.0;      // [s] of wall time before the screenshot
  std::vector<char*> rest;  // what RunComponent parses
};

// takes our own options out of the command line; false (with a message) when they are malformed
bool ParseOptions(int argc, char** argv, Options* out) {
  out->rest.push_back(argv[0]);
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--screenshot" || arg == "--after") {
      if (i + 1 >= argc) {
        std::cerr << "caliper-renderer: error: option " << arg << " needs a value\n";
        return false;
      }
      const std::string value = argv[++i];
      if (arg == "--screenshot") {
        out->screenshot = value;
      } else {
        char* end = nullptr;
        out->after = std::strtod(value.c_str(), &end);
        if (end == value.c_str() || *end != '\0' || out->after < 0) {
          std::cerr << "caliper-renderer: error: --after needs a number of seconds >= 0\n";
          return false;
        }
      }
    } else {
      out->rest.push_back(argv[i]);
    }
  }
  out->rest.push_back(nullptr);
  return true;
}

// moves what arrived into the scene graph; true when something changed
bool Apply(renderer::SceneMailbox& mailbox, render_coin::SceneGraph& graph, bool* framed) {
  renderer::PendingUpdate pending = mailbox.Take();
  if (pending.empty()) return false;
  if (pending.cleared) graph.Clear();
  if (pending.scene) {
    graph.Build(*pending.scene);
    *framed = false;
  }
  graph.SetBodyPoses(pending.body_indices, pending.body_poses);
  if (!pending.tendons.empty()) graph.SetTendons(pending.tendons);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (!ParseOptions(argc, argv, &options)) return 2;
  // every thread inherits this mask; the runtime's signal watcher takes SIGINT/SIGTERM/SIGHUP
  sigset_t blocked;
  sigemptyset(&blocked);
  sigaddset(&blocked, SIGINT);
  sigaddset(&blocked, SIGTERM);
  sigaddset(&blocked, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &blocked, nullptr);

  if (std::getenv("DISPLAY") == nullptr || *std::getenv("DISPLAY") == '\0') {
    std::cerr << "caliper-renderer: error: no DISPLAY (the renderer needs X with GLX; run it "
                 "under Xvfb when headless)\n";
    return 1;
  }
  QApplication app(argc, argv);
  QWidget* top_level = nullptr;
  if (options.screenshot.empty()) top_level = render_coin::InitializeViewer(argc, argv, "caliper-renderer");
  render_coin::SceneGraph graph;
  renderer::SceneMailbox mailbox;

  // the component runtime; when it ends (signal, exit(), bad arguments), the GUI ends too
  std::atomic<int> rtc_exit{0};
  std::thread runtime_thread([&] {
    rtc::ComponentType type;
    type.name = "renderer";
    type.description =
        "Scene Renderer: draws the Model's scene with Coin3D (options of caliper-renderer: "
        "--screenshot FILE --after SECONDS)";
    type.category = "viewer";
    type.config_keys = renderer::RendererComponent::ConfigKeys();
    int rest_argc = static_cast<int>(options.rest.size()) - 1;
    rtc_exit = rtc::RunComponent(
        rest_argc, options.rest.data(), type,
        [&](rtc::Runtime& rt) { return std::make_unique<renderer::RendererComponent>(rt, mailbox); },
        [](rtc::Runtime& rt, rtc::Component&) -> PortableServer::Servant {
          return new rtc::DataFlowServant(rt);
        });
    QMetaObject::invokeMethod(&app, "quit", Qt::QueuedConnection);
  });
  auto request_exit = [] { kill(getpid(), SIGTERM); };

  bool framed = false;
  std::unique_ptr<render_coin::Viewer> viewer;
  if (top_level != nullptr) viewer = std::make_unique<render_coin::Viewer>(top_level, graph);

  // at most max_fps: apply what arrived; the viewer redraws when the graph changed
  QTimer frame_timer;
  QObject::connect(&frame_timer, &QTimer::timeout, [&] {
    const int interval = static_cast<int>(1000.0 / mailbox.settings().max_fps);
    if (frame_timer.interval() != interval) frame_timer.setInterval(interval);
    if (!Apply(mailbox, graph, &framed)) return;
    if (!framed && graph.body_count() > 0) {
      if (viewer) viewer->ViewAll();
      framed = true;
    }
  });
  frame_timer.start(33);

  int screenshot_exit = 0;
  if (!options.screenshot.empty()) {
    QTimer::singleShot(static_cast<int>(options.after * 1000), [&] {
      Apply(mailbox, graph, &framed);
      auto& log = logging::Get("renderer");
      try {
        if (graph.body_count() == 0) log.warn("no scene received yet: the screenshot shows none");
        const renderer::ViewSettings s = mailbox.settings();
        render_coin::OffscreenRenderer offscreen;
        offscreen.SavePng(graph, options.screenshot, s.width, s.height);
        log.notice("screenshot %s (%dx%d, %zu bodies, %llu updates received)",
                   options.screenshot.c_str(), s.width, s.height, graph.body_count(),
                   static_cast<unsigned long long>(mailbox.transforms_received()));
      } catch (const std::exception& e) {
        log.error("screenshot failed: %s", e.what());
        screenshot_exit = 1;
      }
      request_exit();
    });
  } else {
    render_coin::Viewer::Show(top_level);
    viewer->Render();
  }

  app.exec();
  request_exit();  // the window was closed: end the runtime too (a no-op when it has ended)
  runtime_thread.join();
  return screenshot_exit != 0 ? screenshot_exit : rtc_exit.load();
}
