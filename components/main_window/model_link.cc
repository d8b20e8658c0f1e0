#include "model_link.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <utility>
#include <vector>

#include "caliper/client/model.h"
#include "caliper/client/scene_transfer.h"
#include "caliper/client/session.h"
#include "caliper/core/confined_path.h"
#include "caliper/core/ids.h"
#include "caliper/model.hh"
#include "caliper/rtc.hh"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/idl_names.h"
#include "caliper/rtc/naming.h"

namespace caliper::main_window {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;
namespace RTC = ::Caliper::RTC;
using Clock = std::chrono::steady_clock;

/// The worker's CORBA state; touched by the worker thread only.
struct ModelLink::Impl {
  CORBA::ORB_var orb;
  M::Model_var model;
  std::string scene;  // the scene the channel list belongs to
  bool channels_listed = false;
  Clock::time_point last_lookup{};
  Clock::time_point last_listing{};
  CosNaming::NamingContext_var root;  // nil until resolved; dropped on failure
  bool scene_read = false;            // SceneInfo read for `edit_scene` at `edit_revision`
  std::string edit_scene;
  std::uint64_t edit_revision = 0;
  bool files_read = false;         // write_dir read from this Model
  bool relist_components = false;  // a component action ran since the last listing

  CosNaming::NamingContext_ptr Root(const std::string& nameservice) {
    if (CORBA::is_nil(root)) root = rtc::ResolveRoot(orb, client::ResolveNamingAddress(nameservice));
    return root.in();
  }
};

ModelLink::ModelLink(Options options)
    : impl_(std::make_unique<Impl>()), options_(std::move(options)) {
  impl_->orb = rtc::ClientOrb();
  snapshot_.connection_message = "no Model: looking for " + options_.instance + " ...";
  // the hooks use `this`: the destructor waits for the worker, however long its call takes
  const auto short_ms = static_cast<CORBA::ULong>(options_.call_timeout_ms);
  client::Worker::Hooks hooks;
  hooks.start = [short_ms] { omniORB::setClientConnectTimeout(short_ms); };
  hooks.after_jobs = [this] { ListComponentsIfDue(); };
  hooks.tick = [this] {
    ListComponentsIfDue();
    Poll();
  };
  hooks.finish = [this] {
    impl_->model = M::Model::_nil();
    impl_->root = CosNaming::NamingContext::_nil();
  };
  worker_ = std::make_unique<client::Worker>(
      client::Worker::Options{std::chrono::milliseconds(options_.poll_period_ms),
                              client::Worker::kForever},
      std::move(hooks));
  worker_->Start();
}

ModelLink::~ModelLink() { worker_->Stop(client::Worker::kForever); }

Snapshot ModelLink::snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return snapshot_;
}

void ModelLink::Queue(std::string what, std::function<void(Impl&)> call, bool needs_model) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++snapshot_.commands_queued;
  }
  worker_->Post([this, command = Command{std::move(what), std::move(call), needs_model}] {
    RunCommand(command);
  });
}

