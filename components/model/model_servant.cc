#include "model_servant.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include "caliper/actuators/actuator.h"
#include "caliper/collada/importer.h"
#include "caliper/logging/log.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"
#include "caliper/rtc/peers.h"
#include "caliper/rtc/reason.h"
#include "model_convert.h"

namespace caliper::model {

namespace S = ::Caliper::Scene;
namespace D = ::Caliper::Daq;
namespace M = ::Caliper::Simulation;
using namespace simulation;

namespace {

using rtc::ClientOf;


// raises `Refused` unless `ref` answers within the push deadline and is a `repository_id`
template <class Refused>
void RequireReachable(CORBA::Object_ptr ref, const char* what, const char* repository_id,
                      std::chrono::milliseconds timeout) {
  const std::string why = rtc::Unreachable(ref, what, repository_id, timeout);
  if (!why.empty()) throw Refused(why.c_str());
}

/// Runs a core call and turns its C++ exceptions into the IDL's user exceptions; `Unavailable`
/// is the operation's declared "cannot serve now" exception (Simulation's or Daq's NotAvailable).
template <class Unavailable = M::NotAvailable, class F>
auto Guard(F&& f) -> decltype(f()) {
  // reasons quote what the client sent (ids, names, paths): bounded, whatever their size
  using rtc::BoundedReason;
  try {
    return f();
  } catch (const UnknownId& e) {
    throw D::UnknownId(BoundedReason(e.what()).c_str(), BoundedReason(e.id()).c_str());
  } catch (const InvalidValue& e) {
    throw D::InvalidParameter(BoundedReason(e.what()).c_str());
  } catch (const NotAvailable& e) {
    throw Unavailable(BoundedReason(e.what()).c_str());
  } catch (const LimitExceeded& e) {
    throw D::LimitExceeded(BoundedReason(e.what()).c_str(), e.limit());
  } catch (const sgal::EditError& e) {
    // only the editing operations make these; they declare EditRefused
    throw M::EditRefused(BoundedReason(e.what()).c_str());
  } catch (const CORBA::UserException&) {
    throw;
  } catch (const std::exception& e) {
    const std::string reason = BoundedReason(e.what());
    logging::Get("model").error("internal error: %s", reason.c_str());
    throw Unavailable(("internal error: " + reason).c_str());
  } catch (...) {
    logging::Get("model").error("internal error: an exception of unknown type");
    throw Unavailable("internal error: an exception of unknown type");
  }
}

// What a controller's `get` and `control_cycle` read: the ids where they arrived (no string per
// id), the shapes and the values one after the other (no vector per value).
struct FlatValues {
  std::vector<const char*> names;
  std::vector<daq::Shape> shapes;
  std::vector<double> values;

  // the reply: a Daq::Value per id
  void Fill(D::ValueSeq* out) const {
    out->length(static_cast<CORBA::ULong>(shapes.size()));
    const double* at = values.data();
    for (CORBA::ULong i = 0; i < shapes.size(); ++i) {
      D::Value& v = (*out)[i];
      v.rows = shapes[i].rows;
      v.cols = shapes[i].cols;
      const auto n = static_cast<CORBA::ULong>(shapes[i].size());
      v.data.length(n);
      for (CORBA::ULong k = 0; k < n; ++k) v.data[k] = at[k];
      at += n;
    }
  }
};

// The buffers of one call of `ids`, with their names. A controller's cycle reads a few ids every
// cycle: their buffers are the serving thread's, kept from call to call. A larger call, or one
// whose values outgrew what a thread keeps, has buffers of its own, freed when it returns.
class FlatCall {
 public:
  explicit FlatCall(const S::StringSeq& ids) : flat_(ids.length() <= kKeptIds ? Kept() : own_) {
    flat_.names.resize(ids.length());
    for (CORBA::ULong i = 0; i < ids.length(); ++i) flat_.names[i] = ids[i].in();
  }
  ~FlatCall() {
    if (flat_.values.capacity() > kKeptValues) std::vector<double>().swap(flat_.values);
  }
  FlatCall(const FlatCall&) = delete;
  FlatCall& operator=(const FlatCall&) = delete;
  FlatValues* operator->() { return &flat_; }

