// Scene editing in the Scene Renderer: the viewer, its scene graph and the scene editor in the
// test process, on the X display; a real Model process (tests/data/collada/caliper_arm.dae)
// observed over CORBA and edited through the ModelEditClient. The mouse is QTest's, at the pixels
// where known points project through a camera the test sets (a pinhole model of its own).
#include <gtest/gtest.h>

#include <QApplication>
#include <QImage>
#include <QMouseEvent>
#include <QTest>
#include <QVBoxLayout>
#include <QWidget>
#include <array>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "caliper/model.hh"
#include "caliper/render_coin/scene_editor.h"
#include "caliper/render_coin/scene_graph.h"
#include "caliper/render_coin/viewer.h"
#include "caliper/renderer.hh"
#include "caliper/rtc/naming.h"
#include "model_edit_client.h"
#include "observer_servant.h"
#include "scene_mailbox.h"
#include "support/gui_test.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
namespace M = ::Caliper::Simulation;
namespace S = ::Caliper::Scene;
namespace R = render_coin;

constexpr int kWidth = 900;   // [px] of the window: its GL area is wider than tall, so the
constexpr int kHeight = 640;  // camera's height angle is the vertical one
constexpr double kHeightAngle = 0.785398;  // [rad]

// the camera in front of the arm (at -y), looking along +y with z up
R::CameraPose FrontCamera() {
  R::CameraPose c;
  c.position[0] = 0;
  c.position[1] = -1.3;
  c.position[2] = 0.7;
  c.look_at[0] = 0;
  c.look_at[1] = 0;
  c.look_at[2] = 0.7;
  c.up[0] = 0;
  c.up[1] = 0;
  c.up[2] = 1;
  c.height_angle = kHeightAngle;
  return c;
}

// an EditClient that records and refuses what it is told to
class RefusingClient : public R::EditClient {
 public:
  void Select(const R::Entity& e) override { selected.push_back(e); }
  void MovePathPoint(const std::string&, uint32_t, const R::PathPoint&) override {
    ++moves;
    throw R::EditError("refused for the test");
  }
  void InsertPathPoint(const std::string&, uint32_t, const R::PathPoint&) override {
    throw R::EditError("refused for the test");
  }
  void RemovePathPoint(const std::string&, uint32_t) override {
    throw R::EditError("refused for the test");
  }
  void AddTendon(const std::string&, const R::PathPoint&, const R::PathPoint&, double,
                 const std::string&, const std::string&) override {
    throw R::EditError("refused for the test");
  }
  void RemoveTendon(const std::string&) override { throw R::EditError("refused for the test"); }
  void SetObstacle(const R::Obstacle&) override { throw R::EditError("refused for the test"); }
  void RemoveObstacle(const std::string&) override { throw R::EditError("refused for the test"); }
  std::vector<R::ActuatorKindInfo> ActuatorKinds() override { return {}; }
  void Pull(const std::string&, const double*, const double*, double) override {}
  void ReleasePull() override {}

  std::vector<R::Entity> selected;
  int moves = 0;
};

