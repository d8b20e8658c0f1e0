#pragma once
// An interactive SoQt examiner viewer on a SceneGraph (rotate, pan, zoom with the mouse).

#include <QSize>
#include <QWidget>
#include <memory>

#include "caliper/render_coin/scene_graph.h"

namespace caliper::render_coin {

/// Initializes SoQt (and with it Coin and, if none exists yet, the QApplication); returns SoQt's
/// top-level window. Needs an X display with GLX.
QWidget* InitializeViewer(int& argc, char** argv, const char* name);

class Viewer {
 public:
  Viewer(QWidget* parent, SceneGraph& scene);
  ~Viewer();
  void ViewAll();
  /// Draws now (under Xvfb the first frame waits for this).
  void Render();
  QWidget* widget() const;
  /// The GL area itself: where the mouse events arrive (an event filter on it sees them first).
  QWidget* gl_widget() const;
  /// The GL area's size [px].
  QSize view_size() const;
  /// Asks for a redraw at the next turn of the event loop.
  void ScheduleRedraw();
  /// Shows SoQt's top-level window.
  static void Show(QWidget* top_level);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace caliper::render_coin