 private:
  static constexpr CORBA::ULong kKeptIds = 1024;
  static constexpr size_t kKeptValues = 1 << 16;
  static FlatValues& Kept() {
    thread_local FlatValues kept;
    return kept;
  }
  FlatValues own_;
  FlatValues& flat_;
};

// the largest GIOP message this process sends or receives (corba.max_message_size) [bytes]
double MaxMessageBytes(const core::Config& config) {
  return config.GetDouble("corba.max_message_size") * (1 << 20);
}

// bytes in MiB with one decimal, for messages
std::string Mib(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", bytes / (1 << 20));
  return text;
}

}  // namespace

ModelServant::ModelServant(rtc::Runtime& runtime, ModelCore& core, const PushLimits& limits)
    : rtc::RTObjectServant(runtime),
      core_(core),
      files_(ModelFiles::FromConfig(runtime.config())),
      pool_(limits) {
  // the stepping waits for a lossless consumer: its sender should push now, not at its next poll
  core_.SetConsumerWake([this](uint64_t id) { pool_.Due(PushPool::Kind::kSubscription, id); });
}

ModelServant::~ModelServant() { core_.SetConsumerWake(nullptr); }

void ModelServant::load_scene(const char* path) {
  // only below the model search path: a client must not make the Model read any file
  std::string file;
  try {
    file = files_.ResolveScene(path);
  } catch (const collada::ImportError& e) {
    logging::Get("model").error("load %s failed: %s", path, e.what());
    throw M::LoadFailed(e.what());  // a URDF that is not XML: not a refusal
  } catch (const std::exception& e) {
    logging::Get("model").warn("load_scene refused: %s", e.what());
    throw M::LoadFailed((std::string("load_scene: ") + e.what() +
                         "; other files are sent by content (load_scene_data, as caliper-ctl "
                         "load does by itself)")
                            .c_str());
  }
  try {
    core_.Load(file);
  } catch (const std::exception& e) {
    logging::Get("model").error("load %s failed: %s", path, e.what());
    throw M::LoadFailed(e.what());
  }
}

void ModelServant::start() { Guard([&] { core_.Start(); }); }
void ModelServant::pause() { Guard([&] { core_.Pause(); }); }
void ModelServant::stop() { Guard([&] { core_.Stop(); }); }
void ModelServant::reset() { Guard([&] { core_.Reset(); }); }
CORBA::ULong ModelServant::step(CORBA::ULong n) {
  return Guard([&] { return static_cast<CORBA::ULong>(core_.StepNow(n)); });
}
M::CycleResult* ModelServant::control_cycle(const M::CommandSeq& commands, CORBA::ULong n,
                                            const S::StringSeq& ids) {
  std::vector<std::pair<std::string, double>> list;
  for (CORBA::ULong i = 0; i < commands.length(); ++i)
    list.emplace_back(commands[i].actuator.in(), commands[i].value);
  FlatCall flat(ids);
  const uint64_t steps = Guard([&] {
    return core_.ControlCycle(list, n, flat->names.data(), flat->names.size(), &flat->shapes,
                              &flat->values);
  });
  auto result = std::make_unique<M::CycleResult>();
  result->steps = static_cast<CORBA::ULong>(steps);
  flat->Fill(&result->values);
  return result.release();
}

void ModelServant::set_time_step(CORBA::Double s) {
  Guard([&] { core_.SetTimeStep(s); });
}

void ModelServant::set_real_time_factor(CORBA::Double f) {
  Guard([&] { core_.SetRealTimeFactor(f); });
}

M::SimulationStatus* ModelServant::status() {
  const Status s = core_.status();
  auto* result = new M::SimulationStatus;
  M::SimulationStatus& out = *result;
  out.state = static_cast<M::SimulationState>(static_cast<int>(s.state));
  out.scene = s.scene.c_str();
  out.sim_time = s.sim_time;
  out.steps = s.steps;
  out.time_step = s.time_step;
  out.real_time_factor = s.real_time_factor;
  out.achieved_real_time_factor = s.achieved_real_time_factor;
  out.last_error = s.last_error.c_str();
  return result;
}

S::Description* ModelServant::scene_description() {
  return Guard([&] {
    auto scene = core_.description();
    if (!scene) throw NotAvailable("no scene is loaded");
    // meshes make nearly all of it: refuse, saying so, what would fail as a bare MARSHAL
    double bytes = 0;
    std::set<const sgal::Mesh*> meshes;
    auto count = [&](const sgal::Geometry& g) {
      const sgal::Mesh* mesh = nullptr;
      if (const auto* hull = std::get_if<sgal::ConvexHull>(&g)) mesh = hull->mesh.get();
      if (const auto* tri = std::get_if<sgal::TriangleMesh>(&g)) mesh = tri->mesh.get();
      if (mesh != nullptr && meshes.insert(mesh).second)
        bytes += 24.0 * (mesh->vertices.size() + mesh->normals.size()) +
                 12.0 * mesh->triangles.size();
    };
    for (const auto& b : scene->bodies) {
      for (const auto& v : b.visuals) count(v.geometry);
      for (const auto& shape : b.shapes) count(shape.geometry);
    }
    const double limit = MaxMessageBytes(runtime_.config());
    if (bytes > 0.9 * limit)
      throw NotAvailable("the scene description is about " + Mib(bytes) + " MiB of meshes (" +
                         std::to_string(meshes.size()) + " meshes), more than one GIOP message " +
                         "carries (" + Mib(limit) + " MiB, corba.max_message_size): simplify " +
                         "the meshes or raise the limit");
    return ToIdl(*scene);
  });
}

void ModelServant::load_scene_data(const char* file_name, const M::Octets& data) {
  try {
    core_.LoadData(file_name, std::string(reinterpret_cast<const char*>(data.get_buffer()),
                                          data.length()));
  } catch (const NotAvailable& e) {
    throw M::NotAvailable(e.what());  // busy with an experiment: not the file's fault
  } catch (const std::exception& e) {
    const std::string reason = rtc::BoundedReason(e.what());
    logging::Get("model").error("load %s (sent by content) failed: %s",
                                rtc::BoundedReason(file_name).c_str(), reason.c_str());
    throw M::LoadFailed(reason.c_str());
  } catch (...) {
    throw M::LoadFailed("internal error: an exception of unknown type");
  }
}

M::Octets* ModelServant::export_scene() {
  return Guard([&] {
    const std::string bytes = core_.ExportBytes();
    const double limit = MaxMessageBytes(runtime_.config());
    if (static_cast<double>(bytes.size()) > 0.95 * limit)
      throw NotAvailable("the exported scene is " + Mib(static_cast<double>(bytes.size())) +
                         " MiB, more than one GIOP message carries (" + Mib(limit) +
                         " MiB, corba.max_message_size): save it to a file on the Model's host");
    auto* out = new M::Octets(static_cast<CORBA::ULong>(bytes.size()));
    out->length(static_cast<CORBA::ULong>(bytes.size()));
    std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char*>(out->get_buffer()));
    return out;
  });
}

