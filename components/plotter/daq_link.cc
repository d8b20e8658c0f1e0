#include "daq_link.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

#include "caliper/client/model.h"
#include "caliper/model.hh"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/idl_names.h"
#include "caliper/rtc/naming.h"
#include "data_consumer_servant.h"
#include "stream_watch.h"

namespace caliper::plotter {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr size_t kPendingBatches = 256;  // held while a subscribe call is under way
constexpr size_t kHeldBatches = 256;     // held after a reset or reload until the layout is checked
// times and values kept in the inbox, and in `held`, beyond which the oldest batches are dropped
// (the newest is always kept): a batch may carry a million samples, and 4096 of those waiting for
// a busy GUI would take 64 GB (hostile_corba_test sends such batches)
constexpr size_t kMaxQueuedValues = size_t{8} << 20;

size_t ValuesOf(const ReceivedBatch& b) { return b.times.size() + b.data.size(); }

// thrown between two calls of a poll when the link closes: the poll ends without further calls
struct Closing {};

bool Contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

bool SameChannels(const std::vector<ChannelEntry>& a, const std::vector<ChannelEntry>& b) {
  return std::equal(
      a.begin(), a.end(), b.begin(), b.end(), [](const ChannelEntry& x, const ChannelEntry& y) {
        return x.id == y.id && x.unit == y.unit && x.rows == y.rows && x.cols == y.cols &&
               x.is_static == y.is_static && x.description == y.description;
      });
}

bool Subset(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  return std::all_of(a.begin(), a.end(), [&](const std::string& s) { return Contains(b, s); });
}

}  // namespace

// What the servant's ORB threads and the worker share.
struct DaqLink::Shared {
  std::mutex mutex;      // guards everything below
  uint64_t current = 0;  // the subscription whose batches are kept
  std::shared_ptr<const std::vector<SubscribedId>> layout;
  bool subscribing = false;  // a subscribe call is under way: its first batches may come early
  std::map<uint64_t, std::deque<ReceivedBatch>> pending;
  size_t pending_count = 0;
  std::set<uint64_t> foreign;  // subscriptions not (or no longer) ours that still send
  // the simulated time went back (a reset or a reload, which may have given the ids other shapes):
  // the current subscription's batches wait in `held` until the worker has checked the layout
  bool checking = false;
  std::deque<ReceivedBatch> held;
  std::deque<ReceivedBatch> inbox;
  size_t held_values = 0;   // ValuesOf the batches in `held`
  size_t inbox_values = 0;  // ValuesOf the batches in `inbox`
  size_t inbox_capacity = 4096;
  BatchSequence sequence;  // the current subscription's batch numbers
  uint64_t received = 0;
  uint64_t dropped = 0;
  uint64_t discarded = 0;          // held batches of a layout that had changed
  double last_sample_time = kNaN;  // [s] of the current subscription
  uint64_t model_layout = 0;       // the Model's layout number of its last batch (0: none yet)
  Clock::time_point last_batch_wall{};

  // with the mutex held
  void Deliver(ReceivedBatch&& b) {
    inbox_values += ValuesOf(b);
    inbox.push_back(std::move(b));
    while (inbox.size() > inbox_capacity || (inbox_values > kMaxQueuedValues && inbox.size() > 1)) {
      inbox_values -= ValuesOf(inbox.front());
      inbox.pop_front();
      ++dropped;
    }
  }

  // with the mutex held
  void Accept(ReceivedBatch&& b) {
    ++received;
    if (!sequence.Take(b.number)) return;  // older than what was taken in: left out
    b.layout = layout;
    if (!b.times.empty()) {
      if (!std::isnan(last_sample_time) && b.times.front() < last_sample_time) checking = true;
      last_sample_time = b.times.back();
    }
    // the Model moved the values within a sample (a reload changed shapes): check the layout
    if (model_layout != 0 && b.model_layout != model_layout) checking = true;
    model_layout = b.model_layout;
    last_batch_wall = Clock::now();
    if (!checking) {
      Deliver(std::move(b));
      return;
    }
    held_values += ValuesOf(b);
    held.push_back(std::move(b));
    while (held.size() > kHeldBatches || (held_values > kMaxQueuedValues && held.size() > 1)) {
      held_values -= ValuesOf(held.front());
      held.pop_front();
      ++dropped;
    }
  }