void ModelLink::LoadScene(const std::string& path) {
  const int long_ms = options_.long_call_timeout_ms;
  Queue("load " + path, [this, path, long_ms](Impl& i) {
    omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(long_ms));
    // the rule of client::SendsByContent: by path when the Model reads it there (a URDF with
    // its meshes), else by content, a URDF converted to COLLADA here
    const bool by_content = client::SendsByContent(i.model, path, true, false,
                                                   core::ConfinedPaths::Access::kRead);
    const client::SentScene sent = client::LoadScene(i.model, path, by_content);
    const auto& warnings = sent.warnings;
    if (!warnings.empty()) {
      // the Model imports the converted COLLADA without a word: the URDF's warnings are said
      // here, in the status bar and on the terminal
      std::string notice = sent.file_name + " (converted from " + path +
                           "): " + std::to_string(warnings.size()) + " import warning" +
                           (warnings.size() == 1 ? "" : "s") + ": " + warnings.front();
      for (const auto& w : warnings)
        std::fprintf(stderr, "caliper-main: warning: %s\n", w.c_str());
      std::lock_guard<std::mutex> lock(mutex_);
      snapshot_.last_notice = std::move(notice);
      ++snapshot_.notice_serial;
    }
    i.channels_listed = false;
  });
}
void ModelLink::Start() {
  Queue("start", [](Impl& i) { i.model->start(); });
}
void ModelLink::Pause() {
  Queue("pause", [](Impl& i) { i.model->pause(); });
}
void ModelLink::Stop() {
  Queue("stop", [](Impl& i) { i.model->stop(); });
}
void ModelLink::Reset() {
  Queue("reset", [](Impl& i) { i.model->reset(); });
}
void ModelLink::Step(unsigned n) {
  const int long_ms = options_.long_call_timeout_ms;
  Queue("step " + std::to_string(n), [n, long_ms](Impl& i) {
    omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(long_ms));
    i.model->step(n);
  });
}
void ModelLink::SetTimeStep(double seconds) {
  Queue("set the time step", [seconds](Impl& i) { i.model->set_time_step(seconds); });
}
void ModelLink::SetRealTimeFactor(double factor) {
  Queue("set the real-time factor", [factor](Impl& i) { i.model->set_real_time_factor(factor); });
}
void ModelLink::Set(const std::string& id, double value) {
  Queue("set " + id, [id, value](Impl& i) {
    D::Value v;
    v.rows = 1;
    v.cols = 1;
    v.data.length(1);
    v.data[0] = value;
    i.model->set(id.c_str(), v);
  });
}

namespace {

RecordInfo FromIdl(const M::RecordStatus& s) {
  return RecordInfo{bool(s.recording), s.path.in(), s.first_step, s.steps, s.bytes, s.error.in()};
}

ReplayInfo FromIdl(const M::ReplayStatus& s) {
  return ReplayInfo{bool(s.replaying), s.path.in(), s.first_step, s.last_step, s.step,
                    s.start_time,      s.end_time,  s.time};
}

}  // namespace

void ModelLink::StartRecording(const std::string& path, unsigned keyframe_every) {
  Queue("record to " + path, [this, path, keyframe_every](Impl& i) {
    M::RecordOptions options;
    options.keyframe_every = keyframe_every;
    options.channels_every = 1;
    options.channels.length(0);
    options.max_bytes = 0;
    M::RecordStatus_var got = i.model->start_recording(path.c_str(), options);
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.recordings = true;
    snapshot_.record = FromIdl(got.in());
  });
}
void ModelLink::StopRecording() {
  Queue("stop recording", [this](Impl& i) {
    M::RecordStatus_var got = i.model->stop_recording();
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.record = FromIdl(got.in());
  });
}
void ModelLink::OpenReplay(const std::string& path) {
  const int long_ms = options_.long_call_timeout_ms;
  Queue("open recording " + path, [this, path, long_ms](Impl& i) {
    // the Model loads the recording's scene and its first keyframe: as long as a load
    omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(long_ms));
    M::ReplayStatus_var got = i.model->open_replay(path.c_str());
    i.channels_listed = false;  // the recording's scene may differ from the one loaded
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.replay = FromIdl(got.in());
  });
}
void ModelLink::Seek(double time_s) {
  const int long_ms = options_.long_call_timeout_ms;
  Queue("seek", [this, time_s, long_ms](Impl& i) {
    // a seek re-simulates from the keyframe before it: longer than a short call on a big scene
    omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(long_ms));
    M::ReplayStatus_var got = i.model->seek(time_s);
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.replay = FromIdl(got.in());
  });
}
void ModelLink::Fork() {
  Queue("fork", [this](Impl& i) {
    i.model->fork();
    M::ReplayStatus_var got = i.model->replay_status();
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.replay = FromIdl(got.in());
  });
}

const BodyInfo* SceneInfo::FindBody(const std::string& n) const {
  for (const auto& b : bodies)
    if (b.name == n) return &b;
  return nullptr;
}
const ObstacleInfo* SceneInfo::FindObstacle(const std::string& n) const {
  for (const auto& o : obstacles)
    if (o.name == n) return &o;
  return nullptr;
}
const TendonInfo* SceneInfo::FindTendon(const std::string& n) const {
  for (const auto& t : tendons)
    if (t.name == n) return &t;
  return nullptr;
}

