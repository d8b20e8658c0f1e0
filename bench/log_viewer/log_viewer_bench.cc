// The Log Viewer with 100,000 records: the cost of what a user waits for, against a 100 ms
// responsiveness budget. A synthetic session (8 components, 40 categories, all priorities) is
// written as a session log, then timed:
//   load       ReadSessionFile + LogModel::Replace (File > Open)
//   regex      a regular expression typed into the text filter (every message searched)
//   text       the same as a plain substring
//   priority   the minimum priority changed while the regex stays (only that filter recomputed)
//   category   a category subtree unchecked
//   reset      LogModel::SetFilter back to no filter: the model reset, with a QTableView attached
//   append     a live batch of 1,000 records appended to the 100,000 (beginInsertRows)
//   paint      QTableView::grab() of a 1280x720 table scrolled to the end
// Each figure is the median of --repeats runs (default 5) in milliseconds, then a RATIO line per
// operation: its share of the 100 ms budget (target < 1). Then the heap a RecordStore and a
// LogModel hold per record (glibc's mallinfo2, in-use bytes before and after). Options:
// --records N, --repeats N.
// Runs on QT_QPA_PLATFORM=offscreen (set when unset).
#include <malloc.h>
#include <unistd.h>

#include <QApplication>
#include <QHeaderView>
#include <QTableView>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "log_filter.h"
#include "log_model.h"
#include "record_store.h"
#include "session_file.h"

namespace caliper::bench {
namespace {

using Clock = std::chrono::steady_clock;
using log_viewer::FilterSettings;
using log_viewer::LogModel;

int records = 100000;
int repeats = 5;
constexpr double kBudgetMs = 100.0;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Median over `repeats` of one call of `measured` [ms]; `before` runs untimed ahead of each.
double TimeMs(const std::function<void()>& before, const std::function<void()>& measured) {
  std::vector<double> runs;
  for (int r = 0; r < repeats; ++r) {
    before();
    const auto start = Clock::now();
    measured();
    runs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  return Median(runs);
}

// A session of `n` records from 8 components over 40 categories, priorities weighted like a
// real run (mostly DEBUG and INFO), messages of 20 to 80 characters.
std::vector<logging::Record> Session(int n, uint64_t first_seq) {
  std::mt19937 rng(42 + static_cast<unsigned>(first_seq));
  const char* components[] = {"model0",    "model1", "pd0",      "pd1",
                              "renderer0", "main0",  "plotter0", "logger0"};
  const char* types[] = {"model",    "model", "pd_controller", "pd_controller",
                         "renderer", "main",  "plotter",       "logger"};
  const char* areas[] = {"rtc", "physics", "daq", "observer", "tendons"};
  const char* muscles[] = {"biceps", "triceps", "deltoid", "brachialis", "anconeus"};
  const int priorities[] = {logging::kDebug, logging::kDebug, logging::kDebug,  logging::kInfo,
                            logging::kInfo,  logging::kInfo,  logging::kNotice, logging::kWarn,
                            logging::kError, logging::kCrit};
  std::vector<logging::Record> out;
  out.reserve(static_cast<size_t>(n));
  char message[160];
  for (int i = 0; i < n; ++i) {
    logging::Record r;
    const int c = static_cast<int>(rng() % 8);
    r.time_us = 1709632800LL * 1000000 + static_cast<int64_t>(first_seq + i) * 2000;
    r.priority = priorities[rng() % 10];
    r.component = components[c];
    r.category = std::string("caliper.") + types[c] + "." + areas[rng() % 5];
    r.host = c < 4 ? "node1" : "desk";
    r.pid = 4100 + c;
    r.source = r.host + ":" + std::to_string(r.pid) + ":1709632790";
    r.seq = first_seq + static_cast<uint64_t>(i);
    const char* muscle = muscles[rng() % 5];
    const unsigned value = rng() % 100000;
    switch (rng() % 6) {
      case 0:
        std::snprintf(message, sizeof message, "step %d: %.3f ms", i, value / 1e4);
        break;
      case 1:
        std::snprintf(message, sizeof message, "tendon %s slack for %u steps", muscle, value % 100);
        break;
      case 2:
        std::snprintf(message, sizeof message, "observer batch dropped (stale seq %d)", i);
        break;
      case 3:
        std::snprintf(message, sizeof message, "set %s.%s.stiffness = %.4f N/m",
                      r.component.c_str(), muscle, value / 10.0);
        break;
      case 4:
        std::snprintf(message, sizeof message, "command joint %s %.3f rad (tracking error %.4f)",
                      muscle, value / 3e4, value / 1e9);
        break;
      default:
        std::snprintf(message, sizeof message,
                      "lost model%u: TRANSIENT (connect failed); retrying in 1 s", value % 2);
        break;
    }
    r.message = message;
    out.push_back(std::move(r));
  }
  return out;
}

// heap bytes in use
size_t HeapInUse() { return mallinfo2().uordblks; }

// heap held per record by what `fill` builds from `n` records (freed again before returning)
template <typename T>
double BytesPerRecord(int n, const std::function<void(T&, std::vector<logging::Record>)>& fill) {
  malloc_trim(0);
  const size_t before = HeapInUse();
  auto holder = std::make_unique<T>();
  fill(*holder, Session(n, 1));
  return (static_cast<double>(HeapInUse()) - static_cast<double>(before)) / n;
}

void Report(const char* name, double ms) { std::printf("log_viewer_%s_ms %.2f\n", name, ms); }

void Ratio(const char* name, double ms) {
  std::printf("RATIO log_viewer_%s_of_100ms_budget %.3f (target < 1)\n", name, ms / kBudgetMs);
}

int Run(int argc, char** argv) {
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--records") == 0) records = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--repeats") == 0) repeats = std::atoi(argv[i + 1]);
  }
  if (std::getenv("QT_QPA_PLATFORM") == nullptr) setenv("QT_QPA_PLATFORM", "offscreen", 1);
  int qt_argc = 1;
  QApplication app(qt_argc, argv);

