#include "model_servant.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <variant>

#include "caliper/actuators/actuator.h"
#include "caliper/collada/importer.h"
#include "caliper/logging/log.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"
#include "caliper/rtc/peers.h"
#include "caliper/rtc/reason.h"

namespace caliper::model {

namespace S = ::Caliper::Scene;
namespace D = ::Caliper::Daq;
namespace M = ::Caliper::Simulation;

namespace {

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

using rtc::ClientOf;
using rtc::PeerGone;

// raises `Refused` unless `ref` answers within the push deadline and is a `repository_id`
template <class Refused>
void RequireReachable(CORBA::Object_ptr ref, const char* what, const char* repository_id,
                      std::chrono::milliseconds timeout) {
  const std::string why = rtc::Unreachable(ref, what, repository_id, timeout);
  if (!why.empty()) throw Refused(why.c_str());
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
  return d;
}

// ------------------------------------------------------------------------ sender pool

using Clock = std::chrono::steady_clock;

// how often a subscription without batches is looked at again
constexpr std::chrono::milliseconds kPollInterval{20};

PushPool::PushPool(const PushLimits& limits) : limits_(limits) {
  for (size_t i = 0; i < std::max<size_t>(1, limits_.threads); ++i)
    threads_.emplace_back([this] { Work(); });
}

PushPool::~PushPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& t : threads_) t.join();
  for (auto& [key, entry] : entries_) entry->target->Detach();
}

uint64_t PushPool::Find(Kind kind, CORBA::Object_ptr ref) {
  std::lock_guard<std::mutex> lock(mutex_);
  return FindLocked(kind, ref);
}

uint64_t PushPool::FindLocked(Kind kind, CORBA::Object_ptr ref) {
  for (auto& [key, entry] : entries_)
    if (key.first == kind && entry->ref->_is_equivalent(ref)) {
      entry->retry_at = Clock::time_point{};
      wake_.notify_one();
      return key.second;
    }
  return 0;
}

size_t PushPool::CountLocked(Kind kind, const std::string* client) const {
  size_t n = 0;
  for (const auto& [key, entry] : entries_)
    if (key.first == kind && (client == nullptr || entry->client == *client)) ++n;
  return n;
}

void PushPool::CheckRoom(Kind kind, const std::string& client) {
  std::lock_guard<std::mutex> lock(mutex_);
  CheckRoomLocked(kind, client);
}

void PushPool::CheckRoomLocked(Kind kind, const std::string& client) const {
  const bool observers = kind == Kind::kObserver;
  const char* what = observers ? "observers" : "subscriptions";
  const size_t per_client =
      observers ? limits_.observers_per_client : limits_.subscriptions_per_client;
  const size_t total = observers ? limits_.observers : limits_.subscriptions;
  if (CountLocked(kind, &client) >= per_client)
    throw D::LimitExceeded((std::string("client ") + client + " has " +
                            std::to_string(per_client) + " " + what +
                            ", the most one client may have")
                               .c_str(),
                           per_client);
  if (CountLocked(kind, nullptr) >= total)
    throw D::LimitExceeded((std::string("the Model serves ") + std::to_string(total) + " " + what +
                            ", the most it takes")
                               .c_str(),
                           total);
}

uint64_t PushPool::Add(Kind kind, uint64_t id, const std::string& client, CORBA::Object_ptr ref,
                       std::shared_ptr<PushTarget> target) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (kind == Kind::kObserver) {
    // registered meanwhile by a call of its own
    const uint64_t existing = FindLocked(kind, ref);
    if (existing != 0) return existing;
  }
  CheckRoomLocked(kind, client);
  auto entry = std::make_shared<Entry>();
  entry->target = std::move(target);
  entry->client = client;
  entry->ref = CORBA::Object::_duplicate(ref);
  entries_[{kind, id}] = std::move(entry);
  wake_.notify_one();
  return id;
}

bool PushPool::Remove(Kind kind, uint64_t id) {
  std::shared_ptr<Entry> entry;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = entries_.find({kind, id});
    if (it == entries_.end()) return false;
    entry = it->second;
    entry->removed = true;
    entries_.erase(it);
  }
  entry->target->Detach();
  return true;
}

void PushPool::Due(Kind kind, uint64_t id) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = entries_.find({kind, id});
    if (it == entries_.end()) return;
    it->second->retry_at = Clock::time_point{};
  }
  wake_.notify_one();
}

