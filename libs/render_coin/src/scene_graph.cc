#include "caliper/render_coin/scene_graph.h"

#include <Inventor/SbLinear.h>
#include <Inventor/SbViewportRegion.h>
#include <Inventor/SoDB.h>
#include <Inventor/SoPickedPoint.h>
#include <Inventor/actions/SoGetBoundingBoxAction.h>
#include <Inventor/actions/SoRayPickAction.h>
#include <Inventor/nodes/SoAnnotation.h>
#include <Inventor/nodes/SoBaseColor.h>
#include <Inventor/nodes/SoCone.h>
#include <Inventor/nodes/SoCoordinate3.h>
#include <Inventor/nodes/SoCube.h>
#include <Inventor/nodes/SoCylinder.h>
#include <Inventor/nodes/SoDrawStyle.h>
#include <Inventor/nodes/SoFont.h>
#include <Inventor/nodes/SoIndexedFaceSet.h>
#include <Inventor/nodes/SoLightModel.h>
#include <Inventor/nodes/SoLineSet.h>
#include <Inventor/nodes/SoMaterial.h>
#include <Inventor/nodes/SoNormal.h>
#include <Inventor/nodes/SoNormalBinding.h>
#include <Inventor/nodes/SoOrthographicCamera.h>
#include <Inventor/nodes/SoPerspectiveCamera.h>
#include <Inventor/nodes/SoPickStyle.h>
#include <Inventor/nodes/SoPointSet.h>
#include <Inventor/nodes/SoRotationXYZ.h>
#include <Inventor/nodes/SoSeparator.h>
#include <Inventor/nodes/SoShapeHints.h>
#include <Inventor/nodes/SoSphere.h>
#include <Inventor/nodes/SoSwitch.h>
#include <Inventor/nodes/SoText2.h>
#include <Inventor/nodes/SoTransform.h>
#include <Inventor/nodes/SoTranslation.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace caliper::render_coin {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGridHalfSize = 1.0;  // [m]
constexpr double kGridSpacing = 0.1;   // [m]
constexpr double kAxisLength = 0.2;    // [m]
constexpr float kTendonWidth = 3.0f;   // [px]
constexpr float kObstacleTransparency = 0.65f;
constexpr double kMarkerRadius = 0.006;    // [m], the spheres drawn at path points
constexpr float kPickRadius = 6.0f;        // [px] around the cursor for thin lines
constexpr float kHighlightWidth = 7.0f;    // [px], a selected tendon
constexpr double kJointAxisLength = 0.12;  // [m], centred on the joint
constexpr float kJointAxisWidth = 4.0f;     // [px]

void SetTransform(SoTransform* t, const Pose& pose) {
  t->translation.setValue(static_cast<float>(pose.p[0]), static_cast<float>(pose.p[1]),
                          static_cast<float>(pose.p[2]));
  // SbRotation takes x y z w
  t->rotation.setValue(static_cast<float>(pose.q[1]), static_cast<float>(pose.q[2]),
                       static_cast<float>(pose.q[3]), static_cast<float>(pose.q[0]));
}

double Dim(const Shape& s, size_t i, double fallback) {
  return i < s.dims.size() ? s.dims[i] : fallback;
}

// Coin's cylinders and cones run along y, ours along z
SoRotationXYZ* YToZ() {
  auto* r = new SoRotationXYZ;
  r->axis = SoRotationXYZ::X;
  r->angle = static_cast<float>(kPi / 2);
  return r;
}

SoNode* MeshNode(const Mesh& mesh) {
  auto* sep = new SoSeparator;
  auto* hints = new SoShapeHints;
  hints->creaseAngle = 0.6f;
  sep->addChild(hints);
  auto* coords = new SoCoordinate3;
  const int n = static_cast<int>(mesh.vertices.size() / 3);
  coords->point.setNum(n);
  SbVec3f* pts = coords->point.startEditing();
  for (int i = 0; i < n; ++i)
    pts[i].setValue(mesh.vertices[3 * i], mesh.vertices[3 * i + 1], mesh.vertices[3 * i + 2]);
  coords->point.finishEditing();
  sep->addChild(coords);
  if (mesh.triangles.empty()) {
    sep->addChild(new SoPointSet);
    return sep;
  }
  if (mesh.normals.size() == mesh.vertices.size()) {
    auto* normals = new SoNormal;
    normals->vector.setNum(n);
    SbVec3f* v = normals->vector.startEditing();
    for (int i = 0; i < n; ++i)
      v[i].setValue(mesh.normals[3 * i], mesh.normals[3 * i + 1], mesh.normals[3 * i + 2]);
    normals->vector.finishEditing();
    sep->addChild(normals);
    auto* binding = new SoNormalBinding;
    binding->value = SoNormalBinding::PER_VERTEX_INDEXED;
    sep->addChild(binding);
  }
  auto* faces = new SoIndexedFaceSet;
  const size_t triangles = mesh.triangles.size() / 3;
  faces->coordIndex.setNum(static_cast<int>(triangles * 4));
  int32_t* idx = faces->coordIndex.startEditing();
  for (size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) idx[4 * t + k] = static_cast<int32_t>(mesh.triangles[3 * t + k]);
    idx[4 * t + 3] = SO_END_FACE_INDEX;
  }
  faces->coordIndex.finishEditing();
  sep->addChild(faces);
  return sep;
}

