#include "visual_scene.h"

#include <algorithm>

#include "math3d.h"

namespace caliper::collada::internal {

namespace {
constexpr int kMaxDepth = 256;
constexpr double kPi = 3.14159265358979323846;
}  // namespace

bool VisualScene::IsTransform(const Element& e) {
  const std::string_view n = e.local_name();
  return n == "translate" || n == "rotate" || n == "scale" || n == "matrix" || n == "lookat" ||
         n == "skew";
}

Eigen::Affine3d VisualScene::Root() const {
  Eigen::Affine3d root = Eigen::Affine3d::Identity();
  root.linear() = ctx_.up;
  return root;
}

Eigen::Affine3d VisualScene::TransformOf(const Element& t) const {
  Eigen::Affine3d m = Eigen::Affine3d::Identity();
  const std::string_view n = t.local_name();
  if (n == "translate") {
    m.translation() = ctx_.Vector3(t) * ctx_.meter;
  } else if (n == "rotate") {
    const auto v = ctx_.Numbers(t, 4);
    m.linear() = AxisAngleDegrees(Eigen::Vector3d(v[0], v[1], v[2]), v[3]);
  } else if (n == "scale") {
    m.linear() = ctx_.Vector3(t).asDiagonal();
  } else if (n == "matrix") {
    const auto v = ctx_.Numbers(t, 16);
    Eigen::Matrix4d mat;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) mat(r, c) = v[4 * r + c];
    m.linear() = mat.topLeftCorner<3, 3>();
    m.translation() = mat.topRightCorner<3, 1>() * ctx_.meter;
  } else if (n == "lookat") {
    // the frame sits at the eye, looks along -z at the interest point, with y towards up
    const auto v = ctx_.Numbers(t, 9);
    const Eigen::Vector3d eye(v[0], v[1], v[2]), interest(v[3], v[4], v[5]), up(v[6], v[7], v[8]);
    Eigen::Vector3d z = eye - interest;
    if (!(z.norm() > 0)) ctx_.Fail(&t, "eye and interest point coincide");
    z.normalize();
    Eigen::Vector3d x = up.cross(z);
    if (!(x.norm() > 0)) ctx_.Fail(&t, "up is parallel to the viewing direction");
    x.normalize();
    m.linear().col(0) = x;
    m.linear().col(1) = z.cross(x);
    m.linear().col(2) = z;
    m.translation() = eye * ctx_.meter;
  } else if (n == "skew") {
    // RenderMan's skew: points move along the second axis by tan(angle) times their component
    // along the first
    const auto v = ctx_.Numbers(t, 7);
    Eigen::Vector3d a(v[1], v[2], v[3]), b(v[4], v[5], v[6]);
    if (!(a.norm() > 0) || !(b.norm() > 0)) ctx_.Fail(&t, "skew axes must not be zero");
    a.normalize();
    b.normalize();
    m.linear() += std::tan(v[0] * kPi / 180.0) * b * a.transpose();
  }
  return m;
}

Eigen::Affine3d VisualScene::Local(const Element& node, const Element* stop) const {
  Eigen::Affine3d local = Eigen::Affine3d::Identity();
  for (const auto& c : node.children) {
    if (c.get() == stop) break;
    if (IsTransform(*c)) local = local * TransformOf(*c);
  }
  return local;
}

void VisualScene::Build(const Element& visual_scene) {
  std::vector<const Element*> path;
  for (const Element* node : visual_scene.Children("node")) Visit(*node, -1, Root(), &path);
}

std::vector<int> VisualScene::InstancesOf(const Element* node) const {
  std::vector<int> out;
  const auto range = by_node_.equal_range(node);
  for (auto it = range.first; it != range.second; ++it) out.push_back(it->second);
  std::sort(out.begin(), out.end());
  return out;
}

void VisualScene::Visit(const Element& node, int parent, const Eigen::Affine3d& parent_world,
                        std::vector<const Element*>* path) {
  if (std::find(path->begin(), path->end(), &node) != path->end())
    ctx_.Fail(&node, "instantiates itself (an <instance_node> cycle)");
  if (path->size() > kMaxDepth)
    ctx_.Fail(&node, "nodes nested deeper than " + std::to_string(kMaxDepth));
  path->push_back(&node);
  NodeInstance inst;
  inst.node = &node;
  inst.parent = parent;
  inst.parent_world = parent_world;
  inst.world = parent_world * Local(node);
  for (const auto& c : node.children) {
    const std::string_view n = c->local_name();
    if (n == "instance_geometry") {
      inst.geometry.push_back({c.get(), &ctx_.Resolve(*c, c->Attribute("url"))});
    } else if (n == "instance_controller") {
      // a skin or morph: drawn as its source geometry in the bind pose
      const Element* target = &ctx_.Resolve(*c, c->Attribute("url"));
      for (int hops = 0; hops < 8 && target != nullptr && target->local_name() == "controller";
           ++hops) {
        const Element* inner = target->Child("skin");
        if (inner == nullptr) inner = target->Child("morph");
        target = inner == nullptr ? nullptr : &ctx_.Resolve(*inner, inner->Attribute("source"));
      }
      if (target == nullptr || target->local_name() != "geometry") {
        ctx_.Warn(c.get(), "controller leads to no geometry; not shown");
        continue;
      }
      if (!warned_controller_) {
        warned_controller_ = true;
        ctx_.Warn(
            c.get(),
            "skinned or morphed geometry is shown in its bind pose (controllers are not animated)");
      }
      inst.geometry.push_back({c.get(), target});
    }
  }
  const int index = static_cast<int>(nodes_.size());
  const Eigen::Affine3d world = inst.world;
  nodes_.push_back(std::move(inst));
  by_node_.emplace(&node, index);
  for (const auto& c : node.children) {
    if (c->local_name() == "node") {
      Visit(*c, index, world, path);
    } else if (c->local_name() == "instance_node") {
      const Element& target = ctx_.Resolve(*c, c->Attribute("url"));
      if (target.local_name() != "node")
        ctx_.Fail(c.get(), "url '" + c->Attribute("url") + "' is a <" +
                               std::string(target.local_name()) + ">, not a <node>");
      Visit(target, index, world, path);
    }
  }
  path->pop_back();
}

}  // namespace caliper::collada::internal
