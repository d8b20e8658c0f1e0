#include "raw_bullet.h"

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <vector>

namespace caliper::bench {

namespace {
btVector3 Bt(const Eigen::Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }
btQuaternion Bt(const Eigen::Quaterniond& q) { return btQuaternion(q.x(), q.y(), q.z(), q.w()); }
}  // namespace

struct RawBulletWorld::Impl {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<Eigen::Matrix3d> axes;  // each body's Bullet frame in its own frame
  std::vector<std::unique_ptr<btTypedConstraint>> constraints;
  struct Spring {
    btRigidBody* a;
    btRigidBody* b;
    btVector3 pa, pb;  // in the bodies' frames
    double rest;
  };
  std::vector<Spring> springs;
};

RawBulletWorld::RawBulletWorld(const sgal::Scene& s) : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.world.setGravity(Bt(s.gravity));
  for (const auto& b : s.bodies) {
    // like Caliper's scene (like for like): a moving body with one shape at its centre of mass,
    // whose tensor is diagonal in the shape's axes (to 1e-12 of its trace), has Bullet's frame in
    // those axes and goes to Bullet as that shape alone; a fixed body only when its one shape
    // sits at its origin in its axes; any other body gets a compound. The bench trees have the
    // centre of mass at the body's origin, so the arm capsules (turned to x) qualify as well as
    // the spine's
    const bool dynamic = b.type == sgal::BodyType::kDynamic;
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // Bullet's frame in the body's
    bool alone = false;
    if (b.shapes.size() == 1 && b.shapes[0].pose.position.isZero()) {
      const Eigen::Matrix3d turn = b.shapes[0].pose.ToIsometry().linear();
      const Eigen::Matrix3d in_shape = turn.transpose() * b.inertia.tensor * turn;
      const double off =
          std::abs(in_shape(0, 1)) + std::abs(in_shape(0, 2)) + std::abs(in_shape(1, 2));
      if (dynamic ? off <= 1e-12 * in_shape.trace() : turn == Eigen::Matrix3d::Identity()) {
        axes = turn;
        alone = true;
      }
    }
    std::unique_ptr<btCompoundShape> compound;
    btCollisionShape* collision_shape = nullptr;
    for (const auto& shape : b.shapes) {
      std::unique_ptr<btCollisionShape> child;
      if (const auto* c = std::get_if<sgal::Capsule>(&shape.geometry))
        child = std::make_unique<btCapsuleShapeZ>(c->radius, c->length);
      else
        child = std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0);
      if (alone) {
        collision_shape = child.get();
      } else {
        if (!compound) compound = std::make_unique<btCompoundShape>();
        const btTransform pose(Bt(shape.pose.orientation), Bt(shape.pose.position));
        compound->addChildShape(pose, child.get());
        collision_shape = compound.get();
      }
      w.shapes.push_back(std::move(child));
    }
    if (!collision_shape) {  // a body without shapes: an empty compound, as in Caliper
      compound = std::make_unique<btCompoundShape>();
      collision_shape = compound.get();
    }
    const double mass = dynamic ? b.inertia.mass : 0;
    const btVector3 inertia =
        dynamic ? Bt(Eigen::Vector3d((axes.transpose() * b.inertia.tensor * axes).diagonal()))
                : btVector3(0, 0, 0);
    btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, collision_shape, inertia);
    const Eigen::Quaterniond frame = b.pose.orientation * Eigen::Quaterniond(axes);
    info.m_startWorldTransform = btTransform(Bt(frame), Bt(b.pose.position));
    auto rb = std::make_unique<btRigidBody>(info);
    rb->setActivationState(DISABLE_DEACTIVATION);
    uint32_t group = 0, mask = 0;
    for (const auto& shape : b.shapes) {
      group |= shape.group;
      mask |= shape.mask;
    }
    w.world.addRigidBody(rb.get(), static_cast<int>(group & 0x7fff),
                         static_cast<int>(mask & 0x7fff));
    if (compound) w.shapes.push_back(std::move(compound));
    w.bodies.push_back(std::move(rb));
    w.axes.push_back(axes);
  }
  auto body = [&](const std::string& name) { return w.bodies[s.BodyIndex(name)].get(); };
  // a frame or point given in a body's frame, in Bullet's frame of that body
  auto in_bullet = [&](const std::string& name, const sgal::Pose& p) {
    const Eigen::Matrix3d axes = w.axes[s.BodyIndex(name)];
    return btTransform(Bt(Eigen::Quaterniond(axes.transpose()) * p.orientation),
                       Bt(Eigen::Vector3d(axes.transpose() * p.position)));
  };
  auto point_in_bullet = [&](const std::string& name, const Eigen::Vector3d& p) {
    return Bt(Eigen::Vector3d(w.axes[s.BodyIndex(name)].transpose() * p));
  };
  for (const auto& c : s.constraints) {
    auto hinge = std::make_unique<btHingeConstraint>(*body(c.body_a), *body(c.body_b),
                                                     in_bullet(c.body_a, c.frame_a),
                                                     in_bullet(c.body_b, c.frame_b));
    w.world.addConstraint(hinge.get(), true);
    w.constraints.push_back(std::move(hinge));
  }
  for (const auto& t : s.tendons) {
    Impl::Spring spring{body(t.path.front().body), body(t.path.back().body),
                        point_in_bullet(t.path.front().body, t.path.front().position),
                        point_in_bullet(t.path.back().body, t.path.back().position), 0};
    const btVector3 a = spring.a->getWorldTransform() * spring.pa;
    const btVector3 b = spring.b->getWorldTransform() * spring.pb;
    spring.rest = (b - a).length() * 0.98;  // slightly stretched: every spring pulls
    w.springs.push_back(spring);
  }
}

RawBulletWorld::~RawBulletWorld() {
  for (auto& c : impl_->constraints) impl_->world.removeConstraint(c.get());
  for (auto& b : impl_->bodies) impl_->world.removeRigidBody(b.get());
}

void RawBulletWorld::Step(double dt) {
  constexpr double kStiffness = 2000, kDamping = 5;
  for (auto& s : impl_->springs) {
    const btVector3 a = s.a->getWorldTransform() * s.pa;
    const btVector3 b = s.b->getWorldTransform() * s.pb;
    btVector3 d = b - a;
    const double length = d.length();
    if (length <= s.rest || length < 1e-9) continue;
    d /= length;
    const btVector3 va = s.a->getVelocityInLocalPoint(a - s.a->getCenterOfMassPosition());
    const btVector3 vb = s.b->getVelocityInLocalPoint(b - s.b->getCenterOfMassPosition());
    double f = kStiffness * (length - s.rest) + kDamping * d.dot(vb - va);
    if (f < 0) f = 0;
    s.a->applyForce(d * f, a - s.a->getCenterOfMassPosition());
    s.b->applyForce(-d * f, b - s.b->getCenterOfMassPosition());
  }
  impl_->world.stepSimulation(dt, 0, dt);
}

}  // namespace caliper::bench