// the shape of a visual in its own frame; nullptr for what is not drawn (planes: the grid)
SoNode* ShapeNode(const Shape& shape, const std::vector<Mesh>& meshes) {
  switch (shape.kind) {
    case ShapeKind::kBox: {
      auto* cube = new SoCube;
      cube->width = static_cast<float>(Dim(shape, 0, 0.1));
      cube->height = static_cast<float>(Dim(shape, 1, 0.1));
      cube->depth = static_cast<float>(Dim(shape, 2, 0.1));
      return cube;
    }
    case ShapeKind::kSphere: {
      auto* sphere = new SoSphere;
      sphere->radius = static_cast<float>(Dim(shape, 0, 0.05));
      return sphere;
    }
    case ShapeKind::kCylinder: {
      auto* sep = new SoSeparator;
      sep->addChild(YToZ());
      auto* cylinder = new SoCylinder;
      cylinder->radius = static_cast<float>(Dim(shape, 0, 0.05));
      cylinder->height = static_cast<float>(Dim(shape, 1, 0.1));
      sep->addChild(cylinder);
      return sep;
    }
    case ShapeKind::kCone: {
      auto* sep = new SoSeparator;
      sep->addChild(YToZ());
      auto* cone = new SoCone;
      cone->bottomRadius = static_cast<float>(Dim(shape, 0, 0.05));
      cone->height = static_cast<float>(Dim(shape, 1, 0.1));
      sep->addChild(cone);
      return sep;
    }
    case ShapeKind::kCapsule: {
      const float r = static_cast<float>(Dim(shape, 0, 0.05));
      const float length = static_cast<float>(Dim(shape, 1, 0.1));
      auto* sep = new SoSeparator;
      sep->addChild(YToZ());
      auto* cylinder = new SoCylinder;
      cylinder->radius = r;
      cylinder->height = length;
      cylinder->parts = SoCylinder::SIDES;
      sep->addChild(cylinder);
      auto* sphere = new SoSphere;
      sphere->radius = r;
      auto* up = new SoTranslation;
      up->translation.setValue(0, length / 2, 0);
      sep->addChild(up);
      sep->addChild(sphere);
      auto* down = new SoTranslation;
      down->translation.setValue(0, -length, 0);
      sep->addChild(down);
      sep->addChild(sphere);
      return sep;
    }
    case ShapeKind::kConvexHull:
    case ShapeKind::kTriangleMesh:
      if (shape.mesh < 0 || static_cast<size_t>(shape.mesh) >= meshes.size()) return nullptr;
      return MeshNode(meshes[static_cast<size_t>(shape.mesh)]);
    case ShapeKind::kPlane:
      return nullptr;
  }
  return nullptr;
}

// children: the transform, the material, the shape
SoSeparator* ObstacleNode(const Obstacle& o) {
  auto* sep = new SoSeparator;
  auto* t = new SoTransform;
  SetTransform(t, o.pose);
  sep->addChild(t);
  auto* material = new SoMaterial;
  material->diffuseColor.setValue(0.9f, 0.9f, 0.3f);
  material->transparency = kObstacleTransparency;
  sep->addChild(material);
  Shape shape;
  if (o.kind == "cylinder") {
    shape.kind = ShapeKind::kCylinder;
    shape.dims = {o.radius, o.length};
  } else {
    shape.kind = ShapeKind::kSphere;
    shape.dims = {o.radius};
  }
  sep->addChild(ShapeNode(shape, {}));
  return sep;
}

SoPickStyle* Unpickable() {
  auto* style = new SoPickStyle;
  style->style = SoPickStyle::UNPICKABLE;
  return style;
}

// a small sphere at a path point; children: the material, the translation, the sphere
SoSeparator* MarkerNode(const PathPoint& point, bool end) {
  auto* sep = new SoSeparator;
  auto* material = new SoMaterial;
  if (end)
    material->diffuseColor.setValue(0.2f, 0.85f, 0.35f);  // attachments green
  else
    material->diffuseColor.setValue(1.0f, 0.6f, 0.1f);  // via points orange
  sep->addChild(material);
  auto* at = new SoTranslation;
  at->translation.setValue(static_cast<float>(point.p[0]), static_cast<float>(point.p[1]),
                           static_cast<float>(point.p[2]));
  sep->addChild(at);
  auto* sphere = new SoSphere;
  sphere->radius = static_cast<float>(kMarkerRadius);
  sep->addChild(sphere);
  return sep;
}

std::string Key(const Entity& e) { return e.kind + '\n' + e.name + '\n' + std::to_string(e.index); }

