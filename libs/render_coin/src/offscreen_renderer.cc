#include "caliper/render_coin/offscreen_renderer.h"

#include <Inventor/SbViewportRegion.h>
#include <Inventor/actions/SoGLRenderAction.h>
#include <Inventor/elements/SoGLCacheContextElement.h>
#include <Inventor/nodes/SoCamera.h>
#include <Inventor/nodes/SoDirectionalLight.h>
#include <Inventor/nodes/SoSeparator.h>

#include <QOffscreenSurface>
#include <QOpenGLContext>
#include <QOpenGLFramebufferObject>
#include <QOpenGLFunctions>
#include <stdexcept>

namespace caliper::render_coin {

namespace {
constexpr float kBackground[3] = {0.12f, 0.13f, 0.16f};
}  // namespace

struct OffscreenRenderer::Impl {
  QOffscreenSurface surface;
  QOpenGLContext context;
  uint32_t cache_context = 0;
};

OffscreenRenderer::OffscreenRenderer() : impl_(std::make_unique<Impl>()) {
  InitializeCoin();
  QSurfaceFormat format;
  format.setDepthBufferSize(24);
  format.setSamples(4);
  impl_->surface.setFormat(format);
  impl_->surface.create();
  impl_->context.setFormat(format);
  if (!impl_->context.create() || !impl_->context.makeCurrent(&impl_->surface))
    throw std::runtime_error("no OpenGL context for offscreen rendering (is there an X display?)");
  impl_->cache_context = SoGLCacheContextElement::getUniqueCacheContext();
  impl_->context.doneCurrent();
}

OffscreenRenderer::~OffscreenRenderer() = default;

QImage OffscreenRenderer::RenderToImage(SceneGraph& scene, int width, int height, bool view_all) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("image size must be positive");
  if (!impl_->context.makeCurrent(&impl_->surface))
    throw std::runtime_error("cannot make the offscreen OpenGL context current");
  if (view_all) scene.ViewAll(static_cast<double>(width) / height);
  scene.FitClippingPlanes();

  QOpenGLFramebufferObjectFormat fbo_format;
  fbo_format.setAttachment(QOpenGLFramebufferObject::CombinedDepthStencil);
  fbo_format.setSamples(4);
  QOpenGLFramebufferObject multisampled(width, height, fbo_format);
  multisampled.bind();
  QOpenGLFunctions* gl = impl_->context.functions();
  gl->glEnable(GL_DEPTH_TEST);
  gl->glClearColor(kBackground[0], kBackground[1], kBackground[2], 1.0f);
  gl->glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  // a headlight: the scene has none of its own (the viewer supplies one)
  SoSeparator* root = new SoSeparator;
  root->ref();
  auto* light = new SoDirectionalLight;
  SbVec3f direction;
  scene.camera()->orientation.getValue().multVec(SbVec3f(0, 0, -1), direction);
  light->direction = direction;
  root->addChild(light);
  root->addChild(scene.root());

  SoGLRenderAction action(SbViewportRegion(static_cast<short>(width), static_cast<short>(height)));
  action.setCacheContext(impl_->cache_context);
  action.setTransparencyType(SoGLRenderAction::SORTED_OBJECT_BLEND);
  action.apply(root);
  root->unref();
  multisampled.release();

  QImage image = multisampled.toImage();
  impl_->context.doneCurrent();
  return image.convertToFormat(QImage::Format_RGB32);
}

void OffscreenRenderer::SavePng(SceneGraph& scene, const std::string& path, int width, int height,
                                bool view_all) {
  const QImage image = RenderToImage(scene, width, height, view_all);
  if (!image.save(QString::fromStdString(path), "PNG"))
    throw std::runtime_error("cannot write the PNG '" + path + "'");
}

}  // namespace caliper::render_coin