  // with the mutex held: the layout still holds, the held batches go to the GUI
  void Release() {
    checking = false;
    for (auto& b : held) Deliver(std::move(b));
    held.clear();
    held_values = 0;
  }

  // the current subscription ends here (its layout too when `layout_too`): returns its id (0:
  // none); what it holds cannot be read
  uint64_t EndCurrent(bool layout_too) {
    std::lock_guard<std::mutex> lock(mutex);
    const uint64_t id = current;
    current = 0;
    if (layout_too) layout.reset();
    Discard();
    return id;
  }

  // with the mutex held: the subscription ends, what it holds cannot be read
  void Discard() {
    checking = false;
    discarded += held.size();
    held.clear();
    held_values = 0;
  }

  // a subscribe call ended: `id` (0: none) becomes the current subscription, laid out as
  // `id_layout`; the batches that came meanwhile are taken in or their subscriptions ended
  void Settle(uint64_t id, const std::shared_ptr<const std::vector<SubscribedId>>& id_layout) {
    std::lock_guard<std::mutex> lock(mutex);
    subscribing = false;
    if (id != 0) {
      current = id;
      layout = id_layout;
      sequence.Restart();
      last_sample_time = kNaN;
      model_layout = 0;  // a new subscription starts at the Model's layout 1
      last_batch_wall = Clock::now();
    }
    for (auto& [sub, batches] : pending) {
      if (sub == id) {
        for (auto& b : batches) Accept(std::move(b));
      } else {
        foreign.insert(sub);
      }
    }
    pending.clear();
    pending_count = 0;
  }

  void Receive(ReceivedBatch&& b) {
    std::lock_guard<std::mutex> lock(mutex);
    if (current != 0 && b.subscription == current) {
      Accept(std::move(b));
    } else if (subscribing && pending_count < kPendingBatches) {
      pending[b.subscription].push_back(std::move(b));
      ++pending_count;
    } else if (b.subscription != current) {
      foreign.insert(b.subscription);
    }
  }
};

// The worker's CORBA state; touched by the worker thread only (and the constructor), but for
// `servant`, whose counter status() reads, and `has_model`.
struct DaqLink::Impl {
  CORBA::ORB_var orb;
  PortableServer::POA_var poa;
  PortableServer::ObjectId_var oid;
  DataConsumerServant* servant = nullptr;  // owned by the POA while activated
  D::DataConsumer_var consumer;
  M::Model_var model;
  Clock::time_point last_lookup{};
  Clock::time_point last_listing{};
  bool channels_listed = false;
  std::string scene;  // the scene the channel list belongs to
  uint64_t steps = 0;
  std::vector<ChannelEntry> channels;
  std::vector<std::string> subscribed;  // ids of the current subscription
  uint32_t subscribed_every = 0;
  std::unique_ptr<StreamWatch> watch;  // of the current subscription
  std::atomic<bool> has_model{false};  // `model` is not nil: a wanted change wakes the worker
  uint64_t seen_version = 0;           // the wanted_version_ of the last poll
  uint64_t layout_resubscriptions = 0;
};