M::Recording* ModelServant::run_experiment(const M::Experiment& in) {
  const experiment::Experiment e = FromIdl(in);
  const std::string bytes(reinterpret_cast<const char*>(in.scene_data.get_buffer()),
                          in.scene_data.length());
  const RunResult result = Guard([&] {
    // the run's own failures first: Guard passes the IDL's exceptions through
    try {
      return core_.RunExperiment(e, e.scene, bytes);
    } catch (const experiment::FormatError& error) {
      throw D::InvalidParameter(rtc::BoundedReason(error.what()).c_str());
    } catch (const RunFailed& error) {
      // the fault itself was logged once, as an error, where it happened
      const std::string reason = rtc::BoundedReason(error.what());
      logging::Get("model").info("%s", reason.c_str());
      throw M::RunFailed(reason.c_str());
    } catch (const LoadError& error) {
      const std::string reason = rtc::BoundedReason(error.what());
      logging::Get("model").error("%s", reason.c_str());
      throw M::LoadFailed(reason.c_str());
    }
  });
  return Guard([&] { return ToIdl(result); });
}

void ModelServant::save_scene(const char* path) {
  Guard([&] {
    // only into the write directory: a client must not make the Model overwrite any file
    std::string file;
    try {
      file = files_.write.Resolve(path, core::ConfinedPaths::Access::kWrite).string();
    } catch (const std::exception& e) {
      logging::Get("model").warn("save_scene refused: %s", e.what());
      throw InvalidValue(std::string("save_scene: ") + e.what() +
                         "; other clients fetch the scene with export_scene (as caliper-ctl save "
                         "does by itself)");
    }
    try {
      core_.Save(file);
    } catch (const NotAvailable&) {
      throw;
    } catch (const std::exception& e) {
      throw InvalidValue(std::string("cannot save ") + path + ": " + e.what());
    }
  });
}

