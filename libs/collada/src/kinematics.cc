#include "kinematics.h"

#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "math3d.h"
#include "sid.h"

namespace caliper::collada::internal {

namespace {

constexpr double kPi = 3.14159265358979323846;

// A joint of a kinematics model: a <joint>, or an <instance_joint> of a library joint.
struct JointInfo {
  const Element* identity = nullptr;  // <joint> or <instance_joint>
  const Element* parent_link = nullptr;
  const Element* child_link = nullptr;
  int depth = -1;  // of its child link below the root link (-1 unknown)
  std::map<const Element*, std::string> constraints;  // axis element -> constraint name
};

// A joint axis bound to a transform element of a visual node.
struct Binding {
  const Element* bind = nullptr;       // <bind_joint_axis>
  const Element* transform = nullptr;  // <rotate> or <translate> in the node
  const Element* node = nullptr;       // that node
  const Element* axis = nullptr;       // <revolute> or <prismatic>
  const Element* identity = nullptr;   // its joint
};

// The joint an element path ends in (for a <joint> reached through an <instance_joint>, the
// instance).
const Element* JointIdentity(const std::vector<const Element*>& trail) {
  for (size_t i = trail.size(); i-- > 0;) {
    const std::string_view n = trail[i]->local_name();
    if (n == "instance_joint") return trail[i];
    if (n == "joint")
      return i > 0 && trail[i - 1]->local_name() == "instance_joint" ? trail[i - 1] : trail[i];
  }
  return nullptr;
}

// An affine expression c + sum k_i x_i of a MathML formula.
struct AffineForm {
  double constant = 0;
  std::map<std::string, double> terms;
  bool Constant() const {
    for (const auto& [s, k] : terms)
      if (k != 0) return false;
    return true;
  }
};

std::optional<AffineForm> Evaluate(const Element& e) {
  const std::string_view n = e.local_name();
  if (n == "math" || n == "semantics") {
    for (const auto& c : e.children)
      if (c->local_name() != "annotation" && c->local_name() != "annotation-xml")
        return Evaluate(*c);
    return std::nullopt;
  }
  if (n == "cn") {
    std::vector<double> v;
    std::string bad;
    if (!ParseNumbers(e.text, &v, &bad) || v.size() != 1) return std::nullopt;
    AffineForm f;
    f.constant = v[0];
    return f;
  }
  if (n == "csymbol" || n == "ci") {
    AffineForm f;
    f.terms[e.Trimmed()] = 1;
    return f;
  }
  if (n != "apply" || e.children.empty()) return std::nullopt;
  const std::string_view op = e.children[0]->local_name();
  std::vector<AffineForm> args;
  for (size_t i = 1; i < e.children.size(); ++i) {
    auto a = Evaluate(*e.children[i]);
    if (!a) return std::nullopt;
    args.push_back(*a);
  }
  AffineForm r;
  if (op == "plus") {
    for (const auto& a : args) {
      r.constant += a.constant;
      for (const auto& [s, k] : a.terms) r.terms[s] += k;
    }
    return r;
  }
  if (op == "minus" && (args.size() == 1 || args.size() == 2)) {
    const double sign = args.size() == 1 ? -1 : 1;
    r.constant = sign * args[0].constant;
    for (const auto& [s, k] : args[0].terms) r.terms[s] = sign * k;
    if (args.size() == 2) {
      r.constant -= args[1].constant;
      for (const auto& [s, k] : args[1].terms) r.terms[s] -= k;
    }
    return r;
  }
  if (op == "times") {
    r.constant = 1;
    bool variable = false;
    for (const auto& a : args) {
      if (a.Constant()) {
        r.constant *= a.constant;
        for (auto& [s, k] : r.terms) k *= a.constant;
      } else {
        if (variable) return std::nullopt;  // a product of two variables
        variable = true;
        const double c = r.constant;
        r.terms.clear();
        for (const auto& [s, k] : a.terms) r.terms[s] = c * k;
        r.constant = c * a.constant;
      }
    }
    return r;
  }
  if (op == "divide" && args.size() == 2 && args[1].Constant() && args[1].constant != 0) {
    r.constant = args[0].constant / args[1].constant;
    for (const auto& [s, k] : args[0].terms) r.terms[s] = k / args[1].constant;
    return r;
  }
  return std::nullopt;
}

class KinematicsReader {
 public:
  KinematicsReader(Context& ctx, const VisualScene& visual) : ctx_(ctx), visual_(visual) {}