DaqLink::DaqLink(Options options)
    : options_(std::move(options)),
      impl_(std::make_unique<Impl>()),
      shared_(std::make_shared<Shared>()) {
  shared_->inbox_capacity = std::max<size_t>(1, options_.inbox_batches);
  status_.instance = options_.instance;
  status_.message = "no Model: looking for " + options_.instance + " ...";
  Impl& i = *impl_;
  i.watch = std::make_unique<StreamWatch>(options_.silence_s);
  i.orb = rtc::ClientOrb();
  CORBA::Object_var obj = i.orb->resolve_initial_references("RootPOA");
  i.poa = PortableServer::POA::_narrow(obj);
  PortableServer::POAManager_var manager = i.poa->the_POAManager();
  manager->activate();
  std::shared_ptr<Shared> shared = shared_;
  auto* servant =
      new DataConsumerServant([shared](ReceivedBatch&& b) { shared->Receive(std::move(b)); });
  PortableServer::ServantBase_var owner = servant;  // the POA keeps its own reference
  i.oid = i.poa->activate_object(servant);
  i.servant = servant;
  CORBA::Object_var ref = i.poa->id_to_reference(i.oid);
  i.consumer = D::DataConsumer::_narrow(ref);
  // the hooks use `this`: the destructor waits for the worker (its calls are bounded)
  const auto timeout_ms = static_cast<CORBA::ULong>(options_.call_timeout_ms);
  client::Worker::Hooks hooks;
  hooks.start = [timeout_ms] {
    omniORB::setClientConnectTimeout(timeout_ms);
    omniORB::setClientThreadCallTimeout(timeout_ms);
  };
  hooks.tick = [this] { Tick(); };
  hooks.finish = [this] { Close(); };
  worker_ = std::make_unique<client::Worker>(
      client::Worker::Options{std::chrono::milliseconds(options_.poll_period_ms),
                              client::Worker::kForever},
      std::move(hooks));
  worker_->Start();
}

DaqLink::~DaqLink() {
  worker_->Stop(client::Worker::kForever);
  try {
    impl_->poa->deactivate_object(impl_->oid);
  } catch (const CORBA::Exception&) {
    // the ORB is shutting down: nothing to deactivate any more
  }
}

std::string DaqLink::ConsumerReference() const {
  CORBA::String_var ior = impl_->orb->object_to_string(impl_->consumer);
  return ior.in();
}

LinkStatus DaqLink::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  LinkStatus s = status_;
  s.consumer_failures = impl_->servant->failures();
  std::lock_guard<std::mutex> shared_lock(shared_->mutex);
  s.batches_received = shared_->received;
  s.batches_missing = shared_->sequence.missing();
  s.batches_late = shared_->sequence.late();
  s.batches_dropped = shared_->dropped;
  s.batches_discarded = shared_->discarded;
  return s;
}

void DaqLink::Want(std::vector<std::string> ids, uint32_t every_n_steps) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const uint32_t every = std::max<uint32_t>(1, every_n_steps);
    if (ids == wanted_ && every == every_n_steps_) return;
    wanted_ = std::move(ids);
    every_n_steps_ = every;
    ++wanted_version_;
  }
  if (impl_->has_model) worker_->TickIn(std::chrono::milliseconds(0));
}

std::vector<ReceivedBatch> DaqLink::TakeBatches() {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  std::vector<ReceivedBatch> out(std::make_move_iterator(shared_->inbox.begin()),
                                 std::make_move_iterator(shared_->inbox.end()));
  shared_->inbox.clear();
  shared_->inbox_values = 0;
  return out;
}

void DaqLink::Relist() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    relist_ = true;
  }
  worker_->TickIn(std::chrono::milliseconds(0));
}

void DaqLink::Resubscribe(uint64_t subscription, const std::string& why) {
  if (subscription == 0) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (resubscribe_ == subscription) return;
    resubscribe_ = subscription;
    resubscribe_why_ = why;
  }
  if (impl_->has_model) worker_->TickIn(std::chrono::milliseconds(0));
}

// What the GUI asked for since the last poll.
struct DaqLink::Request {
  std::vector<std::string> wanted;
  uint32_t every = 1;
  bool relist = false;
  uint64_t renew = 0;  // a subscription whose batches the GUI cannot read
  std::string renew_why;
};