class RendererEdit : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string why = NoDisplay("the renderer's viewer needs X with GLX"); !why.empty())
      GTEST_SKIP() << why;
    App();
    // SoQt once per process; each test's viewer in a window of its own
    static QWidget* soqt_shell = [] {
      static int argc = 1;
      static char name[] = "renderer_edit_test";
      static char* argv[] = {name, nullptr};
      return R::InitializeViewer(argc, argv, "renderer_edit_test");
    }();
    ASSERT_NE(soqt_shell, nullptr);
    naming_ = std::make_unique<NamingService>(dir_.path());
    const std::string scene =
        std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/tests/data/collada/caliper_arm.dae";
    model_process_ =
        StartModelProcess(naming_->address(), scene, dir_.path(), dir_.path() + "/model.out");
    model_ = WaitForModel(naming_->address());
    ASSERT_FALSE(CORBA::is_nil(model_)) << model_process_->Output();
    model_ref_.Set(model_.in());

    // the renderer's own observer, in this process
    CORBA::Object_var obj = Orb()->resolve_initial_references("RootPOA");
    poa_ = PortableServer::POA::_narrow(obj);
    PortableServer::POAManager_var manager = poa_->the_POAManager();
    manager->activate();
    observer_ = new renderer::ObserverServant(mailbox_);
    observer_id_ = poa_->activate_object(observer_);
    observer_->_remove_ref();
    CORBA::Object_var ref = poa_->id_to_reference(observer_id_);
    S::SceneObserver_var observer = S::SceneObserver::_narrow(ref);
    observer_number_ = model_->add_observer(observer);

    window_ = std::make_unique<QWidget>();
    auto* layout = new QVBoxLayout(window_.get());
    layout->setContentsMargins(0, 0, 0, 0);
    viewer_ = std::make_unique<R::Viewer>(window_.get(), graph_);
    layout->addWidget(viewer_->widget());
    window_->resize(kWidth, kHeight);
    window_->show();
    // the GL area is the window less the viewer's decorations
    ASSERT_TRUE(WaitInGui(
        [&] {
          Pump();
          size_ = viewer_->view_size();
          return graph_.body_count() == 4 && graph_.tendon_state(0) != nullptr &&
                 size_ == gl()->size() && size_.width() > size_.height() &&
                 size_.height() > kHeight / 2;
        },
        seconds(15)))
        << "bodies " << graph_.body_count() << ", GL area " << size_.width() << "x"
        << size_.height() << ", GL widget " << gl()->width() << "x" << gl()->height() << "\n"
        << model_process_->Output();
    graph_.SetCamera(FrontCamera());
    viewer_->Render();
    editor_ = std::make_unique<R::SceneEditor>(graph_, *viewer_, &client_);
  }

  void TearDown() override {
    editor_.reset();
    viewer_.reset();
    window_.reset();
    if (!CORBA::is_nil(model_)) {
      try {
        model_->remove_observer(observer_number_);
      } catch (const CORBA::Exception&) {
        // the Model ended first: nothing to unregister from
      }
    }
    if (!CORBA::is_nil(poa_) && observer_ != nullptr) poa_->deactivate_object(observer_id_);
    model_ref_.Set(M::Model::_nil());
  }

  // applies what the Model sent, as the renderer's frame timer does
  void Pump() {
    renderer::PendingUpdate pending = mailbox_.Take();
    if (pending.cleared) graph_.Clear();
    if (pending.scene) {
      graph_.Build(*pending.scene);
      ++scenes_;
    }
    graph_.SetBodyPoses(pending.body_indices, pending.body_poses);
    if (!pending.tendons.empty()) graph_.SetTendons(pending.tendons);
    if (!pending.body_indices.empty() || !pending.tendons.empty()) sim_time_ = pending.sim_time;
  }

  bool PumpUntil(const std::function<bool()>& condition, milliseconds timeout) {
    return WaitInGui(
        [&] {
          Pump();
          return condition();
        },
        timeout);
  }

  QWidget* gl() { return viewer_->gl_widget(); }

  // the editor calls the Model on its worker: waits (bounded) for every answer queued so far
  bool Answered() {
    return WaitInGui([&] { return editor_->pending_answers() == 0; }, seconds(10));
  }

  // the pixel (from the top left) where `world` projects through FrontCamera(): x right, z up
  QPoint Project(const std::array<double, 3>& world) const {
    const R::CameraPose c = FrontCamera();
    const double depth = world[1] - c.position[1];
    const double px_per_m = 1.0 / MetresPerPixel(depth);
    return QPoint(
        static_cast<int>(std::lround(size_.width() / 2.0 + (world[0] - c.position[0]) * px_per_m)),
        static_cast<int>(
            std::lround(size_.height() / 2.0 - (world[2] - c.position[2]) * px_per_m)));
  }

  // metres per pixel at `depth` [m] in front of FrontCamera()
  double MetresPerPixel(double depth) const {
    return depth * std::tan(kHeightAngle / 2) / (size_.height() / 2.0);
  }

  // world position of element `index` of `tendon` as the graph draws its marker now
  std::array<double, 3> MarkerWorld(const std::string& tendon, uint32_t index) {
    double local[3];
    EXPECT_TRUE(graph_.PathPointMarker(tendon, index, local));
    const R::Tendon* t = nullptr;
    for (const R::Tendon& each : graph_.scene().tendons)
      if (each.name == tendon) t = &each;
    R::Pose body;
    EXPECT_TRUE(t != nullptr && graph_.BodyPose(t->path[index].body, &body));
    std::array<double, 3> world;
    R::ToWorld(body, local, world.data());
    return world;
  }

  std::array<double, 3> BodyWorld(const std::string& body, std::array<double, 3> local) {
    R::Pose pose;
    EXPECT_TRUE(graph_.BodyPose(body, &pose));
    std::array<double, 3> world;
    R::ToWorld(pose, local.data(), world.data());
    return world;
  }

  S::PathPoint DeclaredPoint(const std::string& tendon, uint32_t index) {
    S::Description_var scene = model_->scene_description();
    for (CORBA::ULong t = 0; t < scene->tendons.length(); ++t)
      if (std::string(scene->tendons[t].name.in()) == tendon) return scene->tendons[t].path[index];
    ADD_FAILURE() << "no tendon " << tendon;
    return S::PathPoint();
  }

  size_t PathLength(const std::string& tendon) {
    S::Description_var scene = model_->scene_description();
    for (CORBA::ULong t = 0; t < scene->tendons.length(); ++t)
      if (std::string(scene->tendons[t].name.in()) == tendon)
        return scene->tendons[t].path.length();
    return 0;
  }

  R::Pose PoseNow(const std::string& body) {
    R::Pose pose;
    EXPECT_TRUE(graph_.BodyPose(body, &pose));
    return pose;
  }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> model_process_;
  M::Model_var model_;
  renderer::ModelReference model_ref_;
  renderer::ModelEditClient client_{model_ref_};
  renderer::SceneMailbox mailbox_;
  PortableServer::POA_var poa_;
  renderer::ObserverServant* observer_ = nullptr;
  PortableServer::ObjectId_var observer_id_;
  CORBA::ULongLong observer_number_ = 0;
  R::SceneGraph graph_;
  std::unique_ptr<QWidget> window_;
  std::unique_ptr<R::Viewer> viewer_;
  std::unique_ptr<R::SceneEditor> editor_;
  QSize size_;  // of the GL area [px]
  int scenes_ = 0;
  double sim_time_ = 0;  // [s] of the transforms applied last
};