void PushPool::Wake() {
  { std::lock_guard<std::mutex> lock(mutex_); }
  wake_.notify_one();
}

std::shared_ptr<PushPool::Entry> PushPool::PickLocked(Clock::time_point now,
                                                      Clock::time_point* wake_at) {
  *wake_at = now + std::chrono::hours(1);
  if (entries_.empty()) return nullptr;
  // in turn, starting after the one served last
  auto it = entries_.upper_bound(cursor_);
  for (size_t n = 0; n < entries_.size(); ++n, ++it) {
    if (it == entries_.end()) it = entries_.begin();
    Entry& e = *it->second;
    if (e.busy || in_flight_.count(e.client) > 0) continue;
    if (e.retry_at > now) {
      *wake_at = std::min(*wake_at, e.retry_at);
      continue;
    }
    if (!e.target->HasWork()) continue;
    cursor_ = it->first;
    return it->second;
  }
  return nullptr;
}

void PushPool::Work() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    Clock::time_point wake_at;
    const std::shared_ptr<Entry> entry = PickLocked(Clock::now(), &wake_at);
    if (!entry) {
      wake_.wait_until(lock, wake_at);
      continue;
    }
    const Key key = cursor_;
    entry->busy = true;
    ++in_flight_[entry->client];
    lock.unlock();
    std::string why;
    PushTarget::Outcome outcome;
    try {
      outcome = entry->target->Push(&why);
    } catch (const std::exception& e) {
      outcome = PushTarget::Outcome::kFailed;
      why = e.what();
    } catch (...) {
      outcome = PushTarget::Outcome::kFailed;
      why = "an exception of unknown type";
    }
    lock.lock();
    entry->busy = false;
    if (--in_flight_[entry->client] == 0) in_flight_.erase(entry->client);
    const std::shared_ptr<PushTarget> dropped = AccountLocked(key, *entry, outcome, why);
    if (dropped) {
      lock.unlock();
      dropped->Detach();
      lock.lock();
    }
  }
}

std::shared_ptr<PushTarget> PushPool::AccountLocked(const Key& key, Entry& entry,
                                                    PushTarget::Outcome outcome,
                                                    const std::string& why) {
  using Outcome = PushTarget::Outcome;
  const bool observer = key.first == Kind::kObserver;
  auto& log = logging::Get(observer ? "observers" : "daq");
  const auto id = static_cast<unsigned long long>(key.second);
  const auto now = Clock::now();
  if (outcome == Outcome::kNothing) {
    // subscriptions are polled (their batches come from the recorder, which tells no one)
    if (!observer) entry.retry_at = now + kPollInterval;
    return nullptr;
  }
  if (outcome == Outcome::kSent) {
    if (entry.failures > 0)
      log.info("%s %llu (client %s) answers again after %llu failed pushes",
               observer ? "observer" : "subscription", id, entry.client.c_str(),
               static_cast<unsigned long long>(entry.failures));
    entry.failures = 0;
    entry.failing_since.reset();
    return nullptr;
  }
  const bool gone = outcome == Outcome::kGone;
  if (!gone) {
    if (!entry.failing_since) entry.failing_since = now;
    if (entry.failures++ == 0)
      log.warn("%s %llu (client %s) is slow or unreachable: %s; retrying every %lld ms with the "
               "latest state",
               observer ? "observer" : "subscription", id, entry.client.c_str(), why.c_str(),
               static_cast<long long>(limits_.retry_after.count()));
    entry.retry_at = now + limits_.retry_after;
    if (now - *entry.failing_since < limits_.drop_after) return nullptr;
  }
  if (entry.removed) return nullptr;  // removed by its client meanwhile
  const std::string reason =
      gone ? why
           : "no push succeeded for " +
                 std::to_string(std::chrono::duration_cast<std::chrono::seconds>(
                                    now - *entry.failing_since)
                                    .count()) +
                 " s (last: " + why + ")";
  if (observer)
    log.info("dropping an observer (%llu, client %s): %s", id, entry.client.c_str(),
             reason.c_str());
  else
    log.info("dropping subscription %llu (client %s): %s", id, entry.client.c_str(),
             reason.c_str());
  entry.removed = true;
  std::shared_ptr<PushTarget> target = entry.target;
  entries_.erase(key);
  return target;
}

// ------------------------------------------------------------------------ observers

