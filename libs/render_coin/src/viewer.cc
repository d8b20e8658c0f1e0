#include "caliper/render_coin/viewer.h"

#include <Inventor/Qt/SoQt.h>
#include <Inventor/Qt/viewers/SoQtExaminerViewer.h>
#include <Inventor/nodes/SoSeparator.h>

namespace caliper::render_coin {

QWidget* InitializeViewer(int& argc, char** argv, const char* name) {
  return SoQt::init(argc, argv, name);
}

struct Viewer::Impl {
  SceneGraph* scene = nullptr;
  SoQtExaminerViewer* viewer = nullptr;
};

Viewer::Viewer(QWidget* parent, SceneGraph& scene) : impl_(std::make_unique<Impl>()) {
  impl_->scene = &scene;
  impl_->viewer = new SoQtExaminerViewer(parent);
  impl_->viewer->setBackgroundColor(SbColor(0.12f, 0.13f, 0.16f));
  impl_->viewer->setTransparencyType(SoGLRenderAction::SORTED_OBJECT_BLEND);
  impl_->viewer->setSceneGraph(scene.root());
  impl_->viewer->setTitle("Caliper scene");
}

Viewer::~Viewer() { delete impl_->viewer; }

void Viewer::ViewAll() {
  const SbVec2s size = impl_->viewer->getViewportRegion().getWindowSize();
  impl_->scene->ViewAll(size[0] > 0 && size[1] > 0 ? static_cast<double>(size[0]) / size[1] : 1.0);
}

void Viewer::Render() { impl_->viewer->render(); }

QWidget* Viewer::widget() const { return impl_->viewer->getWidget(); }

QWidget* Viewer::gl_widget() const { return impl_->viewer->getGLWidget(); }

QSize Viewer::view_size() const {
  const SbVec2s size = impl_->viewer->getViewportRegion().getWindowSize();
  return QSize(size[0], size[1]);
}

void Viewer::ScheduleRedraw() { impl_->viewer->scheduleRedraw(); }

void Viewer::Show(QWidget* top_level) { SoQt::show(top_level); }

}  // namespace caliper::render_coin