namespace {

// what the worker reads of the current subscription's stream
struct Stream {
  uint64_t current = 0;
  std::shared_ptr<const std::vector<SubscribedId>> layout;
  bool checking = false;
  double last_sample = kNaN;
  Clock::time_point last_batch_wall;
};

// the wanted ids the Model has (in the order wanted) and those it has not
void SplitWanted(const std::vector<std::string>& wanted, const std::vector<ChannelEntry>& channels,
                 std::vector<std::string>* target, std::vector<std::string>* missing) {
  target->clear();
  missing->clear();
  for (const auto& id : wanted) {
    const bool known = std::any_of(channels.begin(), channels.end(),
                                   [&](const ChannelEntry& c) { return c.id == id; });
    (known ? target : missing)->push_back(id);
  }
}

Stream CurrentStream(DaqLink::Shared& sh) {
  std::lock_guard<std::mutex> lock(sh.mutex);
  return Stream{sh.current, sh.layout, sh.checking, sh.last_sample_time, sh.last_batch_wall};
}

}  // namespace

void DaqLink::Tick() {
  PollOnce();
  // what the GUI asked for meanwhile comes at once
  bool again = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    again = relist_ || ((wanted_version_ != impl_->seen_version || resubscribe_ != 0) &&
                        !CORBA::is_nil(impl_->model));
  }
  if (again) worker_->TickIn(std::chrono::milliseconds(0));
}

DaqLink::Request DaqLink::TakeRequest() {
  std::lock_guard<std::mutex> lock(mutex_);
  Request r;
  r.wanted = wanted_;
  r.every = every_n_steps_;
  impl_->seen_version = wanted_version_;
  r.relist = relist_;
  relist_ = false;
  r.renew = resubscribe_;
  r.renew_why = resubscribe_why_;
  resubscribe_ = 0;
  return r;
}

void DaqLink::CheckClosing() const {
  if (worker_->stopping()) throw Closing{};
}

void DaqLink::SetMessage(const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  status_.message = message;
}

void DaqLink::Lost(const std::string& why) {
  Impl& i = *impl_;
  Shared& sh = *shared_;
  i.model = M::Model::_nil();
  i.has_model = false;
  i.channels_listed = false;
  i.subscribed.clear();
  {
    std::lock_guard<std::mutex> lock(sh.mutex);
    sh.current = 0;
    sh.layout.reset();
    sh.subscribing = false;
    sh.Discard();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  status_.connected = false;
  status_.state.clear();
  status_.subscription = 0;
  status_.subscribed.clear();
  status_.missing.clear();
  status_.message = "no Model reachable: " + why;
}

void DaqLink::PollOnce() {
  const Request request = TakeRequest();
  omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(options_.call_timeout_ms));
  try {
    if (CORBA::is_nil(impl_->model) && !LookUp()) return;
    Poll(request);
  } catch (const Closing&) {
    // the worker ends: no further call
  } catch (const CORBA::Exception& e) {
    Lost(rtc::Describe(e));
  } catch (const std::exception& e) {
    SetMessage(e.what());
  }
}

bool DaqLink::LookUp() {
  // not more often than the reconnect period
  Impl& i = *impl_;
  if (Clock::now() - i.last_lookup < std::chrono::milliseconds(options_.reconnect_period_ms))
    return false;
  i.last_lookup = Clock::now();
  const auto timeout_ms = static_cast<CORBA::ULong>(options_.call_timeout_ms);
  CheckClosing();
  std::string why;
  i.model =
      client::TryLookUpModel(i.orb, options_.nameservice, options_.instance, timeout_ms, &why);
  if (CORBA::is_nil(i.model)) {
    Lost(why);
    return false;
  }
  i.has_model = true;
  i.channels_listed = false;
  i.steps = 0;
  return true;
}