  const std::vector<logging::Record> session = Session(records, 1);
  const std::string path = "/tmp/log_viewer_bench_" + std::to_string(getpid()) + ".log";
  {
    std::vector<const logging::Record*> all;
    for (const auto& r : session) all.push_back(&r);
    log_viewer::WriteSessionFile(path, all, "log_viewer_bench");
  }
  std::printf("# Log Viewer with %d records (median of %d runs; budget %.0f ms per action)\n",
              records, repeats, kBudgetMs);

  LogModel model;
  QTableView table;
  table.setModel(&model);
  table.verticalHeader()->setSectionResizeMode(QHeaderView::Fixed);
  table.horizontalHeader()->setStretchLastSection(true);
  table.resize(1280, 720);
  table.show();
  QApplication::processEvents();

  // File > Open: parse every line, then one model reset
  const double load = TimeMs([&] { model.Replace({}); },
                             [&] { model.Replace(log_viewer::ReadSessionFile(path).records); });
  std::vector<logging::Record> parsed;
  const double parse = TimeMs([] {}, [&] { parsed = log_viewer::ReadSessionFile(path).records; });
  std::remove(path.c_str());

  FilterSettings none;
  FilterSettings regex;
  regex.text = "tendon (biceps|triceps) slack for [0-9]+ steps";
  regex.regex = true;
  FilterSettings text;
  text.text = "TRANSIENT";
  FilterSettings priority = regex;
  priority.max_priority = logging::kWarn;
  FilterSettings category;
  category.excluded_categories = {"caliper.model.physics", "caliper.pd_controller"};

  const double regex_ms = TimeMs([&] { model.SetFilter(none); }, [&] { model.SetFilter(regex); });
  const size_t regex_rows = model.view().rows().size();
  const double text_ms = TimeMs([&] { model.SetFilter(none); }, [&] { model.SetFilter(text); });
  const size_t text_rows = model.view().rows().size();
  const double priority_ms =
      TimeMs([&] { model.SetFilter(regex); }, [&] { model.SetFilter(priority); });
  const size_t priority_rows = model.view().rows().size();
  const double category_ms =
      TimeMs([&] { model.SetFilter(none); }, [&] { model.SetFilter(category); });
  const size_t category_rows = model.view().rows().size();
  const double reset_ms =
      TimeMs([&] { model.SetFilter(category); }, [&] { model.SetFilter(none); });

  // a live batch of 1,000 records on top of the session
  uint64_t next_seq = static_cast<uint64_t>(records) + 1;
  std::vector<std::vector<logging::Record>> batches;
  for (int r = 0; r < repeats; ++r) {
    batches.push_back(Session(1000, next_seq));
    next_seq += 1000;
  }
  int batch = 0;
  model.SetFilter(none);
  const double append_ms = TimeMs([] {},
                                  [&] {
                                    model.Append(std::move(batches[static_cast<size_t>(batch++)]));
                                    table.scrollToBottom();
                                  });
  QApplication::processEvents();
  const double paint_ms = TimeMs([] {}, [&] { table.grab(); });

  std::printf(
      "log_viewer_records %zu (rows: regex %zu, text %zu, regex+priority %zu, "
      "category %zu)\n",
      model.store().size(), regex_rows, text_rows, priority_rows, category_rows);
  Report("load", load);
  std::printf("# of which ReadSessionFile (logging::ParseLine per line): %.2f ms\n", parse);
  Report("regex_filter", regex_ms);
  Report("text_filter", text_ms);
  Report("priority_filter", priority_ms);
  Report("category_filter", category_ms);
  Report("model_reset", reset_ms);
  Report("append_1000", append_ms);
  Report("paint", paint_ms);
  const double store_bytes = BytesPerRecord<log_viewer::RecordStore>(
      records,
      [](log_viewer::RecordStore& s, std::vector<logging::Record> r) { s.Append(std::move(r)); });
  const double model_bytes = BytesPerRecord<LogModel>(
      records, [](LogModel& m, std::vector<logging::Record> r) { m.Append(std::move(r)); });
  std::printf("log_viewer_store_bytes_per_record %.1f\n", store_bytes);
  std::printf("log_viewer_model_bytes_per_record %.1f (store, filter bits and rows)\n",
              model_bytes);
  std::printf("# at the 1,000,000-record cap: %.0f MB\n", model_bytes * 1e6 / 1048576);
  Ratio("load", load);
  Ratio("regex_filter", regex_ms);
  Ratio("text_filter", text_ms);
  Ratio("priority_filter", priority_ms);
  Ratio("category_filter", category_ms);
  Ratio("model_reset", reset_ms);
  Ratio("append_1000", append_ms);
  Ratio("paint", paint_ms);
  return 0;
}

}  // namespace
}  // namespace caliper::bench

int main(int argc, char** argv) { return caliper::bench::Run(argc, argv); }
