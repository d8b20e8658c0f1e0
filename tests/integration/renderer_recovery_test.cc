// The Scene Renderer after a slow moment and after its Model was restarted, as processes: renderer
// A is stopped (SIGSTOP) for 10 s while the Model moves on, then continued: within a second its
// screenshot shows the Model's current pose, the one that renderer B, never stopped, shows. Then
// the Model is killed and a new one loads another scene: A shows it without being restarted.
// Needs an X display with GLX (launch/caliper test starts Xvfb); skipped without DISPLAY.
#include <gtest/gtest.h>
#include <signal.h>

#include <QImage>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>

#include "caliper/model.hh"
#include "caliper/renderer.hh"
#include "caliper/rtc/naming.h"
#include "support/gui_test.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

namespace M = ::Caliper::Simulation;
namespace V = ::Caliper::Viewer;

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr int kWidth = 480;
constexpr int kHeight = 360;

/// Pixels that differ between two images of the same size (all of them when the sizes differ).
int Differing(const QImage& a, const QImage& b) {
  if (a.size() != b.size() || a.isNull()) return kWidth * kHeight;
  int n = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      if (a.pixel(x, y) != b.pixel(x, y)) ++n;
  return n;
}

// two renderings of one state by two renderer processes agree to the pixel but for a few
// (tendon colours are interpolated); different poses differ in thousands
constexpr int kSame = 50;

class RendererRecoveryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string why = NoDisplay("the renderer needs X with GLX"); !why.empty())
      GTEST_SKIP() << why;
    naming_ = std::make_unique<NamingService>(dir_.path());
    models_ = std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/models/";
  }

  std::unique_ptr<Process> StartModel(const std::string& scene, const std::string& log) {
    return StartModelProcess(naming_->address(), models_ + scene, dir_.path(),
                             dir_.path() + "/" + log);
  }

  /// An interactive renderer (a viewer window, no --screenshot) with the default check interval.
  std::unique_ptr<Process> StartRenderer(const std::string& log) {
    return std::make_unique<Process>(
        std::vector<std::string>{Bin("caliper-renderer"), "--nameservice", naming_->address(),
                                 "-o", "log.service=none", "-o",
                                 "log.spool_dir=" + dir_.path() + "/spool", "-o",
                                 "renderer.write_dir=" + ArtifactDir(dir_.path())},
        dir_.path() + "/" + log);
  }

  V::Renderer_ptr WaitForRenderer(const std::string& instance) {
    V::Renderer_var renderer;
    WaitFor(
        [&] {
          try {
            CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming_->address());
            renderer = V::Renderer::_narrow(rtc::FindComponent(root, instance).object);
            return !CORBA::is_nil(renderer) && !renderer->_non_existent();
          } catch (...) {
            return false;
          }
        },
        seconds(20));
    return renderer._retn();
  }

  /// A screenshot of `renderer` (a null image when it cannot take one now).
  QImage Shot(V::Renderer_ptr renderer, const std::string& name) {
    const std::string path = ArtifactPath(name, dir_.path());
    std::remove(path.c_str());
    try {
      renderer->screenshot(path.c_str(), kWidth, kHeight);
    } catch (const V::NotAvailable&) {
      return QImage();
    } catch (const CORBA::SystemException&) {
      return QImage();
    }
    QImage image;
    image.load(QString::fromStdString(path));
    return image;
  }

  /// Waits until `a` and `b` show the same picture, one that differs from `unlike` (when given)
  /// in more than 1000 pixels; returns it (null after `timeout`).
  QImage WaitUntilAlike(V::Renderer_ptr a, V::Renderer_ptr b, const std::string& name,
                        milliseconds timeout, const QImage& unlike = QImage()) {
    QImage last;
    WaitFor(
        [&] {
          const QImage ia = Shot(a, name + "_a.png");
          const QImage ib = Shot(b, name + "_b.png");
          if (ia.isNull() || ib.isNull() || Differing(ia, ib) > kSame) return false;
          if (!unlike.isNull() && Differing(ia, unlike) <= 1000) return false;
          last = ia;
          return true;
        },
        timeout);
    return last;
  }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::string models_;
};