TEST_F(RendererEdit, AClickSelectsWhatIsUnderTheCursorAndTellsTheModel) {
  // the biceps' via point: 45 mm beside the upper arm, in its frame
  const QPoint via = Project(MarkerWorld("biceps_line", 1));
  QTest::mouseClick(gl(), Qt::LeftButton, Qt::NoModifier, via);
  ASSERT_TRUE(Answered());
  M::Selection_var s = model_->current_selection();
  EXPECT_EQ(std::string(s->kind.in()), "path_point");
  EXPECT_EQ(std::string(s->name.in()), "biceps_line");
  EXPECT_EQ(s->index, 1u);
  EXPECT_EQ(graph_.highlight(), (R::Entity{"path_point", "biceps_line", 1}));
  EXPECT_EQ(editor_->description(),
            "tendon biceps_line point 1 (via point) on body upper_arm at 45.0 0.0 0.0 mm (body "
            "frame)");
  EXPECT_EQ(graph_.status_text(), editor_->description());

  // the upper arm's front face, off the tendons
  QTest::mouseClick(gl(), Qt::LeftButton, Qt::NoModifier,
                    Project(BodyWorld("upper_arm", {-0.01, -0.035, 0.08})));
  ASSERT_TRUE(Answered());
  s = model_->current_selection();
  EXPECT_EQ(std::string(s->kind.in()), "body");
  EXPECT_EQ(std::string(s->name.in()), "upper_arm");
  EXPECT_EQ(editor_->description().rfind("body upper_arm (moving, 2 kg) at ", 0), 0u)
      << editor_->description();

  // the biceps between its shoulder attachment and its via point: tension and length
  const auto a = MarkerWorld("biceps_line", 0), b = MarkerWorld("biceps_line", 1);
  QTest::mouseClick(gl(), Qt::LeftButton, Qt::NoModifier,
                    Project({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}));
  ASSERT_TRUE(Answered());
  s = model_->current_selection();
  EXPECT_EQ(std::string(s->kind.in()), "tendon");
  EXPECT_EQ(std::string(s->name.in()), "biceps_line");
  EXPECT_TRUE(std::regex_match(editor_->description(),
                               std::regex("tendon biceps_line: tension -?[0-9.]+ N, length "
                                          "[0-9.]+ mm")))
      << editor_->description();

  // empty space selects nothing
  const CORBA::ULongLong revision = M::Selection_var(model_->current_selection())->revision;
  QTest::mouseClick(gl(), Qt::LeftButton, Qt::NoModifier, QPoint(20, 20));
  ASSERT_TRUE(Answered());
  s = model_->current_selection();
  EXPECT_EQ(std::string(s->kind.in()), "");
  EXPECT_EQ(graph_.highlight(), R::Entity());
  EXPECT_EQ(s->revision, revision + 1);
}

