// caliper-renderer: the Scene Renderer. The GUI (Qt, Coin) runs on the main thread; the component
// runtime (CORBA, lifecycle) on a second one; they meet in the SceneMailbox.
//
//   caliper-renderer [component options]                    an examiner viewer window
//   caliper-renderer --screenshot FILE [--after SECONDS]    a PNG after SECONDS of wall time, exit
//   --geometry WxH+X+Y   where the viewer window goes
//   --session FILE       the GUI session file shared with the Main Window: the window's geometry
//                        is restored from it (unless --geometry) and written back to it
#include <signal.h>
#include <unistd.h>

#include <QApplication>
#include <QBuffer>
#include <QByteArray>
#include <QTimer>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <future>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "caliper/core/arguments.h"
#include "caliper/core/numbers.h"
#include "caliper/gui_session/tool_window.h"
#include "caliper/logging/log.h"
#include "caliper/render_coin/offscreen_renderer.h"
#include "caliper/render_coin/scene_editor.h"
#include "caliper/render_coin/scene_graph.h"
#include "caliper/render_coin/viewer.h"
#include "caliper/rtc/rtobject_servant.h"
#include "model_edit_client.h"
#include "renderer_component.h"
#include "renderer_servant.h"

namespace {

using namespace caliper;

struct Options {
  std::string screenshot;  // PNG path; empty for the interactive viewer
  double after = 3.0;      // [s] of wall time before the screenshot
  QRect geometry;          // --geometry WxH+X+Y: where the viewer window goes (invalid: none)
  QString session;         // --session FILE: the GUI session file
  std::vector<char*> rest;  // what RunComponent parses
};

// takes our own options out of the command line; false (with a message) when they are malformed
bool ParseOptions(int argc, char** argv, Options* out) {
  core::ArgumentSpec spec;
  spec.valued = {"--screenshot", "--after", "--geometry", "--session"};
  spec.help = {};  // RunComponent's, as every other word
  spec.pass = [](const std::string&) { return 1; };
  const core::Arguments args = core::ParseArguments({argv + 1, argv + argc}, spec);
  if (!args.Error().empty()) {
    std::cerr << "caliper-renderer: error: " << args.Error() << "\n";
    return false;
  }
  out->screenshot = args.Value("--screenshot");
  out->session = QString::fromStdString(args.Value("--session"));
  if (args.Has("--geometry") &&
      !gui_session::ParseGeometry(QString::fromStdString(args.Value("--geometry")),
                                  &out->geometry)) {
    std::cerr << "caliper-renderer: error: --geometry needs WIDTHxHEIGHT+X+Y, not '"
              << args.Value("--geometry") << "'\n";
    return false;
  }
  if (args.Has("--after") &&
      (!core::ParseDouble(args.Value("--after"), &out->after) || !(out->after >= 0))) {
    std::cerr << "caliper-renderer: error: --after needs a number of seconds >= 0\n";
    return false;
  }
  out->rest.push_back(argv[0]);
  for (const size_t i : args.passed) out->rest.push_back(argv[i + 1]);
  out->rest.push_back(nullptr);
  return true;
}

// moves what arrived into the scene graph; true when something changed. Only a different scene
// is framed again: an edit sends the same scene (name and bodies) changed, and the camera stays.
bool Apply(renderer::SceneMailbox& mailbox, render_coin::SceneGraph& graph, bool* framed) {
  static std::string shown;  // SceneIdentity() of the scene last built (one graph per process)
  renderer::PendingUpdate pending = mailbox.Take();
  if (pending.empty()) return false;
  if (pending.cleared) graph.Clear();
  if (pending.scene) {
    const std::string identity = renderer::SceneIdentity(*pending.scene);
    graph.Build(*pending.scene);
    if (identity != shown) *framed = false;
    shown = identity;
  }
  graph.SetBodyPoses(pending.body_indices, pending.body_poses);
  if (!pending.tendons.empty()) graph.SetTendons(pending.tendons);
  return true;
}

// frames a newly built scene once: through the viewer (its window's aspect) or the graph alone
void FrameIfNew(render_coin::SceneGraph& graph, render_coin::Viewer* viewer, bool* framed,
                double aspect) {
  if (*framed || graph.body_count() == 0) return;
  if (viewer != nullptr)
    viewer->ViewAll();
  else
    graph.ViewAll(aspect);
  *framed = true;
}

// the control interface's work, on the GUI thread
class GuiControl : public renderer::ViewControl {
 public:
  GuiControl(renderer::SceneMailbox& mailbox, render_coin::SceneGraph& graph, bool* framed)
      : mailbox_(mailbox), graph_(graph), framed_(framed) {}
  void set_viewer(render_coin::Viewer* viewer) { viewer_ = viewer; }

