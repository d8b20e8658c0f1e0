#include "model_convert.h"

#include <algorithm>
#include <cstring>
#include <variant>

namespace caliper::model {

namespace S = ::Caliper::Scene;
namespace D = ::Caliper::Daq;
namespace M = ::Caliper::Simulation;
using simulation::ModelCore;

S::Frame ToFrame(const sgal::Pose& p) {
  S::Frame f;
  f.px = p.position.x();
  f.py = p.position.y();
  f.pz = p.position.z();
  f.qw = p.orientation.w();
  f.qx = p.orientation.x();
  f.qy = p.orientation.y();
  f.qz = p.orientation.z();
  return f;
}

S::ShapeGeometry ToGeometry(const sgal::Geometry& g,
                            std::map<const sgal::Mesh*, CORBA::Long>* meshes) {
  S::ShapeGeometry out;
  out.mesh = -1;
  auto dims = [&](std::initializer_list<double> values) {
    out.dims.length(static_cast<CORBA::ULong>(values.size()));
    CORBA::ULong i = 0;
    for (double v : values) out.dims[i++] = v;
  };
  std::visit(
      [&](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, sgal::Box>) {
          out.kind = S::BOX;
          dims({s.size.x(), s.size.y(), s.size.z()});
        } else if constexpr (std::is_same_v<T, sgal::Sphere>) {
          out.kind = S::SPHERE;
          dims({s.radius});
        } else if constexpr (std::is_same_v<T, sgal::Capsule>) {
          out.kind = S::CAPSULE;
          dims({s.radius, s.length});
        } else if constexpr (std::is_same_v<T, sgal::Cylinder>) {
          out.kind = S::CYLINDER;
          dims({s.radius, s.length});
        } else if constexpr (std::is_same_v<T, sgal::Cone>) {
          out.kind = S::CONE;
          dims({s.radius, s.length});
        } else if constexpr (std::is_same_v<T, sgal::Plane>) {
          out.kind = S::PLANE;
          dims({s.normal.x(), s.normal.y(), s.normal.z(), s.offset});
        } else {
          out.kind = std::is_same_v<T, sgal::ConvexHull> ? S::CONVEX_HULL : S::TRIANGLE_MESH;
          if (s.mesh) {
            const auto it = meshes->find(s.mesh.get());
            if (it != meshes->end()) {
              out.mesh = it->second;
            } else {
              const CORBA::Long index = static_cast<CORBA::Long>(meshes->size());
              (*meshes)[s.mesh.get()] = index;
              out.mesh = index;
            }
          }
        }
      },
      g);
  return out;
}

S::TendonStateSeq ToIdl(const std::vector<sgal::TendonState>& tendons) {
  S::TendonStateSeq out;
  out.length(static_cast<CORBA::ULong>(tendons.size()));
  for (CORBA::ULong i = 0; i < tendons.size(); ++i) {
    const auto& t = tendons[i];
    out[i].tendon_index = i;
    out[i].length = t.length;
    out[i].tension = t.tension;
    out[i].points.length(static_cast<CORBA::ULong>(3 * t.points.size()));
    for (CORBA::ULong k = 0; k < t.points.size(); ++k)
      for (int c = 0; c < 3; ++c) out[i].points[3 * k + c] = t.points[k][c];
  }
  return out;
}

D::Value ToIdl(const daq::Reading& v) {
  D::Value out;
  out.rows = v.shape.rows;
  out.cols = v.shape.cols;
  out.data.length(static_cast<CORBA::ULong>(v.values.size()));
  for (CORBA::ULong i = 0; i < v.values.size(); ++i) out.data[i] = v.values[i];
  return out;
}

D::ChannelInfoSeq* ToIdl(const std::vector<daq::ChannelInfo>& channels) {
  auto* out = new D::ChannelInfoSeq;
  out->length(static_cast<CORBA::ULong>(channels.size()));
  for (CORBA::ULong i = 0; i < channels.size(); ++i) {
    const auto& c = channels[i];
    (*out)[i].id = c.id.c_str();
    (*out)[i].unit = c.unit.c_str();
    (*out)[i].rows = c.shape.rows;
    (*out)[i].cols = c.shape.cols;
    (*out)[i].writable = c.writable;
    (*out)[i].is_static = c.is_static;
    (*out)[i].description = c.description.c_str();
  }
  return out;
}

std::vector<std::string> FromIdl(const S::StringSeq& ids) {
  std::vector<std::string> out;
  for (CORBA::ULong i = 0; i < ids.length(); ++i) out.emplace_back(ids[i].in());
  return out;
}

