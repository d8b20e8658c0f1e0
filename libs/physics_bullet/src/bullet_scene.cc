#include "caliper/physics_bullet/bullet_scene.h"

#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "caliper/actuators/actuator.h"
#include "caliper/actuators/tendon_contact.h"
#include "caliper/actuators/tendon_path.h"

namespace caliper::physics_bullet {

namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

btVector3 ToBt(const Vector3d& v, double s = 1.0) {
  return btVector3(static_cast<btScalar>(v.x() * s), static_cast<btScalar>(v.y() * s),
                   static_cast<btScalar>(v.z() * s));
}

Vector3d FromBt(const btVector3& v, double s = 1.0) {
  return Vector3d(v.x(), v.y(), v.z()) / s;
}

btTransform ToBt(const Isometry3d& t, double s) {
  const Eigen::Quaterniond q(t.rotation());
  return btTransform(btQuaternion(static_cast<btScalar>(q.x()), static_cast<btScalar>(q.y()),
                                  static_cast<btScalar>(q.z()), static_cast<btScalar>(q.w())),
                     ToBt(Vector3d(t.translation()), s));
}

Isometry3d FromBt(const btTransform& t, double s) {
  const btQuaternion q = t.getRotation();
  Isometry3d out = Isometry3d::Identity();
  out.linear() = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).normalized().toRotationMatrix();
  out.translation() = FromBt(t.getOrigin(), s);
  return out;
}

struct BodyData {
  const sgal::Body* desc = nullptr;
  std::unique_ptr<btCompoundShape> compound;
  std::vector<std::unique_ptr<btCollisionShape>> children;
  std::unique_ptr<btRigidBody> rigid;
  Isometry3d com_in_body = Isometry3d::Identity();  // principal-axes frame at the com
  std::vector<actuators::WorldShape> world_shapes;  // refreshed each step when contact is on
  std::vector<Isometry3d> shape_poses;               // shapes in the body frame
};

struct JointData {
  const sgal::Constraint* desc = nullptr;
  Isometry3d frame_a = Isometry3d::Identity();  // joint frames in the body frames
  Isometry3d frame_b = Isometry3d::Identity();
  std::unique_ptr<btTypedConstraint> constraint;
  int body_a = -1, body_b = -1;
  double position = 0;  // [rad] or [m]
  double velocity = 0;  // [rad/s] or [m/s]
  Vector3d axis = Vector3d::UnitZ();  // world, this step
};

/// A path element with its names resolved once.
struct ElementRef {
  const sgal::PathElement* desc = nullptr;
  int body = -1;
  const sgal::WrapObstacle* obstacle = nullptr;
};

struct TendonData {
  const sgal::Tendon* desc = nullptr;
  std::vector<ElementRef> elements;
  std::vector<actuators::WorldElement> world;  // reused every step
  actuators::TendonPath path;
  actuators::PathGeometry geometry;
  double previous_length = -1;
  double tension = 0;
  int contacts = 0;
  std::vector<int> actuators;
};

struct ActuatorData {
  const sgal::Actuator* desc = nullptr;
  std::unique_ptr<actuators::TendonActuator> model;
  int tendon = -1;
};

struct Snapshot {
  btTransform transform;
  btVector3 linear, angular;
};

class BulletScene : public sgal::PhysicsScene {
 public:
  BulletScene(const sgal::Scene& scene, Options options);
  ~BulletScene() override;

  void Step() override;
  double time() const override { return time_; }
  uint64_t steps() const override { return steps_; }
  const sgal::Scene& description() const override { return scene_; }
  std::vector<sgal::BodyState> BodyStates() const override;
  std::vector<sgal::TendonState> TendonStates() const override;
  void SetCommand(const std::string& actuator, double value) override;
  std::vector<sgal::ParameterInfo> Parameters() const override;
  double GetParameter(const std::string& id) const override;
  void SetParameter(const std::string& id, double value) override;

 private:
  void BuildBody(size_t index);
  void BuildConstraint(size_t index);
  void BuildTendons();
  Isometry3d BodyPose(int body) const;  // world pose of a body frame [m]
  void CacheBodyPoses();
  Vector3d PointVelocity(int body, const Vector3d& world_point) const;
  void UpdateJoints();
  void RefreshWorldShapes();
  void EvaluateTendons();
  void ApplyTendonForces();
  void ApplyJointSprings();
  void CheckState();

  sgal::Scene scene_;
  Options options_;
  double scale_;  // engine units per metre
  double dt_;
  double time_ = 0;
  uint64_t steps_ = 0;

