#pragma once
// The renderer's CORBA control interface (Caliper::Viewer::Renderer, idl/caliper/renderer.idl).
// The ORB calls it on its own threads; everything that touches Qt or Coin is handed to the GUI
// thread through a GuiCall and waited for. Errors come back as NotAvailable with the reason.

#include <functional>
#include <string>

#include "caliper/core/confined_path.h"
#include "caliper/render_coin/scene_description.h"
#include "caliper/renderer.hh"
#include "caliper/rtc/rtobject_servant.h"

namespace caliper::renderer {

/// What the GUI does for the control interface; called on the GUI thread only. Throws
/// std::exception (its what() becomes NotAvailable::reason).
class ViewControl {
 public:
  virtual ~ViewControl() = default;
  virtual void ViewAll() = 0;
  virtual void SetCamera(const render_coin::CameraPose& camera) = 0;
  virtual void Screenshot(const std::string& path, int width, int height) = 0;
  /// The same image as the bytes of a PNG file.
  virtual std::string ScreenshotPng(int width, int height) = 0;
  virtual void ShowConstraintAxes(bool on) = 0;
};

/// Runs a function on the GUI thread and waits for it; returns "" when it ran without an
/// exception, else the reason (its what(), or why it could not run at all).
using GuiCall = std::function<std::string(std::function<void()>)>;

/// The camera looking from `pose` along its -z with its +y up (Inventor's convention); throws
/// std::invalid_argument for a zero quaternion or an angle outside (0, pi).
render_coin::CameraPose CameraFromFrame(const render_coin::Pose& pose, double height_angle);

/// Where screenshot() may write: renderer.write_dir, else $CALIPER_FILES_DIR (the session's files/
/// directory when the launcher started the renderer), else nowhere.
core::ConfinedPaths ScreenshotDirectory(const core::Config& config);

class RendererServant : public virtual POA_Caliper::Viewer::Renderer, public rtc::RTObjectServant {
 public:
  RendererServant(rtc::Runtime& runtime, ViewControl& control, GuiCall gui)
      : rtc::RTObjectServant(runtime),
        control_(control),
        gui_(std::move(gui)),
        files_(ScreenshotDirectory(runtime.config())) {}

  void view_all() override;
  void set_camera(const Caliper::Scene::Frame& pose, CORBA::Double height_angle_rad) override;
  void screenshot(const char* path, CORBA::ULong width, CORBA::ULong height) override;
  Caliper::Viewer::Png* screenshot_png(CORBA::ULong width, CORBA::ULong height) override;
  char* screenshot_dir() override;
  void show_constraint_axes(CORBA::Boolean on) override;

 private:
  /// Runs `what` on the GUI thread; raises NotAvailable with the reason when it failed.
  void Run(std::function<void()> what);

  ViewControl& control_;
  GuiCall gui_;
  const core::ConfinedPaths files_;  // where screenshot() may write
};

}  // namespace caliper::renderer
