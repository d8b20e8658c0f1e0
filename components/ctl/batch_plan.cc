#include "batch_plan.h"

#include <algorithm>

namespace caliper::ctl {

const char* ToString(Outcome::State state) {
  switch (state) {
    case Outcome::State::kPending: return "pending";
    case Outcome::State::kRunning: return "running";
    case Outcome::State::kDone: return "done";
    case Outcome::State::kFailed: return "failed";
  }
  return "?";
}

BatchPlan::BatchPlan(size_t runs, int max_attempts)
    : max_attempts_(std::max(1, max_attempts)), outcomes_(runs), live_(runs), live_model_(runs) {
  for (size_t i = 0; i < runs; ++i) waiting_.push_back(i);
}

std::optional<BatchPlan::Ticket> BatchPlan::Next(const std::string& model,
                                                 std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto deadline = std::chrono::steady_clock::now() + wait;
  // entries of runs that ended meanwhile (a late result) are dropped on the way
  auto skip_ended = [this] {
    while (!waiting_.empty()) {
      const Outcome& o = outcomes_[waiting_.front()];
      if (o.state != Outcome::State::kDone && o.state != Outcome::State::kFailed) return;
      waiting_.pop_front();
    }
  };
  skip_ended();
  while (!closed_ && waiting_.empty() && ended_ != outcomes_.size() &&
         changed_.wait_until(lock, deadline) != std::cv_status::timeout)
    skip_ended();
  skip_ended();
  if (!closed_ && !waiting_.empty()) {
    const size_t run = waiting_.front();
    waiting_.pop_front();
    Outcome& o = outcomes_[run];
    o.state = Outcome::State::kRunning;
    ++o.attempts;
    const Ticket ticket{run, next_token_++};
    live_[run].insert(ticket.token);
    live_model_[run] = model;
    return ticket;
  }
  return std::nullopt;
}

bool BatchPlan::Live(const Ticket& ticket) const { return live_[ticket.run].count(ticket.token) > 0; }

void BatchPlan::Release(const Ticket& ticket) { live_[ticket.run].erase(ticket.token); }

bool BatchPlan::Complete(const Ticket& ticket, Outcome result) {
  std::lock_guard<std::mutex> lock(mutex_);
  Outcome& o = outcomes_[ticket.run];
  Release(ticket);
  if (closed_ || o.state == Outcome::State::kDone || o.state == Outcome::State::kFailed)
    return false;
  result.state = Outcome::State::kDone;
  result.retries = std::move(o.retries);
  result.attempts = o.attempts;
  o = std::move(result);
  ++ended_;
  changed_.notify_all();
  return true;
}

void BatchPlan::Fail(const Ticket& ticket, const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  // an attempt already given up on does not decide the run: the one under way does
  if (!Live(ticket)) return;
  Outcome& o = outcomes_[ticket.run];
  Release(ticket);
  if (closed_ || o.state == Outcome::State::kDone || o.state == Outcome::State::kFailed) return;
  o.state = Outcome::State::kFailed;
  o.reason = reason;
  o.model = live_model_[ticket.run];
  ++ended_;
  changed_.notify_all();
}

void BatchPlan::Retry(const Ticket& ticket, const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!Live(ticket)) return;
  Outcome& o = outcomes_[ticket.run];
  Release(ticket);
  if (o.state == Outcome::State::kDone || o.state == Outcome::State::kFailed) return;
  o.retries.push_back({live_model_[ticket.run], reason});
  if (o.attempts >= max_attempts_) {
    o.state = Outcome::State::kFailed;
    o.reason = "gave up after " + std::to_string(o.attempts) + " attempts";
    ++ended_;
  } else {
    o.state = Outcome::State::kPending;
    waiting_.push_front(ticket.run);  // first in line: it has waited longest
  }
  changed_.notify_all();
}

void BatchPlan::Abandon(const Ticket& ticket, bool stopping) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!Live(ticket)) return;
  Outcome& o = outcomes_[ticket.run];
  Release(ticket);
  if (o.state == Outcome::State::kDone || o.state == Outcome::State::kFailed) return;
  if (o.attempts > 0) --o.attempts;
  o.stopped = o.stopped || stopping;
  o.state = Outcome::State::kPending;
  waiting_.push_front(ticket.run);
  changed_.notify_all();
}

void BatchPlan::Close() {
  std::lock_guard<std::mutex> lock(mutex_);
  closed_ = true;
  waiting_.clear();
  changed_.notify_all();
}

bool BatchPlan::finished() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return ended_ == outcomes_.size();
}

void BatchPlan::WaitForChange(std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(mutex_);
  const size_t ended = ended_;
  changed_.wait_for(lock, wait, [&] { return ended_ != ended; });
}

size_t BatchPlan::done() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<size_t>(std::count_if(outcomes_.begin(), outcomes_.end(), [](const Outcome& o) {
    return o.state == Outcome::State::kDone;
  }));
}

size_t BatchPlan::failed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<size_t>(std::count_if(outcomes_.begin(), outcomes_.end(), [](const Outcome& o) {
    return o.state == Outcome::State::kFailed;
  }));
}

size_t BatchPlan::running() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<size_t>(std::count_if(outcomes_.begin(), outcomes_.end(), [](const Outcome& o) {
    return o.state == Outcome::State::kRunning;
  }));
}

std::vector<Outcome> BatchPlan::outcomes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return outcomes_;
}

}  // namespace caliper::ctl