// lines in the z = 0 plane every kGridSpacing, unlit grey
SoSeparator* GridNode() {
  auto* sep = new SoSeparator;
  sep->addChild(Unpickable());
  auto* model = new SoLightModel;
  model->model = SoLightModel::BASE_COLOR;
  sep->addChild(model);
  auto* color = new SoBaseColor;
  color->rgb.setValue(0.45f, 0.45f, 0.48f);
  sep->addChild(color);
  auto* coords = new SoCoordinate3;
  auto* lines = new SoLineSet;
  const int n = static_cast<int>(std::lround(2 * kGridHalfSize / kGridSpacing)) + 1;
  int k = 0;
  for (int i = 0; i < n; ++i) {
    const float c = static_cast<float>(-kGridHalfSize + i * kGridSpacing);
    const float h = static_cast<float>(kGridHalfSize);
    coords->point.set1Value(k++, c, -h, 0);
    coords->point.set1Value(k++, c, h, 0);
    coords->point.set1Value(k++, -h, c, 0);
    coords->point.set1Value(k++, h, c, 0);
  }
  for (int i = 0; i < 2 * n; ++i) lines->numVertices.set1Value(i, 2);
  sep->addChild(coords);
  sep->addChild(lines);
  return sep;
}

// x red, y green, z blue from the origin
SoSeparator* AxesNode() {
  auto* sep = new SoSeparator;
  sep->addChild(Unpickable());
  auto* model = new SoLightModel;
  model->model = SoLightModel::BASE_COLOR;
  sep->addChild(model);
  auto* style = new SoDrawStyle;
  style->lineWidth = 3;
  sep->addChild(style);
  const float l = static_cast<float>(kAxisLength);
  const float dirs[3][3] = {{l, 0, 0}, {0, l, 0}, {0, 0, l}};
  for (int a = 0; a < 3; ++a) {
    auto* axis = new SoSeparator;
    auto* color = new SoBaseColor;
    color->rgb.setValue(a == 0 ? 1.f : 0.f, a == 1 ? 0.8f : 0.f, a == 2 ? 1.f : 0.f);
    axis->addChild(color);
    auto* coords = new SoCoordinate3;
    coords->point.set1Value(0, 0, 0, 0);
    coords->point.set1Value(1, dirs[a][0], dirs[a][1], dirs[a][2]);
    axis->addChild(coords);
    axis->addChild(new SoLineSet);
    sep->addChild(axis);
  }
  return sep;
}

// a constraint's axis: a line along z of `frame` (in the body frame), unlit, with a dot at the joint
SoSeparator* JointAxisNode(const Constraint& c) {
  auto* sep = new SoSeparator;
  auto* t = new SoTransform;
  SetTransform(t, c.frame_a);
  sep->addChild(t);
  auto* model = new SoLightModel;
  model->model = SoLightModel::BASE_COLOR;
  sep->addChild(model);
  auto* style = new SoDrawStyle;
  style->lineWidth = kJointAxisWidth;
  style->pointSize = 2 * kJointAxisWidth;
  sep->addChild(style);
  auto* color = new SoBaseColor;
  if (c.kind == "slider")
    color->rgb.setValue(1.0f, 0.55f, 0.0f);
  else
    color->rgb.setValue(0.0f, 1.0f, 1.0f);
  sep->addChild(color);
  auto* coords = new SoCoordinate3;
  const float h = static_cast<float>(kJointAxisLength / 2);
  coords->point.set1Value(0, 0, 0, -h);
  coords->point.set1Value(1, 0, 0, h);
  coords->point.set1Value(2, 0, 0, 0);
  sep->addChild(coords);
  auto* line = new SoLineSet;
  line->numVertices.setValue(2);
  sep->addChild(line);
  auto* dot = new SoPointSet;
  dot->startIndex = 2;
  dot->numPoints = 1;
  sep->addChild(dot);
  return sep;
}

}  // namespace

void InitializeCoin() {
  if (!SoDB::isInitialized()) SoDB::init();
}

void ToWorld(const Pose& pose, const double local[3], double world[3]) {
  const SbRotation r(static_cast<float>(pose.q[1]), static_cast<float>(pose.q[2]),
                     static_cast<float>(pose.q[3]), static_cast<float>(pose.q[0]));
  SbVec3f v;
  r.multVec(SbVec3f(static_cast<float>(local[0]), static_cast<float>(local[1]),
                    static_cast<float>(local[2])),
            v);
  for (int i = 0; i < 3; ++i) world[i] = pose.p[i] + v[i];
}

void ToLocal(const Pose& pose, const double world[3], double local[3]) {
  const SbRotation r(static_cast<float>(pose.q[1]), static_cast<float>(pose.q[2]),
                     static_cast<float>(pose.q[3]), static_cast<float>(pose.q[0]));
  SbVec3f v;
  r.inverse().multVec(
      SbVec3f(static_cast<float>(world[0] - pose.p[0]), static_cast<float>(world[1] - pose.p[1]),
              static_cast<float>(world[2] - pose.p[2])),
      v);
  for (int i = 0; i < 3; ++i) local[i] = v[i];
}