bool DaqLink::ListChannels(const std::string& scene) {
  Impl& i = *impl_;
  CheckClosing();
  D::ChannelInfoSeq_var infos = i.model->channels("*");
  std::vector<ChannelEntry> channels;
  channels.reserve(infos->length());
  for (CORBA::ULong k = 0; k < infos->length(); ++k) {
    const D::ChannelInfo& c = infos[k];
    channels.push_back(ChannelEntry{c.id.in(), c.unit.in(), c.rows, c.cols, bool(c.is_static),
                                    c.description.in()});
  }
  const bool changed = !i.channels_listed || !SameChannels(channels, i.channels);
  i.channels = std::move(channels);
  i.channels_listed = true;
  i.scene = scene;
  i.last_listing = Clock::now();
  return changed;
}

void DaqLink::EndForeignSubscriptions() {
  // subscriptions that are not ours any more but still send: end them
  Shared& sh = *shared_;
  std::set<uint64_t> foreign;
  {
    std::lock_guard<std::mutex> lock(sh.mutex);
    foreign.swap(sh.foreign);
    foreign.erase(sh.current);
  }
  for (const uint64_t f : foreign) {
    CheckClosing();
    impl_->model->unsubscribe(f);
  }
}

void DaqLink::Subscribe(const std::vector<std::string>& ids, uint32_t every, double sim_time) {
  Impl& i = *impl_;
  Shared& sh = *shared_;
  const uint64_t old = sh.EndCurrent(true);
  i.subscribed.clear();
  if (old != 0) {
    CheckClosing();
    try {
      i.model->unsubscribe(old);
    } catch (const CORBA::UserException&) {
      // gone already
    }
  }
  if (ids.empty()) return;
  CheckClosing();

  auto layout = std::make_shared<const std::vector<SubscribedId>>(LayoutOf(ids, i.channels));
  S::StringSeq seq;
  seq.length(static_cast<CORBA::ULong>(ids.size()));
  for (size_t k = 0; k < ids.size(); ++k) seq[static_cast<CORBA::ULong>(k)] = ids[k].c_str();
  {
    std::lock_guard<std::mutex> lock(sh.mutex);
    sh.subscribing = true;
    sh.pending.clear();
    sh.pending_count = 0;
  }
  // whatever happens, the batches held meanwhile are settled
  CORBA::ULongLong id = 0;
  try {
    id = i.model->subscribe(seq, every, i.consumer);
  } catch (const D::UnknownId& e) {
    sh.Settle(0, layout);
    i.channels_listed = false;  // the scene changed under us: list again
    SetMessage("subscribing: " + std::string(e.reason.in()));
    return;
  } catch (const D::InvalidParameter& e) {
    sh.Settle(0, layout);
    SetMessage("subscribing: " + std::string(e.reason.in()));
    return;
  } catch (const D::NotAvailable& e) {
    sh.Settle(0, layout);
    SetMessage("the Model takes no subscription now: " + std::string(e.reason.in()));
    return;
  } catch (...) {
    sh.Settle(0, layout);
    throw;
  }
  sh.Settle(id, layout);
  i.subscribed = ids;
  i.subscribed_every = every;
  i.watch->Start(sim_time, every, Clock::now());
  std::lock_guard<std::mutex> lock(mutex_);
  ++status_.subscriptions_made;
  status_.message.clear();
}