  std::unique_ptr<btDefaultCollisionConfiguration> configuration_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btDbvtBroadphase> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::unique_ptr<btRigidBody> fixed_body_;  // the world side of joints with one body
  std::vector<BodyData> bodies_;
  std::vector<JointData> joints_;
  std::vector<TendonData> tendons_;
  std::vector<ActuatorData> actuators_;
  std::vector<Isometry3d> poses_;        // body frames this step [m]
  std::vector<Vector3d> coms_;           // centres of mass this step [m]
  std::vector<Vector3d> velocities_;     // of the centres of mass [m/s]
  std::vector<Vector3d> spins_;          // angular velocities [rad/s]
  std::vector<Snapshot> snapshot_;
  double detour_reach_ = 0.1;  // twice the largest finite shape bounding radius [m]
};

std::unique_ptr<btCollisionShape> MakeShape(const sgal::Geometry& geometry, double s, bool dynamic,
                                            const std::string& where) {
  return std::visit(
      [&](const auto& g) -> std::unique_ptr<btCollisionShape> {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, sgal::Box>) {
          return std::make_unique<btBoxShape>(ToBt(g.size / 2, s));
        } else if constexpr (std::is_same_v<T, sgal::Sphere>) {
          return std::make_unique<btSphereShape>(static_cast<btScalar>(g.radius * s));
        } else if constexpr (std::is_same_v<T, sgal::Capsule>) {
          return std::make_unique<btCapsuleShapeZ>(static_cast<btScalar>(g.radius * s),
                                                   static_cast<btScalar>(g.length * s));
        } else if constexpr (std::is_same_v<T, sgal::Cylinder>) {
          return std::make_unique<btCylinderShapeZ>(
              ToBt(Vector3d(g.radius, g.radius, g.length / 2), s));
        } else if constexpr (std::is_same_v<T, sgal::Cone>) {
          return std::make_unique<btConeShapeZ>(static_cast<btScalar>(g.radius * s),
                                                static_cast<btScalar>(g.length * s));
        } else if constexpr (std::is_same_v<T, sgal::Plane>) {
          if (dynamic) throw std::invalid_argument(where + ": a plane can only belong to a static body");
          return std::make_unique<btStaticPlaneShape>(ToBt(g.normal),
                                                      static_cast<btScalar>(g.offset * s));
        } else {
          // convex hulls, and triangle meshes of moving bodies, collide as their convex hull
          if (!g.mesh || g.mesh->vertices.empty())
            throw std::invalid_argument(where + ": mesh without vertices");
          auto hull = std::make_unique<btConvexHullShape>();
          for (const auto& v : g.mesh->vertices) hull->addPoint(ToBt(v.template cast<double>(), s), false);
          hull->recalcLocalAabb();
          return hull;
        }
      },
      geometry);
}

BulletScene::BulletScene(const sgal::Scene& scene, Options options)
    : scene_(scene),
      options_(options),
      scale_(scene.settings.world_scale),
      dt_(scene.settings.time_step) {
  const auto errors = sgal::Validate(scene_);
  if (!errors.empty()) {
    std::ostringstream msg;
    msg << (scene_.source.empty() ? scene_.name : scene_.source) << ": " << errors.size()
        << " problem(s):";
    for (const auto& e : errors) msg << "\n  " << e;
    throw std::invalid_argument(msg.str());
  }
  configuration_ = std::make_unique<btDefaultCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(configuration_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
  world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                     solver_.get(), configuration_.get());
  world_->setGravity(ToBt(scene_.gravity, scale_));
  world_->getSolverInfo().m_numIterations = scene_.settings.solver_iterations;
  fixed_body_ = std::make_unique<btRigidBody>(0, nullptr, nullptr);
  fixed_body_->setMassProps(0, btVector3(0, 0, 0));

  bodies_.resize(scene_.bodies.size());
  for (size_t i = 0; i < scene_.bodies.size(); ++i) BuildBody(i);
  joints_.resize(scene_.constraints.size());
  for (size_t i = 0; i < scene_.constraints.size(); ++i) BuildConstraint(i);
  BuildTendons();
}

BulletScene::~BulletScene() {
  for (auto& j : joints_) world_->removeConstraint(j.constraint.get());
  for (auto& b : bodies_) world_->removeRigidBody(b.rigid.get());
}