TEST_F(RendererEdit, DraggingTheSelectedViaPointMovesItInTheModel) {
  const auto before = MarkerWorld("biceps_line", 1);
  const QPoint at = Project(before);
  QTest::mouseClick(gl(), Qt::LeftButton, Qt::NoModifier, at);
  ASSERT_EQ(editor_->selection(), (R::Entity{"path_point", "biceps_line", 1}));
  const R::CameraPose camera = graph_.camera_pose();
  // 20 px right, 10 px up, in small steps as a hand would
  QTest::mousePress(gl(), Qt::LeftButton, Qt::NoModifier, at);
  for (int i = 1; i <= 5; ++i) QTest::mouseMove(gl(), at + QPoint(4 * i, -2 * i));
  // while dragging, the marker follows the mouse; the Model has not been asked yet
  EXPECT_GT(MarkerWorld("biceps_line", 1)[0], before[0] + 0.02);
  EXPECT_NEAR(DeclaredPoint("biceps_line", 1).x, 0.045, 1e-9);
  QTest::mouseRelease(gl(), Qt::LeftButton, Qt::NoModifier, at + QPoint(20, -10));
  ASSERT_TRUE(Answered());
  EXPECT_EQ(editor_->last_error(), "");

  // the plane through the grabbed point (on the marker's front, 6 mm before its centre)
  const double step = MetresPerPixel(before[1] - 0.006 - camera.position[1]);
  const S::PathPoint moved = DeclaredPoint("biceps_line", 1);
  EXPECT_EQ(std::string(moved.body.in()), "upper_arm");
  EXPECT_NEAR(moved.x, 0.045 + 20 * step, 0.002);
  EXPECT_NEAR(moved.y, 0.0, 0.002);
  EXPECT_NEAR(moved.z, 10 * step, 0.002);
  RecordProperty("via_x_mm", std::to_string(1000 * moved.x));
  RecordProperty("via_z_mm", std::to_string(1000 * moved.z));
  M::EditStatus_var status = model_->edit_status();
  EXPECT_EQ(status->revision, 1u);

  // the file written holds the new place: the via element of the biceps, in metres
  M::Octets_var bytes = model_->export_scene();
  const std::string text(reinterpret_cast<const char*>(bytes->get_buffer()), bytes->length());
  std::smatch match;
  ASSERT_TRUE(std::regex_search(
      text, match,
      std::regex("<via body=\"upper_arm\"[^>]*>\\s*([-0-9.e]+) ([-0-9.e]+) ([-0-9.e]+)")))
      << text.substr(text.find("biceps_line"), 400);
  EXPECT_NEAR(std::stod(match[1]), moved.x, 1e-6);
  EXPECT_NEAR(std::stod(match[3]), moved.z, 1e-6);

  // the edited scene comes back: drawn where it was dropped, the camera where it was
  ASSERT_TRUE(PumpUntil([&] { return scenes_ >= 2; }, seconds(5)));
  double local[3];
  ASSERT_TRUE(graph_.PathPointMarker("biceps_line", 1, local));
  EXPECT_NEAR(local[0], moved.x, 1e-6);
  EXPECT_EQ(graph_.highlight(), (R::Entity{"path_point", "biceps_line", 1}));
  const R::CameraPose after = graph_.camera_pose();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(after.position[i], camera.position[i], 1e-6);
}

TEST_F(RendererEdit, ARefusedEditSaysWhyAndLeavesTheSceneAsItWas) {
  // the biceps' end on the forearm: an end cannot be removed
  const QPoint end = Project(MarkerWorld("biceps_line", 2));
  const std::vector<std::string> offered = editor_->ContextActions(end);
  ASSERT_EQ(offered, std::vector<std::string>{"Remove via point"});
  EXPECT_TRUE(editor_->RunContextAction(end, "Remove via point"));  // sent; the answer follows
  ASSERT_TRUE(Answered());
  EXPECT_NE(editor_->last_error().find("is an end of the tendon"), std::string::npos)
      << editor_->last_error();
  EXPECT_NE(graph_.status_text().find("refused: "), std::string::npos) << graph_.status_text();
  EXPECT_EQ(PathLength("biceps_line"), 3u);
  M::EditStatus_var status = model_->edit_status();
  EXPECT_EQ(status->revision, 0u);

  // a drag the Model refuses puts the point back where it was declared
  RefusingClient refusing;
  editor_->set_client(&refusing);
  const QPoint via = Project(MarkerWorld("biceps_line", 1));
  QTest::mouseClick(gl(), Qt::LeftButton, Qt::NoModifier, via);
  ASSERT_TRUE(Answered());
  ASSERT_EQ(editor_->selection(), (R::Entity{"path_point", "biceps_line", 1}));
  QTest::mousePress(gl(), Qt::LeftButton, Qt::NoModifier, via);
  QTest::mouseMove(gl(), via + QPoint(30, 0));
  QTest::mouseRelease(gl(), Qt::LeftButton, Qt::NoModifier, via + QPoint(30, 0));
  ASSERT_TRUE(Answered());
  EXPECT_EQ(refusing.moves, 1);
  EXPECT_EQ(editor_->last_error(), "refused for the test");
  double local[3];
  ASSERT_TRUE(graph_.PathPointMarker("biceps_line", 1, local));
  EXPECT_NEAR(local[0], 0.045, 1e-6);
  editor_->set_client(&client_);
}

