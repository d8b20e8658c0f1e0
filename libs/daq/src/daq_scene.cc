#include "caliper/daq/daq_scene.h"

#include <stdexcept>
#include <string>

namespace caliper::daq {

SceneSampler::SceneSampler(const sgal::PhysicsScene& scene)
    : scene_(scene),
      body_count_(scene.description().bodies.size()),
      values_(body_count_ * kValuesPerBody) {}

void SceneSampler::Fetch() {
  scene_.ReadBodyStates(&states_);
  const std::vector<sgal::BodyState>& states = states_;
  if (states.size() != body_count_)
    throw std::runtime_error("the scene has " + std::to_string(states.size()) +
                             " bodies, its DAQ channels were registered for " +
                             std::to_string(body_count_));
  for (size_t i = 0; i < body_count_; ++i) {
    const sgal::BodyState& b = states[i];
    double* out = values_.data() + i * kValuesPerBody;
    const Eigen::Quaterniond& q = b.pose.orientation;
    Eigen::Map<Eigen::Vector3d>(out + kPosition) = b.pose.position;
    out[kOrientation + 0] = q.w();
    out[kOrientation + 1] = q.x();
    out[kOrientation + 2] = q.y();
    out[kOrientation + 3] = q.z();
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(out + kRotation) =
        q.toRotationMatrix();
    Eigen::Map<Eigen::Vector3d>(out + kLinearVelocity) = b.linear_velocity;
    Eigen::Map<Eigen::Vector3d>(out + kAngularVelocity) = b.angular_velocity;
  }
  fresh_ = true;
  ++fetches_;
}

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

  // per body: pose and velocities read in place from the per-step cache
  const auto& bodies = scene.description().bodies;
  for (size_t i = 0; i < bodies.size(); ++i) {
    const std::string base = prefix + bodies[i].name;
    const double* values = result.sampler->values(i);
    auto channel = [&](const char* field, const char* unit, Shape shape, const char* what,
                       size_t offset) {
      ChannelInfo info;
      info.id = base + "." + field;
      info.unit = unit;
      info.shape = shape;
      info.description = std::string(what) + " of body " + bodies[i].name;
      if (registry.Contains(info.id)) {
        result.skipped.push_back(info.id);
        return;
      }
      result.ids.push_back(info.id);
      registry.Add(std::move(info), Source{result.sampler, values + offset});
    };
    channel("position", "m", Shape::Vector(3), "world position of the frame origin",
            SceneSampler::kPosition);
    channel("orientation", "", Shape::Vector(4), "orientation quaternion w x y z",
            SceneSampler::kOrientation);
    channel("rotation", "", Shape::Matrix(3, 3), "rotation matrix (body to world, row-major)",
            SceneSampler::kRotation);
    channel("linear_velocity", "m/s", Shape::Vector(3), "world velocity of the frame origin",
            SceneSampler::kLinearVelocity);
    channel("angular_velocity", "rad/s", Shape::Vector(3), "world angular velocity",
            SceneSampler::kAngularVelocity);
  }
  return result;
}

}  // namespace caliper::daq