void DaqLink::Poll(const Request& request) {
  Impl& i = *impl_;
  i.watch->PollStarts(Clock::now());
  Shared& sh = *shared_;
  CheckClosing();
  M::SimulationStatus_var s = i.model->status();
  const std::string scene = s->scene.in();
  const bool rewound = s->steps < i.steps;
  i.steps = s->steps;
  EndForeignSubscriptions();
  const Stream stream = CurrentStream(sh);
  const uint64_t current = stream.current;
  const bool renew_asked_now = request.renew != 0 && request.renew == current;

  // a new scene, a reset, a periodic listing, held batches or unreadable ones: list again
  bool listed = false;  // the GUI gets the new list
  bool fresh = false;   // listed in this poll
  const bool due =
      Clock::now() - i.last_listing >= std::chrono::milliseconds(options_.relist_period_ms);
  if (!i.channels_listed || scene != i.scene || rewound || request.relist || due ||
      stream.checking || renew_asked_now) {
    listed = ListChannels(scene);
    fresh = true;
  }

  std::vector<std::string> target, missing;
  SplitWanted(request.wanted, i.channels, &target, &missing);
  // ids that vanished stay subscribed (their values come as NaN, marked stale, and come back
  // when a scene has them again); a new wanted id, a removed one or a new rate subscribe anew
  bool renew = (current == 0 && !target.empty()) || !Subset(target, i.subscribed) ||
               !Subset(i.subscribed, request.wanted) ||
               (current != 0 && request.every != i.subscribed_every);
  std::string why;
  // the scene gave subscribed ids another shape or unit: the values moved within a sample
  if (fresh && current != 0 && stream.layout) {
    const std::string change = LayoutChange(*stream.layout, i.channels);
    if (!change.empty()) {
      renew = true;
      why = "the scene changed (" + change + "): subscribed again";
      ++i.layout_resubscriptions;
    } else if (stream.checking) {
      std::lock_guard<std::mutex> lock(sh.mutex);
      if (sh.current == current) sh.Release();
    }
  }
  if (renew_asked_now && why.empty()) {
    renew = true;
    why = request.renew_why + ": subscribed again";
  }
  // a stream gone quiet while the Model runs (e.g. the Model dropped us): subscribe again
  if (current != 0 &&
      i.watch->Quiet(s->state == M::RUNNING, s->sim_time, s->time_step, stream.last_sample,
                     stream.last_batch_wall, Clock::now()) &&
      !renew) {
    renew = true;
    why = "no samples for " + std::to_string(i.watch->quiet_for()) +
          " s of simulated time: subscribed again";
  }
  if (renew) {
    // the layout comes from a listing of now
    if (!fresh) {
      listed |= ListChannels(scene);
      SplitWanted(request.wanted, i.channels, &target, &missing);
    }
    Subscribe(target, request.every, s->sim_time);
  }

  std::lock_guard<std::mutex> lock(mutex_);
  status_.connected = true;
  if (!why.empty()) status_.message = why;
  if (status_.message.rfind("no Model", 0) == 0) status_.message.clear();
  status_.state = rtc::Name(s->state);
  status_.scene = scene;
  status_.sim_time = s->sim_time;
  status_.time_step = s->time_step;
  if (listed) {
    status_.channels = i.channels;
    ++status_.channels_version;
  }
  status_.subscribed = i.subscribed;
  status_.missing = missing;
  status_.layout_resubscriptions = i.layout_resubscriptions;
  std::lock_guard<std::mutex> shared_lock(sh.mutex);
  status_.subscription = sh.current;
}

void DaqLink::Close() {
  // closing: one short call ends the subscription so that the Model stops sending; none when the
  // Model was found gone (a Model drops a consumer that no longer answers anyway)
  Impl& i = *impl_;
  Shared& sh = *shared_;
  const uint64_t current = sh.EndCurrent(false);
  if (current != 0 && !CORBA::is_nil(i.model)) {
    const auto final_ms = static_cast<CORBA::ULong>(
        std::clamp(options_.final_call_timeout_ms, 1, options_.call_timeout_ms));
    omniORB::setClientThreadCallTimeout(final_ms);
    omniORB::setClientCallTimeout(i.model, final_ms);
    try {
      i.model->unsubscribe(current);
    } catch (const CORBA::Exception&) {
      // the Model is gone or slow: it drops us when its next batch finds no consumer
    }
  }
  i.model = M::Model::_nil();
  i.has_model = false;
}

}  // namespace caliper::plotter
