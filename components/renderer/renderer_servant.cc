#include "renderer_servant.h"

#include <cmath>
#include <stdexcept>

#include "caliper/logging/log.h"
#include "observer_servant.h"

namespace caliper::renderer {

namespace V = ::Caliper::Viewer;

render_coin::CameraPose CameraFromFrame(const render_coin::Pose& pose, double height_angle) {
  if (!(height_angle > 0 && height_angle < M_PI))
    throw std::invalid_argument("the height angle must be in (0, pi) rad");
  double w = pose.q[0], x = pose.q[1], y = pose.q[2], z = pose.q[3];
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(norm > 1e-9) || !std::isfinite(norm))
    throw std::invalid_argument("the camera orientation is not a quaternion");
  w /= norm, x /= norm, y /= norm, z /= norm;
  // columns of the rotation matrix: -z is the viewing direction, y is up
  const double zc[3] = {2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)};
  const double yc[3] = {2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)};
  render_coin::CameraPose c;
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(pose.p[i])) throw std::invalid_argument("the camera position is not finite");
    c.position[i] = pose.p[i];
    c.look_at[i] = pose.p[i] - zc[i];
    c.up[i] = yc[i];
  }
  c.height_angle = height_angle;
  return c;
}

void RendererServant::Run(std::function<void()> what) {
  const std::string error = gui_(std::move(what));
  if (!error.empty()) throw V::NotAvailable(error.c_str());
}

void RendererServant::view_all() {
  try {
    Run([this] { control_.ViewAll(); });
  } catch (const V::NotAvailable& e) {
    logging::Get("renderer").warn("view_all: %s", e.reason.in());
  }
}

void RendererServant::set_camera(const Caliper::Scene::Frame& pose, CORBA::Double height_angle) {
  render_coin::CameraPose camera;
  try {
    camera = CameraFromFrame(FromIdl(pose), height_angle);
  } catch (const std::exception& e) {
    throw V::NotAvailable(e.what());
  }
  Run([this, camera] { control_.SetCamera(camera); });
}

void RendererServant::screenshot(const char* path, CORBA::ULong width, CORBA::ULong height) {
  const std::string file = path;
  if (file.empty()) throw V::NotAvailable("no path for the screenshot");
  if (width < 16 || height < 16 || width > 8192 || height > 8192)
    throw V::NotAvailable("the screenshot size must be 16 .. 8192 px on each side");
  Run([this, file, width, height] {
    control_.Screenshot(file, static_cast<int>(width), static_cast<int>(height));
  });
}

void RendererServant::show_constraint_axes(CORBA::Boolean on) {
  const bool show = on;
  try {
    Run([this, show] { control_.ShowConstraintAxes(show); });
  } catch (const V::NotAvailable& e) {
    logging::Get("renderer").warn("show_constraint_axes: %s", e.reason.in());
  }
}

}  // namespace caliper::renderer
