#include "logger_component.h"

#include <unistd.h>

#include "caliper/core/system.h"
#include "caliper/logging/batching_appender.h"
#include "caliper/logging/log.h"

namespace caliper::logger {

namespace {

/// The logger's own records go straight into its store.
class LocalSink : public logging::RecordSink {
 public:
  explicit LocalSink(LoggerComponent* component) : component_(component) {}
  void Send(const std::vector<logging::Record>& batch) override {
    try {
      component_->Submit(batch, true);
    } catch (const std::exception& e) {
      throw logging::SinkUnavailable(e.what());
    }
  }

 private:
  LoggerComponent* component_;
};

}  // namespace

std::vector<core::ConfigKey> LoggerComponent::ConfigKeys() {
  using Type = core::ConfigKey::Type;
  return {
      {"logger.directory", Type::kString, "~/.local/state/caliper/logs",
       "directory of the session log files"},
      {"logger.session", Type::kString, "", "session id in the file name ('' = p<pid>)"},
      {"logger.memory_records", Type::kInt, "200000", "records kept in memory for queries", 1,
       1e8},
  };
}

LoggerComponent::LoggerComponent(rtc::Runtime& runtime) : runtime_(runtime) {}

rtc::ReturnCode LoggerComponent::OnInitialize() {
  const auto& config = runtime_.config();
  std::string session = config.GetString("logger.session");
  if (session.empty()) session = "p" + std::to_string(getpid());
  store_ = std::make_unique<LogStore>(core::ExpandHome(config.GetString("logger.directory")),
                                      session,
                                      static_cast<size_t>(config.GetInt("logger.memory_records")));
  logging::AppenderOptions options;
  options.spool_dir = core::ExpandHome(config.GetString("log.spool_dir"));
  options.spool_name = "logger-" + std::to_string(getpid());
  options.replay_orphans = false;  // other components' spools are theirs to replay
  logging::AddAppender(
      new logging::BatchingAppender("session-file", std::make_unique<LocalSink>(this), options));
  logging::Get("store").notice("session log %s", store_->path().c_str());
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode LoggerComponent::OnFinalize() {
  logging::Get("store").notice("session log closed: %llu records",
                               static_cast<unsigned long long>(store_->size()));
  return rtc::ReturnCode::kOk;
}

std::vector<StoredRecord> LoggerComponent::Submit(const std::vector<logging::Record>& records,
                                                  bool own) {
  if (!store_) throw NotAccepting("the logger is not initialized");
  if (!own && runtime_.lifecycle().state() != rtc::State::kActive)
    throw NotAccepting("the logger is not ACTIVE");
  std::vector<StoredRecord> stored;
  try {
    stored = store_->Submit(records);
  } catch (const std::runtime_error& e) {
    // a full disk: the senders keep the batch in their spools and send it again
    bool first = false;
    {
      std::lock_guard<std::mutex> lock(write_mutex_);
      ++refused_batches_;
      if (!write_failing_) {
        first = write_failing_ = true;
        failing_since_us_ = core::NowMicros();
      }
    }
    if (first)
      logging::Get("store").error(
          "%s; records are refused until it can be written again (their senders keep them in "
          "their spools, within log.spool_max, and send them again)",
          e.what());
    throw NotAccepting(e.what());
  }
  {
    std::lock_guard<std::mutex> lock(write_mutex_);
    if (write_failing_ && !stored.empty()) {
      write_failing_ = false;
      logging::Get("store").notice(
          "session log %s written again after %.1f s; %llu batches were refused meanwhile",
          store_->path().c_str(), (core::NowMicros() - failing_since_us_) / 1e6,
          static_cast<unsigned long long>(refused_batches_));
      refused_batches_ = 0;
    }
  }
  std::lock_guard<std::mutex> lock(listener_mutex_);
  if (listener_ && !stored.empty()) listener_(stored);
  return stored;
}

std::vector<StoredRecord> LoggerComponent::Query(const QueryFilter& filter) const {
  if (!store_) return {};
  return store_->Query(filter);
}

std::string LoggerComponent::session_file() const { return store_ ? store_->path() : ""; }

void LoggerComponent::SetListener(
    std::function<void(const std::vector<StoredRecord>&)> listener) {
  std::lock_guard<std::mutex> lock(listener_mutex_);
  listener_ = std::move(listener);
}

}  // namespace caliper::logger