TEST_F(RendererRecoveryTest, ShowsTheCurrentPoseAfterASigstopAndFollowsARestartedModel) {
  auto model = StartModel("pendulum_tendon.dae", "model1.out");
  M::Model_var pendulum = WaitForModel(naming_->address());
  ASSERT_FALSE(CORBA::is_nil(pendulum)) << model->Output();
  auto first = StartRenderer("renderer_a.out");
  V::Renderer_var a = WaitForRenderer("renderer0");
  ASSERT_FALSE(CORBA::is_nil(a)) << first->Output();
  auto second = StartRenderer("renderer_b.out");
  V::Renderer_var b = WaitForRenderer("renderer1");
  ASSERT_FALSE(CORBA::is_nil(b)) << second->Output();

  // both look at the pendulum from the front, and show the same paused pose
  const Caliper::Scene::Frame camera{0, -1.6, 0.8, 0.70710678, 0.70710678, 0, 0};
  ASSERT_TRUE(WaitFor(
      [&] {
        try {
          a->set_camera(camera, 0.7);
          b->set_camera(camera, 0.7);
          return true;
        } catch (const V::NotAvailable&) {
          return false;  // no scene yet
        }
      },
      seconds(20)))
      << first->Output() << second->Output();
  pendulum->step(10);
  const QImage before = WaitUntilAlike(a, b, "recovery_before", seconds(10));
  ASSERT_FALSE(before.isNull()) << "A and B show the paused pose\n" << first->Output();

  // A stops for 10 s while the motor swings the pendulum up (the Model's pushes to A time out)
  first->Signal(SIGSTOP);
  pendulum->set_command("motor", 6);
  pendulum->start();
  std::this_thread::sleep_for(seconds(9));
  pendulum->pause();
  std::this_thread::sleep_for(seconds(1));
  const QImage now = Shot(b, "recovery_current_b.png");
  ASSERT_FALSE(now.isNull());
  ASSERT_GT(Differing(before, now), 1000) << "the pendulum moved while A was stopped";

  // continued, A shows the current pose within a second
  first->Signal(SIGCONT);
  const auto continued = Clock::now();
  QImage shown;
  const bool current = WaitFor(
      [&] {
        shown = Shot(a, "recovery_current_a.png");
        return !shown.isNull() && Differing(shown, now) <= kSame;
      },
      milliseconds(1000));
  std::printf("A showed the current pose %lld ms after SIGCONT\n",
              static_cast<long long>(
                  std::chrono::duration_cast<milliseconds>(Clock::now() - continued).count()));
  EXPECT_TRUE(current) << Differing(shown, now) << " pixels differ from B's picture after "
                       << std::chrono::duration_cast<milliseconds>(Clock::now() - continued).count()
                       << " ms\n"
                       << model->Output() << first->Output();
  EXPECT_FALSE(model->Output().find("dropping an observer") != std::string::npos)
      << model->Output();

  // the Model dies and a new one loads another scene: A follows without a restart
  model->Signal(SIGKILL);
  ASSERT_EQ(model->Wait(seconds(10)), 128 + SIGKILL);
  model = StartModel("two_link_antagonistic.dae", "model2.out");
  const QImage after = WaitUntilAlike(a, b, "recovery_restarted", seconds(20), now);
  ASSERT_FALSE(after.isNull()) << "A shows the new Model's scene, as B does\n"
                               << first->Output() << second->Output();
  const std::string out = first->Output();
  const auto registered = out.find("observing the Model");
  EXPECT_NE(out.find("observing the Model", registered + 1), std::string::npos) << out;
  EXPECT_TRUE(first->Running());

  for (Process* p : {first.get(), second.get(), model.get()}) {
    p->Signal(SIGTERM);
    EXPECT_EQ(p->Wait(seconds(10)), 0) << p->Output();
  }
}

}  // namespace
}  // namespace caliper::testing