void BulletScene::BuildBody(size_t index) {
  const sgal::Body& desc = scene_.bodies[index];
  BodyData& data = bodies_[index];
  data.desc = &desc;
  const bool dynamic = desc.type == sgal::BodyType::kDynamic;
  const double s = scale_;

  // Bullet wants the body frame at the centre of mass along the principal axes
  btVector3 principal(0, 0, 0);
  if (dynamic) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(desc.inertia.tensor);
    Eigen::Matrix3d axes = eig.eigenvectors();
    if (axes.determinant() < 0) axes.col(2) *= -1;
    data.com_in_body.linear() = axes;
    data.com_in_body.translation() = desc.inertia.com;
    principal = ToBt(eig.eigenvalues(), s * s);
  }
  data.compound = std::make_unique<btCompoundShape>();
  const Isometry3d body_to_com = data.com_in_body.inverse();
  for (const auto& shape : desc.shapes) {
    auto child = MakeShape(shape.geometry, s, dynamic, "body '" + desc.name + "' shape '" + shape.name + "'");
    data.compound->addChildShape(ToBt(body_to_com * shape.pose.ToIsometry(), s), child.get());
    data.children.push_back(std::move(child));
  }
  const double mass = dynamic ? desc.inertia.mass : 0.0;
  btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(mass), nullptr,
                                                data.compound.get(), principal);
  info.m_startWorldTransform = ToBt(desc.pose.ToIsometry() * data.com_in_body, s);
  double friction = 0.5, restitution = 0.0;
  if (!desc.shapes.empty())
    for (const auto& m : scene_.materials)
      if (m.name == desc.shapes.front().material) {
        friction = m.friction;
        restitution = m.restitution;
      }
  info.m_friction = static_cast<btScalar>(friction);
  info.m_restitution = static_cast<btScalar>(restitution);
  data.rigid = std::make_unique<btRigidBody>(info);
  data.rigid->setUserIndex(static_cast<int>(index));
  if (desc.type == sgal::BodyType::kKinematic) {
    data.rigid->setCollisionFlags(data.rigid->getCollisionFlags() |
                                  btCollisionObject::CF_KINEMATIC_OBJECT);
  }
  if (dynamic) {
    data.rigid->setActivationState(DISABLE_DEACTIVATION);
    data.rigid->setLinearVelocity(ToBt(desc.linear_velocity, s));
    data.rigid->setAngularVelocity(ToBt(desc.angular_velocity));
  }
  uint32_t group = 0, mask = 0;
  for (const auto& shape : desc.shapes) {
    group |= shape.group;
    mask |= shape.mask;
  }
  if (desc.shapes.empty()) {
    group = 0;  // a body without shapes collides with nothing
    mask = 0;
  }
  world_->addRigidBody(data.rigid.get(), static_cast<int>(group & 0x7fff),
                       static_cast<int>(mask & 0x7fff));
}

Isometry3d BulletScene::BodyPose(int body) const {
  if (body < 0) return Isometry3d::Identity();
  const BodyData& b = bodies_[body];
  return FromBt(b.rigid->getCenterOfMassTransform(), scale_) * b.com_in_body.inverse();
}

void BulletScene::CacheBodyPoses() {
  const size_t n = bodies_.size();
  poses_.resize(n);
  coms_.resize(n);
  velocities_.resize(n);
  spins_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const btRigidBody& rb = *bodies_[i].rigid;
    const Isometry3d com = FromBt(rb.getCenterOfMassTransform(), scale_);
    poses_[i] = com * bodies_[i].com_in_body.inverse();
    coms_[i] = com.translation();
    velocities_[i] = FromBt(rb.getLinearVelocity(), scale_);
    spins_[i] = FromBt(rb.getAngularVelocity());
  }
}


Vector3d BulletScene::PointVelocity(int body, const Vector3d& p) const {
  if (body < 0) return Vector3d::Zero();
  const btRigidBody& rb = *bodies_[body].rigid;
  const Vector3d com = FromBt(rb.getCenterOfMassPosition(), scale_);
  return FromBt(rb.getLinearVelocity(), scale_) + FromBt(rb.getAngularVelocity()).cross(p - com);
}