struct SceneGraph::Impl {
  SoSeparator* root = nullptr;       // camera, world, legend
  SoPerspectiveCamera* camera = nullptr;
  SoSeparator* bodies = nullptr;     // one separator per body
  SoSeparator* tendons = nullptr;    // style, then one separator per tendon
  SoText2* legend = nullptr;
  SoBaseColor* legend_low = nullptr;
  std::vector<SoSwitch*> joint_axes;  // one per hinge or slider, under its body_a
  bool joint_axes_visible = false;
  std::vector<SoTransform*> body_transforms;
  std::vector<Pose> body_poses;
  std::vector<SoSeparator*> tendon_nodes;
  std::vector<std::array<float, 3>> tendon_colors;
  std::vector<double> tendon_tensions;
  std::vector<TendonState> tendon_states;  // as last received, per tendon
  std::vector<bool> tendon_seen;
  SceneDescription scene;  // as last built
  std::map<std::string, int> body_by_name;
  // what a highlight or a marker changes, per entity (Key())
  struct Item {
    std::vector<SoMaterial*> materials;
    SoTranslation* marker = nullptr;   // a path point's place in its body
    SoTransform* transform = nullptr;  // an obstacle's pose in its body
    double declared[3] = {0, 0, 0};    // a path point's declared place
    Pose declared_pose;                // an obstacle's declared pose
  };
  std::map<std::string, Item> items;
  std::map<const SoNode*, Entity> entity_of;  // the separators picks map to entities
  Entity highlight;
  size_t markers = 0;
  SoSwitch* pull_switch = nullptr;
  SoCoordinate3* pull_coords = nullptr;
  int pull_body = -1;
  double pull_local[3] = {0, 0, 0};
  double pull_target[3] = {0, 0, 0};
  SoText2* status = nullptr;

  Item* Find(const Entity& e) {
    const auto it = items.find(Key(e));
    return it == items.end() ? nullptr : &it->second;
  }
  void UpdatePullLine() {
    if (pull_body < 0 || static_cast<size_t>(pull_body) >= body_poses.size()) {
      pull_switch->whichChild = SO_SWITCH_NONE;
      return;
    }
    double from[3];
    ToWorld(body_poses[static_cast<size_t>(pull_body)], pull_local, from);
    pull_coords->point.set1Value(0, static_cast<float>(from[0]), static_cast<float>(from[1]),
                                 static_cast<float>(from[2]));
    pull_coords->point.set1Value(1, static_cast<float>(pull_target[0]),
                                 static_cast<float>(pull_target[1]),
                                 static_cast<float>(pull_target[2]));
    pull_switch->whichChild = 0;
  }
};

SceneGraph::SceneGraph() : impl_(std::make_unique<Impl>()) {
  InitializeCoin();
  Impl& m = *impl_;
  m.root = new SoSeparator;
  m.root->ref();
  m.camera = new SoPerspectiveCamera;
  m.root->addChild(m.camera);
  CameraPose initial;
  initial.position[0] = 1.2;
  initial.position[1] = -1.6;
  initial.position[2] = 0.9;
  SetCamera(initial);

  auto* world = new SoSeparator;
  world->addChild(GridNode());
  world->addChild(AxesNode());
  m.bodies = new SoSeparator;
  world->addChild(m.bodies);
  m.tendons = new SoSeparator;
  world->addChild(m.tendons);
  // the Ctrl+drag pull: a white line from the body's point to the target, never picked
  m.pull_switch = new SoSwitch;
  auto* pull = new SoSeparator;
  pull->addChild(Unpickable());
  auto* pull_model = new SoLightModel;
  pull_model->model = SoLightModel::BASE_COLOR;
  pull->addChild(pull_model);
  auto* pull_style = new SoDrawStyle;
  pull_style->lineWidth = 2;
  pull_style->pointSize = 7;
  pull->addChild(pull_style);
  auto* pull_color = new SoBaseColor;
  pull_color->rgb.setValue(1.0f, 1.0f, 1.0f);
  pull->addChild(pull_color);
  m.pull_coords = new SoCoordinate3;
  m.pull_coords->point.setNum(2);
  pull->addChild(m.pull_coords);
  pull->addChild(new SoLineSet);
  auto* pull_end = new SoPointSet;
  pull_end->startIndex = 1;
  pull_end->numPoints = 1;
  pull->addChild(pull_end);
  m.pull_switch->addChild(pull);
  m.pull_switch->whichChild = SO_SWITCH_NONE;
  // drawn over the bodies: the grabbed point is on a surface, often half inside it
  auto* on_top = new SoAnnotation;
  on_top->addChild(m.pull_switch);
  world->addChild(on_top);
  m.root->addChild(world);

  // the legend in normalized screen coordinates, drawn over everything
  auto* legend = new SoAnnotation;
  auto* ortho = new SoOrthographicCamera;
  ortho->viewportMapping = SoCamera::LEAVE_ALONE;
  ortho->height = 2;
  ortho->position.setValue(0, 0, 1);
  legend->addChild(ortho);
  auto* model = new SoLightModel;
  model->model = SoLightModel::BASE_COLOR;
  legend->addChild(model);
  auto* font = new SoFont;
  font->size = 14;
  legend->addChild(font);
  m.legend_low = new SoBaseColor;
  m.legend_low->rgb.setValue(0.9f, 0.9f, 0.9f);
  legend->addChild(m.legend_low);
  auto* status = new SoSeparator;
  auto* status_where = new SoTranslation;
  status_where->translation.setValue(-0.95f, 0.9f, 0);
  status->addChild(status_where);
  m.status = new SoText2;
  status->addChild(m.status);
  legend->addChild(status);
  auto* where = new SoTranslation;
  where->translation.setValue(-0.95f, -0.92f, 0);
  legend->addChild(where);
  m.legend = new SoText2;
  legend->addChild(m.legend);
  m.root->addChild(legend);
  m.legend->string = legend_text().c_str();
}

