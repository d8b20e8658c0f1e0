#pragma once
// The bookkeeping of a batch run, without CORBA: which runs wait, which Model has which, the
// retries with their reasons, and the rule that every run ends exactly once (the first result
// wins; a late duplicate from a Model that was given up on is dropped).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace caliper::ctl {

struct Retry {
  std::string model;   // where the attempt ran (model1@hostb)
  std::string reason;  // why it was given up (TRANSIENT, no answer for 5 s, ...)
};

struct Outcome {
  enum class State { kPending, kRunning, kDone, kFailed };
  State state = State::kPending;
  std::string model;            // the Model whose result counts
  std::string reason;           // why it failed
  std::vector<Retry> retries;
  int attempts = 0;
  double wall_s = 0;            // dispatch to result, as the client saw it [s]
  double load_wall_s = 0;       // the Model's scene import and build [s]
  double step_wall_s = 0;       // the Model's stepping and sampling [s]
  uint64_t steps = 0;
  size_t samples = 0;
  bool stopped = false;         // an attempt was under way when the batch was stopped
};

const char* ToString(Outcome::State state);

class BatchPlan {
 public:
  /// `runs` runs, each tried at most `max_attempts` times.
  BatchPlan(size_t runs, int max_attempts);

  /// One attempt of one run.
  struct Ticket {
    size_t run = 0;
    uint64_t token = 0;
  };
  /// The next waiting run for `model`, waiting at most `wait`; nothing when none waits (then
  /// see finished()).
  std::optional<Ticket> Next(const std::string& model, std::chrono::milliseconds wait);
  /// The attempt's result; true when it is the run's first (the caller keeps it), false for a
  /// run that had already ended.
  bool Complete(const Ticket& ticket, Outcome result);
  /// The run failed for a reason retrying cannot change (a physics fault, a bad id).
  void Fail(const Ticket& ticket, const std::string& reason);
  /// The attempt is lost (the Model died, the link went down, no answer): the run waits again,
  /// unless it ended meanwhile or ran out of attempts. Once per ticket; later calls do nothing.
  void Retry(const Ticket& ticket, const std::string& reason);
  /// The batch is being stopped (SIGINT, SIGTERM: the Models go down with it): the attempt does
  /// not count, and the run waits again without a retry, so that the summary says it was
  /// interrupted rather than failed.
  /// `stopping`: the batch is being stopped (the run is then said to have been stopped while it
  /// ran, if it does not end otherwise).
  void Abandon(const Ticket& ticket, bool stopping = false);
  /// The batch was stopped and its outcomes are about to be reported: from now on a result
  /// (Complete, Fail) no longer ends its run, which stays pending or running, so that what the
  /// summary says of each run cannot change under it (and no result file appears beside a run
  /// the summary calls interrupted). Nothing is handed out any more either.
  void Close();

  bool finished() const;
  /// Returns when a run ends or `wait` has passed.
  void WaitForChange(std::chrono::milliseconds wait);
  size_t done() const;
  size_t failed() const;
  size_t running() const;
  size_t size() const { return outcomes_.size(); }
  std::vector<Outcome> outcomes() const;

 private:
  bool Live(const Ticket& ticket) const;
  void Release(const Ticket& ticket);

  int max_attempts_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<size_t> waiting_;
  std::vector<Outcome> outcomes_;
  std::vector<std::set<uint64_t>> live_;   // tokens of the attempts in flight, per run
  std::vector<std::string> live_model_;    // the model of the newest attempt, per run
  uint64_t next_token_ = 1;
  size_t ended_ = 0;
  bool closed_ = false;
};

}  // namespace caliper::ctl