void BulletScene::BuildConstraint(size_t index) {
  const sgal::Constraint& c = scene_.constraints[index];
  JointData& j = joints_[index];
  j.desc = &c;
  j.frame_a = c.frame_a.ToIsometry();
  j.frame_b = c.frame_b.ToIsometry();
  j.body_a = scene_.BodyIndex(c.body_a);
  j.body_b = c.body_b.empty() ? -1 : scene_.BodyIndex(c.body_b);
  btRigidBody& a = *bodies_[j.body_a].rigid;
  btRigidBody& b = j.body_b < 0 ? *fixed_body_ : *bodies_[j.body_b].rigid;
  // joint frames relative to each Bullet body (centre of mass, principal axes)
  const Isometry3d fa = bodies_[j.body_a].com_in_body.inverse() * c.frame_a.ToIsometry();
  const Isometry3d fb = j.body_b < 0 ? c.frame_b.ToIsometry()
                                     : bodies_[j.body_b].com_in_body.inverse() * c.frame_b.ToIsometry();
  const btTransform ta = ToBt(fa, scale_), tb = ToBt(fb, scale_);
  switch (c.kind) {
    case sgal::ConstraintKind::kHinge: {
      auto hinge = std::make_unique<btHingeConstraint>(a, b, ta, tb);
      if (c.limits[0].enabled())
        hinge->setLimit(static_cast<btScalar>(c.limits[0].lower),
                        static_cast<btScalar>(c.limits[0].upper));
      j.constraint = std::move(hinge);
      break;
    }
    case sgal::ConstraintKind::kSlider: {
      // Bullet slides along x: turn the frames so that our z becomes its x
      const btTransform z_to_x(btQuaternion(btVector3(0, 1, 0), -SIMD_HALF_PI));
      auto slider = std::make_unique<btSliderConstraint>(a, b, ta * z_to_x, tb * z_to_x, true);
      if (c.limits[0].enabled()) {
        slider->setLowerLinLimit(static_cast<btScalar>(c.limits[0].lower * scale_));
        slider->setUpperLinLimit(static_cast<btScalar>(c.limits[0].upper * scale_));
      } else {
        slider->setLowerLinLimit(1);
        slider->setUpperLinLimit(-1);
      }
      slider->setLowerAngLimit(0);
      slider->setUpperAngLimit(0);
      j.constraint = std::move(slider);
      break;
    }
    case sgal::ConstraintKind::kBall:
      j.constraint = std::make_unique<btPoint2PointConstraint>(a, b, ta.getOrigin(), tb.getOrigin());
      break;
    case sgal::ConstraintKind::kFixed:
      j.constraint = std::make_unique<btFixedConstraint>(a, b, ta, tb);
      break;
    case sgal::ConstraintKind::kGeneric6Dof: {
      auto g = std::make_unique<btGeneric6DofSpring2Constraint>(a, b, ta, tb);
      for (int i = 0; i < 6; ++i) {
        const auto& l = c.limits[i];
        const double unit = i < 3 ? scale_ : 1.0;
        // our free (lower > upper) is Bullet's free too
        g->setLimit(i, static_cast<btScalar>(l.lower * unit), static_cast<btScalar>(l.upper * unit));
        const auto& sp = c.springs[i];
        if (sp.stiffness > 0 || sp.damping > 0) {
          const double k_unit = i < 3 ? 1.0 : scale_ * scale_;
          g->enableSpring(i, true);
          g->setStiffness(i, static_cast<btScalar>(sp.stiffness * k_unit));
          g->setDamping(i, static_cast<btScalar>(sp.damping * k_unit));
          g->setEquilibriumPoint(i, static_cast<btScalar>(sp.rest * unit));
        }
      }
      j.constraint = std::move(g);
      break;
    }
  }
  world_->addConstraint(j.constraint.get(), !c.collide_connected);
}

void BulletScene::BuildTendons() {
  tendons_.resize(scene_.tendons.size());
  for (size_t i = 0; i < scene_.tendons.size(); ++i) {
    TendonData& t = tendons_[i];
    t.desc = &scene_.tendons[i];
    for (const auto& e : t.desc->path) {
      ElementRef ref;
      ref.desc = &e;
      if (e.kind == sgal::PathElement::Kind::kPoint) {
        ref.body = e.body.empty() ? -1 : scene_.BodyIndex(e.body);
      } else {
        ref.obstacle = scene_.FindObstacle(e.obstacle);
        ref.body = ref.obstacle->body.empty() ? -1 : scene_.BodyIndex(ref.obstacle->body);
      }
      t.elements.push_back(ref);
    }
  }
  actuators_.resize(scene_.actuators.size());
  for (size_t i = 0; i < scene_.actuators.size(); ++i) {
    ActuatorData& a = actuators_[i];
    a.desc = &scene_.actuators[i];
    a.model = actuators::Make(*a.desc);
    for (size_t t = 0; t < scene_.tendons.size(); ++t)
      if (scene_.tendons[t].name == a.desc->tendon) a.tendon = static_cast<int>(t);
    tendons_[a.tendon].actuators.push_back(static_cast<int>(i));
  }
  double largest = 0;
  for (const auto& b : scene_.bodies)
    for (const auto& shape : b.shapes) {
      const double r = std::visit(
          [](const auto& g) -> double {
            using T = std::decay_t<decltype(g)>;
            if constexpr (std::is_same_v<T, sgal::Box>) return g.size.norm() / 2;
            else if constexpr (std::is_same_v<T, sgal::Sphere>) return g.radius;
            else if constexpr (std::is_same_v<T, sgal::Capsule>) return g.radius + g.length / 2;
            else if constexpr (std::is_same_v<T, sgal::Cylinder> || std::is_same_v<T, sgal::Cone>)
              return std::hypot(g.radius, g.length / 2);
            else if constexpr (std::is_same_v<T, sgal::Plane>) return 0.0;
            else {
              double m = 0;
              if (g.mesh)
                for (const auto& v : g.mesh->vertices) m = std::max(m, static_cast<double>(v.norm()));
              return m;
            }
          },
          shape.geometry);
      largest = std::max(largest, r + shape.pose.position.norm());
    }
  detour_reach_ = 2 * largest;
  CacheBodyPoses();
  RefreshWorldShapes();
  EvaluateTendons();
  for (auto& a : actuators_) a.model->Reset(tendons_[a.tendon].geometry.length);
  UpdateJoints();
}