SceneGraph::~SceneGraph() { impl_->root->unref(); }

void SceneGraph::Clear() {
  Impl& m = *impl_;
  m.bodies->removeAllChildren();
  m.tendons->removeAllChildren();
  m.joint_axes.clear();
  m.body_transforms.clear();
  m.body_poses.clear();
  m.tendon_nodes.clear();
  m.tendon_colors.clear();
  m.tendon_tensions.clear();
  m.tendon_states.clear();
  m.tendon_seen.clear();
  m.scene = SceneDescription();
  m.body_by_name.clear();
  m.items.clear();
  m.entity_of.clear();
  m.markers = 0;
  m.pull_body = -1;
  m.UpdatePullLine();
  tension_scale_ = 1.0;
  m.legend->string = legend_text().c_str();
}

void SceneGraph::Build(const SceneDescription& scene) {
  Clear();
  Impl& m = *impl_;
  std::map<std::string, SoSeparator*> by_name;
  for (const Body& body : scene.bodies) {
    auto* sep = new SoSeparator;
    auto* t = new SoTransform;
    SetTransform(t, body.pose);
    sep->addChild(t);
    const Entity body_entity{"body", body.name, 0};
    Impl::Item& item = m.items[Key(body_entity)];
    m.entity_of[sep] = body_entity;
    m.body_by_name[body.name] = static_cast<int>(m.body_transforms.size());
    for (const Visual& v : body.visuals) {
      SoNode* shape = ShapeNode(v.geometry, scene.meshes);
      if (shape == nullptr) continue;
      auto* vsep = new SoSeparator;
      auto* vt = new SoTransform;
      SetTransform(vt, v.pose);
      vsep->addChild(vt);
      auto* material = new SoMaterial;
      material->diffuseColor.setValue(v.rgba[0], v.rgba[1], v.rgba[2]);
      material->ambientColor.setValue(0.3f * v.rgba[0], 0.3f * v.rgba[1], 0.3f * v.rgba[2]);
      material->specularColor.setValue(0.15f, 0.15f, 0.15f);
      material->transparency = 1.0f - v.rgba[3];
      item.materials.push_back(material);
      vsep->addChild(material);
      vsep->addChild(shape);
      sep->addChild(vsep);
    }
    m.bodies->addChild(sep);
    m.body_transforms.push_back(t);
    m.body_poses.push_back(body.pose);
    by_name[body.name] = sep;
  }
  for (const Constraint& c : scene.constraints) {
    if (c.kind != "hinge" && c.kind != "slider") continue;
    const auto it = by_name.find(c.body_a);
    if (it == by_name.end()) continue;
    auto* sw = new SoSwitch;
    sw->addChild(JointAxisNode(c));
    sw->whichChild = m.joint_axes_visible ? 0 : SO_SWITCH_NONE;
    it->second->addChild(sw);
    m.joint_axes.push_back(sw);
  }
  for (const Obstacle& o : scene.obstacles) {
    const auto it = by_name.find(o.body);
    SoSeparator* node = ObstacleNode(o);
    (it == by_name.end() ? m.bodies : it->second)->addChild(node);
    const Entity entity{"obstacle", o.name, 0};
    m.entity_of[node] = entity;
    Impl::Item& item = m.items[Key(entity)];
    item.materials.push_back(static_cast<SoMaterial*>(node->getChild(1)));
    item.transform = static_cast<SoTransform*>(node->getChild(0));
    item.declared_pose = o.pose;
  }
  for (const Tendon& t : scene.tendons) {
    for (size_t e = 0; e < t.path.size(); ++e) {
      const PathPoint& point = t.path[e];
      if (!point.obstacle.empty()) continue;
      const auto it = by_name.find(point.body);
      SoSeparator* node = MarkerNode(point, e == 0 || e + 1 == t.path.size());
      (it == by_name.end() ? m.bodies : it->second)->addChild(node);
      const Entity entity{"path_point", t.name, static_cast<uint32_t>(e)};
      m.entity_of[node] = entity;
      Impl::Item& item = m.items[Key(entity)];
      item.materials.push_back(static_cast<SoMaterial*>(node->getChild(0)));
      item.marker = static_cast<SoTranslation*>(node->getChild(1));
      for (int k = 0; k < 3; ++k) item.declared[k] = point.p[k];
      ++m.markers;
    }
  }
  auto* model = new SoLightModel;
  model->model = SoLightModel::BASE_COLOR;
  m.tendons->addChild(model);
  auto* style = new SoDrawStyle;
  style->lineWidth = kTendonWidth;
  m.tendons->addChild(style);
  for (size_t i = 0; i < scene.tendons.size(); ++i) {
    // children: the width (wider when highlighted), the colour, the points, the lines
    auto* sep = new SoSeparator;
    auto* width = new SoDrawStyle;
    width->lineWidth = kTendonWidth;
    sep->addChild(width);
    auto* color = new SoBaseColor;
    const auto rgb = TensionColor(0);
    color->rgb.setValue(rgb[0], rgb[1], rgb[2]);
    sep->addChild(color);
    sep->addChild(new SoCoordinate3);
    auto* lines = new SoLineSet;
    lines->numVertices.setValue(0);
    sep->addChild(lines);
    m.tendons->addChild(sep);
    m.tendon_nodes.push_back(sep);
    m.tendon_colors.push_back(rgb);
    m.tendon_tensions.push_back(0);
    m.tendon_states.emplace_back();
    m.tendon_seen.push_back(false);
    const Entity entity{"tendon", scene.tendons[i].name, 0};
    m.entity_of[sep] = entity;
    m.items[Key(entity)];
  }
  m.scene = scene;
  // the highlight outlives the rebuild of an edit when its entity still exists
  const Entity highlighted = m.highlight;
  m.highlight = Entity();
  SetHighlight(m.Find(highlighted) != nullptr ? highlighted : Entity());
}