TEST_F(RendererEdit, TheContextMenuEditsReachTheModel) {
  // a via point a quarter of the way from the biceps' via point to its shoulder end: in the
  // upper arm (the nearer end's body; no body lies under it there)
  const auto a = MarkerWorld("biceps_line", 0), b = MarkerWorld("biceps_line", 1);
  const std::array<double, 3> on_tendon = {b[0] + (a[0] - b[0]) / 4, b[1] + (a[1] - b[1]) / 4,
                                           b[2] + (a[2] - b[2]) / 4};
  const QPoint at = Project(on_tendon);
  ASSERT_EQ(editor_->ContextActions(at),
            (std::vector<std::string>{"Insert via point here", "Remove tendon"}));
  ASSERT_TRUE(editor_->RunContextAction(at, "Insert via point here")) << editor_->last_error();
  ASSERT_TRUE(Answered());
  ASSERT_EQ(editor_->last_error(), "");
  ASSERT_EQ(PathLength("biceps_line"), 4u);
  const S::PathPoint inserted = DeclaredPoint("biceps_line", 1);
  EXPECT_EQ(std::string(inserted.body.in()), "upper_arm");
  R::Pose upper_arm = PoseNow("upper_arm");
  double expected[3];
  R::ToLocal(upper_arm, on_tendon.data(), expected);
  const double pixel = MetresPerPixel(on_tendon[1] - FrontCamera().position[1]);
  EXPECT_NEAR(inserted.x, expected[0], 2 * pixel);
  EXPECT_NEAR(inserted.z, expected[2], 2 * pixel);
  EXPECT_NEAR(DeclaredPoint("biceps_line", 2).x, 0.045, 1e-9);  // the old via point, one on

  // an obstacle on the upper arm's front face, then grown by a fifth
  ASSERT_TRUE(PumpUntil([&] { return graph_.scene().tendons[0].path.size() == 4; }, seconds(5)));
  const QPoint face = Project(BodyWorld("upper_arm", {-0.01, -0.035, 0.08}));
  ASSERT_TRUE(editor_->RunContextAction(face, "Add obstacle here")) << editor_->last_error();
  ASSERT_TRUE(Answered());
  ASSERT_EQ(editor_->last_error(), "");
  auto obstacle = [&]() -> S::Obstacle {
    S::Description_var scene = model_->scene_description();
    for (CORBA::ULong o = 0; o < scene->obstacles.length(); ++o)
      if (std::string(scene->obstacles[o].name.in()) == "obstacle1") return scene->obstacles[o];
    return S::Obstacle();
  };
  S::Obstacle added = obstacle();
  EXPECT_EQ(std::string(added.body.in()), "upper_arm");
  EXPECT_EQ(std::string(added.kind.in()), "sphere");
  EXPECT_NEAR(added.radius, 0.02, 1e-12);
  EXPECT_NEAR(added.pose.px, -0.01, 2 * pixel);
  EXPECT_NEAR(added.pose.py, -0.035, 0.002);
  EXPECT_NEAR(added.pose.pz, 0.08, 2 * pixel);
  ASSERT_TRUE(PumpUntil([&] { return graph_.scene().obstacles.size() == 3; }, seconds(5)));
  ASSERT_EQ(editor_->ContextActions(face),
            (std::vector<std::string>{"Grow 20%", "Shrink 20%", "Remove obstacle"}));
  ASSERT_TRUE(editor_->RunContextAction(face, "Grow 20%")) << editor_->last_error();
  ASSERT_TRUE(Answered());
  ASSERT_EQ(editor_->last_error(), "");
  EXPECT_NEAR(obstacle().radius, 0.024, 1e-12);

  // a new tendon from the forearm's front to the hand's, with the first actuator kind offered
  QStringList offered;
  editor_->set_kind_chooser([&](const QStringList& kinds, QString* chosen) {
    offered = kinds;
    *chosen = kinds.front();
    return true;
  });
  const QPoint forearm = Project(BodyWorld("forearm", {-0.01, -0.03, 0.0}));
  const QPoint hand = Project(BodyWorld("hand", {0.0, -0.015, 0.0}));
  ASSERT_TRUE(editor_->RunContextAction(forearm, "Start tendon here")) << editor_->last_error();
  ASSERT_TRUE(editor_->RunContextAction(hand, "End tendon here")) << editor_->last_error();
  ASSERT_TRUE(Answered());
  ASSERT_EQ(editor_->last_error(), "");
  ASSERT_FALSE(offered.isEmpty());
  S::Description_var scene = model_->scene_description();
  ASSERT_EQ(scene->tendons.length(), 6u);
  const S::Tendon& added_tendon = scene->tendons[5];
  EXPECT_EQ(std::string(added_tendon.name.in()), "tendon1");
  ASSERT_EQ(added_tendon.path.length(), 2u);
  EXPECT_EQ(std::string(added_tendon.path[0].body.in()), "forearm");
  EXPECT_EQ(std::string(added_tendon.path[1].body.in()), "hand");
  M::EditStatus_var status = model_->edit_status();
  EXPECT_EQ(status->revision, 4u);
}