void BulletScene::RefreshWorldShapes() {
  if (!options_.tendon_body_contact) return;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    BodyData& b = bodies_[i];
    const Isometry3d& pose = poses_[i];
    if (b.shape_poses.size() != b.desc->shapes.size()) {
      b.shape_poses.clear();
      for (const auto& shape : b.desc->shapes) b.shape_poses.push_back(shape.pose.ToIsometry());
    }
    b.world_shapes.resize(b.desc->shapes.size());
    for (size_t s = 0; s < b.desc->shapes.size(); ++s) {
      b.world_shapes[s].geometry = &b.desc->shapes[s].geometry;
      b.world_shapes[s].pose = pose * b.shape_poses[s];
      b.world_shapes[s].body = static_cast<int>(i);
    }
  }
}

struct AabbCollector : public btBroadphaseAabbCallback {
  std::vector<int> bodies;
  bool process(const btBroadphaseProxy* proxy) override {
    const auto* object = static_cast<const btCollisionObject*>(proxy->m_clientObject);
    if (object != nullptr && object->getUserIndex() >= 0) bodies.push_back(object->getUserIndex());
    return true;
  }
};

void BulletScene::EvaluateTendons() {
  auto pose = [&](int body) { return body < 0 ? Isometry3d::Identity() : poses_[body]; };
  auto velocity = [&](int body, const Vector3d& p) -> Vector3d {
    if (body < 0) return Vector3d::Zero();
    return velocities_[body] + spins_[body].cross(p - coms_[body]);
  };
  for (auto& t : tendons_) {
    t.world.resize(t.elements.size());
    for (size_t k = 0; k < t.elements.size(); ++k) {
      const ElementRef& ref = t.elements[k];
      const sgal::PathElement& e = *ref.desc;
      actuators::WorldElement& w = t.world[k];
      w.kind = e.kind;
      w.body = ref.body;
      if (e.kind == sgal::PathElement::Kind::kPoint) {
        w.point = pose(ref.body) * e.position;
        w.velocity = velocity(ref.body, w.point);
        w.friction = e.friction;
      } else {
        const sgal::WrapObstacle* o = ref.obstacle;
        const Isometry3d body_pose = pose(ref.body);
        w.obstacle.kind = o->kind;
        w.obstacle.pose = body_pose * o->pose.ToIsometry();
        w.obstacle.radius = o->radius;
        w.obstacle.length = o->length;
        w.velocity = velocity(ref.body, w.obstacle.pose.translation());
        if (e.side) w.side = body_pose * (*e.side);
      }
    }
    t.geometry = t.path.Evaluate(t.world);
    t.contacts = 0;
    if (options_.tendon_body_contact && t.desc->collide_with_bodies) {
      AabbCollector collector;
      const actuators::ShapeQuery query = [&](const Vector3d& a, const Vector3d& b, double pad,
                                              std::vector<actuators::WorldShape>* out) {
        collector.bodies.clear();
        broadphase_->aabbTest(ToBt(a.cwiseMin(b) - Vector3d::Constant(pad), scale_),
                              ToBt(a.cwiseMax(b) + Vector3d::Constant(pad), scale_), collector);
        for (int body : collector.bodies)
          out->insert(out->end(), bodies_[body].world_shapes.begin(), bodies_[body].world_shapes.end());
      };
      actuators::ContactOptions contact;
      contact.margin = t.desc->radius;
      contact.detour_reach = detour_reach_;
      t.contacts = actuators::WrapAroundBodies(&t.geometry, query, contact);
      if (t.contacts > 0 && t.previous_length >= 0)
        t.geometry.speed = (t.geometry.length - t.previous_length) / dt_;
    }
  }
}