  void Read() {
    const Element* scene = ctx_.doc.root->Child("scene");
    std::set<const Element*> bound_models;
    if (scene != nullptr) {
      for (const Element* iks : scene->Children("instance_kinematics_scene")) {
        const Element& ks = ctx_.Resolve(*iks, iks->Attribute("url"));
        if (ks.local_name() != "kinematics_scene")
          ctx_.Fail(iks, "url '" + iks->Attribute("url") + "' is not a <kinematics_scene>");
        for (const Element* bkm : iks->Children("bind_kinematics_model"))
          BindModel(*bkm, ks, &bound_models);
        for (const Element* bja : iks->Children("bind_joint_axis")) BindAxis(*bja, ks);
      }
    }
    for (const Element* model : bound_models) ParseLinks(*model);
    MakeConstraints();
    for (const Element* model : bound_models) {
      const Element* tc = model->Child("technique_common");
      if (tc == nullptr) continue;
      for (const Element* f : tc->Children("formula")) Couple(*f);
      for (const Element* inst : tc->Children("instance_formula"))
        ctx_.Warn(inst,
                  "instance_formula (a formula with set parameters) is not supported; ignored");
    }
    // kinematics models no scene binds
    for (const Element* lib : ctx_.doc.root->Children("library_kinematics_models"))
      for (const Element* model : lib->Children("kinematics_model"))
        if (bound_models.count(model) == 0)
          ctx_.Warn(model,
                    "is not bound to the visual scene by an instance_kinematics_scene; its joints "
                    "are not imported");
    for (const Element* lib : ctx_.doc.root->Children("library_formulas"))
      for (const Element* f : lib->Children("formula")) Couple(*f);
  }

 private:
  // The element a <param> or <SIDREF> child of `holder` leads to, with the elements passed.
  const Element* Follow(const Element& holder, const Element& scope,
                        std::vector<const Element*>* trail) {
    if (const Element* sidref = holder.Child("SIDREF"); sidref != nullptr) {
      *trail = ResolveSidRef(ctx_, sidref->Trimmed(), &scope);
      if (trail->empty()) return nullptr;
      const Element* last = trail->back();
      trail->pop_back();
      return FollowParam(ctx_, last, trail);
    }
    const Element* param = holder.Child("param");
    if (param == nullptr) return nullptr;
    const Element* np = FindNewParam(ctx_, param->Trimmed(), &scope);
    if (np == nullptr) return nullptr;
    return FollowParam(ctx_, np, trail);
  }

  // The node element a SIDREF to a node (or an instance_node) means.
  const Element* NodeOf(const std::string& ref) {
    auto trail = ResolveSidRef(ctx_, ref);
    if (trail.empty()) return nullptr;
    const Element* e = trail.back();
    if (e->local_name() == "instance_node") e = ctx_.TryResolve(e->Attribute("url"));
    return e != nullptr && e->local_name() == "node" ? e : nullptr;
  }

  void BindModel(const Element& bkm, const Element& ks, std::set<const Element*>* models) {
    const Element* node = NodeOf(bkm.Attribute("node"));
    if (node == nullptr)
      ctx_.Fail(&bkm, "dangling reference: node '" + bkm.Attribute("node") + "' not found");
    std::vector<const Element*> trail;
    const Element* model = Follow(bkm, ks, &trail);
    if (model == nullptr || model->local_name() != "kinematics_model")
      ctx_.Fail(&bkm, "does not lead to a <kinematics_model>");
    models->insert(model);
    root_node_[model] = node;
  }