  void ViewAll() override {
    Apply(mailbox_, graph_, framed_);
    if (viewer_ != nullptr)
      viewer_->ViewAll();
    else
      graph_.ViewAll(4.0 / 3.0);
    *framed_ = graph_.body_count() > 0;
  }
  void SetCamera(const render_coin::CameraPose& camera) override {
    Apply(mailbox_, graph_, framed_);
    FrameIfNew(graph_, viewer_, framed_, 4.0 / 3.0);  // a later frame must not move it again
    graph_.SetCamera(camera);
  }
  void Screenshot(const std::string& path, int width, int height) override {
    if (!Render(width, height).save(QString::fromStdString(path), "PNG"))
      throw std::runtime_error("cannot write the PNG '" + path + "'");
    Logged(path, width, height);
  }
  std::string ScreenshotPng(int width, int height) override {
    QByteArray bytes;
    QBuffer buffer(&bytes);
    buffer.open(QIODevice::WriteOnly);
    if (!Render(width, height).save(&buffer, "PNG"))
      throw std::runtime_error("cannot encode the PNG");
    Logged("(sent by content)", width, height);
    return std::string(bytes.constData(), static_cast<size_t>(bytes.size()));
  }
  void ShowConstraintAxes(bool on) override {
    graph_.SetConstraintAxesVisible(on);
    logging::Get("renderer").info("constraint axes %s", on ? "shown" : "hidden");
  }

 private:
  // the current view at width x height
  QImage Render(int width, int height) {
    Apply(mailbox_, graph_, framed_);
    if (graph_.body_count() == 0) throw std::runtime_error("no scene received from the Model yet");
    FrameIfNew(graph_, viewer_, framed_, static_cast<double>(width) / height);
    if (!offscreen_) offscreen_ = std::make_unique<render_coin::OffscreenRenderer>();
    return offscreen_->RenderToImage(graph_, width, height, /*view_all=*/false);
  }
  void Logged(const std::string& where, int width, int height) {
    const render_coin::CameraPose c = graph_.camera_pose();
    logging::Get("renderer").info(
        "screenshot %s (%dx%d), camera at %.2f %.2f %.2f looking at %.2f %.2f %.2f",
        where.c_str(), width, height, c.position[0], c.position[1], c.position[2], c.look_at[0],
        c.look_at[1], c.look_at[2]);
  }

  renderer::SceneMailbox& mailbox_;
  render_coin::SceneGraph& graph_;
  bool* framed_;
  render_coin::Viewer* viewer_ = nullptr;
  std::unique_ptr<render_coin::OffscreenRenderer> offscreen_;
};

}  // namespace

rtc::ComponentType RendererType() {
  rtc::ComponentType type;
  type.name = "renderer";
  type.description =
      "Scene Renderer: draws the Model's scene with Coin3D. Its own options:\n"
      "  --screenshot FILE    write a PNG of the scene after --after SECONDS (3) and exit\n"
      "  --geometry WxH+X+Y   where the viewer window goes\n"
      "  --session FILE       the GUI session file (window places; the Main Window passes it)\n"
      "It needs an X display with GLX (Xvfb when headless).";
  type.category = "viewer";
  type.config_keys = renderer::RendererComponent::ConfigKeys();
  return type;
}