TEST_F(RendererEdit, CtrlDragPullsAHangingLinkTowardsTheCursor) {
  constexpr CORBA::ULong kSteps = 600;  // 0.3 s at 0.5 ms
  const std::array<double, 3> grab = BodyWorld("hand", {0, -0.015, 0});
  const double start_x = PoseNow("hand").p[0];
  // without a pull first: where the hand goes by itself
  model_->step(kSteps);
  ASSERT_TRUE(PumpUntil([&] { return sim_time_ >= 0.3 - 1e-9; }, seconds(5)));
  const double free_x = PoseNow("hand").p[0];
  model_->reset();
  ASSERT_TRUE(
      PumpUntil([&] { return std::abs(PoseNow("hand").p[0] - start_x) < 1e-6; }, seconds(5)));

  // Ctrl+drag the hand 100 px to the right (about 0.2 m) and hold it there while stepping
  const QPoint at = Project(grab);
  QTest::mousePress(gl(), Qt::LeftButton, Qt::ControlModifier, at);
  EXPECT_TRUE(graph_.pull_line_visible());
  for (int i = 1; i <= 5; ++i) QTest::mouseMove(gl(), at + QPoint(20 * i, 0));
  ASSERT_TRUE(WaitInGui([&] { return editor_->pulls_sent() >= 2; }, seconds(2)));
  const double target_x = grab[0] + 100 * MetresPerPixel(grab[1] - FrontCamera().position[1]);
  model_->step(kSteps);
  ASSERT_TRUE(PumpUntil([&] { return sim_time_ >= 0.3 - 1e-9; }, seconds(5)));
  const double pulled_x = PoseNow("hand").p[0];
  QTest::mouseRelease(gl(), Qt::LeftButton, Qt::ControlModifier, at + QPoint(100, 0));
  EXPECT_FALSE(graph_.pull_line_visible());
  ASSERT_TRUE(Answered());
  EXPECT_EQ(editor_->last_error(), "");

  RecordProperty("hand_x_free_mm", std::to_string(1000 * free_x));
  RecordProperty("hand_x_pulled_mm", std::to_string(1000 * pulled_x));
  RecordProperty("target_x_mm", std::to_string(1000 * target_x));
  EXPECT_GT(pulled_x, free_x + 0.02)
      << "free " << free_x << " m, pulled " << pulled_x << " m, target " << target_x << " m";
  EXPECT_LT(pulled_x, target_x + 0.05);
  // released: the Model pulls no more (its log says so)
  EXPECT_TRUE(
      WaitFor([&] { return model_process_->Output().find("pull released") != std::string::npos; },
              seconds(5)));
}

// an EditClient that answers slowly and records the pulls it is sent (called on the worker)
class SlowClient : public RefusingClient {
 public:
  void Select(const R::Entity&) override { std::this_thread::sleep_for(milliseconds(1500)); }
  void Pull(const std::string&, const double*, const double* target, double) override {
    std::this_thread::sleep_for(milliseconds(150));
    std::lock_guard<std::mutex> lock(mutex);
    targets.push_back({target[0], target[1], target[2]});
  }
  size_t Pulls() {
    std::lock_guard<std::mutex> lock(mutex);
    return targets.size();
  }
  std::array<double, 3> Last() {
    std::lock_guard<std::mutex> lock(mutex);
    return targets.back();
  }
  std::mutex mutex;
  std::vector<std::array<double, 3>> targets;
};