ObserverTarget::ObserverTarget(ModelCore& core, PushPool& pool, S::SceneObserver_ptr observer)
    : core_(core), pool_(pool), observer_(S::SceneObserver::_duplicate(observer)) {
  omniORB::setClientCallTimeout(observer_.in(),
                                static_cast<CORBA::ULong>(pool.limits().call_timeout.count()));
}

void ObserverTarget::MarkPending() {
  if (!pending_.exchange(true)) pool_.Wake();
}

void ObserverTarget::OnScene(std::shared_ptr<const sgal::Scene> scene, uint64_t generation) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    scene_ = std::move(scene);
    scene_generation_ = generation;
    snapshot_.reset();
  }
  MarkPending();
}

void ObserverTarget::OnSnapshot(std::shared_ptr<const Snapshot> snapshot) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_ = std::move(snapshot);
  }
  MarkPending();
}

void ObserverTarget::OnCleared() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cleared_ = true;
    scene_.reset();
    snapshot_.reset();
  }
  MarkPending();
}

PushTarget::Outcome ObserverTarget::Push(std::string* why) {
  pending_ = false;  // what arrives from now on marks it again
  bool cleared;
  std::shared_ptr<const sgal::Scene> scene;
  uint64_t scene_generation;
  std::shared_ptr<const Snapshot> snapshot;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cleared = cleared_;
    cleared_ = false;
    scene = std::move(scene_);
    scene_.reset();
    scene_generation = scene_generation_;
    snapshot = std::move(snapshot_);
    snapshot_.reset();
  }
  if (!cleared && !scene && !snapshot) return Outcome::kNothing;
  enum { kClearing, kDescribing, kMoving } stage = kClearing;
  try {
    if (cleared) observer_->on_scene_cleared();
    stage = kDescribing;
    if (scene) {
      std::unique_ptr<S::Description> description(ToIdl(*scene));
      observer_->on_scene(*description);
      generation_ = scene_generation;
      filter_ = sgal::ChangeFilter();
    }
    stage = kMoving;
    if (snapshot && snapshot->generation == generation_) {
      const std::vector<int> changed = filter_.Changed(snapshot->bodies);
      S::BodyTransformSeq transforms;
      transforms.length(static_cast<CORBA::ULong>(changed.size()));
      for (CORBA::ULong i = 0; i < changed.size(); ++i) {
        transforms[i].body_index = static_cast<CORBA::ULong>(changed[i]);
        transforms[i].pose = ToFrame(snapshot->bodies[changed[i]].pose);
      }
      observer_->on_transforms(++update_, snapshot->time, transforms, ToIdl(snapshot->tendons));
    }
    return Outcome::kSent;
  } catch (const CORBA::Exception& e) {
    *why = rtc::Describe(e);
    if (PeerGone(e)) return Outcome::kGone;
    // the backlog goes, the observer stays: what did not arrive is sent again unless something
    // newer replaced it, and the next transforms carry every body
    filter_ = sgal::ChangeFilter();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const bool newer = cleared_ || scene_;
      if (stage == kClearing) cleared_ = true;
      if (!newer && stage <= kDescribing && scene) {
        scene_ = std::move(scene);
        scene_generation_ = scene_generation;
      }
      if (!newer && !snapshot_) snapshot_ = std::move(snapshot);
    }
    pending_ = true;
    return Outcome::kFailed;
  }
}

// ------------------------------------------------------------------------ subscriptions

SubscriptionTarget::SubscriptionTarget(ModelCore& core, uint64_t subscription,
                                       D::DataConsumer_ptr consumer, bool lossless)
    : core_(core),
      subscription_(subscription),
      consumer_(D::DataConsumer::_duplicate(consumer)),
      lossless_(lossless) {}