namespace {

EditInfo FromIdl(const M::EditStatus& s) {
  return EditInfo{s.revision, s.last.in(), s.undo.in(), s.redo.in()};
}

S::PathPoint ToIdl(const PathPointInfo& p) {
  S::PathPoint out;
  out.body = p.body.c_str();
  out.x = p.x_m;
  out.y = p.y_m;
  out.z = p.z_m;
  out.obstacle = p.obstacle.c_str();
  return out;
}

std::string KindName(S::ShapeKind kind) {
  switch (kind) {
    case S::BOX:
      return "box";
    case S::SPHERE:
      return "sphere";
    case S::CAPSULE:
      return "capsule";
    case S::CYLINDER:
      return "cylinder";
    case S::CONE:
      return "cone";
    case S::PLANE:
      return "plane";
    case S::CONVEX_HULL:
      return "convex_hull";
    case S::TRIANGLE_MESH:
      return "triangle_mesh";
  }
  return "?";
}

}  // namespace

void ModelLink::QueueEdit(std::string what, std::function<EditInfo(Impl&)> call) {
  const int long_ms = options_.long_call_timeout_ms;
  Queue(what, [this, call, long_ms](Impl& i) {
    // an edit rebuilds the engine: on a big scene that takes longer than a short call, and a
    // timeout would report failed an edit the Model applied
    omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(long_ms));
    // the next poll sees the revision move and reads the edited scene and its parameters
    const EditInfo info = call(i);
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.editing = true;
    snapshot_.edit = info;
  });
}

void ModelLink::Undo() {
  QueueEdit("undo", [](Impl& i) { return FromIdl(M::EditStatus_var(i.model->undo()).in()); });
}
void ModelLink::Redo() {
  QueueEdit("redo", [](Impl& i) { return FromIdl(M::EditStatus_var(i.model->redo()).in()); });
}
void ModelLink::Select(const std::string& kind, const std::string& name, unsigned index) {
  Queue("select " + (kind.empty() ? std::string("nothing") : kind + " " + name),
        [kind, name, index](Impl& i) { i.model->select(kind.c_str(), name.c_str(), index); });
}
void ModelLink::SetMass(const std::string& body, double mass_kg) {
  QueueEdit("set the mass of " + body, [body, mass_kg](Impl& i) {
    return FromIdl(M::EditStatus_var(i.model->set_mass(body.c_str(), mass_kg)).in());
  });
}
void ModelLink::SetMeasurementDelay(const std::string& id, double delay_s) {
  QueueEdit("delay " + id, [id, delay_s](Impl& i) {
    return FromIdl(M::EditStatus_var(i.model->set_measurement_delay(id.c_str(), delay_s)).in());
  });
}
void ModelLink::SetShapeDims(const std::string& body, unsigned index, std::vector<double> dims_m) {
  QueueEdit("set shape " + std::to_string(index) + " of " + body, [body, index, dims_m](Impl& i) {
    S::DoubleSeq dims;
    dims.length(static_cast<CORBA::ULong>(dims_m.size()));
    for (CORBA::ULong k = 0; k < dims.length(); ++k) dims[k] = dims_m[k];
    return FromIdl(M::EditStatus_var(i.model->set_shape_dims(body.c_str(), index, dims)).in());
  });
}
void ModelLink::SetObstacle(const ObstacleInfo& o) {
  QueueEdit("set obstacle " + o.name, [o](Impl& i) {
    S::Obstacle out;
    out.name = o.name.c_str();
    out.body = o.body.c_str();
    out.kind = o.kind.c_str();
    out.pose.px = o.position_m[0];
    out.pose.py = o.position_m[1];
    out.pose.pz = o.position_m[2];
    out.pose.qw = o.orientation[0];
    out.pose.qx = o.orientation[1];
    out.pose.qy = o.orientation[2];
    out.pose.qz = o.orientation[3];
    out.radius = o.radius_m;
    out.length = o.length_m;
    return FromIdl(M::EditStatus_var(i.model->set_obstacle(out)).in());
  });
}
void ModelLink::RemoveObstacle(const std::string& obstacle) {
  QueueEdit("remove obstacle " + obstacle, [obstacle](Impl& i) {
    return FromIdl(M::EditStatus_var(i.model->remove_obstacle(obstacle.c_str())).in());
  });
}
void ModelLink::MovePathPoint(const std::string& tendon, unsigned index,
                              const PathPointInfo& point) {
  QueueEdit(
      "move point " + std::to_string(index) + " of " + tendon, [tendon, index, point](Impl& i) {
        return FromIdl(
            M::EditStatus_var(i.model->move_path_point(tendon.c_str(), index, ToIdl(point))).in());
      });
}
void ModelLink::RemovePathPoint(const std::string& tendon, unsigned index) {
  QueueEdit("remove point " + std::to_string(index) + " of " + tendon, [tendon, index](Impl& i) {
    return FromIdl(M::EditStatus_var(i.model->remove_path_point(tendon.c_str(), index)).in());
  });
}
void ModelLink::RemoveTendon(const std::string& tendon) {
  QueueEdit("remove tendon " + tendon, [tendon](Impl& i) {
    return FromIdl(M::EditStatus_var(i.model->remove_tendon(tendon.c_str())).in());
  });
}
void ModelLink::AddTendon(const std::string& tendon, const PathPointInfo& from,
                          const PathPointInfo& to, double radius_m, const std::string& actuator,
                          const std::string& kind) {
  QueueEdit("add tendon " + tendon, [=](Impl& i) {
    return FromIdl(M::EditStatus_var(i.model->add_tendon(tendon.c_str(), ToIdl(from), ToIdl(to),
                                                         radius_m, actuator.c_str(), kind.c_str()))
                       .in());
  });
}