M::FileAccess* ModelServant::file_access() {
  auto* out = new M::FileAccess;
  const std::vector<std::string>& read = files_.read.dirs();
  out->read_dirs.length(static_cast<CORBA::ULong>(read.size()));
  for (CORBA::ULong i = 0; i < read.size(); ++i) out->read_dirs[i] = read[i].c_str();
  out->write_dir = files_.write.dirs().empty() ? "" : files_.write.dirs().front().c_str();
  return out;
}

M::ActuatorInfoSeq* ModelServant::actuators() {
  return Guard([&] {
    const auto list = core_.Actuators();
    auto* out = new M::ActuatorInfoSeq;
    out->length(static_cast<CORBA::ULong>(list.size()));
    for (CORBA::ULong i = 0; i < list.size(); ++i) {
      (*out)[i].name = list[i].name.c_str();
      (*out)[i].kind = list[i].kind.c_str();
      (*out)[i].tendon = list[i].tendon.c_str();
      (*out)[i].command_unit = list[i].command_unit.c_str();
    }
    return out;
  });
}

void ModelServant::set_command(const char* actuator, CORBA::Double value) {
  Guard([&] { core_.SetCommands({{actuator, value}}); });
}

void ModelServant::set_commands(const M::CommandSeq& commands) {
  std::vector<std::pair<std::string, double>> list;
  for (CORBA::ULong i = 0; i < commands.length(); ++i)
    list.emplace_back(commands[i].actuator.in(), commands[i].value);
  Guard([&] { core_.SetCommands(list); });
}

M::ActuatorStateSeq* ModelServant::actuator_states() {
  return Guard([&] {
    const auto states = core_.ActuatorStates();
    auto* out = new M::ActuatorStateSeq;
    out->length(static_cast<CORBA::ULong>(states.size()));
    for (CORBA::ULong i = 0; i < states.size(); ++i) {
      (*out)[i].name = states[i].name.c_str();
      (*out)[i].command = states[i].command;
      (*out)[i].tension = states[i].tension;
    }
    return out;
  });
}

D::ChannelInfoSeq* ModelServant::list(const char* pattern) {
  return Guard<D::NotAvailable>([&] { return ToIdl(core_.Channels(pattern)); });
}

D::ValueSeq* ModelServant::get(const S::StringSeq& ids) {
  return Guard<D::NotAvailable>([&] {
    FlatCall flat(ids);
    core_.SampleInto(flat->names.data(), flat->names.size(), &flat->shapes, &flat->values);
    D::ValueSeq_var out = new D::ValueSeq;
    flat->Fill(&out.inout());
    return out._retn();
  });
}

void ModelServant::set(const char* id, const D::Value& value) {
  std::vector<double> values;
  for (CORBA::ULong i = 0; i < value.data.length(); ++i) values.push_back(value.data[i]);
  Guard<D::NotAvailable>([&] { core_.SetChannel(id, values); });
}

D::ChannelInfoSeq* ModelServant::channels(const char* pattern) { return list(pattern); }

