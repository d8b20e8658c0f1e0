// Cost of DAQ sampling per simulation step: 1,000 ids read through pre-resolved handles, as the
// Model does for a subscription sampled every step. Three cases:
//   synthetic  1,000 scalar channels reading doubles from memory (the registry's own overhead);
//   bodies     a Bullet scene of 200 free balls, 5 body channels each (position, orientation,
//              rotation, linear and angular velocity: 1,000 ids, 4,400 doubles) read in place
//              from the per-step SceneSampler cache (the recorder copies neighbouring ids in
//              one go);
//   chain      a Bullet chain of 100 hinged links: all 502 scene parameters (each read through
//              PhysicsScene::GetParameter(id)) plus 498 body channels;
// plus the recorder's OnStep for a 1,000-id subscription on the bodies scene (sampling + batch
// hand-over). Each figure is the median of several repetitions, printed in microseconds per step
// next to the step time of the same scene measured in the same run. Options: --steps N,
// --repeats N.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "caliper/daq/daq_scene.h"
#include "caliper/daq/recorder.h"
#include "caliper/daq/registry.h"
#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::bench {
namespace {

using Clock = std::chrono::steady_clock;
using Eigen::Vector3d;

int steps = 2000;
int repeats = 5;
volatile double sink = 0;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double Micros(Clock::duration d) { return std::chrono::duration<double, std::micro>(d).count(); }

/// Median over `repeats` of the mean time per call of `f` over `steps` calls [us].
double TimePerCall(const std::function<void()>& f) {
  std::vector<double> runs;
  for (int r = 0; r < repeats; ++r) {
    const auto start = Clock::now();
    for (int i = 0; i < steps; ++i) f();
    runs.push_back(Micros(Clock::now() - start) / steps);
  }
  return Median(runs);
}

/// Median over `repeats` of the mean time of `measured` over `steps` calls [us]; `before` runs
/// untimed ahead of each call (the simulation step).
double TimeAfter(const std::function<void()>& before, const std::function<void()>& measured) {
  std::vector<double> runs;
  for (int r = 0; r < repeats; ++r) {
    Clock::duration total{};
    for (int i = 0; i < steps; ++i) {
      before();
      const auto start = Clock::now();
      measured();
      total += Clock::now() - start;
    }
    runs.push_back(Micros(total) / steps);
  }
  return Median(runs);
}

/// `n` free balls in a grid, no gravity, drifting and spinning slowly (no contacts).
sgal::Scene Balls(int n) {
  sgal::Scene s;
  s.name = "balls";
  s.gravity = Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    sgal::Body b;
    b.name = "ball" + std::to_string(i);
    b.pose.position = Vector3d(0.3 * (i % 20), 0.3 * (i / 20), 0);
    b.inertia.mass = 1.0;
    b.inertia.tensor = Eigen::Matrix3d::Identity() * 4e-4;
    b.shapes.push_back({"ball", sgal::Sphere{0.05}, {}});
    b.linear_velocity = Vector3d(0.01, 0, 0);
    b.angular_velocity = Vector3d(0, 0, 0.5);
    s.bodies.push_back(b);
  }
  return s;
}

/// A chain of `n` 0.1 m links hanging from the world, hinged about y.
sgal::Scene Chain(int n) {
  sgal::Scene s;
  s.name = "chain";
  const Eigen::Quaterniond z_to_y(Eigen::AngleAxisd(-M_PI / 2, Vector3d::UnitX()));
  for (int i = 0; i < n; ++i) {
    sgal::Body b;
    b.name = "link" + std::to_string(i);
    b.pose.position = Vector3d(0.1 * (i + 0.5), 0, 0);
    b.inertia.mass = 0.1;
    b.inertia.tensor = Eigen::Matrix3d::Identity() * 1e-4;
    b.shapes.push_back({"box", sgal::Box{Vector3d(0.1, 0.02, 0.02)}, {}});
    s.bodies.push_back(b);
    sgal::Constraint c;
    c.name = "joint" + std::to_string(i);
    c.body_a = b.name;
    c.body_b = i == 0 ? "" : "link" + std::to_string(i - 1);
    c.frame_a.position = Vector3d(-0.05, 0, 0);
    c.frame_a.orientation = z_to_y;
    c.frame_b.position = i == 0 ? Vector3d::Zero() : Vector3d(0.05, 0, 0);
    c.frame_b.orientation = z_to_y;
    s.constraints.push_back(c);
  }
  return s;
}