void ModelLink::ReadScene() {
  Impl& i = *impl_;
  SceneInfo scene;
  S::Description_var d = i.model->scene_description();
  scene.name = d->name.in();
  scene.daq_name = core::IdSafe(scene.name);
  for (CORBA::ULong k = 0; k < d->bodies.length(); ++k) {
    BodyInfo body;
    body.name = d->bodies[k].name.in();
    body.moving = d->bodies[k].moving;
    S::VisualSeq_var shapes = i.model->body_shapes(body.name.c_str());
    for (CORBA::ULong j = 0; j < shapes->length(); ++j) {
      const S::Visual& v = shapes[j];
      ShapeInfo shape{v.name.in(), KindName(v.geometry.kind), {}};
      for (CORBA::ULong n = 0; n < v.geometry.dims.length(); ++n)
        shape.dims.push_back(v.geometry.dims[n]);
      body.shapes.push_back(std::move(shape));
    }
    scene.bodies.push_back(std::move(body));
  }
  for (CORBA::ULong k = 0; k < d->obstacles.length(); ++k) {
    const S::Obstacle& o = d->obstacles[k];
    ObstacleInfo info;
    info.name = o.name.in();
    info.body = o.body.in();
    info.kind = o.kind.in();
    info.position_m[0] = o.pose.px;
    info.position_m[1] = o.pose.py;
    info.position_m[2] = o.pose.pz;
    info.orientation[0] = o.pose.qw;
    info.orientation[1] = o.pose.qx;
    info.orientation[2] = o.pose.qy;
    info.orientation[3] = o.pose.qz;
    info.radius_m = o.radius;
    info.length_m = o.length;
    scene.obstacles.push_back(std::move(info));
  }
  for (CORBA::ULong k = 0; k < d->tendons.length(); ++k) {
    const S::Tendon& t = d->tendons[k];
    TendonInfo info{t.name.in(), t.radius, {}};
    for (CORBA::ULong j = 0; j < t.path.length(); ++j) {
      const S::PathPoint& p = t.path[j];
      info.path.push_back(PathPointInfo{p.body.in(), p.x, p.y, p.z, p.obstacle.in()});
    }
    scene.tendons.push_back(std::move(info));
  }
  for (CORBA::ULong k = 0; k < d->constraints.length(); ++k)
    scene.constraints.push_back(d->constraints[k].name.in());
  for (CORBA::ULong k = 0; k < d->sensor_delays.length(); ++k)
    scene.sensor_delays_s[d->sensor_delays[k].id.in()] = d->sensor_delays[k].delay;
  M::ActuatorInfoSeq_var actuators = i.model->actuators();
  for (CORBA::ULong k = 0; k < actuators->length(); ++k)
    scene.actuators.push_back(
        ActuatorInfo{actuators[k].name.in(), actuators[k].kind.in(), actuators[k].tendon.in()});

  std::vector<ActuatorKindInfo> kinds;
  M::ActuatorKindSeq_var got = i.model->actuator_kinds();
  for (CORBA::ULong k = 0; k < got->length(); ++k) {
    ActuatorKindInfo info;
    info.kind = got[k].kind.in();
    for (CORBA::ULong j = 0; j < got[k].parameters.length(); ++j) {
      info.parameters.push_back(got[k].parameters[j].in());
      info.defaults.push_back(j < got[k].defaults.length() ? got[k].defaults[j] : 0.0);
      info.units.push_back(j < got[k].units.length() ? got[k].units[j].in() : "");
    }
    kinds.push_back(std::move(info));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  snapshot_.scene = std::move(scene);
  snapshot_.actuator_kinds = std::move(kinds);
  ++snapshot_.scene_version;
}

void ModelLink::ComponentAction(const std::string& instance, const std::string& verb) {
  const std::string ns = options_.nameservice;
  Queue(
      verb + " " + instance,
      [instance, verb, ns](Impl& i) {
        RTC::LightweightRTObject_var comp =
            RTC::LightweightRTObject::_narrow(rtc::FindComponent(i.Root(ns), instance).object);
        if (CORBA::is_nil(comp)) throw std::runtime_error(instance + " is not a component");
        RTC::ReturnCode rc;
        if (verb == "exit") {
          rc = comp->exit();
        } else {
          RTC::ExecutionContextList_var ecs = comp->get_owned_contexts();
          if (ecs->length() == 0) throw std::runtime_error(instance + " owns no execution context");
          RTC::ExecutionContext_ptr ec = ecs[0];
          rc = verb == "activate"     ? ec->activate_component(comp)
               : verb == "deactivate" ? ec->deactivate_component(comp)
               : verb == "reset"      ? ec->reset_component(comp)
                                      : throw std::runtime_error("unknown action " + verb);
        }
        if (rc != RTC::RTC_OK) {
          std::string msg = rtc::Name(rc);
          CORBA::String_var why = comp->get_last_error();
          if (std::string(why.in()).size() > 0) msg += "; reason: " + std::string(why.in());
          throw std::runtime_error(msg);
        }
      },
      false);
}

// Lists the naming service's components with their states; on the worker thread only.
void ModelLink::ListComponents() {
  Impl& i = *impl_;
  std::vector<ComponentInfo> list;
  bool reachable = false;
  try {
    const auto entries = rtc::ListComponents(i.Root(options_.nameservice));
    reachable = true;
    for (const auto& e : entries) {
      ComponentInfo info{e.instance, e.path, "UNREACHABLE"};
      try {
        RTC::LightweightRTObject_var comp = RTC::LightweightRTObject::_narrow(e.object);
        if (!CORBA::is_nil(comp)) {
          RTC::ExecutionContextList_var ecs = comp->get_owned_contexts();
          info.state = ecs->length() == 0 ? "?" : rtc::Name(ecs[0]->get_component_state(comp));
        }
      } catch (const CORBA::Exception&) {
      }
      list.push_back(std::move(info));
    }
  } catch (const CORBA::Exception&) {
    i.root = CosNaming::NamingContext::_nil();
  } catch (const std::exception&) {
    i.root = CosNaming::NamingContext::_nil();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  snapshot_.naming_reachable = reachable;
  snapshot_.components = std::move(list);
  ++snapshot_.components_version;
}

void ModelLink::Watch(std::vector<std::string> ids) {
  std::lock_guard<std::mutex> lock(mutex_);
  watched_ = std::move(ids);
}

namespace {

ModelStatus FromIdl(const M::SimulationStatus& s) {
  ModelStatus status;
  status.state = rtc::Name(s.state);
  status.scene = s.scene.in();
  status.sim_time = s.sim_time;
  status.steps = s.steps;
  status.time_step = s.time_step;
  status.real_time_factor = s.real_time_factor;
  status.achieved_real_time_factor = s.achieved_real_time_factor;
  status.last_error = s.last_error.in();
  return status;
}

}  // namespace

void ModelLink::RunCommand(const Command& command) {
  Impl& i = *impl_;
  const auto short_ms = static_cast<CORBA::ULong>(options_.call_timeout_ms);
  const std::string& what = command.what;
  std::string error;
  if (!command.needs_model) {
    i.relist_components = true;
    try {
      omniORB::setClientThreadCallTimeout(short_ms);
      command.call(i);
    } catch (const CORBA::Exception& e) {
      error = what + ": " + rtc::Describe(e);
    } catch (const std::exception& e) {
      error = what + ": " + e.what();
    }
  } else if (CORBA::is_nil(i.model)) {
    error = what + ": no Model reachable";
  } else {
    try {
      omniORB::setClientThreadCallTimeout(short_ms);
      command.call(i);
    } catch (const D::UnknownId& e) {
      error = what + ": " + e.reason.in();
    } catch (const D::InvalidParameter& e) {
      error = what + ": " + e.reason.in();
    } catch (const M::NotAvailable& e) {
      error = what + ": " + e.reason.in();
    } catch (const D::NotAvailable& e) {
      error = what + ": " + e.reason.in();
    } catch (const M::LoadFailed& e) {
      error = what + ": " + e.reason.in();
    } catch (const M::EditRefused& e) {
      error = what + ": " + e.reason.in();
    } catch (const CORBA::SystemException& e) {
      error = what + ": " + rtc::Describe(e);
      Lost(rtc::Describe(e));
    } catch (const CORBA::Exception& e) {
      error = what + ": " + rtc::Describe(e);
    } catch (const std::exception& e) {
      // a file that cannot be read or converted here (client::LoadScene)
      error = what + ": " + e.what();
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ++snapshot_.commands_done;
  if (!error.empty()) {
    snapshot_.last_error = error;
    ++snapshot_.error_serial;
  }
}

void ModelLink::ListComponentsIfDue() {
  Impl& i = *impl_;
  omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(options_.call_timeout_ms));
  if (i.relist_components ||
      Clock::now() - i.last_listing >= std::chrono::milliseconds(options_.components_period_ms)) {
    i.relist_components = false;
    i.last_listing = Clock::now();
    ListComponents();
  }
}

void ModelLink::Lost(const std::string& why) {
  Impl& i = *impl_;
  i.model = M::Model::_nil();
  i.channels_listed = false;
  i.scene_read = false;
  i.files_read = false;
  std::lock_guard<std::mutex> lock(mutex_);
  snapshot_.connected = false;
  snapshot_.connection_message = "no Model reachable: " + why;
}

bool ModelLink::LookUp() {
  // not more often than the reconnect period
  Impl& i = *impl_;
  if (Clock::now() - i.last_lookup < std::chrono::milliseconds(options_.reconnect_period_ms))
    return false;
  i.last_lookup = Clock::now();
  std::string why;
  M::Model_var model =
      client::TryLookUpModel(i.orb, options_.nameservice, options_.instance, 0, &why);
  if (CORBA::is_nil(model)) {
    Lost(why);
    return false;
  }
  i.model = model;
  return true;
}

void ModelLink::Poll() {
  if (CORBA::is_nil(impl_->model) && !LookUp()) return;
  std::vector<std::string> watched;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    watched = watched_;
  }
  try {
    PollModel(watched);
  } catch (const CORBA::SystemException& e) {
    Lost(rtc::Describe(e));
  } catch (const CORBA::Exception& e) {
    Lost(rtc::Describe(e));
  }
}

bool ModelLink::ListChannels(const std::string& scene, std::vector<Channel>* channels) {
  Impl& i = *impl_;
  if (i.channels_listed && scene == i.scene) return false;
  D::ChannelInfoSeq_var infos = i.model->list("*");
  for (CORBA::ULong k = 0; k < infos->length(); ++k) {
    const D::ChannelInfo& c = infos[k];
    channels->push_back(Channel{c.id.in(), c.unit.in(), c.rows, c.cols, bool(c.writable),
                                bool(c.is_static), c.description.in()});
  }
  i.channels_listed = true;
  i.scene = scene;
  return true;
}

std::map<std::string, double> ModelLink::ReadValues(const std::vector<std::string>& watched) {
  Impl& i = *impl_;
  std::map<std::string, double> values;
  S::StringSeq ids;
  ids.length(static_cast<CORBA::ULong>(watched.size()));
  for (CORBA::ULong k = 0; k < ids.length(); ++k) ids[k] = watched[k].c_str();
  try {
    D::ValueSeq_var got = i.model->get(ids);
    for (CORBA::ULong k = 0; k < got->length() && k < ids.length(); ++k)
      if (got[k].data.length() == 1) values[watched[k]] = got[k].data[0];
  } catch (const D::UnknownId&) {
    i.channels_listed = false;  // the scene changed under us: list again
  }
  return values;
}

bool ModelLink::ReadEditing(const ModelStatus& status, EditInfo* edit_info,
                            SelectionInfo* selection_info) {
  // the edit history and the selection, shared with the renderer and other clients; the
  // scene is read again after each edit (from any client) and with each new scene
  Impl& i = *impl_;
  M::EditStatus_var edit;
  M::Selection_var selection;
  try {
    edit = i.model->edit_status();
    selection = i.model->current_selection();
  } catch (const CORBA::BAD_OPERATION&) {
    // a Model built before scene editing: everything else still works
    i.scene_read = false;
    return false;
  }
  if (status.state == "EMPTY") {
    i.scene_read = false;
  } else if (!i.scene_read || edit->revision != i.edit_revision || status.scene != i.edit_scene) {
    // an edit may add or remove parameters (a tendon's actuator): list them again
    if (i.scene_read && edit->revision != i.edit_revision) i.channels_listed = false;
    try {
      // a scene with large meshes takes longer than a short call to describe
      omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(options_.long_call_timeout_ms));
      ReadScene();
      i.scene_read = true;
      i.edit_scene = status.scene;
      i.edit_revision = edit->revision;
    } catch (const M::NotAvailable&) {
      // no scene (a load in progress): read it at the next poll
    } catch (const M::EditRefused&) {
      // a body went away between the description and its shapes: read it again
    }
    omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(options_.call_timeout_ms));
  }
  *edit_info = FromIdl(edit.in());
  *selection_info = SelectionInfo{selection->kind.in(), selection->name.in(), selection->index,
                                  selection->revision};
  return true;
}

