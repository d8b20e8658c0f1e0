#include "observer_servant.h"

#include <cmath>
#include <exception>

#include "caliper/logging/log.h"
#include "caliper/rtc/reason.h"

namespace caliper::renderer {

namespace S = ::Caliper::Scene;
namespace R = render_coin;

R::Pose FromIdl(const S::Frame& f) {
  R::Pose p;
  p.p[0] = f.px;
  p.p[1] = f.py;
  p.p[2] = f.pz;
  p.q[0] = f.qw;
  p.q[1] = f.qx;
  p.q[2] = f.qy;
  p.q[3] = f.qz;
  return p;
}

namespace {

R::ShapeKind FromIdl(S::ShapeKind kind) {
  switch (kind) {
    case S::BOX: return R::ShapeKind::kBox;
    case S::SPHERE: return R::ShapeKind::kSphere;
    case S::CAPSULE: return R::ShapeKind::kCapsule;
    case S::CYLINDER: return R::ShapeKind::kCylinder;
    case S::CONE: return R::ShapeKind::kCone;
    case S::PLANE: return R::ShapeKind::kPlane;
    case S::CONVEX_HULL: return R::ShapeKind::kConvexHull;
    case S::TRIANGLE_MESH: return R::ShapeKind::kTriangleMesh;
    default: return R::ShapeKind::kBox;
  }
}

template <typename Seq, typename T>
std::vector<T> ToVector(const Seq& seq) {
  std::vector<T> out(seq.length());
  for (CORBA::ULong i = 0; i < seq.length(); ++i) out[i] = static_cast<T>(seq[i]);
  return out;
}

}  // namespace

R::SceneDescription FromIdl(const S::Description& scene) {
  R::SceneDescription out;
  out.name = scene.name.in();
  for (CORBA::ULong b = 0; b < scene.bodies.length(); ++b) {
    const S::Body& in = scene.bodies[b];
    R::Body body;
    body.name = in.name.in();
    body.pose = FromIdl(in.pose);
    body.moving = in.moving;
    body.mass = std::isfinite(in.mass) ? in.mass : 0.0;
    for (CORBA::ULong v = 0; v < in.visuals.length(); ++v) {
      const S::Visual& iv = in.visuals[v];
      R::Visual visual;
      visual.name = iv.name.in();
      visual.geometry.kind = FromIdl(iv.geometry.kind);
      visual.geometry.dims = ToVector<S::DoubleSeq, double>(iv.geometry.dims);
      visual.geometry.mesh = iv.geometry.mesh;
      visual.pose = FromIdl(iv.pose);
      visual.rgba[0] = iv.r;
      visual.rgba[1] = iv.g;
      visual.rgba[2] = iv.b;
      visual.rgba[3] = iv.a;
      body.visuals.push_back(std::move(visual));
    }
    out.bodies.push_back(std::move(body));
  }
  for (CORBA::ULong m = 0; m < scene.meshes.length(); ++m) {
    R::Mesh mesh;
    mesh.vertices = ToVector<S::FloatSeq, float>(scene.meshes[m].vertices);
    mesh.triangles = ToVector<S::IndexSeq, uint32_t>(scene.meshes[m].triangles);
    mesh.normals = ToVector<S::FloatSeq, float>(scene.meshes[m].normals);
    out.meshes.push_back(std::move(mesh));
  }
  for (CORBA::ULong c = 0; c < scene.constraints.length(); ++c) {
    const S::Constraint& in = scene.constraints[c];
    R::Constraint constraint;
    constraint.name = in.name.in();
    constraint.kind = in.kind.in();
    constraint.body_a = in.body_a.in();
    constraint.body_b = in.body_b.in();
    constraint.frame_a = FromIdl(in.frame_a);
    constraint.frame_b = FromIdl(in.frame_b);
    out.constraints.push_back(std::move(constraint));
  }
  for (CORBA::ULong o = 0; o < scene.obstacles.length(); ++o) {
    const S::Obstacle& in = scene.obstacles[o];
    R::Obstacle obstacle;
    obstacle.name = in.name.in();
    obstacle.body = in.body.in();
    obstacle.kind = in.kind.in();
    obstacle.pose = FromIdl(in.pose);
    obstacle.radius = in.radius;
    obstacle.length = in.length;
    out.obstacles.push_back(std::move(obstacle));
  }
  for (CORBA::ULong t = 0; t < scene.tendons.length(); ++t) {
    const S::Tendon& in = scene.tendons[t];
    R::Tendon tendon;
    tendon.name = in.name.in();
    tendon.radius = in.radius;
    for (CORBA::ULong e = 0; e < in.path.length(); ++e) {
      R::PathPoint point;
      point.body = in.path[e].body.in();
      point.p[0] = in.path[e].x;
      point.p[1] = in.path[e].y;
      point.p[2] = in.path[e].z;
      point.obstacle = in.path[e].obstacle.in();
      tendon.path.push_back(std::move(point));
    }
    out.tendons.push_back(std::move(tendon));
  }
  return out;
}

void ObserverServant::on_scene(const S::Description& scene) {
  try {
    size_t visuals = 0;
    for (CORBA::ULong b = 0; b < scene.bodies.length(); ++b)
      visuals += scene.bodies[b].visuals.length();
    if (visuals > kMaxVisuals) {
      logging::Get("renderer").error(
          "scene with %zu visuals not shown: the renderer draws at most %zu", visuals,
          kMaxVisuals);
      mailbox_.PutCleared();
      return;
    }
    R::SceneDescription plain = FromIdl(scene);
    logging::Get("renderer").info("scene '%s': %zu bodies, %zu tendons",
                                  rtc::BoundedReason(plain.name).c_str(), plain.bodies.size(),
                                  plain.tendons.size());
    std::lock_guard<std::mutex> lock(mutex_);
    last_update_ = 0;  // a new registration (or a new Model) counts from 1 again
    mailbox_.PutScene(std::move(plain));
  } catch (const std::exception& e) {
    logging::Get("renderer").error("cannot take the scene: %s", e.what());
  }
}

void ObserverServant::on_transforms(CORBA::ULongLong update, CORBA::Double sim_time,
                                    const S::BodyTransformSeq& changed,
                                    const S::TendonStateSeq& tendons) {
  try {
    std::vector<uint32_t> indices(changed.length());
    std::vector<R::Pose> poses(changed.length());
    for (CORBA::ULong i = 0; i < changed.length(); ++i) {
      indices[i] = changed[i].body_index;
      poses[i] = FromIdl(changed[i].pose);
    }
    std::vector<R::TendonState> states(tendons.length());
    for (CORBA::ULong i = 0; i < tendons.length(); ++i) {
      states[i].tendon_index = tendons[i].tendon_index;
      states[i].points = ToVector<S::DoubleSeq, double>(tendons[i].points);
      states[i].length = tendons[i].length;
      states[i].tension = tendons[i].tension;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (update <= last_update_) {
      logging::Get("renderer").debug("ignored transforms %llu (applied %llu already)",
                                     static_cast<unsigned long long>(update),
                                     static_cast<unsigned long long>(last_update_));
      return;
    }
    last_update_ = update;
    mailbox_.PutTransforms(update, sim_time, indices, poses, std::move(states));
  } catch (const std::exception& e) {
    logging::Get("renderer").error("cannot take transforms: %s", e.what());
  }
}

void ObserverServant::on_scene_cleared() { mailbox_.PutCleared(); }

}  // namespace caliper::renderer
