#include "caliper/simulation/experiment_runner.h"

#include <algorithm>

#include "caliper/simulation/core_types.h"

namespace caliper::simulation {

std::shared_ptr<const sgal::Scene> ImportCache::Get(const std::string& file_name,
                                                    const std::string& bytes,
                                                    const Importer& import) {
  // the importer is deterministic, so an equal file gives an equal scene
  if (!scene_ || file_name != name_ || bytes != bytes_) {
    scene_.reset();
    scene_ = std::make_shared<const sgal::Scene>(import(file_name, bytes));
    name_ = file_name;
    bytes_ = bytes;
  }
  return scene_;
}

void ApplyOverrides(const experiment::Experiment& e, daq::Registry& registry) {
  for (const auto& o : e.overrides) {
    if (!registry.Contains(o.id))
      throw UnknownId("experiment '" + e.name + "': unknown id '" + o.id + "' in set", o.id);
    try {
      registry.Set(o.id, o.values);
    } catch (const std::exception& error) {
      throw InvalidValue("experiment '" + e.name + "': set " + o.id + ": " + error.what());
    }
  }
}

ExperimentRunner::ExperimentRunner(const experiment::Experiment& e, const daq::Registry& registry,
                                   const std::vector<sgal::Actuator>& actuators, double dt,
                                   uint64_t max_steps, size_t max_bytes)
    : registry_(registry), schedule_(e.schedule), every_n_steps_(e.every_n_steps), time_step_(dt) {
  experiment::Recording& rec = recording_;
  // resolved once: sampling reads through handles (no hashing, no allocation per sample)
  for (const auto& id : e.record) {
    if (!registry_.Contains(id))
      throw UnknownId("experiment '" + e.name + "': unknown id '" + id + "' in record", id);
    const daq::ChannelInfo& info = registry_.Info(id);
    rec.channels.push_back({id, info.unit, info.shape.rows, info.shape.cols});
    columns_.emplace_back(registry_.Resolve(id), rec.values_per_sample);
    rec.values_per_sample += info.shape.size();
  }
  for (const auto& c : e.schedule)
    if (std::none_of(actuators.begin(), actuators.end(),
                     [&](const sgal::Actuator& a) { return a.name == c.actuator; }))
      throw UnknownId("experiment '" + e.name + "': no actuator '" + c.actuator + "'", c.actuator);
  steps_ = experiment::StepCount(e.duration_s, dt);
  if (steps_ > max_steps)
    throw InvalidValue("experiment '" + e.name + "': " + std::to_string(steps_) + " steps of " +
                       std::to_string(dt) + " s; one run takes at most " +
                       std::to_string(max_steps) + " (split it, or use a longer time step)");
  const uint64_t samples = steps_ / e.every_n_steps + 1;
  // the recording travels in one message: refuse what cannot arrive before spending the run
  const double bytes = static_cast<double>(samples) * (rec.values_per_sample + 1) * 8;
  if (bytes > max_bytes)
    throw InvalidValue("experiment '" + e.name + "': " + std::to_string(samples) + " samples of " +
                       std::to_string(rec.values_per_sample) + " values are " +
                       std::to_string(static_cast<long>(bytes / (1 << 20))) +
                       " MiB, more than one reply carries (" + std::to_string(max_bytes >> 20) +
                       " MiB): sample less often (every_n_steps) or record fewer ids");
  rec.times.reserve(samples);
  rec.data.reserve(samples * rec.values_per_sample);
}

void ExperimentRunner::TakeDueCommands(double time,
                                       std::vector<std::pair<std::string, double>>* pending) {
  // commands due by the start of this step (a part per billion of a step counts as due)
  const double now = time + 1e-9 * time_step_;
  for (; next_command_ < schedule_.size() && schedule_[next_command_].time_s <= now;
       ++next_command_) {
    const auto& c = schedule_[next_command_];
    pending->emplace_back(c.actuator, c.value);
  }
}

void ExperimentRunner::Sample(double time) {
  experiment::Recording& rec = recording_;
  rec.times.push_back(time);
  const size_t at = rec.data.size();
  rec.data.resize(at + rec.values_per_sample);
  for (const auto& [handle, offset] : columns_) registry_.Read(handle, &rec.data[at + offset]);
}

}  // namespace caliper::simulation