void ModelLink::PollModel(const std::vector<std::string>& watched) {
  Impl& i = *impl_;
  M::SimulationStatus_var s = i.model->status();
  const ModelStatus status = FromIdl(s.in());
  std::vector<Channel> channels;
  const bool relist = ListChannels(status.scene, &channels);
  std::map<std::string, double> values;
  if (!watched.empty() && !relist) values = ReadValues(watched);
  EditInfo edit;
  SelectionInfo selection;
  const bool editing = ReadEditing(status, &edit, &selection);

  // the recording and the replay (a Model built before recordings has neither)
  bool recordings = false;
  RecordInfo record;
  ReplayInfo replay;
  try {
    record = FromIdl(M::RecordStatus_var(i.model->recording_status()).in());
    replay = FromIdl(M::ReplayStatus_var(i.model->replay_status()).in());
    recordings = true;
  } catch (const CORBA::BAD_OPERATION&) {
  }
  std::string write_dir;
  if (!i.files_read) {
    write_dir = M::FileAccess_var(i.model->file_access())->write_dir.in();
  }

  std::lock_guard<std::mutex> lock(mutex_);
  if (!i.files_read) {
    snapshot_.write_dir = write_dir;
    i.files_read = true;
  }
  snapshot_.recordings = recordings;
  snapshot_.record = record;
  snapshot_.replay = replay;
  snapshot_.editing = editing;
  if (editing) {
    snapshot_.edit = edit;
    snapshot_.selection = selection;
  }
  snapshot_.connected = true;
  snapshot_.connection_message.clear();
  snapshot_.status = status;
  if (relist) {
    snapshot_.channels = std::move(channels);
    ++snapshot_.channels_version;
    snapshot_.values.clear();
  }
  for (auto& [id, v] : values) snapshot_.values[id] = v;
}

}  // namespace caliper::main_window