/// Registers `scene`, picks 1,000 ids (parameters first, then body channels) and prints the step
/// time and the sampling time per step.
void BenchScene(const std::string& name, sgal::PhysicsScene& scene, bool parameters_first) {
  daq::Registry registry;
  daq::SceneChannels channels = daq::RegisterScene(registry, name, scene);
  std::vector<std::string> ids;
  const std::vector<std::string> suffixes = {".position", ".orientation", ".rotation",
                                             ".linear_velocity", ".angular_velocity"};
  if (parameters_first)
    for (const auto& p : scene.Parameters()) ids.push_back(name + "." + p.id);
  for (const auto& b : scene.description().bodies)
    for (const auto& s : suffixes)
      if (ids.size() < 1000) ids.push_back(name + "." + b.name + s);
  ids.resize(std::min<size_t>(ids.size(), 1000));

  std::vector<daq::Handle> handles;
  std::vector<size_t> sizes;
  size_t doubles = 0;
  for (const auto& id : ids) {
    handles.push_back(registry.Resolve(id));
    sizes.push_back(registry.Info(id).shape.size());
    doubles += sizes.back();
  }
  std::vector<double> buffer(doubles);

  const double step_us = TimePerCall([&] { scene.Step(); });
  auto step = [&] {
    scene.Step();
    channels.sampler->Refresh();
  };
  const double sample_us = TimeAfter(step, [&] {
    double* out = buffer.data();
    for (size_t i = 0; i < handles.size(); ++i) {
      registry.Read(handles[i], out);
      out += sizes[i];
    }
    sink = buffer[0];
  });
  std::printf("# %s: %zu ids (%zu doubles), step %.1f us\n", name.c_str(), ids.size(), doubles,
              step_us);
  std::printf("daq_sample_1000_ids_us[%s] %.2f (%.1f %% of the step)\n", name.c_str(), sample_us,
              100 * sample_us / step_us);
  const double states_us = TimePerCall([&] { sink = scene.BodyStates()[0].pose.position.x(); });
  std::printf("# of which PhysicsScene::BodyStates() (once per step): %.2f us\n", states_us);

  daq::Recorder recorder(registry);
  daq::SubscriptionOptions options;
  options.ids = ids;
  options.batch_steps = 100;
  options.queue_capacity = 4;  // nobody takes them: the oldest are dropped, as with a slow client
  recorder.Subscribe(options);
  const double record_us = TimeAfter(step, [&] { recorder.OnStep(scene.steps(), scene.time()); });
  std::printf("daq_record_1000_ids_us[%s] %.2f (%.1f %% of the step)\n", name.c_str(), record_us,
              100 * record_us / step_us);
  std::printf("RATIO daq_1000_ids_share_of_step[%s] %.3f (target 0.10)%s\n", name.c_str(),
              record_us / step_us, record_us / step_us <= 0.10 ? "" : "  <- off target");
}

void BenchSynthetic() {
  daq::Registry registry;
  std::vector<double> values(1000);
  std::vector<daq::Handle> handles;
  for (int i = 0; i < 1000; ++i) {
    values[i] = i;
    daq::ChannelInfo info;
    info.id = "synthetic.channel" + std::to_string(i) + ".value";
    info.unit = "m";
    handles.push_back(registry.Add(info, [p = &values[i]](double* out) { out[0] = *p; }));
  }
  std::vector<double> buffer(1000);
  const double us = TimePerCall([&] {
    for (size_t i = 0; i < handles.size(); ++i) registry.Read(handles[i], &buffer[i]);
    sink = buffer[999];
  });
  std::printf("daq_sample_1000_ids_us[synthetic] %.2f (%.1f ns per id)\n", us, us);
  std::vector<std::string> ids;
  for (const auto& c : registry.List()) ids.push_back(c.id);
  const double by_id_us = TimePerCall([&] { sink = registry.Sample(ids)[999].values[0]; });
  std::printf("# for comparison, Registry::Sample(ids) by string: %.2f us per 1,000 ids\n",
              by_id_us);
}

}  // namespace
}  // namespace caliper::bench

int main(int argc, char** argv) {
  using namespace caliper::bench;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--steps")) steps = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--repeats")) repeats = std::atoi(argv[i + 1]);
  }
  std::printf("# DAQ sampling of 1,000 ids per step through handles (median of %d x %d steps)\n",
              repeats, steps);
  BenchSynthetic();
  auto balls = caliper::physics_bullet::MakeScene(Balls(200));
  BenchScene("balls", *balls, false);
  auto chain = caliper::physics_bullet::MakeScene(Chain(100));
  BenchScene("chain", *chain, true);
  return 0;
}