D::ValueSeq* ModelServant::sample(const S::StringSeq& ids) { return get(ids); }

CORBA::ULongLong ModelServant::subscribe(const S::StringSeq& ids, CORBA::ULong every_n_steps,
                                         D::DataConsumer_ptr consumer) {
  return Subscribe(ids, every_n_steps, consumer, false);
}

CORBA::ULongLong ModelServant::subscribe_lossless(const S::StringSeq& ids,
                                                  CORBA::ULong every_n_steps,
                                                  D::DataConsumer_ptr consumer) {
  return Subscribe(ids, every_n_steps, consumer, true);
}

D::SubscriptionStatus ModelServant::subscription_status(CORBA::ULongLong subscription) {
  try {
    const FeedStatus f = core_.SubscriptionStatus(subscription);
    D::SubscriptionStatus out;
    out.lossless = f.lossless;
    out.samples = f.samples;
    out.batches = f.batches;
    out.dropped_batches = f.dropped_batches;
    out.dropped_samples = f.dropped_samples;
    out.queued = f.queued;
    out.waited = f.waited_s;
    return out;
  } catch (const UnknownId& e) {
    throw D::UnknownId(e.what(), e.id().c_str());
  }
}

CORBA::ULongLong ModelServant::Subscribe(const S::StringSeq& ids, CORBA::ULong every_n_steps,
                                         D::DataConsumer_ptr consumer, bool lossless) {
  if (CORBA::is_nil(consumer)) throw D::InvalidParameter("the consumer is nil");
  const std::string client = ClientOf(consumer);
  pool_.CheckRoom(PushPool::Kind::kSubscription, client);
  RequireReachable<D::InvalidParameter>(consumer, "DataConsumer", D::DataConsumer::_PD_repoId,
                                        pool_.limits().call_timeout);
  // batches about twenty times a second of simulated time
  const double dt = core_.status().time_step;
  const double per_sample = (dt > 0 ? dt : 1e-3) * std::max<CORBA::ULong>(every_n_steps, 1);
  const size_t batch_steps = std::max<size_t>(1, static_cast<size_t>(0.05 / per_sample));
  const uint64_t id =
      Guard<D::NotAvailable>([&] {
        // a lossless consumer that takes nothing for two push deadlines is ended
        return core_.Subscribe(FromIdl(ids), every_n_steps, batch_steps,
                               lossless ? 2 * pool_.limits().call_timeout
                                        : std::chrono::milliseconds(0));
      });
  try {
    pool_.Add(PushPool::Kind::kSubscription, id, client, consumer,
              std::make_shared<SubscriptionTarget>(core_, id, consumer, lossless));
  } catch (const D::LimitExceeded&) {
    core_.Unsubscribe(id);  // another call of the same client took the last place meanwhile
    throw;
  }
  logging::Get("daq").info("subscription %llu added (client %s): %u ids every %u steps",
                           static_cast<unsigned long long>(id), client.c_str(), ids.length(),
                           std::max<CORBA::ULong>(every_n_steps, 1));
  return id;
}

void ModelServant::unsubscribe(CORBA::ULongLong subscription) {
  core_.Unsubscribe(subscription);
  pool_.Remove(PushPool::Kind::kSubscription, subscription);
}

CORBA::ULongLong ModelServant::add_observer(S::SceneObserver_ptr observer) {
  if (CORBA::is_nil(observer)) throw M::NotAvailable("the observer is nil");
  // registering again (a client checking that it is still registered) is cheap and keeps its id
  const uint64_t existing = pool_.Find(PushPool::Kind::kObserver, observer);
  if (existing != 0) return existing;
  const std::string client = ClientOf(observer);
  pool_.CheckRoom(PushPool::Kind::kObserver, client);
  RequireReachable<M::NotAvailable>(observer, "SceneObserver", S::SceneObserver::_PD_repoId,
                                    pool_.limits().call_timeout);
  const uint64_t id = next_observer_++;
  auto target = std::make_shared<ObserverTarget>(core_, pool_, observer);
  core_.AddListener(target.get());  // the scene and the current state are its first push
  uint64_t used = 0;
  try {
    used = pool_.Add(PushPool::Kind::kObserver, id, client, observer, target);
  } catch (...) {
    core_.RemoveListener(target.get());
    throw;
  }
  if (used != id)
    core_.RemoveListener(target.get());
  else
    logging::Get("observers").info("observer %llu added (client %s)",
                                   static_cast<unsigned long long>(id), client.c_str());
  return used;
}