PushTarget::Outcome SubscriptionTarget::Push(std::string* why) {
  bool gone = false;
  uint64_t queue_dropped = 0;
  const auto batches = core_.TakeBatches(subscription_, &gone, &queue_dropped);
  if (gone) {
    *why = "the Model ended the subscription (the reason is logged above)";
    return Outcome::kGone;
  }
  // a real-time run does not wait for a slow consumer: say what it lost, every 10 s at most
  const auto now = std::chrono::steady_clock::now();
  if (queue_dropped > queue_dropped_ && now - queue_logged_ >= std::chrono::seconds(10)) {
    logging::Get("daq").warn(
        "%ssubscription %llu: %llu samples dropped so far (its queue was full: the consumer is "
        "slower than the simulation runs%s)",
        lossless_ ? "lossless " : "", static_cast<unsigned long long>(subscription_),
        static_cast<unsigned long long>(queue_dropped),
        lossless_ ? "; the Model waits for it only in lock-step or as fast as possible" : "");
    queue_dropped_ = queue_dropped;
    queue_logged_ = now;
  }
  if (batches.empty()) return Outcome::kNothing;
  for (size_t k = 0; k < batches.size(); ++k) {
    const daq::Batch& b = batches[k];
    D::SampleBatch out;
    out.subscription = subscription_;
    out.batch = b.sequence;
    out.first_step = b.first_step;
    out.layout = b.layout;
    out.times.length(static_cast<CORBA::ULong>(b.times.size()));
    for (CORBA::ULong i = 0; i < b.times.size(); ++i) out.times[i] = b.times[i];
    out.values_per_sample = static_cast<CORBA::ULong>(b.values_per_sample);
    out.data.length(static_cast<CORBA::ULong>(b.data.size()));
    for (CORBA::ULong i = 0; i < b.data.size(); ++i) out.data[i] = b.data[i];
    const std::vector<std::string> stale = b.StaleIds();
    out.stale_ids.length(static_cast<CORBA::ULong>(stale.size()));
    for (CORBA::ULong i = 0; i < stale.size(); ++i) out.stale_ids[i] = stale[i].c_str();
    try {
      consumer_->on_samples(out);
    } catch (const CORBA::Exception& e) {
      // this batch and the rest of the backlog go; the consumer sees the gap in `batch`
      uint64_t samples = 0;
      for (size_t j = k; j < batches.size(); ++j) samples += batches[j].step_count;
      dropped_ += batches.size() - k;
      core_.NoteUndelivered(subscription_, batches.size() - k, samples);
      *why = rtc::Describe(e) + " (" + std::to_string(dropped_) + " batches dropped so far)";
      if (lossless_)
        *why = "a push failed: " + *why + "; a lossless subscription ends at its first failed push";
      last_failure_ = *why;
      return PeerGone(e) || lossless_ ? Outcome::kGone : Outcome::kFailed;
    }
  }
  last_failure_.clear();
  return Outcome::kSent;
}

// ------------------------------------------------------------------------ servant

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
  const std::string bytes(reinterpret_cast<const char*>(in.scene_data.get_buffer()), in.scene_data.length());
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
  return Guard([&] {
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
  });
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
    const auto values = core_.Sample(FromIdl(ids));
    auto* out = new D::ValueSeq;
    out->length(static_cast<CORBA::ULong>(values.size()));
    for (CORBA::ULong i = 0; i < values.size(); ++i) (*out)[i] = ToIdl(values[i]);
    return out;
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

namespace {

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

}  // namespace

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
    const std::vector<std::string> kinds = actuators::Kinds();
    if (std::find(kinds.begin(), kinds.end(), std::string(kind)) == kinds.end()) {
      std::string known;
      for (const auto& k : kinds) known += (known.empty() ? "" : ", ") + k;
      throw sgal::EditError("add_tendon: no actuator kind '" + std::string(kind) + "' (" + known +
                            ")");
    }
    sgal::Actuator a;
    a.name = actuator;
    a.kind = kind;
    // a parameter without a default (a ligament's stiffness, a muscle's force) is taken from
    // the scene's first actuator of the kind that has it; tune it afterwards as any parameter
    const auto scene = core_.description();
    std::string missing;
    for (const auto& p : actuators::KindParameters(kind)) {
      if (!p.required) {
        a.parameters[p.name] = p.default_value;
        continue;
      }
      bool found = false;
      for (const auto& other : scene ? scene->actuators : std::vector<sgal::Actuator>{})
        if (other.kind == kind && other.parameters.count(p.name) != 0 && !found) {
          a.parameters[p.name] = other.parameters.at(p.name);
          found = true;
        }
      if (!found) missing += (missing.empty() ? "" : ", ") + p.name;
    }
    if (!missing.empty())
      throw sgal::EditError("add_tendon: a " + std::string(kind) + " needs " + missing +
                            ", which have no default and no " + kind +
                            " in the scene to copy from: declare it in the model file");
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

namespace {

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

}  // namespace

M::RecordStatus* ModelServant::start_recording(const char* path, const M::RecordOptions& options) {
  return Guard([&] {
    // only into the write directory: a client must not make the Model write any file
    std::string where;
    try {
      where = files_.write.Resolve(path, core::ConfinedPaths::Access::kWrite).string();
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