void SceneGraph::SetBodyPoses(const std::vector<uint32_t>& indices, const std::vector<Pose>& poses) {
  Impl& m = *impl_;
  const size_t n = std::min(indices.size(), poses.size());
  for (size_t i = 0; i < n; ++i) {
    if (indices[i] >= m.body_transforms.size()) continue;
    SetTransform(m.body_transforms[indices[i]], poses[i]);
    m.body_poses[indices[i]] = poses[i];
  }
  if (m.pull_body >= 0) m.UpdatePullLine();
}

void SceneGraph::SetTendons(const std::vector<TendonState>& tendons) {
  Impl& m = *impl_;
  double largest = tension_scale_;
  for (const TendonState& t : tendons) largest = std::max(largest, t.tension);
  const bool rescaled = largest > tension_scale_;
  tension_scale_ = largest;
  for (const TendonState& t : tendons) {
    if (t.tendon_index >= m.tendon_nodes.size()) continue;
    SoSeparator* sep = m.tendon_nodes[t.tendon_index];
    auto* coords = static_cast<SoCoordinate3*>(sep->getChild(2));
    auto* lines = static_cast<SoLineSet*>(sep->getChild(3));
    const int n = static_cast<int>(t.points.size() / 3);
    coords->point.setNum(n);
    SbVec3f* pts = coords->point.startEditing();
    for (int i = 0; i < n; ++i)
      pts[i].setValue(static_cast<float>(t.points[3 * i]), static_cast<float>(t.points[3 * i + 1]),
                      static_cast<float>(t.points[3 * i + 2]));
    coords->point.finishEditing();
    lines->numVertices.setValue(n);
    m.tendon_tensions[t.tendon_index] = t.tension;
    m.tendon_states[t.tendon_index] = t;
    m.tendon_seen[t.tendon_index] = true;
  }
  // colours of all tendons follow the scale, which may just have grown
  for (size_t i = 0; i < m.tendon_nodes.size(); ++i) {
    const auto rgb = TensionColor(m.tendon_tensions[i] / tension_scale_);
    if (rgb == m.tendon_colors[i] && !rescaled) continue;
    m.tendon_colors[i] = rgb;
    if (m.highlight.kind == "tendon" && m.highlight.name == m.scene.tendons[i].name) continue;
    static_cast<SoBaseColor*>(m.tendon_nodes[i]->getChild(1))->rgb.setValue(rgb[0], rgb[1], rgb[2]);
  }
  if (rescaled) m.legend->string = legend_text().c_str();
}

void SceneGraph::SetConstraintAxesVisible(bool on) {
  Impl& m = *impl_;
  m.joint_axes_visible = on;
  for (SoSwitch* sw : m.joint_axes) sw->whichChild = on ? 0 : SO_SWITCH_NONE;
}
bool SceneGraph::constraint_axes_visible() const { return impl_->joint_axes_visible; }
size_t SceneGraph::constraint_axis_count() const { return impl_->joint_axes.size(); }

size_t SceneGraph::body_count() const { return impl_->body_transforms.size(); }
size_t SceneGraph::tendon_count() const { return impl_->tendon_nodes.size(); }
Pose SceneGraph::body_pose(size_t index) const { return impl_->body_poses.at(index); }
std::array<float, 3> SceneGraph::tendon_color(size_t index) const {
  return impl_->tendon_colors.at(index);
}

std::string SceneGraph::legend_text() const {
  char text[96];
  std::snprintf(text, sizeof text, "tendon tension  0 N (blue) .. %.3g N (red)", tension_scale_);
  return text;
}

std::array<float, 3> SceneGraph::TensionColor(double fraction) {
  const float f = static_cast<float>(std::clamp(fraction, 0.0, 1.0));
  return {0.1f + 0.9f * f, 0.1f, 1.0f - 0.9f * f};
}

bool SceneGraph::BodyBounds(std::array<double, 3>* min, std::array<double, 3>* max) const {
  if (impl_->body_transforms.empty()) return false;
  SoGetBoundingBoxAction action(SbViewportRegion(640, 480));
  action.apply(impl_->bodies);
  const SbBox3f box = action.getBoundingBox();
  if (box.isEmpty()) return false;
  for (int i = 0; i < 3; ++i) {
    (*min)[i] = box.getMin()[i];
    (*max)[i] = box.getMax()[i];
  }
  return true;
}

