#pragma once
// The Graph Plotter's connection to the Model's data acquisition: a worker thread (client::Worker,
// polling at poll_period_ms, at once when the GUI asks for something new) that finds the
// Model (`model0`) in the naming service, lists its channels, keeps one DAQ subscription for the
// ids being plotted and re-makes it when the ids change, when the Model is restarted or reloaded,
// when batches stop coming while the Model runs, and when a reloaded scene gives subscribed ids
// other shapes or units (which moves values within a sample). The Model pushes sample batches to
// a DataConsumer servant in this process; they wait in an inbox until the GUI takes them (after a
// reset or reload they are held until the worker has checked the layout against a fresh channel
// listing). The GUI only reads status snapshots, takes batches and says which ids it wants, so a
// dead or slow Model never blocks it. No Qt here; CORBA stays in the .cc files.

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/client/worker.h"
#include "channel_layout.h"

namespace caliper::plotter {

/// A batch of samples of the current subscription, without CORBA.
struct ReceivedBatch {
  uint64_t subscription = 0;
  uint64_t number = 0;                                      ///< 1, 2, 3, ... per subscription
  std::shared_ptr<const std::vector<SubscribedId>> layout;  ///< the subscription's ids
  std::vector<double> times;                                ///< simulated time of each sample [s]
  size_t values_per_sample = 0;
  std::vector<double> data;            ///< times.size() * values_per_sample values
  std::vector<std::string> stale_ids;  ///< subscribed ids the Model no longer has (NaN)
  uint64_t model_layout = 1;  ///< the Model's layout number: grows when a reload moved the values
};

/// What the GUI reads: a copy of what the worker last learnt.
struct LinkStatus {
  bool connected = false;         ///< the Model answered the last poll
  std::string message;            ///< why not connected, or the last problem
  std::string instance;           ///< the Model's instance name
  std::string state;              ///< EMPTY, STOPPED, RUNNING, PAUSED, FAULTED
  std::string scene;              ///< file of the loaded scene
  double sim_time = 0;            ///< [s]
  double time_step = 0;           ///< [s]
  uint64_t channels_version = 0;  ///< changes whenever `channels` is listed anew
  std::vector<ChannelEntry> channels;
  std::vector<std::string> subscribed;  ///< ids of the current subscription
  std::vector<std::string> missing;     ///< wanted ids the connected Model does not have
  uint64_t subscription = 0;            ///< the current subscription (0: none)
  uint64_t subscriptions_made = 0;      ///< counts successful subscribe calls
  uint64_t batches_received = 0;        ///< of the current subscriptions, since start
  uint64_t batches_missing = 0;         ///< batch numbers skipped (the Model dropped them)
  /// batches numbered below one already taken, left out (see BatchSequence)
  uint64_t batches_late = 0;
  uint64_t batches_dropped = 0;         ///< dropped here: the GUI took none for too long
  uint64_t batches_discarded = 0;  ///< held after a reset or reload, of a layout that had changed
  uint64_t layout_resubscriptions = 0;  ///< subscribed again: ids changed shape or unit
  uint64_t consumer_failures = 0;       ///< batches the consumer servant could not take in
};

/// The worker, its subscription and its inbox. Every method returns at once.
class DaqLink {
 public:
  struct Options {
    std::string nameservice;          ///< corbaname::HOST:PORT; "" for the default
    std::string instance = "model0";  ///< the Model's instance name
    /// Every call to the Model (set on its reference) and to the naming service's root context;
    /// the naming service's other contexts follow the ORB's own call timeout.
    int call_timeout_ms = 1500;
    int poll_period_ms = 250;        ///< status (and channels when the scene changed)
    int reconnect_period_ms = 1000;  ///< looking the Model up again while none is reachable
    int relist_period_ms = 5000;     ///< listing the channels again (also on a new scene)
    /// Re-subscribe when the Model runs and this much simulated (and wall) time passed without a
    /// batch [s]; longer when samples are sparse (see QuietThreshold).
    double silence_s = 2.0;
    /// The unsubscribe call when closing (none when the Model was found gone) [ms].
    int final_call_timeout_ms = 300;
    size_t inbox_batches = 4096;  ///< batches kept for the GUI before the oldest are dropped
  };

  /// Uses the process's ORB (initialises one when there is none), activates the consumer servant
  /// in its RootPOA and starts the worker.
  explicit DaqLink(Options options);
  /// Ends the subscription and stops the worker: waits for a call under way (at most the call
  /// timeout), makes no further call but the unsubscribe (at most final_call_timeout_ms, none
  /// when the Model was found gone).
  ~DaqLink();
  DaqLink(const DaqLink&) = delete;
  DaqLink& operator=(const DaqLink&) = delete;

  /// A copy of the latest status (cheap enough for a few calls a second).
  LinkStatus status() const;
  /// The ids to stream (whole DAQ ids, not elements) and one sample every `every_n_steps` steps;
  /// the worker subscribes anew when they differ from the current subscription.
  void Want(std::vector<std::string> ids, uint32_t every_n_steps);
  /// Moves out the batches received since the last call, oldest first.
  std::vector<ReceivedBatch> TakeBatches();
  /// Lists the channels again at the next poll.
  void Relist();
  /// Lists the channels and subscribes anew at the next poll, if `subscription` is still the
  /// current one: its batches do not fit its layout (`why` goes into the status message).
  void Resubscribe(uint64_t subscription, const std::string& why);

  /// The options it was made with.
  const Options& options() const { return options_; }
  /// The stringified reference of the consumer the Model pushes batches to (what the link gives
  /// the Model at each subscribe).
  std::string ConsumerReference() const;

  struct Impl;    ///< the worker's CORBA state
  struct Shared;  ///< shared with the consumer servant

 private:
  struct Request;  ///< what the GUI asked for since the last poll
  // on the worker thread only, from here on
  /// A tick: polls, then asks for the next at once when the GUI asked for something meanwhile.
  void Tick();
  void PollOnce();
  Request TakeRequest();
  /// Throws when the link closes: a poll makes no further call.
  void CheckClosing() const;
  void SetMessage(const std::string& message);
  /// Forgets the Model after a system exception: it is looked up again.
  void Lost(const std::string& why);
  /// Looks the Model up, not more often than reconnect_period_ms; true when found.
  bool LookUp();
  void Poll(const Request& request);
  /// The Model's channels now; true when they differ from the last listing.
  bool ListChannels(const std::string& scene);
  void EndForeignSubscriptions();
  /// Ends the current subscription and makes one for `ids` (none when empty) laid out as the
  /// channels listed last say; a system exception propagates (the Model is gone).
  void Subscribe(const std::vector<std::string>& ids, uint32_t every, double sim_time);
  /// Ends the subscription when closing.
  void Close();

  Options options_;
  std::unique_ptr<Impl> impl_;
  std::shared_ptr<Shared> shared_;
  mutable std::mutex mutex_;  // guards the fields below
  bool relist_ = false;
  uint64_t resubscribe_ = 0;  // the subscription to replace (0: none)
  std::string resubscribe_why_;
  std::vector<std::string> wanted_;
  uint32_t every_n_steps_ = 1;
  uint64_t wanted_version_ = 0;
  LinkStatus status_;
  std::unique_ptr<client::Worker> worker_;  // its hooks use everything above
};

}  // namespace caliper::plotter