  void BindAxis(const Element& bja, const Element& ks) {
    const std::string target = bja.Attribute("target");
    auto path = ResolveSidRef(ctx_, target);
    if (path.empty()) ctx_.Fail(&bja, "dangling reference: target '" + target + "' not found");
    Binding b;
    b.bind = &bja;
    b.transform = path.back();
    b.node = Ancestor(b.transform->parent, "node");
    if (b.node == nullptr) ctx_.Fail(&bja, "target '" + target + "' is not inside a <node>");
    const Element* axis_holder = bja.Child("axis");
    if (axis_holder == nullptr) ctx_.Fail(&bja, "has no <axis>");
    std::vector<const Element*> trail;
    b.axis = Follow(*axis_holder, ks, &trail);
    if (b.axis == nullptr) ctx_.Fail(axis_holder, "does not lead to a joint axis");
    if (b.axis->local_name() != "revolute" && b.axis->local_name() != "prismatic")
      ctx_.Fail(axis_holder, "leads to a <" + std::string(b.axis->local_name()) +
                                 ">, not to a revolute or prismatic axis");
    trail.push_back(b.axis);
    b.identity = JointIdentity(trail);
    if (b.identity == nullptr) b.identity = b.axis->parent;
    joints_[b.identity].identity = b.identity;
    bindings_.push_back(b);
  }

  void ParseLinks(const Element& model) {
    const Element* tc = model.Child("technique_common");
    if (tc == nullptr) return;
    const auto links = tc->Children("link");
    if (links.size() > 1)
      ctx_.Warn(&model, "has several root links; the first is bound to the node");
    for (const Element* link : links) {
      if (link == links.front()) link_node_[link] = root_node_[&model];
      ParseLink(*link, model, 0);
    }
  }

  void ParseLink(const Element& link, const Element& model, int depth) {
    for (const auto& c : link.children) {
      const std::string_view n = c->local_name();
      if (n == "attachment_start" || n == "attachment_end") {
        ctx_.Warn(c.get(), "closed kinematic loops are not supported; attachment ignored");
        continue;
      }
      if (n != "attachment_full") continue;
      const auto trail = ResolveSidRef(ctx_, c->Attribute("joint"), &model);
      const Element* identity = JointIdentity(trail);
      if (identity == nullptr)
        ctx_.Fail(c.get(), "dangling reference: joint '" + c->Attribute("joint") + "' not found");
      JointInfo& j = joints_[identity];
      j.identity = identity;
      j.parent_link = &link;
      j.child_link = c->Child("link");
      j.depth = depth + 1;
      if (j.child_link != nullptr) ParseLink(*j.child_link, model, depth + 1);
    }
  }

  // The body a node element is moved by: its first instance's, or the nearest ancestor's.
  std::string BodyOfNode(const Element* node, int* instance) {
    const auto instances = visual_.InstancesOf(node);
    if (instances.empty()) return "";
    if (instance != nullptr) *instance = instances.front();
    for (int k = instances.front(); k >= 0; k = visual_.nodes()[k].parent) {
      const auto it = ctx_.instance_body.find(k);
      if (it != ctx_.instance_body.end()) return it->second;
    }
    return "";
  }

  void MakeConstraints() {
    // a node bound to several joints (the CTS repeats a chain's transforms in each node) is the
    // child link of the deepest of them
    std::map<const Element*, const Element*> deepest;  // node -> joint identity
    for (const auto& b : bindings_) {
      auto& d = deepest[b.node];
      if (d == nullptr || joints_[b.identity].depth > joints_[d].depth) d = b.identity;
    }
    for (const auto& [node, identity] : deepest) {
      const JointInfo& j = joints_[identity];
      if (j.child_link != nullptr && link_node_.count(j.child_link) == 0)
        link_node_[j.child_link] = node;
    }
    for (const auto& b : bindings_) {
      if (deepest[b.node] != b.identity) continue;
      MakeConstraint(b);
    }
  }

