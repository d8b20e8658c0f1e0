#include "renderer_servant.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>

#include "caliper/logging/log.h"
#include "caliper/rtc/client_orb.h"
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

core::ConfinedPaths ScreenshotDirectory(const core::Config& config) {
  std::string dir = config.GetString("renderer.write_dir");
  const char* files = std::getenv("CALIPER_FILES_DIR");
  if (dir.empty() && files != nullptr) dir = files;
  std::vector<std::string> dirs;
  if (!dir.empty()) dirs.push_back(dir);
  return core::ConfinedPaths(dirs, "renderer.write_dir", "the renderer writes screenshots");
}

namespace {

void CheckSize(CORBA::ULong width, CORBA::ULong height) {
  if (width < 16 || height < 16 || width > 8192 || height > 8192)
    throw V::NotAvailable("the screenshot size must be 16 .. 8192 px on each side");
}

}  // namespace

void RendererServant::screenshot(const char* path, CORBA::ULong width, CORBA::ULong height) {
  if (*path == '\0') throw V::NotAvailable("no path for the screenshot");
  CheckSize(width, height);
  // only into the write directory: a client must not make the renderer overwrite any file
  std::string file;
  try {
    file = files_.Resolve(path, core::ConfinedPaths::Access::kWrite).string();
  } catch (const std::exception& e) {
    logging::Get("renderer").warn("screenshot refused: %s", e.what());
    throw V::NotAvailable((std::string("screenshot: ") + e.what() +
                           "; other clients take screenshot_png (as caliper-ctl screenshot does "
                           "by itself)")
                              .c_str());
  }
  Run([this, file, width, height] {
    control_.Screenshot(file, static_cast<int>(width), static_cast<int>(height));
  });
}

V::Png* RendererServant::screenshot_png(CORBA::ULong width, CORBA::ULong height) {
  CheckSize(width, height);
  // shared: a GUI that does not answer in time may still run it after this call has returned
  auto result = std::make_shared<std::string>();
  Run([this, result, width, height] {
    *result = control_.ScreenshotPng(static_cast<int>(width), static_cast<int>(height));
  });
  const std::string& png = *result;
  // the configured limit of this process's messages, not the clients' default
  const double limit = runtime_.config().GetDouble("corba.max_message_size") * (1 << 20);
  if (static_cast<double>(png.size()) > 0.95 * limit) {
    char sizes[96];
    std::snprintf(sizes, sizeof sizes, "%.1f MiB, more than one GIOP message carries (%.1f MiB",
                  static_cast<double>(png.size()) / (1 << 20), limit / (1 << 20));
    throw V::NotAvailable((std::string("the PNG is ") + sizes +
                           ", corba.max_message_size): take a smaller one, or screenshot() into " +
                           files_.Describe())
                              .c_str());
  }
  auto* out = new V::Png(static_cast<CORBA::ULong>(png.size()));
  out->length(static_cast<CORBA::ULong>(png.size()));
  std::copy(png.begin(), png.end(), reinterpret_cast<char*>(out->get_buffer()));
  return out;
}

char* RendererServant::screenshot_dir() {
  return CORBA::string_dup(files_.dirs().empty() ? "" : files_.dirs().front().c_str());
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