int main(int argc, char** argv) {
  Options options;
  if (!ParseOptions(argc, argv, &options)) return 2;
  for (size_t i = 1; i + 1 < options.rest.size(); ++i) {
    const std::string word = options.rest[i];
    if (word != "-h" && word != "--help") continue;
    // the help needs no display: RunComponent prints it before it makes anything (should the
    // word be an option's value instead, the component is never made: the factories refuse)
    int rest_argc = static_cast<int>(options.rest.size()) - 1;
    return rtc::RunComponent(
        rest_argc, options.rest.data(), RendererType(),
        [](rtc::Runtime&) -> std::unique_ptr<rtc::Component> {
          throw std::runtime_error("the Scene Renderer needs an X display (DISPLAY is not set)");
        },
        [](rtc::Runtime&, rtc::Component&) -> PortableServer::Servant {
          throw std::runtime_error("the Scene Renderer needs an X display (DISPLAY is not set)");
        });
  }
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
  renderer::ModelReference model_ref;  // set by the component's thread, called by the GUI's
  bool framed = false;
  GuiControl control(mailbox, graph, &framed);
  // runs a function on the GUI thread and waits; a call the GUI drops (it ended) or never gets to
  // is reported, never waited for forever
  renderer::GuiCall gui_call = [&app](std::function<void()> what) -> std::string {
    std::promise<std::string> done;
    std::future<std::string> result = done.get_future();
    const bool queued = QMetaObject::invokeMethod(
        &app,
        [what = std::move(what), done = std::make_shared<std::promise<std::string>>(
                                     std::move(done))] {
          try {
            what();
            done->set_value("");
          } catch (const std::exception& e) {
            done->set_value(e.what());
          } catch (...) {
            done->set_value("unknown error");
          }
        },
        Qt::QueuedConnection);
    if (!queued) return "the renderer's GUI has ended";
    if (result.wait_for(std::chrono::seconds(30)) != std::future_status::ready)
      return "the renderer's GUI does not answer";
    try {
      return result.get();
    } catch (const std::future_error&) {
      return "the renderer's GUI has ended";
    }
  };

  // the component runtime; when it ends (signal, exit(), bad arguments), the GUI ends too
  std::atomic<int> rtc_exit{0};
  std::thread runtime_thread([&] {
    int rest_argc = static_cast<int>(options.rest.size()) - 1;
    rtc_exit = rtc::RunComponent(
        rest_argc, options.rest.data(), RendererType(),
        [&](rtc::Runtime& rt) {
          return std::make_unique<renderer::RendererComponent>(rt, mailbox, model_ref);
        },
        [&](rtc::Runtime& rt, rtc::Component&) -> PortableServer::Servant {
          return new renderer::RendererServant(rt, control, gui_call);
        });
    QMetaObject::invokeMethod(&app, "quit", Qt::QueuedConnection);
  });
  auto request_exit = [] { kill(getpid(), SIGTERM); };

  std::unique_ptr<render_coin::Viewer> viewer;
  renderer::ModelEditClient edit_client(model_ref);
  std::unique_ptr<render_coin::SceneEditor> editor;
  if (top_level != nullptr) {
    viewer = std::make_unique<render_coin::Viewer>(top_level, graph);
    editor = std::make_unique<render_coin::SceneEditor>(graph, *viewer, &edit_client);
  }
  control.set_viewer(viewer.get());

  // at most max_fps: apply what arrived; the viewer redraws when the graph changed
  QTimer frame_timer;
  QObject::connect(&frame_timer, &QTimer::timeout, [&] {
    const int interval = static_cast<int>(1000.0 / mailbox.settings().max_fps);
    if (frame_timer.interval() != interval) frame_timer.setInterval(interval);
    if (mailbox.TakeSettingsChanged())
      graph.SetConstraintAxesVisible(mailbox.settings().show_constraint_axes);
    if (!Apply(mailbox, graph, &framed)) return;
    if (viewer) FrameIfNew(graph, viewer.get(), &framed, 1.0);
  });
  frame_timer.start(33);

  int screenshot_exit = 0;
  if (!options.screenshot.empty()) {
    QTimer::singleShot(static_cast<int>(options.after * 1000), [&] {
      if (mailbox.TakeSettingsChanged())
        graph.SetConstraintAxesVisible(mailbox.settings().show_constraint_axes);
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
    auto* window = new gui_session::ToolWindow(top_level, "renderer", options.session);
    const QRect wanted = window->Restore(options.geometry);
    render_coin::Viewer::Show(top_level);
    // SoQt sizes a top-level viewer to its own preference when showing it: place it again
    if (wanted.isValid() && top_level->geometry() != wanted) top_level->setGeometry(wanted);
    viewer->Render();
  }

  app.exec();
  // the editor's worker calls the Model through the ORB: end it (and a pull in progress)
  // while the runtime still runs
  editor.reset();
  request_exit();  // the window was closed: end the runtime too (a no-op when it has ended)
  runtime_thread.join();
  return screenshot_exit != 0 ? screenshot_exit : rtc_exit.load();
}