S::Description* ToIdl(const sgal::Scene& scene) {
  auto* d = new S::Description;
  d->name = scene.name.c_str();
  d->source = scene.source.c_str();
  d->time_step = scene.settings.time_step;
  std::map<const sgal::Mesh*, CORBA::Long> meshes;
  d->bodies.length(static_cast<CORBA::ULong>(scene.bodies.size()));
  for (CORBA::ULong i = 0; i < scene.bodies.size(); ++i) {
    const auto& b = scene.bodies[i];
    S::Body& out = d->bodies[i];
    out.name = b.name.c_str();
    out.pose = ToFrame(b.pose);
    out.moving = b.type != sgal::BodyType::kStatic;
    out.mass = b.type == sgal::BodyType::kDynamic ? b.inertia.mass : 0.0;
    // what to draw: the visuals, or the collision shapes of a body that has none
    std::vector<sgal::Visual> visuals = b.visuals;
    if (visuals.empty())
      for (const auto& s : b.shapes) visuals.push_back({s.name, s.geometry, s.pose, {0.7f, 0.7f, 0.7f, 1}});
    out.visuals.length(static_cast<CORBA::ULong>(visuals.size()));
    for (CORBA::ULong k = 0; k < visuals.size(); ++k) {
      out.visuals[k].name = visuals[k].name.c_str();
      out.visuals[k].geometry = ToGeometry(visuals[k].geometry, &meshes);
      out.visuals[k].pose = ToFrame(visuals[k].pose);
      out.visuals[k].r = visuals[k].color[0];
      out.visuals[k].g = visuals[k].color[1];
      out.visuals[k].b = visuals[k].color[2];
      out.visuals[k].a = visuals[k].color[3];
    }
  }
  d->meshes.length(static_cast<CORBA::ULong>(meshes.size()));
  for (const auto& [mesh, index] : meshes) {
    S::MeshData& m = d->meshes[index];
    m.vertices.length(static_cast<CORBA::ULong>(3 * mesh->vertices.size()));
    for (CORBA::ULong k = 0; k < mesh->vertices.size(); ++k)
      for (int c = 0; c < 3; ++c) m.vertices[3 * k + c] = mesh->vertices[k][c];
    m.triangles.length(static_cast<CORBA::ULong>(3 * mesh->triangles.size()));
    for (CORBA::ULong k = 0; k < mesh->triangles.size(); ++k)
      for (int c = 0; c < 3; ++c) m.triangles[3 * k + c] = mesh->triangles[k][c];
    m.normals.length(static_cast<CORBA::ULong>(3 * mesh->normals.size()));
    for (CORBA::ULong k = 0; k < mesh->normals.size(); ++k)
      for (int c = 0; c < 3; ++c) m.normals[3 * k + c] = mesh->normals[k][c];
  }
  static const char* const kKinds[] = {"hinge", "slider", "ball", "fixed", "generic_6dof"};
  d->constraints.length(static_cast<CORBA::ULong>(scene.constraints.size()));
  for (CORBA::ULong i = 0; i < scene.constraints.size(); ++i) {
    const auto& c = scene.constraints[i];
    d->constraints[i].name = c.name.c_str();
    d->constraints[i].kind = kKinds[static_cast<int>(c.kind)];
    d->constraints[i].body_a = c.body_a.c_str();
    d->constraints[i].body_b = c.body_b.c_str();
    d->constraints[i].frame_a = ToFrame(c.frame_a);
    d->constraints[i].frame_b = ToFrame(c.frame_b);
  }
  d->obstacles.length(static_cast<CORBA::ULong>(scene.obstacles.size()));
  for (CORBA::ULong i = 0; i < scene.obstacles.size(); ++i) {
    const auto& o = scene.obstacles[i];
    d->obstacles[i].name = o.name.c_str();
    d->obstacles[i].body = o.body.c_str();
    d->obstacles[i].kind = o.kind == sgal::ObstacleKind::kSphere ? "sphere" : "cylinder";
    d->obstacles[i].pose = ToFrame(o.pose);
    d->obstacles[i].radius = o.radius;
    d->obstacles[i].length = o.length;
  }
  d->tendons.length(static_cast<CORBA::ULong>(scene.tendons.size()));
  for (CORBA::ULong i = 0; i < scene.tendons.size(); ++i) {
    const auto& t = scene.tendons[i];
    d->tendons[i].name = t.name.c_str();
    d->tendons[i].radius = t.radius;
    CORBA::ULong n = 0;
    d->tendons[i].path.length(static_cast<CORBA::ULong>(t.path.size()));
    for (CORBA::ULong k = 0; k < t.path.size(); ++k) {
      const auto& e = t.path[k];
      S::PathPoint& p = d->tendons[i].path[k];
      p.body = e.body.c_str();
      p.x = e.position.x();
      p.y = e.position.y();
      p.z = e.position.z();
      p.obstacle = e.kind == sgal::PathElement::Kind::kWrap ? e.obstacle.c_str() : "";
      if (e.kind == sgal::PathElement::Kind::kWrap) {
        d->tendons[i].obstacles.length(n + 1);
        d->tendons[i].obstacles[n++] = e.obstacle.c_str();
      }
    }
  }
  SensorDelaysToIdl(scene, &d->sensor_delays);
  return d;
}

