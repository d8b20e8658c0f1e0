#include "model_runs.h"

#include <fnmatch.h>
#include <signal.h>

#include <filesystem>
#include <stdexcept>

#include "caliper/rtc/client_orb.h"
#include "caliper/model_file/model_file.h"

namespace caliper::ctl {

namespace M = ::Caliper::Simulation;

bool InterruptPending() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  const timespec none = {0, 0};
  return sigtimedwait(&set, nullptr, &none) > 0;
}

std::vector<ModelEntry> FindModels(CosNaming::NamingContext_ptr root, const std::string& glob) {
  std::vector<ModelEntry> out;
  for (auto& e : rtc::ListComponents(root)) {
    const std::string name = e.instance + "@" + e.host;
    if (fnmatch(glob.c_str(), e.instance.c_str(), 0) != 0 &&
        fnmatch(glob.c_str(), name.c_str(), 0) != 0)
      continue;
    out.push_back({name, e.path, e.object});
  }
  return out;
}

std::string ReadScene(const std::string& path, std::vector<std::string>* warnings) {
  // ImportError and ExportError (std::runtime_error) name the file
  const std::string bytes = model_file::ContentToSend(path, warnings).bytes;
  const size_t limit = static_cast<size_t>(rtc::kMaxMessageBytes) - (1u << 20);
  if (bytes.size() > limit)
    throw std::runtime_error(path + " is " + std::to_string(bytes.size() >> 20) +
                             " MiB: scenes travel in one CORBA message of at most " +
                             std::to_string(limit >> 20) + " MiB");
  return bytes;
}

std::string SceneFileName(const std::string& path) {
  if (model_file::FormatOf(path) == model_file::Format::kUrdf)
    return std::filesystem::path(path).stem().string() + ".dae";
  return std::filesystem::path(path).filename().string();
}

M::Octets ToOctets(const std::string& bytes) {
  M::Octets out(static_cast<CORBA::ULong>(bytes.size()));
  out.length(static_cast<CORBA::ULong>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char*>(out.get_buffer()));
  return out;
}

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

}  // namespace caliper::ctl
