#include "caliper/daq/daq_scene.h"

#include <stdexcept>

namespace caliper::daq {

void SceneSampler::Fetch() {
  states_ = scene_.BodyStates();
  rotations_.resize(states_.size());
  for (size_t i = 0; i < states_.size(); ++i)
    rotations_[i] = states_[i].pose.orientation.toRotationMatrix();
  fresh_ = true;
  ++fetches_;
}

namespace {

void Write3(const Eigen::Vector3d& v, double* out) {
  out[0] = v.x();
  out[1] = v.y();
  out[2] = v.z();
}

}  // namespace

SceneChannels RegisterScene(Registry& registry, const std::string& model_name,
                            sgal::PhysicsScene& scene) {
  SceneChannels result;
  result.sampler = std::make_shared<SceneSampler>(scene);
  const std::string prefix = model_name + ".";
  auto add = [&](ChannelInfo info, Getter getter, Setter setter) {
    if (registry.Contains(info.id)) {
      result.skipped.push_back(info.id);
      return;
    }
    result.ids.push_back(info.id);
    registry.Add(std::move(info), std::move(getter), std::move(setter));
  };

  // the scene's own scalar parameters
  for (const auto& p : scene.Parameters()) {
    ChannelInfo info;
    info.id = prefix + p.id;
    info.unit = p.unit;
    info.shape = Shape::Scalar();
    info.is_static = p.is_static;
    info.description = std::string(p.is_static ? "model parameter " : "simulation state ") + p.id;
    sgal::PhysicsScene* s = &scene;
    // by index: no string lookup per sample
    Getter get = [s, index = s->ParameterIndex(p.id)](double* out) {
      out[0] = s->GetParameter(index);
    };
    Setter set;
    if (p.writable)
      set = [s, id = p.id](const double* v) {
        try {
          s->SetParameter(id, v[0]);
        } catch (const std::out_of_range& e) {
          // the scene no longer knows an id it listed: a refusal, not an unknown channel
          throw std::invalid_argument(e.what());
        }
      };
    add(std::move(info), std::move(get), std::move(set));
  }

  // per body: pose and velocities from the per-step cache
  const auto& bodies = scene.description().bodies;
  for (size_t i = 0; i < bodies.size(); ++i) {
    const std::string base = prefix + bodies[i].name;
    SceneSampler* sampler = result.sampler.get();
    std::shared_ptr<SceneSampler> keep = result.sampler;
    auto channel = [&](const char* field, const char* unit, Shape shape, const char* what) {
      ChannelInfo info;
      info.id = base + "." + field;
      info.unit = unit;
      info.shape = shape;
      info.description = std::string(what) + " of body " + bodies[i].name;
      return info;
    };
    add(
        channel("position", "m", Shape::Vector(3), "world position of the frame origin"),
        [keep, sampler, i](double* out) { Write3(sampler->body(i).pose.position, out); }, nullptr);
    add(
        channel("orientation", "", Shape::Vector(4), "orientation quaternion w x y z"),
        [keep, sampler, i](double* out) {
          const Eigen::Quaterniond& q = sampler->body(i).pose.orientation;
          out[0] = q.w();
          out[1] = q.x();
          out[2] = q.y();
          out[3] = q.z();
        },
        nullptr);
    add(
        channel("rotation", "", Shape::Matrix(3, 3), "rotation matrix (body to world, row-major)"),
        [keep, sampler, i](double* out) {
          const Eigen::Matrix3d& r = sampler->rotation(i);
          for (int row = 0; row < 3; ++row)
            for (int col = 0; col < 3; ++col) out[row * 3 + col] = r(row, col);
        },
        nullptr);
    add(
        channel("linear_velocity", "m/s", Shape::Vector(3), "world velocity of the frame origin"),
        [keep, sampler, i](double* out) { Write3(sampler->body(i).linear_velocity, out); },
        nullptr);
    add(
        channel("angular_velocity", "rad/s", Shape::Vector(3), "world angular velocity"),
        [keep, sampler, i](double* out) { Write3(sampler->body(i).angular_velocity, out); },
        nullptr);
  }
  return result;
}

}  // namespace caliper::daq