void BulletScene::ApplyTendonForces() {
  for (auto& t : tendons_) {
    if (t.tension <= 0) continue;
    for (const auto& f : actuators::PathForces(t.geometry, t.tension)) {
      if (f.body < 0 || scene_.bodies[f.body].type != sgal::BodyType::kDynamic) continue;
      bodies_[f.body].rigid->applyForce(ToBt(f.force, scale_), ToBt(f.position - coms_[f.body], scale_));
    }
  }
}

void BulletScene::UpdateJoints() {
  auto pose = [&](int body) { return body < 0 ? Isometry3d::Identity() : poses_[body]; };
  auto spin = [&](int body) { return body < 0 ? Vector3d::Zero() : spins_[body]; };
  auto velocity = [&](int body, const Vector3d& p) -> Vector3d {
    if (body < 0) return Vector3d::Zero();
    return velocities_[body] + spins_[body].cross(p - coms_[body]);
  };
  for (auto& j : joints_) {
    const sgal::Constraint& c = *j.desc;
    if (c.kind != sgal::ConstraintKind::kHinge && c.kind != sgal::ConstraintKind::kSlider) continue;
    const Isometry3d fa = pose(j.body_a) * j.frame_a;
    const Isometry3d fb = pose(j.body_b) * j.frame_b;
    const Vector3d axis = fb.linear().col(2);
    j.axis = axis;
    if (c.kind == sgal::ConstraintKind::kHinge) {
      // rotation of body_a's joint frame relative to body_b's (the parent's), about z
      const Eigen::Matrix3d rel = fb.linear().transpose() * fa.linear();
      j.position = std::atan2(rel(1, 0), rel(0, 0));
      j.velocity = axis.dot(spin(j.body_a) - spin(j.body_b));
    } else {
      j.position = axis.dot(fa.translation() - fb.translation());
      j.velocity = axis.dot(velocity(j.body_a, fa.translation()) -
                            velocity(j.body_b, fa.translation()));
    }
  }
}

void BulletScene::ApplyJointSprings() {
  for (auto& j : joints_) {
    const sgal::Constraint& c = *j.desc;
    if (c.kind != sgal::ConstraintKind::kHinge && c.kind != sgal::ConstraintKind::kSlider) continue;
    const sgal::JointSpring& sp = c.springs[0];
    if (sp.stiffness == 0 && sp.damping == 0) continue;
    const double load = -(sp.stiffness * (j.position - sp.rest) + sp.damping * j.velocity);
    const Vector3d axis = j.axis;
    auto push = [&](int body, double sign) {
      if (body < 0 || scene_.bodies[body].type != sgal::BodyType::kDynamic) return;
      btRigidBody& rb = *bodies_[body].rigid;
      if (c.kind == sgal::ConstraintKind::kHinge)
        rb.applyTorque(ToBt(axis * (sign * load), scale_ * scale_));
      else
        rb.applyCentralForce(ToBt(axis * (sign * load), scale_));
    };
    push(j.body_a, 1.0);
    push(j.body_b, -1.0);
  }
}

void BulletScene::CheckState() {
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const btRigidBody& rb = *bodies_[i].rigid;
    const Vector3d p = FromBt(rb.getCenterOfMassPosition(), scale_);
    const Vector3d v = FromBt(rb.getLinearVelocity(), scale_);
    const Vector3d w = FromBt(rb.getAngularVelocity());
    std::string problem;
    if (!p.allFinite() || !v.allFinite() || !w.allFinite()) {
      problem = "non-finite state";
    } else if (p.norm() > options_.max_distance) {
      problem = "flew off to " + std::to_string(p.norm()) + " m";
    } else if (v.norm() > options_.max_speed) {
      problem = "speed " + std::to_string(v.norm()) + " m/s";
    }
    if (!problem.empty()) {
      const std::string name = scene_.bodies[i].name;
      throw sgal::SimulationFault("body '" + name + "': " + problem + " at t = " +
                                      std::to_string(time_ + dt_) + " s; simulation stopped",
                                  name, time_ + dt_);
    }
  }
}

