// The Scene Renderer as its own process: it finds the Model with the shipped arm, observes it and
// writes a screenshot in which the arm and its tendons are drawn; it follows a restarted Model.
#include <gtest/gtest.h>
#include <signal.h>

#include <QImage>
#include <cstdlib>
#include <fstream>

#include "caliper/model.hh"
#include "caliper/renderer.hh"
#include "caliper/rtc/naming.h"
#include "support/gui_test.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::seconds;
namespace M = ::Caliper::Simulation;

struct PixelCounts {
  int arm = 0;        // the bones' ivory and the joints' gold
  int tendon = 0;     // saturated blue .. purple .. red, unlit
  int background = 0;
};

// counts in the upper two thirds of the frame, where the hanging arm is framed (the world axes,
// also red and blue, are at the bottom)
PixelCounts Count(const QImage& image) {
  PixelCounts n;
  const QColor background = image.pixelColor(2, 2);
  for (int y = 0; y < image.height() * 2 / 3; ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const QColor c = image.pixelColor(x, y);
      const int r = c.red(), g = c.green(), b = c.blue();
      if (c == background) ++n.background;
      if (r > 120 && g > 100 && r > b + 30 && g > b) ++n.arm;
      if (g < 70 && r + b > 180 && std::max(r, b) > 120) ++n.tendon;
    }
  }
  return n;
}

class Renderer : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string why = NoDisplay("the renderer needs X with GLX"); !why.empty())
      GTEST_SKIP() << why;
    naming_ = std::make_unique<NamingService>(dir_.path());
    common_ = {"--nameservice", naming_->address(), "-o", "log.service=none", "-o",
               "log.spool_dir=" + dir_.path() + "/spool"};
  }

  std::unique_ptr<Process> StartModel(const std::string& log) {
    const std::string models = std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/models";
    return StartModelProcess(naming_->address(), models + "/ecce_arm.dae", dir_.path(),
                             dir_.path() + "/" + log);
  }

  std::unique_ptr<Process> StartRenderer(const std::string& png, double after) {
    std::vector<std::string> args = {Bin("caliper-renderer"), "--screenshot", png, "--after",
                                     std::to_string(after), "-o", "renderer.check_interval=0.2"};
    args.insert(args.end(), common_.begin(), common_.end());
    return std::make_unique<Process>(args, dir_.path() + "/renderer.out");
  }

  // the interactive viewer window (no --screenshot), controlled over CORBA
  std::unique_ptr<Process> StartViewer() {
    std::vector<std::string> args = {Bin("caliper-renderer"), "-o", "renderer.check_interval=0.2",
                                     "-o", "renderer.write_dir=" + ArtifactDir(dir_.path())};
    args.insert(args.end(), common_.begin(), common_.end());
    return std::make_unique<Process>(args, dir_.path() + "/viewer.out");
  }

  M::Model_var WaitForModel() { return testing::WaitForModel(naming_->address()); }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::vector<std::string> common_;
};

TEST_F(Renderer, DrawsTheArmAndItsTendonsIntoAScreenshot) {
  auto model = StartModel("model.out");
  M::Model_var arm = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(arm)) << model->Output();
  arm->step(200);  // the arm settles a little and its tendons carry some tension

  const std::string png = ArtifactPath("renderer.png", dir_.path());
  std::remove(png.c_str());
  auto renderer = StartRenderer(png, 3.0);
  ASSERT_EQ(renderer->Wait(seconds(40)), 0) << renderer->Output();
  EXPECT_NE(renderer->Output().find("observing the Model"), std::string::npos) << renderer->Output();

  QImage image;
  ASSERT_TRUE(image.load(QString::fromStdString(png))) << "no readable PNG at " << png;
  EXPECT_EQ(image.width(), 1024);
  EXPECT_EQ(image.height(), 768);
  const PixelCounts n = Count(image);
  const int area = image.width() * image.height() * 2 / 3;
  EXPECT_LT(n.background, area * 95 / 100) << "an empty frame";
  EXPECT_GT(n.arm, 2000) << "the arm's coloured visuals are drawn";
  EXPECT_GT(n.tendon, 300) << "the tendons are drawn in their tension colours";

  model->Signal(SIGTERM);
  EXPECT_EQ(model->Wait(seconds(10)), 0) << model->Output();
}