TEST_F(RendererEdit, ASlowModelDoesNotFreezeTheView) {
  SlowClient slow;
  editor_->set_client(&slow);
  const QPoint via = Project(MarkerWorld("biceps_line", 1));
  const auto before = std::chrono::steady_clock::now();
  QTest::mouseClick(gl(), Qt::LeftButton, Qt::NoModifier, via);
  const auto click_ms =
      std::chrono::duration_cast<milliseconds>(std::chrono::steady_clock::now() - before).count();
  RecordProperty("click_with_a_1500_ms_model_ms", std::to_string(click_ms));
  // the highlight is at once; the Model's answer is still on its way
  EXPECT_LT(click_ms, 500);
  EXPECT_EQ(graph_.highlight(), (R::Entity{"path_point", "biceps_line", 1}));
  EXPECT_EQ(editor_->pending_answers(), 1);
  ASSERT_TRUE(Answered());
  editor_->set_client(&client_);
}

TEST_F(RendererEdit, PullsCoalesceAndAreRenewedWhileTheButtonIsHeld) {
  SlowClient slow;
  editor_->set_client(&slow);
  editor_->set_pull_interval(milliseconds(0));
  const QPoint at = Project(BodyWorld("hand", {0, -0.015, 0}));
  QTest::mousePress(gl(), Qt::LeftButton, Qt::ControlModifier, at);
  ASSERT_TRUE(graph_.pull_line_visible());
  // 30 moves faster than the Model answers: never a backlog, the last target is sent
  // (straight to the GL area: the X server would merge motion events on the way)
  for (int i = 1; i <= 30; ++i) {
    QMouseEvent move(QEvent::MouseMove, at + QPoint(2 * i, 0), Qt::NoButton, Qt::LeftButton,
                     Qt::ControlModifier);
    QApplication::sendEvent(gl(), &move);
  }
  ASSERT_TRUE(WaitInGui([&] { return editor_->pending_answers() == 0; }, seconds(5)));
  const size_t after_moves = slow.Pulls();
  RecordProperty("pulls_sent_for_30_moves", std::to_string(after_moves));
  EXPECT_GE(after_moves, 1u);
  EXPECT_LE(after_moves, 3u);
  // the mouse rests: the target is sent again at least every 0.5 s (the Model's lease is 2 s)
  const std::array<double, 3> last = slow.Last();
  QTest::qWait(1300);
  ASSERT_TRUE(WaitInGui([&] { return editor_->pending_answers() == 0; }, seconds(5)));
  EXPECT_GE(slow.Pulls(), after_moves + 2);
  EXPECT_EQ(slow.Last(), last);
  QTest::mouseRelease(gl(), Qt::LeftButton, Qt::ControlModifier, at + QPoint(60, 0));
  ASSERT_TRUE(Answered());
  const size_t released = slow.Pulls();
  QTest::qWait(700);
  EXPECT_EQ(slow.Pulls(), released) << "no renewal after the release";
  editor_->set_client(&client_);
}

TEST_F(RendererEdit, TheViewFollowsTheModelsSharedSelection) {
  // a pick elsewhere (the Main Window, caliper-ctl edit select) highlights here
  model_->select("tendon", "triceps_line", 0);
  EXPECT_TRUE(WaitInGui(
      [&] {
        return graph_.highlight() == R::Entity{"tendon", "triceps_line", 0};
      },
      seconds(3)));
  EXPECT_EQ(editor_->selection(), (R::Entity{"tendon", "triceps_line", 0}));
  EXPECT_EQ(graph_.status_text().rfind("tendon triceps_line", 0), 0u) << graph_.status_text();

  // an insert before the selected via point: the Model re-points its selection, so does the view
  model_->select("path_point", "biceps_line", 1);
  ASSERT_TRUE(WaitInGui(
      [&] {
        return graph_.highlight() == R::Entity{"path_point", "biceps_line", 1};
      },
      seconds(3)));
  S::PathPoint extra;
  extra.body = "upper_arm";
  extra.x = 0.04;
  extra.y = 0;
  extra.z = 0.1;
  model_->insert_path_point("biceps_line", 1, extra);
  ASSERT_TRUE(PumpUntil(
      [&] {
        return graph_.highlight() == R::Entity{"path_point", "biceps_line", 2} &&
               graph_.scene().tendons[0].path.size() == 4;
      },
      seconds(5)))
      << graph_.highlight().kind << " " << graph_.highlight().index;
  // Delete removes what the Model has selected: the old via point, not the inserted one
  QTest::keyClick(gl(), Qt::Key_Delete);
  ASSERT_TRUE(Answered());
  EXPECT_EQ(editor_->last_error(), "");
  ASSERT_EQ(PathLength("biceps_line"), 3u);
  EXPECT_NEAR(DeclaredPoint("biceps_line", 1).x, 0.04, 1e-9);
  EXPECT_NEAR(DeclaredPoint("biceps_line", 1).z, 0.1, 1e-9);
}