void SceneGraph::ViewAll(double aspect) {
  const int height = 1000;
  // a window being laid out may report any size: keep the region within what SbViewportRegion holds
  if (!(aspect > 0.1)) aspect = aspect > 0 ? 0.1 : 1.0;
  aspect = std::min(aspect, 10.0);
  const int width = std::max(1, static_cast<int>(std::lround(height * aspect)));
  SoNode* what = impl_->body_transforms.empty() ? static_cast<SoNode*>(impl_->root->getChild(1))
                                                : static_cast<SoNode*>(impl_->bodies);
  impl_->camera->viewAll(what, SbViewportRegion(static_cast<short>(width), height), 1.1f);
}

void SceneGraph::FitClippingPlanes() {
  SoGetBoundingBoxAction action(SbViewportRegion(640, 480));
  action.apply(impl_->root->getChild(1));  // the world: grid, axes, bodies, tendons
  const SbBox3f box = action.getBoundingBox();
  if (box.isEmpty()) return;
  SoPerspectiveCamera* camera = impl_->camera;
  SbVec3f direction;
  camera->orientation.getValue().multVec(SbVec3f(0, 0, -1), direction);
  const SbVec3f position = camera->position.getValue();
  const SbVec3f lo = box.getMin(), hi = box.getMax();
  float nearest = 1e30f, farthest = -1e30f;
  for (int i = 0; i < 8; ++i) {
    const SbVec3f corner(i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]);
    const float d = (corner - position).dot(direction);
    nearest = std::min(nearest, d);
    farthest = std::max(farthest, d);
  }
  farthest = std::max(farthest * 1.05f, 0.01f);
  nearest = std::max(nearest * 0.95f, farthest * 1e-4f);
  camera->nearDistance = nearest;
  camera->farDistance = farthest;
}

void SceneGraph::SetCamera(const CameraPose& c) {
  SoPerspectiveCamera* camera = impl_->camera;
  const SbVec3f position(static_cast<float>(c.position[0]), static_cast<float>(c.position[1]),
                         static_cast<float>(c.position[2]));
  const SbVec3f target(static_cast<float>(c.look_at[0]), static_cast<float>(c.look_at[1]),
                       static_cast<float>(c.look_at[2]));
  camera->position = position;
  camera->heightAngle = static_cast<float>(c.height_angle);
  camera->focalDistance = (target - position).length();
  camera->pointAt(target, SbVec3f(static_cast<float>(c.up[0]), static_cast<float>(c.up[1]),
                                  static_cast<float>(c.up[2])));
}

CameraPose SceneGraph::camera_pose() const {
  const SoPerspectiveCamera* camera = impl_->camera;
  CameraPose c;
  const SbVec3f p = camera->position.getValue();
  SbVec3f direction, up;
  camera->orientation.getValue().multVec(SbVec3f(0, 0, -1), direction);
  camera->orientation.getValue().multVec(SbVec3f(0, 1, 0), up);
  const SbVec3f target = p + direction * camera->focalDistance.getValue();
  for (int i = 0; i < 3; ++i) {
    c.position[i] = p[i];
    c.look_at[i] = target[i];
    c.up[i] = up[i];
  }
  c.height_angle = camera->heightAngle.getValue();
  return c;
}

const SceneDescription& SceneGraph::scene() const { return impl_->scene; }

const TendonState* SceneGraph::tendon_state(size_t index) const {
  const Impl& m = *impl_;
  return index < m.tendon_seen.size() && m.tendon_seen[index] ? &m.tendon_states[index] : nullptr;
}

int SceneGraph::body_index(const std::string& name) const {
  const auto it = impl_->body_by_name.find(name);
  return it == impl_->body_by_name.end() ? -1 : it->second;
}

bool SceneGraph::BodyPose(const std::string& name, Pose* pose) const {
  if (name.empty()) {
    *pose = Pose();
    return true;
  }
  const int index = body_index(name);
  if (index < 0) return false;
  *pose = impl_->body_poses[static_cast<size_t>(index)];
  return true;
}

std::vector<Hit> SceneGraph::Pick(double x, double y, int width, int height) const {
  const Impl& m = *impl_;
  std::vector<Hit> hits;
  if (width <= 0 || height <= 0) return hits;
  const SbViewportRegion region(static_cast<short>(width), static_cast<short>(height));
  SoRayPickAction action(region);
  // Coin counts pixels from the bottom
  action.setPoint(
      SbVec2s(static_cast<short>(std::lround(x)), static_cast<short>(std::lround(height - 1 - y))));
  action.setRadius(kPickRadius);
  action.setPickAll(true);
  action.apply(m.root);
  const SoPickedPointList& picked = action.getPickedPointList();
  for (int i = 0; i < picked.getLength(); ++i) {
    const SoPath* path = picked[i]->getPath();
    for (int k = path->getLength() - 1; k >= 0; --k) {
      const auto it = m.entity_of.find(path->getNode(k));
      if (it == m.entity_of.end()) continue;
      Hit hit;
      hit.entity = it->second;
      const SbVec3f p = picked[i]->getPoint();
      for (int j = 0; j < 3; ++j) hit.point[j] = p[j];
      hits.push_back(hit);
      break;
    }
  }
  return hits;
}