void SensorDelaysToIdl(const sgal::Scene& scene, S::SensorDelaySeq* out) {
  // the ids as the DAQ lists them: after the Model's name for the scene (id-safe)
  const std::string prefix = simulation::IdSafe(scene.name) + ".";
  out->length(static_cast<CORBA::ULong>(scene.measurement_delays.size()));
  for (CORBA::ULong i = 0; i < scene.measurement_delays.size(); ++i) {
    (*out)[i].id = (prefix + scene.measurement_delays[i].id).c_str();
    (*out)[i].delay = scene.measurement_delays[i].delay;
  }
}

sgal::PathElement FromIdl(const S::PathPoint& p) {
  sgal::PathElement e;
  if (std::strlen(p.obstacle.in()) > 0) {
    e.kind = sgal::PathElement::Kind::kWrap;
    e.obstacle = p.obstacle.in();
  } else {
    e.body = p.body.in();
    e.position = {p.x, p.y, p.z};
  }
  return e;
}

sgal::Pose FromFrame(const S::Frame& f) {
  sgal::Pose p;
  p.position = {f.px, f.py, f.pz};
  p.orientation = Eigen::Quaterniond(f.qw, f.qx, f.qy, f.qz);
  return p;
}

M::EditStatus* ToIdl(const ModelCore::EditStatus& s) {
  auto* out = new M::EditStatus;
  out->revision = s.revision;
  out->last = s.last.c_str();
  out->undo = s.undo.c_str();
  out->redo = s.redo.c_str();
  return out;
}

M::RecordStatus* ToIdl(const ModelCore::RecordStatus& s) {
  auto* out = new M::RecordStatus;
  out->recording = s.recording;
  out->path = s.path.c_str();
  out->first_step = s.first_step;
  out->steps = s.steps;
  out->bytes = s.bytes;
  out->error = s.error.c_str();
  return out;
}

M::ReplayStatus* ToIdl(const ModelCore::ReplayStatus& s) {
  auto* out = new M::ReplayStatus;
  out->replaying = s.replaying;
  out->path = s.path.c_str();
  out->first_step = s.first_step;
  out->last_step = s.last_step;
  out->step = s.step;
  out->start_time = s.start_time;
  out->end_time = s.end_time;
  out->time = s.time;
  return out;
}

experiment::Experiment FromIdl(const M::Experiment& in) {
  experiment::Experiment e;
  e.name = in.name.in();
  e.scene = in.scene_file_name.in();
  for (CORBA::ULong i = 0; i < in.overrides.length(); ++i) {
    const D::Value& v = in.overrides[i].value;
    e.overrides.push_back({in.overrides[i].id.in(),
                           std::vector<double>(v.data.get_buffer(),
                                               v.data.get_buffer() + v.data.length())});
  }
  for (CORBA::ULong i = 0; i < in.schedule.length(); ++i)
    e.schedule.push_back(
        {in.schedule[i].time, in.schedule[i].actuator.in(), in.schedule[i].value});
  e.record = FromIdl(in.record);
  e.every_n_steps = in.every_n_steps;
  e.duration_s = in.duration;
  return e;
}

M::Recording* ToIdl(const simulation::RunResult& result) {
  const experiment::Recording& rec = result.recording;
  M::Recording_var out = new M::Recording;
  out->channels.length(static_cast<CORBA::ULong>(rec.channels.size()));
  for (CORBA::ULong i = 0; i < rec.channels.size(); ++i) {
    D::ChannelInfo& c = out->channels[i];
    c.id = rec.channels[i].id.c_str();
    c.unit = rec.channels[i].unit.c_str();
    c.rows = rec.channels[i].rows;
    c.cols = rec.channels[i].cols;
    c.writable = false;
    c.is_static = false;
  }
  out->times.length(static_cast<CORBA::ULong>(rec.times.size()));
  std::copy(rec.times.begin(), rec.times.end(), out->times.get_buffer());
  out->data.length(static_cast<CORBA::ULong>(rec.data.size()));
  std::copy(rec.data.begin(), rec.data.end(), out->data.get_buffer());
  out->values_per_sample = static_cast<CORBA::ULong>(rec.values_per_sample);
  out->steps = result.steps;
  out->load_wall_time = result.load_wall_s;
  out->step_wall_time = result.step_wall_s;
  return out._retn();
}

}  // namespace caliper::model