void ModelServant::remove_observer(CORBA::ULongLong id) {
  pool_.Remove(PushPool::Kind::kObserver, id);
}

// ------------------------------------------------------------------------ scene editing


M::EditStatus* ModelServant::move_path_point(const char* tendon, CORBA::ULong index,
                                             const S::PathPoint& point) {
  return Guard([&] {
    const sgal::PathElement to = FromIdl(point);
    return ToIdl(core_.Edit([&](const sgal::Scene& s) {
      return sgal::MovePathPoint(s, tendon, index, to);
    }));
  });
}

M::EditStatus* ModelServant::insert_path_point(const char* tendon, CORBA::ULong index,
                                               const S::PathPoint& point) {
  return Guard([&] {
    const sgal::PathElement element = FromIdl(point);
    return ToIdl(core_.Edit([&](const sgal::Scene& s) {
      return sgal::InsertPathPoint(s, tendon, index, element);
    }));
  });
}

M::EditStatus* ModelServant::remove_path_point(const char* tendon, CORBA::ULong index) {
  return Guard([&] {
    return ToIdl(core_.Edit(
        [&](const sgal::Scene& s) { return sgal::RemovePathPoint(s, tendon, index); }));
  });
}

M::EditStatus* ModelServant::add_tendon(const char* tendon, const S::PathPoint& from,
                                        const S::PathPoint& to, CORBA::Double radius_m,
                                        const char* actuator, const char* kind) {
  return Guard([&] {
    sgal::Tendon t;
    t.name = tendon;
    t.radius = radius_m;
    t.path = {FromIdl(from), FromIdl(to)};
    // a parameter without a default is copied from the scene's first actuator of the kind
    const sgal::Actuator a = NewActuator(core_.description().get(), actuator, kind);
    return ToIdl(core_.Edit([&](const sgal::Scene& s) { return sgal::AddTendon(s, t, a); }));
  });
}

M::EditStatus* ModelServant::remove_tendon(const char* tendon) {
  return Guard([&] {
    return ToIdl(core_.Edit([&](const sgal::Scene& s) { return sgal::RemoveTendon(s, tendon); }));
  });
}

M::EditStatus* ModelServant::set_obstacle(const S::Obstacle& obstacle) {
  return Guard([&] {
    sgal::WrapObstacle o;
    o.name = obstacle.name.in();
    o.body = obstacle.body.in();
    const std::string kind = obstacle.kind.in();
    if (kind != "sphere" && kind != "cylinder")
      throw sgal::EditError("obstacle '" + o.name + "': kind '" + kind +
                            "' is not sphere or cylinder");
    o.kind = kind == "sphere" ? sgal::ObstacleKind::kSphere : sgal::ObstacleKind::kCylinder;
    o.pose = FromFrame(obstacle.pose);
    o.radius = obstacle.radius;
    o.length = obstacle.length;
    return ToIdl(core_.Edit([&](const sgal::Scene& s) { return sgal::SetObstacle(s, o); }));
  });
}

M::EditStatus* ModelServant::remove_obstacle(const char* obstacle) {
  return Guard([&] {
    return ToIdl(
        core_.Edit([&](const sgal::Scene& s) { return sgal::RemoveObstacle(s, obstacle); }));
  });
}

M::EditStatus* ModelServant::set_shape_dims(const char* body, CORBA::ULong index,
                                            const S::DoubleSeq& dims) {
  return Guard([&] {
    if (dims.length() > 4) throw sgal::EditError("set_shape_dims: a shape has at most 4 dimensions");
    std::vector<double> values(dims.get_buffer(), dims.get_buffer() + dims.length());
    return ToIdl(core_.Edit(
        [&](const sgal::Scene& s) { return sgal::SetShapeDims(s, body, index, values); }));
  });
}

