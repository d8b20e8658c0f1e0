#include "caliper/client/experiments.h"

#include <algorithm>

#include "caliper/client/scene_transfer.h"

namespace caliper::client {

namespace M = ::Caliper::Simulation;

M::Experiment ToIdl(const experiment::Experiment& e, const std::string& bytes) {
  M::Experiment out;
  out.name = e.name.c_str();
  out.scene_file_name = SceneFileName(e.scene).c_str();
  out.scene_data = ToOctets(bytes);
  out.overrides.length(static_cast<CORBA::ULong>(e.overrides.size()));
  for (CORBA::ULong i = 0; i < e.overrides.size(); ++i) {
    out.overrides[i].id = e.overrides[i].id.c_str();
    const auto& v = e.overrides[i].values;
    out.overrides[i].value.rows = static_cast<CORBA::ULong>(v.size());
    out.overrides[i].value.cols = 1;
    out.overrides[i].value.data.length(static_cast<CORBA::ULong>(v.size()));
    std::copy(v.begin(), v.end(), out.overrides[i].value.data.get_buffer());
  }
  out.schedule.length(static_cast<CORBA::ULong>(e.schedule.size()));
  for (CORBA::ULong i = 0; i < e.schedule.size(); ++i) {
    out.schedule[i].time = e.schedule[i].time_s;
    out.schedule[i].actuator = e.schedule[i].actuator.c_str();
    out.schedule[i].value = e.schedule[i].value;
  }
  out.record.length(static_cast<CORBA::ULong>(e.record.size()));
  for (CORBA::ULong i = 0; i < e.record.size(); ++i) out.record[i] = e.record[i].c_str();
  out.every_n_steps = e.every_n_steps;
  out.duration = e.duration_s;
  return out;
}

experiment::Recording FromIdl(const M::Recording& r) {
  experiment::Recording out;
  for (CORBA::ULong i = 0; i < r.channels.length(); ++i)
    out.channels.push_back({r.channels[i].id.in(), r.channels[i].unit.in(), r.channels[i].rows,
                            r.channels[i].cols});
  out.times.assign(r.times.get_buffer(), r.times.get_buffer() + r.times.length());
  out.values_per_sample = r.values_per_sample;
  out.data.assign(r.data.get_buffer(), r.data.get_buffer() + r.data.length());
  return out;
}

}  // namespace caliper::client