void SceneGraph::Ray(double x, double y, int width, int height, double origin[3],
                     double direction[3]) const {
  const float aspect = width > 0 && height > 0 ? static_cast<float>(width) / height : 1.0f;
  SbViewVolume volume = impl_->camera->getViewVolume(aspect);
  // a viewer adjusts the camera to a tall window by widening the vertical angle, as Coin does
  if (aspect < 1.0f) volume.scale(1.0f / aspect);
  SbLine line;
  volume.projectPointToLine(SbVec2f(static_cast<float>((x + 0.5) / std::max(width, 1)),
                                    static_cast<float>(1.0 - (y + 0.5) / std::max(height, 1))),
                            line);
  for (int i = 0; i < 3; ++i) {
    origin[i] = line.getPosition()[i];
    direction[i] = line.getDirection()[i];
  }
}

std::array<double, 3> SceneGraph::view_direction() const {
  SbVec3f direction;
  impl_->camera->orientation.getValue().multVec(SbVec3f(0, 0, -1), direction);
  return {direction[0], direction[1], direction[2]};
}

void SceneGraph::SetHighlight(const Entity& entity) {
  Impl& m = *impl_;
  // undo the old one
  if (Impl::Item* old = m.Find(m.highlight)) {
    for (SoMaterial* material : old->materials) material->emissiveColor.setValue(0, 0, 0);
    if (m.highlight.kind == "tendon") {
      for (size_t i = 0; i < m.scene.tendons.size(); ++i) {
        if (m.scene.tendons[i].name != m.highlight.name) continue;
        const auto rgb = m.tendon_colors[i];
        static_cast<SoBaseColor*>(m.tendon_nodes[i]->getChild(1))
            ->rgb.setValue(rgb[0], rgb[1], rgb[2]);
        static_cast<SoDrawStyle*>(m.tendon_nodes[i]->getChild(0))->lineWidth = kTendonWidth;
      }
    }
  }
  Impl::Item* item = m.Find(entity);
  m.highlight = item != nullptr ? entity : Entity();
  if (item == nullptr) return;
  for (SoMaterial* material : item->materials) material->emissiveColor.setValue(0.55f, 0.5f, 0.1f);
  if (entity.kind == "tendon") {
    for (size_t i = 0; i < m.scene.tendons.size(); ++i) {
      if (m.scene.tendons[i].name != entity.name) continue;
      static_cast<SoBaseColor*>(m.tendon_nodes[i]->getChild(1))->rgb.setValue(1.0f, 1.0f, 0.4f);
      static_cast<SoDrawStyle*>(m.tendon_nodes[i]->getChild(0))->lineWidth = kHighlightWidth;
    }
  }
}

const Entity& SceneGraph::highlight() const { return impl_->highlight; }

void SceneGraph::SetPathPointMarker(const std::string& tendon, uint32_t index,
                                    const double* local) {
  Impl::Item* item = impl_->Find({"path_point", tendon, index});
  if (item == nullptr || item->marker == nullptr) return;
  const double* p = local != nullptr ? local : item->declared;
  item->marker->translation.setValue(static_cast<float>(p[0]), static_cast<float>(p[1]),
                                     static_cast<float>(p[2]));
}

bool SceneGraph::PathPointMarker(const std::string& tendon, uint32_t index, double local[3]) const {
  Impl::Item* item = impl_->Find({"path_point", tendon, index});
  if (item == nullptr || item->marker == nullptr) return false;
  const SbVec3f p = item->marker->translation.getValue();
  for (int i = 0; i < 3; ++i) local[i] = p[i];
  return true;
}

void SceneGraph::SetObstacleMarker(const std::string& name, const Pose* pose) {
  Impl::Item* item = impl_->Find({"obstacle", name, 0});
  if (item == nullptr || item->transform == nullptr) return;
  SetTransform(item->transform, pose != nullptr ? *pose : item->declared_pose);
}

void SceneGraph::SetPullLine(int body, const double local[3], const double target[3]) {
  Impl& m = *impl_;
  m.pull_body = body;
  if (body >= 0) {
    for (int i = 0; i < 3; ++i) {
      m.pull_local[i] = local[i];
      m.pull_target[i] = target[i];
    }
  }
  m.UpdatePullLine();
}

bool SceneGraph::pull_line_visible() const {
  return impl_->pull_switch->whichChild.getValue() == 0;
}

void SceneGraph::SetStatus(const std::string& text) { impl_->status->string = text.c_str(); }

std::string SceneGraph::status_text() const {
  const SoMFString& lines = impl_->status->string;
  std::string text;
  for (int i = 0; i < lines.getNum(); ++i)
    text += (i > 0 ? "\n" : "") + std::string(lines[i].getString());
  return text;
}

size_t SceneGraph::path_point_count() const { return impl_->markers; }

SoSeparator* SceneGraph::root() const { return impl_->root; }
SoCamera* SceneGraph::camera() const { return impl_->camera; }

}  // namespace caliper::render_coin