void BulletScene::Step() {
  // keep the last good state: a failing step leaves the scene as it was
  std::vector<Snapshot>& snapshot = snapshot_;
  snapshot.resize(bodies_.size());
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const btRigidBody& rb = *bodies_[i].rigid;
    snapshot[i] = {rb.getCenterOfMassTransform(), rb.getLinearVelocity(), rb.getAngularVelocity()};
  }
  auto restore = [&] {
    for (size_t i = 0; i < bodies_.size(); ++i) {
      btRigidBody& rb = *bodies_[i].rigid;
      rb.setCenterOfMassTransform(snapshot[i].transform);
      rb.setLinearVelocity(snapshot[i].linear);
      rb.setAngularVelocity(snapshot[i].angular);
      rb.clearForces();
    }
  };

  CacheBodyPoses();
  RefreshWorldShapes();
  EvaluateTendons();
  UpdateJoints();
  for (auto& t : tendons_) {
    t.tension = 0;
    for (int index : t.actuators) {
      ActuatorData& a = actuators_[index];
      const double f = a.model->Step(t.geometry.length, t.geometry.speed, dt_);
      if (!std::isfinite(f)) {
        restore();
        throw sgal::SimulationFault("actuator '" + a.desc->name + "': tension is not finite at t = " +
                                        std::to_string(time_ + dt_) + " s; simulation stopped",
                                    a.desc->name, time_ + dt_);
      }
      t.tension += f;
    }
    t.previous_length = t.geometry.length;
  }
  ApplyTendonForces();
  ApplyJointSprings();
  world_->stepSimulation(static_cast<btScalar>(dt_), 0, static_cast<btScalar>(dt_));
  try {
    CheckState();
  } catch (...) {
    restore();
    throw;
  }
  time_ += dt_;
  ++steps_;
}

std::vector<sgal::BodyState> BulletScene::BodyStates() const {
  std::vector<sgal::BodyState> states(bodies_.size());
  for (size_t i = 0; i < bodies_.size(); ++i) {
    states[i].pose = sgal::Pose::FromIsometry(BodyPose(static_cast<int>(i)));
    const btRigidBody& rb = *bodies_[i].rigid;
    states[i].angular_velocity = FromBt(rb.getAngularVelocity());
    states[i].linear_velocity = PointVelocity(static_cast<int>(i), states[i].pose.position);
  }
  return states;
}

std::vector<sgal::TendonState> BulletScene::TendonStates() const {
  std::vector<sgal::TendonState> states(tendons_.size());
  for (size_t i = 0; i < tendons_.size(); ++i) {
    const TendonData& t = tendons_[i];
    for (const auto& p : t.geometry.points) states[i].points.push_back(p.position);
    states[i].length = t.geometry.length;
    states[i].speed = t.geometry.speed;
    states[i].tension = t.tension;
    states[i].contacts = t.contacts;
  }
  return states;
}

void BulletScene::SetCommand(const std::string& actuator, double value) {
  if (!std::isfinite(value))
    throw std::invalid_argument("command for '" + actuator + "' is not finite");
  for (auto& a : actuators_) {
    if (a.desc->name == actuator) {
      a.model->SetCommand(value);
      return;
    }
  }
  throw std::out_of_range("no actuator '" + actuator + "'");
}

std::vector<sgal::ParameterInfo> BulletScene::Parameters() const {
  std::vector<sgal::ParameterInfo> out;
  out.push_back({"simulation.time_step", "s", true, true});
  out.push_back({"simulation.time", "s", false, false});
  for (const auto& b : scene_.bodies)
    if (b.type == sgal::BodyType::kDynamic) out.push_back({b.name + ".mass", "kg", true, true});
  for (const auto& j : joints_) {
    const bool hinge = j.desc->kind == sgal::ConstraintKind::kHinge;
    if (!hinge && j.desc->kind != sgal::ConstraintKind::kSlider) continue;
    out.push_back({j.desc->name + ".position", hinge ? "rad" : "m", false, false});
    out.push_back({j.desc->name + ".velocity", hinge ? "rad/s" : "m/s", false, false});
    out.push_back({j.desc->name + ".spring_stiffness", hinge ? "N m/rad" : "N/m", true, true});
    out.push_back({j.desc->name + ".spring_damping", hinge ? "N m s/rad" : "N s/m", true, true});
  }
  for (const auto& t : tendons_) {
    // tendons often share their actuator's name: their states live under `.tendon.`
    out.push_back({t.desc->name + ".tendon.length", "m", false, false});
    out.push_back({t.desc->name + ".tendon.speed", "m/s", false, false});
    out.push_back({t.desc->name + ".tendon.tension", "N", false, false});
    out.push_back({t.desc->name + ".tendon.contacts", "", false, false});
  }
  for (const auto& a : actuators_) {
    out.push_back({a.desc->name + ".command", a.model->command_unit(), true, false});
    for (const auto& q : a.model->Quantities())
      out.push_back({a.desc->name + "." + q.name, q.unit, q.writable, q.is_static});
  }
  return out;
}