  void MakeConstraint(const Binding& b) {
    JointInfo& j = joints_[b.identity];
    const Element* joint_el = b.axis->parent;
    int child_instance = -1;
    const std::string child = BodyOfNode(b.node, &child_instance);
    if (child_instance < 0) {
      ctx_.Warn(b.bind, "its node '" + b.node->Attribute("id") +
                            "' is not part of the visual scene; joint ignored");
      return;
    }
    if (visual_.InstancesOf(b.node).size() > 1)
      ctx_.Warn(b.bind, "node '" + b.node->Attribute("id") +
                            "' is instanced several times; the joint binds the first");
    if (child.empty()) {
      ctx_.Warn(b.bind, "no body moves node '" + b.node->Attribute("id") + "'; joint ignored");
      return;
    }
    // the parent: the node of the joint's parent link, else the nearest ancestor with a body
    std::string parent;
    const auto pl = j.parent_link == nullptr ? link_node_.end() : link_node_.find(j.parent_link);
    if (pl != link_node_.end() && pl->second != nullptr) {
      parent = BodyOfNode(pl->second, nullptr);
    } else {
      for (int k = visual_.nodes()[child_instance].parent; k >= 0 && parent.empty();
           k = visual_.nodes()[k].parent) {
        const auto it = ctx_.instance_body.find(k);
        if (it != ctx_.instance_body.end()) parent = it->second;
      }
    }
    if (parent == child) {
      ctx_.Warn(b.bind, "joint connects body '" + child + "' to itself; ignored");
      return;
    }
    // the joint frame: where the bound transform element applies, z along the axis
    const NodeInstance& inst = visual_.nodes()[child_instance];
    const Eigen::Isometry3d pre =
        RigidPose(inst.parent_world * visual_.Local(*b.node, b.transform)).ToIsometry();
    const bool revolute = b.axis->local_name() == "revolute";
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
    if (const Element* a = b.axis->Child("axis"); a != nullptr) axis = ctx_.Vector3(*a);
    double q0 = 0;
    const std::string_view tn = b.transform->local_name();
    if (tn == "rotate") {
      const auto v = ctx_.Numbers(*b.transform, 4);
      if (revolute && Eigen::Vector3d(v[0], v[1], v[2]).norm() > 0)
        axis = Eigen::Vector3d(v[0], v[1], v[2]);
      q0 = v[3] * kPi / 180;
    } else if (tn == "translate") {
      if (axis.norm() > 0) q0 = ctx_.Vector3(*b.transform).dot(axis.normalized()) * ctx_.meter;
    } else {
      ctx_.Warn(b.bind,
                "binds a <" + std::string(tn) +
                    ">; only rotate and translate elements carry joint values; joint ignored");
      return;
    }
    if (!(axis.norm() > 0)) ctx_.Fail(b.axis, "joint axis is zero");
    if ((revolute && tn != "rotate") || (!revolute && tn != "translate"))
      ctx_.Warn(b.bind, "binds a " + std::string(b.axis->local_name()) + " axis to a <" +
                            std::string(tn) + ">");
    Eigen::Isometry3d fa = pre;
    fa.linear() = pre.linear() * RotationZTo(axis).toRotationMatrix();
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    if (revolute)
      motion.linear() = Eigen::AngleAxisd(q0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    else
      motion.translation() = Eigen::Vector3d(0, 0, q0);
    const Eigen::Isometry3d fb = fa * motion;

    sgal::Constraint c;
    c.kind = revolute ? sgal::ConstraintKind::kHinge : sgal::ConstraintKind::kSlider;
    std::string name = j.identity->Attribute("name");
    if (name.empty()) name = joint_el->Attribute("name");
    if (name.empty()) name = j.identity->Attribute("sid");
    if (name.empty()) name = j.identity->Attribute("id");
    if (name.empty()) name = "joint";
    if (joint_el->Children("revolute").size() + joint_el->Children("prismatic").size() > 1)
      name += "." + b.axis->Attribute("sid");
    c.name = name;
    for (int i = 2; ctx_.constraint_source.count(c.name) > 0; ++i)
      c.name = name + "_" + std::to_string(i);
    double lower = 1, upper = -1;  // free
    if (const Element* limits = b.axis->Child("limits"); limits != nullptr) {
      const double unit = revolute ? kPi / 180 : ctx_.meter;
      const Element* mn = limits->Child("min");
      const Element* mx = limits->Child("max");
      if (mn != nullptr && mx != nullptr) {
        lower = ctx_.Number(mn, 0) * unit;
        upper = ctx_.Number(mx, 0) * unit;
        if (lower > upper)
          ctx_.Fail(limits, "min " + mn->Trimmed() + " is above max " + mx->Trimmed());
      }
    }
    const sgal::Body& cb = ctx_.scene.bodies[ctx_.scene.BodyIndex(child)];
    if (!parent.empty()) {
      const sgal::Body& pb = ctx_.scene.bodies[ctx_.scene.BodyIndex(parent)];
      c.body_a = parent;
      c.body_b = child;
      c.frame_a = sgal::Pose::FromIsometry(pb.pose.ToIsometry().inverse() * fa);
      c.frame_b = sgal::Pose::FromIsometry(cb.pose.ToIsometry().inverse() * fb);
      c.limits[0] = {lower, upper};
    } else {
      // fixed to the world: body_a is the child, so the joint coordinate changes sign
      c.body_a = child;
      c.frame_a = sgal::Pose::FromIsometry(cb.pose.ToIsometry().inverse() * fb);
      c.frame_b = sgal::Pose::FromIsometry(fa);
      c.limits[0] = lower <= upper ? sgal::Limit{-upper, -lower} : sgal::Limit{lower, upper};
      sign_[c.name] = -1;
    }
    j.constraints[b.axis] = c.name;
    kind_[c.name] = revolute;
    ctx_.constraint_source[c.name] = b.bind;
    ctx_.scene.constraints.push_back(std::move(c));
  }

  // The constraint of a joint named by a SIDREF; "" when there is none.
  std::string ConstraintOf(const std::string& ref, const Element& scope) {
    const auto trail = ResolveSidRef(ctx_, ref, &scope);
    const Element* identity = JointIdentity(trail);
    if (identity == nullptr) return "";
    const auto it = joints_.find(identity);
    if (it == joints_.end() || it->second.constraints.empty()) return "";
    return it->second.constraints.begin()->second;
  }

  void Couple(const Element& f) {
    const Element* target = f.Child("target");
    const Element* tc = f.Child("technique_common");
    const Element* param = target == nullptr ? nullptr : target->Child("param");
    if (param == nullptr || tc == nullptr || tc->children.empty()) {
      ctx_.Warn(&f, "has no target parameter or no technique_common; ignored");
      return;
    }
    const std::string follower = ConstraintOf(param->Trimmed(), f);
    if (follower.empty()) {
      ctx_.Warn(&f, "target '" + param->Trimmed() +
                        "' is not a bound joint, so the formula is no joint coupling; ignored");
      return;
    }
    const auto form = Evaluate(*tc->children.front());
    std::string leader;
    double ratio = 0;
    if (form) {
      for (const auto& [symbol, k] : form->terms) {
        if (k == 0) continue;
        if (!leader.empty()) {
          leader = "?";
          break;
        }
        leader = ConstraintOf(symbol, f);
        if (leader.empty()) leader = "?";
        ratio = k;
      }
    }
    if (!form || leader.empty() || leader == "?") {
      ctx_.Warn(&f,
                "is not of the form joint = ratio * joint + offset over bound joints; not imported "
                "as a coupling");
      return;
    }
    // joint values: revolute in degrees (OpenRAVE writes its formulas in radians), prismatic
    // in the document's unit
    auto scale = [&](const std::string& c) {
      return kind_[c] ? (ctx_.openrave ? 1.0 : kPi / 180) : ctx_.meter;
    };
    sgal::Coupling coupling;
    coupling.leader = leader;
    coupling.follower = follower;
    const double sf = scale(follower), sl = scale(leader);
    const double gf = sign_.count(follower) ? -1 : 1, gl = sign_.count(leader) ? -1 : 1;
    coupling.ratio = ratio * sf / sl * gf * gl;
    coupling.offset = form->constant * sf * gf;
    ctx_.scene.couplings.push_back(coupling);
  }

  Context& ctx_;
  const VisualScene& visual_;
  std::map<const Element*, JointInfo> joints_;
  std::map<const Element*, const Element*> root_node_;  // kinematics model -> bound node
  std::map<const Element*, const Element*> link_node_;  // link -> node
  std::vector<Binding> bindings_;
  std::map<std::string, bool> kind_;  // constraint -> revolute
  std::map<std::string, int> sign_;   // constraints whose coordinate is the joint's negated
};

}  // namespace

void ImportKinematics(Context& ctx, const VisualScene& visual) {
  KinematicsReader(ctx, visual).Read();
}

}  // namespace caliper::collada::internal