TEST_F(Renderer, ObservesARestartedModelAgain) {
  auto model = StartModel("model1.out");
  ASSERT_FALSE(CORBA::is_nil(WaitForModel())) << model->Output();

  const std::string png = dir_.path() + "/restarted.png";
  auto renderer = StartRenderer(png, 8.0);
  ASSERT_TRUE(WaitFor([&] { return renderer->Output().find("observing the Model") !=
                                   std::string::npos; },
                      seconds(10)))
      << renderer->Output();
  model->Signal(SIGTERM);
  ASSERT_EQ(model->Wait(seconds(10)), 0) << model->Output();
  model = StartModel("model2.out");
  ASSERT_TRUE(WaitFor(
      [&] {
        const std::string out = renderer->Output();
        const auto first = out.find("observing the Model");
        return out.find("observing the Model", first + 1) != std::string::npos;
      },
      seconds(15)))
      << "re-registers with the new Model\n"
      << renderer->Output();
  ASSERT_EQ(renderer->Wait(seconds(20)), 0) << renderer->Output();
  QImage image;
  ASSERT_TRUE(image.load(QString::fromStdString(png)));
  EXPECT_GT(Count(image).arm, 2000) << "the new Model's scene is drawn";
  model->Signal(SIGTERM);
  EXPECT_EQ(model->Wait(seconds(10)), 0) << model->Output();
}

TEST_F(Renderer, TakesScreenshotsAndShowsConstraintAxesOverCorba) {
  namespace V = ::Caliper::Viewer;
  auto model = StartModel("model.out");
  CORBA::ORB_ptr orb = Orb();
  ASSERT_FALSE(CORBA::is_nil(WaitForModel())) << model->Output();
  auto viewer = StartViewer();

  V::Renderer_var renderer;
  ASSERT_TRUE(WaitFor(
      [&] {
        try {
          CosNaming::NamingContext_var root = rtc::ResolveRoot(orb, naming_->address());
          renderer = V::Renderer::_narrow(rtc::FindComponent(root, "renderer0").object);
          return !CORBA::is_nil(renderer) && !renderer->_non_existent();
        } catch (...) {
          return false;
        }
      },
      seconds(20)))
      << viewer->Output();

  // the first screenshot succeeds once the Model's scene has arrived
  const std::string plain = ArtifactPath("renderer_corba.png", dir_.path());
  const std::string axes = ArtifactPath("renderer_corba_axes.png", dir_.path());
  std::remove(plain.c_str());
  std::remove(axes.c_str());
  std::string last_reason;
  ASSERT_TRUE(WaitFor(
      [&] {
        try {
          renderer->screenshot(plain.c_str(), 640, 480);
          return true;
        } catch (const V::NotAvailable& e) {
          last_reason = e.reason.in();
          return false;
        }
      },
      seconds(20)))
      << last_reason << "\n"
      << viewer->Output();
  QImage first;
  ASSERT_TRUE(first.load(QString::fromStdString(plain))) << "no readable PNG at " << plain;
  EXPECT_EQ(first.width(), 640);
  EXPECT_EQ(first.height(), 480);
  const PixelCounts n = Count(first);
  EXPECT_LT(n.background, 640 * 480 * 2 / 3 * 95 / 100) << "an empty frame";
  EXPECT_GT(n.arm, 500) << "the arm is drawn\n" << viewer->Output();

  renderer->show_constraint_axes(true);
  renderer->screenshot(axes.c_str(), 640, 480);
  QImage second;
  ASSERT_TRUE(second.load(QString::fromStdString(axes))) << "no readable PNG at " << axes;
  ASSERT_EQ(second.size(), first.size());
  int differing = 0;
  for (int y = 0; y < first.height(); ++y)
    for (int x = 0; x < first.width(); ++x)
      if (first.pixel(x, y) != second.pixel(x, y)) ++differing;
  EXPECT_GT(differing, 100) << "the constraint axes are drawn";

  // the camera can be put anywhere; bad angles are refused
  Caliper::Scene::Frame pose{1.5, -1.5, 1.0, 1, 0, 0, 0};
  EXPECT_THROW(renderer->set_camera(pose, 0.0), V::NotAvailable);
  EXPECT_NO_THROW(renderer->set_camera(pose, 0.8));
  EXPECT_NO_THROW(renderer->view_all());

  try {
    renderer->screenshot("/nonexistent-dir/cannot/shot.png", 640, 480);
    ADD_FAILURE() << "a screenshot to an unwritable path succeeded";
  } catch (const V::NotAvailable& e) {
    EXPECT_NE(std::string(e.reason.in()).find("/nonexistent-dir/cannot/shot.png"), std::string::npos)
        << e.reason.in();
  }
  EXPECT_TRUE(viewer->Running()) << viewer->Output();

  viewer->Signal(SIGTERM);
  EXPECT_EQ(viewer->Wait(seconds(10)), 0) << viewer->Output();
  model->Signal(SIGTERM);
  EXPECT_EQ(model->Wait(seconds(10)), 0) << model->Output();
}

}  // namespace
}  // namespace caliper::testing
