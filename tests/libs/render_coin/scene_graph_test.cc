// The scene graph built from a plain description: bodies, poses, tendon colours, bounds, and an
// offscreen frame (only with an X display).
#include <gtest/gtest.h>

#include <QGuiApplication>
#include <cstdlib>

#include "caliper/render_coin/offscreen_renderer.h"
#include "caliper/render_coin/scene_graph.h"

namespace caliper::render_coin {
namespace {

SceneDescription TwoBoxesAndATendon() {
  SceneDescription scene;
  scene.name = "two";
  for (int i = 0; i < 2; ++i) {
    Body body;
    body.name = "b" + std::to_string(i);
    body.pose.p[2] = 0.5 + i;
    Visual v;
    v.geometry.kind = ShapeKind::kBox;
    v.geometry.dims = {0.2, 0.2, 0.2};
    v.rgba[0] = 0.9f;
    v.rgba[1] = 0.8f;
    v.rgba[2] = 0.2f;
    body.visuals.push_back(v);
    scene.bodies.push_back(body);
  }
  Obstacle o;
  o.name = "pulley";
  o.body = "b0";
  o.kind = "cylinder";
  o.radius = 0.05;
  o.length = 0.1;
  scene.obstacles.push_back(o);
  scene.tendons.push_back({"t", 0.002});
  return scene;
}

TEST(SceneGraph, BuildsOneEntryPerBodyAndTendon) {
  SceneGraph graph;
  EXPECT_EQ(graph.body_count(), 0u);
  graph.Build(TwoBoxesAndATendon());
  EXPECT_EQ(graph.body_count(), 2u);
  EXPECT_EQ(graph.tendon_count(), 1u);
  std::array<double, 3> min{}, max{};
  ASSERT_TRUE(graph.BodyBounds(&min, &max));
  EXPECT_NEAR(min[2], 0.4, 1e-5);
  EXPECT_NEAR(max[2], 1.6, 1e-5);
}

TEST(SceneGraph, DrawsHingeAndSliderAxesOnlyWhenEnabled) {
  SceneDescription scene = TwoBoxesAndATendon();
  for (const char* kind : {"hinge", "slider", "ball"}) {
    Constraint c;
    c.name = kind;
    c.kind = kind;
    c.body_a = "b1";
    c.body_b = "b0";
    c.frame_a.p[0] = 0.5;  // reaches beyond the box: it widens the bounds once shown
    scene.constraints.push_back(c);
  }
  SceneGraph graph;
  EXPECT_FALSE(graph.constraint_axes_visible());
  graph.Build(scene);
  EXPECT_EQ(graph.constraint_axis_count(), 2u) << "hinge and slider, not the ball joint";
  std::array<double, 3> min{}, max{};
  ASSERT_TRUE(graph.BodyBounds(&min, &max));
  EXPECT_NEAR(max[0], 0.1, 1e-5) << "hidden";
  graph.SetConstraintAxesVisible(true);
  ASSERT_TRUE(graph.BodyBounds(&min, &max));
  EXPECT_NEAR(max[0], 0.5, 1e-5) << "shown on b1, at its joint frame";
  graph.Build(scene);
  EXPECT_TRUE(graph.constraint_axes_visible()) << "the setting outlives a rebuild";
  ASSERT_TRUE(graph.BodyBounds(&min, &max));
  EXPECT_NEAR(max[0], 0.5, 1e-5);
}

TEST(SceneGraph, MovesOnlyTheBodiesGiven) {
  SceneGraph graph;
  graph.Build(TwoBoxesAndATendon());
  Pose moved;
  moved.p[0] = 3;
  graph.SetBodyPoses({1, 7}, {moved, moved});  // 7 does not exist: ignored
  EXPECT_EQ(graph.body_pose(1).p[0], 3);
  EXPECT_EQ(graph.body_pose(0).p[0], 0);
  std::array<double, 3> min{}, max{};
  ASSERT_TRUE(graph.BodyBounds(&min, &max));
  EXPECT_NEAR(max[0], 3.1, 1e-5);
}

TEST(SceneGraph, ColoursTendonsByTensionOnAGrowingScale) {
  SceneGraph graph;
  graph.Build(TwoBoxesAndATendon());
  EXPECT_EQ(graph.tendon_color(0), SceneGraph::TensionColor(0));
  TendonState s;
  s.tendon_index = 0;
  s.points = {0, 0, 0.5, 0, 0, 1.5};
  s.tension = 20;
  graph.SetTendons({s});
  EXPECT_DOUBLE_EQ(graph.tension_scale(), 20);
  EXPECT_EQ(graph.tendon_color(0), SceneGraph::TensionColor(1));
  EXPECT_NE(graph.legend_text().find("20 N"), std::string::npos) << graph.legend_text();
  s.tension = 0;
  graph.SetTendons({s});
  EXPECT_EQ(graph.tendon_color(0), SceneGraph::TensionColor(0)) << "low tension is blue";
  const auto low = SceneGraph::TensionColor(0), high = SceneGraph::TensionColor(1);
  EXPECT_GT(low[2], low[0]);
  EXPECT_GT(high[0], high[2]);
}

TEST(SceneGraph, ClearRemovesTheModel) {
  SceneGraph graph;
  graph.Build(TwoBoxesAndATendon());
  graph.Clear();
  EXPECT_EQ(graph.body_count(), 0u);
  std::array<double, 3> min{}, max{};
  EXPECT_FALSE(graph.BodyBounds(&min, &max));
}

TEST(OffscreenRenderer, DrawsTheBodiesInTheirColours) {
  if (std::getenv("DISPLAY") == nullptr) GTEST_SKIP() << "no DISPLAY: offscreen GL needs X (Xvfb)";
  int argc = 1;
  char name[] = "render_coin_test";
  char* argv[] = {name, nullptr};
  QGuiApplication app(argc, argv);
  SceneGraph graph;
  graph.Build(TwoBoxesAndATendon());
  OffscreenRenderer renderer;
  const QImage image = renderer.RenderToImage(graph, 320, 240);
  ASSERT_EQ(image.width(), 320);
  int yellowish = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const QColor c = image.pixelColor(x, y);
      if (c.red() > 80 && c.green() > 60 && c.blue() < c.red() / 2) ++yellowish;
    }
  EXPECT_GT(yellowish, 320 * 240 / 50) << "the boxes cover a good part of the frame";
}

}  // namespace
}  // namespace caliper::render_coin
