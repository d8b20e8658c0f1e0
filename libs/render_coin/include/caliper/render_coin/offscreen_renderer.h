#pragma once
// Renders a SceneGraph into an image without a window: a QOpenGLContext on a QOffscreenSurface, a
// framebuffer object and Coin's GL render action. Needs an X display with GLX (Xvfb will do) and a
// QGuiApplication.

#include <QImage>
#include <memory>
#include <string>

#include "caliper/render_coin/scene_graph.h"

namespace caliper::render_coin {

class OffscreenRenderer {
 public:
  /// Creates the GL context; throws std::runtime_error when there is no usable OpenGL.
  OffscreenRenderer();
  ~OffscreenRenderer();

  /// Draws `scene` through its camera; `view_all` frames all bodies first.
  QImage RenderToImage(SceneGraph& scene, int width, int height, bool view_all = true);
  /// Renders and writes a PNG; throws std::runtime_error when the file cannot be written.
  void SavePng(SceneGraph& scene, const std::string& path, int width, int height,
               bool view_all = true);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace caliper::render_coin