namespace {
/// Splits `name.field` at the last dot.
std::pair<std::string, std::string> SplitId(const std::string& id) {
  const auto dot = id.rfind('.');
  if (dot == std::string::npos) return {id, ""};
  return {id.substr(0, dot), id.substr(dot + 1)};
}
}  // namespace

double BulletScene::GetParameter(const std::string& id) const {
  const auto [name, field] = SplitId(id);
  if (id == "simulation.time_step") return dt_;
  if (id == "simulation.time") return time_;
  for (size_t i = 0; i < bodies_.size(); ++i)
    if (scene_.bodies[i].name == name && field == "mass" &&
        scene_.bodies[i].type == sgal::BodyType::kDynamic)
      return 1.0 / bodies_[i].rigid->getInvMass();
  for (const auto& j : joints_) {
    if (j.desc->name != name) continue;
    if (field == "position") return j.position;
    if (field == "velocity") return j.velocity;
    if (field == "spring_stiffness") return j.desc->springs[0].stiffness;
    if (field == "spring_damping") return j.desc->springs[0].damping;
  }
  for (const auto& t : tendons_) {
    if (t.desc->name + ".tendon" != name) continue;
    if (field == "length") return t.geometry.length;
    if (field == "speed") return t.geometry.speed;
    if (field == "tension") return t.tension;
    if (field == "contacts") return t.contacts;
  }
  for (const auto& a : actuators_) {
    if (a.desc->name != name) continue;
    if (field == "command") return a.model->command();
    return a.model->Get(field);
  }
  throw std::out_of_range("no parameter '" + id + "'");
}

void BulletScene::SetParameter(const std::string& id, double value) {
  if (!std::isfinite(value)) throw std::invalid_argument(id + ": value is not finite");
  const auto [name, field] = SplitId(id);
  if (id == "simulation.time_step") {
    if (!(value > 0 && value <= 0.1)) throw std::invalid_argument(id + ": must be in (0, 0.1] s");
    dt_ = value;
    scene_.settings.time_step = value;
    return;
  }
  for (size_t i = 0; i < bodies_.size(); ++i) {
    if (scene_.bodies[i].name != name || field != "mass") continue;
    if (scene_.bodies[i].type != sgal::BodyType::kDynamic)
      throw std::invalid_argument(id + ": the body is not dynamic");
    if (!(value > 0)) throw std::invalid_argument(id + ": mass must be positive");
    btRigidBody& rb = *bodies_[i].rigid;
    const double ratio = value / (1.0 / rb.getInvMass());
    const btVector3 inv = rb.getInvInertiaDiagLocal();
    const btVector3 inertia(inv.x() > 0 ? 1 / inv.x() : 0, inv.y() > 0 ? 1 / inv.y() : 0,
                            inv.z() > 0 ? 1 / inv.z() : 0);
    rb.setMassProps(static_cast<btScalar>(value), inertia * static_cast<btScalar>(ratio));
    rb.updateInertiaTensor();
    scene_.bodies[i].inertia.mass = value;
    scene_.bodies[i].inertia.tensor *= ratio;
    return;
  }
  for (auto& j : joints_) {
    if (j.desc->name != name) continue;
    auto& spring = scene_.constraints[&j - &joints_[0]].springs[0];
    if (field == "spring_stiffness" || field == "spring_damping") {
      if (value < 0) throw std::invalid_argument(id + ": must not be negative");
      (field == "spring_stiffness" ? spring.stiffness : spring.damping) = value;
      return;
    }
    if (field == "position" || field == "velocity")
      throw std::invalid_argument(id + " is read-only (a state of the simulation)");
  }
  for (auto& t : tendons_)
    if (t.desc->name + ".tendon" == name && (field == "length" || field == "speed" || field == "tension" ||
                                 field == "contacts"))
      throw std::invalid_argument(id + " is read-only (a state of the simulation)");
  for (auto& a : actuators_) {
    if (a.desc->name != name) continue;
    if (field == "command") {
      a.model->SetCommand(value);
      return;
    }
    a.model->Set(field, value);
    // a tuned model parameter goes into the description, so that a saved scene keeps it
    for (const auto& q : a.model->Quantities())
      if (q.name == field && q.is_static)
        scene_.actuators[&a - &actuators_[0]].parameters[field] = value;
    return;
  }
  throw std::out_of_range("no parameter '" + id + "'");
}

}  // namespace

std::unique_ptr<sgal::PhysicsScene> MakeScene(const sgal::Scene& scene, Options options) {
  return std::make_unique<BulletScene>(scene, options);
}

}  // namespace caliper::physics_bullet
