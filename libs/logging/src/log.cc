#include "caliper/logging/log.h"

#include <log4cpp/LoggingEvent.hh>
#include <log4cpp/OstreamAppender.hh>
#include <log4cpp/PatternLayout.hh>
#include <unistd.h>

#include <iostream>
#include <mutex>

#include "caliper/core/system.h"

namespace caliper::logging {

namespace {
std::mutex identity_mutex;
Identity identity;
}  // namespace

void Initialize(const std::string& component_type, int console_priority) {
  {
    std::lock_guard<std::mutex> lock(identity_mutex);
    identity.component_type = component_type;
    identity.instance = component_type;
    identity.host = core::HostName();
    identity.pid = getpid();
    identity.source = identity.host + ":" + std::to_string(identity.pid) + ":" +
                      std::to_string(core::NowMicros());
  }
  auto& root = log4cpp::Category::getInstance("caliper");
  root.setPriority(log4cpp::Priority::DEBUG);
  auto* console = new log4cpp::OstreamAppender("console", &std::cerr);
  auto* layout = new log4cpp::PatternLayout();
  layout->setConversionPattern("%d{%H:%M:%S,%l} %-5p [%c] %m%n");
  console->setLayout(layout);
  console->setThreshold(console_priority);
  root.addAppender(console);
}

void SetInstance(const std::string& instance) {
  std::lock_guard<std::mutex> lock(identity_mutex);
  identity.instance = instance;
}

Identity CurrentIdentity() {
  std::lock_guard<std::mutex> lock(identity_mutex);
  return identity;
}

log4cpp::Category& Get(const std::string& area) {
  std::string type;
  {
    std::lock_guard<std::mutex> lock(identity_mutex);
    type = identity.component_type.empty() ? "process" : identity.component_type;
  }
  return log4cpp::Category::getInstance("caliper." + type + "." + area);
}

void AddAppender(log4cpp::Appender* appender) {
  log4cpp::Category::getInstance("caliper").addAppender(appender);
}

Record MakeRecord(const log4cpp::LoggingEvent& event) {
  Record r;
  r.time_us = static_cast<int64_t>(event.timeStamp.getSeconds()) * 1000000 +
              event.timeStamp.getMicroSeconds();
  r.priority = event.priority;
  r.category = event.categoryName;
  r.message = event.message;
  std::lock_guard<std::mutex> lock(identity_mutex);
  r.component = identity.instance;
  r.host = identity.host;
  r.pid = identity.pid;
  r.source = identity.source;
  return r;
}

void Shutdown() { log4cpp::Category::shutdown(); }

}  // namespace caliper::logging