M::EditStatus* ModelServant::set_mass(const char* body, CORBA::Double mass_kg) {
  return Guard([&] {
    return ToIdl(core_.Edit([&](const sgal::Scene& s) { return sgal::SetMass(s, body, mass_kg); }));
  });
}

M::EditStatus* ModelServant::set_measurement_delay(const char* id, CORBA::Double delay_s) {
  return Guard([&] {
    return ToIdl(core_.Edit(
        [&](const sgal::Scene& s) { return sgal::SetMeasurementDelay(s, id, delay_s); }));
  });
}

S::SensorDelaySeq* ModelServant::measurement_delays() {
  return Guard([&] {
    const auto scene = core_.description();
    if (!scene) throw NotAvailable("no scene is loaded (load one first)");
    auto* out = new S::SensorDelaySeq;
    SensorDelaysToIdl(*scene, out);
    return out;
  });
}

M::EditStatus* ModelServant::undo() {
  return Guard([&] { return ToIdl(core_.Undo()); });
}

M::EditStatus* ModelServant::redo() {
  return Guard([&] { return ToIdl(core_.Redo()); });
}

M::EditStatus* ModelServant::edit_status() { return ToIdl(core_.edit_status()); }

S::VisualSeq* ModelServant::body_shapes(const char* body) {
  return Guard([&] {
    const auto scene = core_.description();
    if (!scene) throw NotAvailable("no scene is loaded (load one first)");
    const sgal::Body* b = scene->FindBody(body);
    if (b == nullptr) throw sgal::EditError("no body '" + std::string(body) + "'");
    auto* out = new S::VisualSeq;
    out->length(static_cast<CORBA::ULong>(b->shapes.size()));
    std::map<const sgal::Mesh*, CORBA::Long> meshes;  // meshes are not sent: index only
    for (CORBA::ULong k = 0; k < b->shapes.size(); ++k) {
      (*out)[k].name = b->shapes[k].name.c_str();
      (*out)[k].geometry = ToGeometry(b->shapes[k].geometry, &meshes);
      (*out)[k].pose = ToFrame(b->shapes[k].pose);
      (*out)[k].r = (*out)[k].g = (*out)[k].b = 0.7f;
      (*out)[k].a = 1;
    }
    return out;
  });
}

M::ActuatorKindSeq* ModelServant::actuator_kinds() {
  auto* out = new M::ActuatorKindSeq;
  const std::vector<std::string> kinds = actuators::Kinds();
  out->length(static_cast<CORBA::ULong>(kinds.size()));
  for (CORBA::ULong i = 0; i < kinds.size(); ++i) {
    M::ActuatorKind& k = (*out)[i];
    k.kind = kinds[i].c_str();
    const auto& specs = actuators::KindParameters(kinds[i]);
    k.parameters.length(static_cast<CORBA::ULong>(specs.size()));
    k.defaults.length(static_cast<CORBA::ULong>(specs.size()));
    k.units.length(static_cast<CORBA::ULong>(specs.size()));
    sgal::Actuator probe;
    probe.name = "probe";
    probe.kind = kinds[i];
    for (CORBA::ULong p = 0; p < specs.size(); ++p) {
      k.parameters[p] = specs[p].name.c_str();
      k.defaults[p] = specs[p].default_value;
      k.units[p] = specs[p].unit.c_str();
      probe.parameters[specs[p].name] = specs[p].default_value;
    }
    try {
      k.command_unit = actuators::Make(probe)->command_unit().c_str();
    } catch (const std::exception&) {
      k.command_unit = "";  // a kind that needs parameters without defaults
    }
  }
  return out;
}

void ModelServant::pull(const char* body, const M::Vector3& point, const M::Vector3& target,
                        CORBA::Double stiffness_n_per_m) {
  Guard([&] {
    core_.Pull(body, {point.x, point.y, point.z}, {target.x, target.y, target.z},
               stiffness_n_per_m);
  });
}