// the renderer as its own process: an edit arrives as a new scene, and the camera stays put
TEST(RendererProcess, AnEditedSceneKeepsTheCameraWhereItWas) {
  namespace V = ::Caliper::Viewer;
  if (const std::string why = NoDisplay("the renderer needs X with GLX"); !why.empty())
    GTEST_SKIP() << why;
  TempDir dir;
  NamingService naming(dir.path());
  auto model_process = StartModelProcess(
      naming.address(),
      std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/tests/data/collada/caliper_arm.dae",
      dir.path(), dir.path() + "/model.out");
  M::Model_var model = WaitForModel(naming.address());
  ASSERT_FALSE(CORBA::is_nil(model)) << model_process->Output();
  Process viewer(
      {Bin("caliper-renderer"), "-o", "renderer.check_interval=0.2", "--nameservice",
       naming.address(), "-o", "log.service=none", "-o", "log.spool_dir=" + dir.path() + "/spool"},
      dir.path() + "/viewer.out");
  V::Renderer_var renderer;
  ASSERT_TRUE(WaitFor(
      [&] {
        try {
          CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming.address());
          renderer = V::Renderer::_narrow(rtc::FindComponent(root, "renderer0").object);
          return !CORBA::is_nil(renderer) && !renderer->_non_existent();
        } catch (...) {
          return false;
        }
      },
      seconds(20)))
      << viewer.Output();
  // close in front of the upper arm (Inventor looks along its -z: turned 90 degrees about x)
  const S::Frame pose{0, -0.6, 0.85, std::sqrt(0.5), std::sqrt(0.5), 0, 0};
  QImage before;
  ASSERT_TRUE(WaitFor(
      [&] {
        try {
          renderer->set_camera(pose, kHeightAngle);
          V::Png_var png = renderer->screenshot_png(320, 240);
          return before.loadFromData(png->get_buffer(), static_cast<int>(png->length()), "PNG");
        } catch (const V::NotAvailable&) {
          return false;  // no scene yet
        }
      },
      seconds(20)))
      << viewer.Output();
  std::this_thread::sleep_for(milliseconds(300));  // a few frames: a pending framing would show

  S::PathPoint point;
  point.body = "upper_arm";
  point.x = 0.06;
  point.y = 0;
  point.z = -0.02;
  model->move_path_point("biceps_line", 1, point);
  auto scenes = [&] {
    const std::string out = viewer.Output();
    size_t n = 0;
    for (size_t at = out.find("scene 'caliper_arm'"); at != std::string::npos;
         at = out.find("scene 'caliper_arm'", at + 1))
      ++n;
    return n;
  };
  ASSERT_TRUE(WaitFor([&] { return scenes() >= 2; }, seconds(5))) << viewer.Output();
  std::this_thread::sleep_for(milliseconds(300));
  V::Png_var png = renderer->screenshot_png(320, 240);
  QImage after;
  ASSERT_TRUE(after.loadFromData(png->get_buffer(), static_cast<int>(png->length()), "PNG"));
  ASSERT_EQ(after.size(), before.size());
  int differing = 0;
  for (int y = 0; y < after.height(); ++y)
    for (int x = 0; x < after.width(); ++x)
      if (after.pixel(x, y) != before.pixel(x, y)) ++differing;
  RecordProperty("pixels_changed_by_the_edit", differing);
  // the moved via point and its tendon change a few hundred pixels; a view framed anew all of them
  EXPECT_GT(differing, 0) << "the edit is drawn";
  EXPECT_LT(differing, after.width() * after.height() / 20) << viewer.Output();
}

TEST(SceneIdentity, AnEditedSceneKeepsItsIdentityAnotherSceneDoesNot) {
  R::SceneDescription a;
  a.name = "arm";
  a.bodies.resize(2);
  a.bodies[0].name = "base";
  a.bodies[1].name = "link";
  R::SceneDescription edited = a;
  edited.tendons.push_back({"new", 0.001, {}});
  edited.obstacles.emplace_back();
  edited.bodies[1].visuals.emplace_back();
  EXPECT_EQ(renderer::SceneIdentity(a), renderer::SceneIdentity(edited));
  R::SceneDescription other = a;
  other.bodies[1].name = "arm";
  EXPECT_NE(renderer::SceneIdentity(a), renderer::SceneIdentity(other));
  other = a;
  other.name = "arm2";
  EXPECT_NE(renderer::SceneIdentity(a), renderer::SceneIdentity(other));
}

}  // namespace
}  // namespace caliper::testing