void ModelServant::release_pull() {
  Guard([&] { core_.ReleasePull(); });
}

void ModelServant::select(const char* kind, const char* name, CORBA::ULong index) {
  try {
    core_.Select(kind, name, index);
  } catch (const std::exception& e) {
    throw M::EditRefused(rtc::BoundedReason(e.what()).c_str());
  }
}

M::Selection* ModelServant::current_selection() {
  const ModelCore::Selection s = core_.selection();
  auto* out = new M::Selection;
  out->kind = s.kind.c_str();
  out->name = s.name.c_str();
  out->index = s.index;
  out->revision = s.revision;
  return out;
}

// ------------------------------------------------------------------------ recordings


M::RecordStatus* ModelServant::start_recording(const char* path, const M::RecordOptions& options) {
  return Guard([&] {
    // only into the write directory: a client must not make the Model write any file
    // one extension for every client: NAME becomes NAME.caliper
    const std::string named = recording::WithExtension(path);
    if (std::filesystem::path(named).extension() != recording::kExtension)
      logging::Get("model").warn("recording to %s: recordings are %s files (the Main Window's "
                                 "dialogs look for them)", named.c_str(), recording::kExtension);
    std::string where;
    try {
      where = files_.write.Resolve(named, core::ConfinedPaths::Access::kWrite).string();
    } catch (const std::exception& e) {
      throw InvalidValue(std::string("start_recording: ") + e.what());
    }
    ModelCore::RecordOptions o;
    o.keyframe_every = options.keyframe_every == 0 ? 100 : options.keyframe_every;
    o.channels_every = options.channels_every == 0 ? 1 : options.channels_every;
    o.channels = FromIdl(options.channels);
    o.max_bytes = options.max_bytes;
    try {
      return ToIdl(core_.StartRecording(where, o));
    } catch (const recording::RecordingError& e) {
      throw InvalidValue(e.what());
    }
  });
}

M::RecordStatus* ModelServant::stop_recording() {
  return Guard([&] { return ToIdl(core_.StopRecording()); });
}

M::RecordStatus* ModelServant::recording_status() {
  return Guard([&] { return ToIdl(core_.recording_status()); });
}

M::ReplayStatus* ModelServant::open_replay(const char* path) {
  return Guard([&] {
    std::string where;
    try {
      where = files_.read.Resolve(path, core::ConfinedPaths::Access::kRead).string();
    } catch (const std::exception& e) {
      throw M::LoadFailed(rtc::BoundedReason(std::string("open_replay: ") + e.what()).c_str());
    }
    try {
      return ToIdl(core_.OpenReplay(where));
    } catch (const recording::RecordingError& e) {
      throw M::LoadFailed(rtc::BoundedReason(e.what()).c_str());
    } catch (const collada::ImportError& e) {
      throw M::LoadFailed(rtc::BoundedReason(e.what()).c_str());
    }
  });
}

M::ReplayStatus* ModelServant::open_replay_data(const char* file_name, const M::Octets& data) {
  return Guard([&] {
    try {
      return ToIdl(core_.OpenReplayData(
          file_name,
          std::string(reinterpret_cast<const char*>(data.get_buffer()), data.length())));
    } catch (const recording::RecordingError& e) {
      throw M::LoadFailed(rtc::BoundedReason(e.what()).c_str());
    } catch (const collada::ImportError& e) {
      throw M::LoadFailed(rtc::BoundedReason(e.what()).c_str());
    }
  });
}

M::ReplayStatus* ModelServant::seek(CORBA::Double time) {
  return Guard([&] {
    try {
      return ToIdl(core_.Seek(time));
    } catch (const recording::RecordingError& e) {
      throw NotAvailable(e.what());
    }
  });
}

M::ReplayStatus* ModelServant::replay_status() {
  return Guard([&] { return ToIdl(core_.replay_status()); });
}

void ModelServant::fork() {
  Guard([&] { core_.Fork(); });
}

}  // namespace caliper::model
